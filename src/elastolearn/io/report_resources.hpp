#pragma once
/// \file Where the files a learning report is made with live: the plotting script, the HTML
/// template and viewer, and three.js (share/elastolearn/report/ in an installed layout, a copy in
/// the build tree made at configure time).
#include <filesystem>

namespace elastolearn::io {

/// The first of these that holds report_plots.py: $ELASTOLEARN_SHARE_DIR/report, then
/// <executable folder>/../share/elastolearn/report (an installed layout), the install prefix's
/// share/elastolearn/report, and the build tree's copy. Throws InputError("report", ...) listing
/// the folders looked in when none does.
std::filesystem::path report_resource_dir();

/// The Python interpreter that draws the plots: $ELASTOLEARN_PYTHON if set, else
/// /usr/bin/python3 (Debian's, which python3-matplotlib installs into).
std::filesystem::path report_python();

} // namespace elastolearn::io
