#pragma once
/// \file The report of a learning run (`learn --report DIR`): DIR/convergence.csv, one row per
/// iteration of the loop's history (its columns: convergence_csv), and DIR/report.json, the
/// learned material's training provenance. Both are written atomically (core/atomic_file.hpp).
#include <elastolearn/learn/learning_loop.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn::io {

/// The convergence table: a header line, then per record its iteration, forward error (rms, max,
/// mean [m]), control force RMS [N], space-time objective (initial, final, iterations), modes,
/// centres, correction misfit and target [N] and the seconds of each stage, comma-separated
/// (doubles as `std::ostream` writes them by default).
std::string convergence_csv(const std::vector<learn::IterationRecord>& history);

/// Write `dir`/convergence.csv (convergence_csv of `history`) and `dir`/report.json (`summary`).
/// `dir` is created if missing. Throws InputError naming the file that cannot be written.
void write_learning_report(const std::filesystem::path& dir,
    const std::vector<learn::IterationRecord>& history, const nlohmann::json& summary);

} // namespace elastolearn::io
