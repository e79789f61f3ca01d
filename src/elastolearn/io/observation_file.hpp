#pragma once
/// \file Observation HDF5 files (DESIGN.md "Files and formats", docs/observations.md), readable
/// and writable with h5py:
///   /observed/vertex_ids (k) i32      mesh vertex index of each observed point
///   /observed/positions (T, k, 3) f64 observed positions [m], frame by frame
///   /observed/valid (T, k) u8         optional: 1 = seen, 0 = lost (its position may be NaN)
///   /time (T) f64                     frame times [s], evenly spaced by dt
///   root attributes: format = "elastolearn-observation/1" ("/2" with /observed/valid),
///   dt (float64 [s]), plus optional
///   free-form string metadata (observe writes source, selection, noise_sigma, seed)
#include <elastolearn/observe/observation.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace elastolearn::io {

/// Write atomically (temporary file + rename): /time is start_time + t·dt; /observed/valid and
/// format version 2 if obs.valid is not empty, else version 1. The observation is validated
/// first (Observation::validate), so a written file always reads back.
/// Throws InputError naming the path (and field) on invalid data or when the file cannot be made.
/// `metadata` become string attributes on the root group ("format" and "dt" are reserved).
void write_observation_h5(const std::filesystem::path& path, const observe::Observation& obs,
    const std::map<std::string, std::string>& metadata = {});

/// Read and validate an observation file: format attribute, shapes ((k,), (T, k, 3), (T,), and
/// (T, k) of integers 0/1 for the optional /observed/valid), integer ids ≥ 0 and distinct,
/// positions finite where seen (anything, NaN included, where lost), at least one entry seen,
/// dt (a number, or a string holding one)
/// positive, /time evenly spaced by dt (each interval within 1e-6 relative).
/// It does not know the mesh: call `obs.validate(num_vertices, frames, dt, path)` against the
/// scene next. Throws InputError("<file>: <dataset>", ...) on any problem.
observe::Observation read_observation_h5(const std::filesystem::path& path);

/// The root attributes of an observation file other than "format" and "dt" (e.g. "noise_sigma"),
/// as text (numbers in shortest round-trip form). Throws InputError like read_observation_h5.
std::map<std::string, std::string> read_observation_metadata(const std::filesystem::path& path);

/// True if `path` is an HDF5 file whose root "format" attribute names an elastolearn observation
/// (any version); false for anything else, including files that cannot be opened, so that a
/// caller can choose the reader whose errors it then reports.
bool is_observation_h5(const std::filesystem::path& path);

/// Read a text list of vertex ids: integers separated by white space or commas, '#' starts a
/// comment to the end of the line. Throws InputError("<file>:<line>", ...) for a token that is
/// not a non-negative integer, and InputError(file, ...) if the file is unreadable or has no id.
std::vector<int> read_vertex_id_list(const std::filesystem::path& path);

} // namespace elastolearn::io
