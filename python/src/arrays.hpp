#pragma once
// numpy <-> elastolearn arrays for the Python module: vertex arrays (n, 3) float64, frame series
// (T, n, 3) float64, index arrays (m, k) int32, validity masks (T, k) bool. Inputs are converted
// (forcecast) to C-ordered arrays; a wrong shape throws InputError naming the argument, which
// Python sees as elastolearn.InputError.
#include <elastolearn/core/types.hpp>
#include <elastolearn/observe/observation.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

namespace elastolearn::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IntArray = py::array_t<int, py::array::c_style | py::array::forcecast>;
using MaskArray = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

/// (n, 3) float64 copy of `x`.
py::array_t<double> to_array(const Positions& x);
/// (T, n, 3) float64 copy of `frames` (every frame n×3; T = 0 gives shape (0, n, 3)).
py::array_t<double> to_array(const std::vector<Positions>& frames, Eigen::Index n);
/// (T, n, 3) float64 copy of flat 3n frames.
py::array_t<double> to_array(const std::vector<VecX>& frames, Eigen::Index n);
/// (m, k) int32 copy of an index matrix (tets, faces, edges).
template <int Cols>
py::array_t<int> to_array(const Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor>& m);
/// (T, k) bool copy of an observation's validity mask (all true for an empty mask, which means
/// every entry was seen).
py::array_t<bool> to_array(const observe::ValidityMask& valid, Eigen::Index frames, Eigen::Index k);
/// 1-D copy.
py::array_t<double> to_array(const std::vector<double>& v);
py::array_t<int> to_array(const std::vector<int>& v);

/// (n, 3) → Positions. Throws InputError("<name>", ...) for another shape.
Positions to_positions(const DoubleArray& a, const std::string& name);
/// (T, n, 3) → frames. Throws InputError("<name>", ...) for another shape.
std::vector<Positions> to_frames(const DoubleArray& a, const std::string& name);
/// (m, Cols) → index matrix. Throws InputError("<name>", ...) for another shape.
template <int Cols>
Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor> to_indices(
    const IntArray& a, const std::string& name);
/// 1-D → vector. Throws InputError("<name>", ...) for another shape.
std::vector<double> to_doubles(const DoubleArray& a, const std::string& name);
std::vector<int> to_ints(const IntArray& a, const std::string& name);
/// (T, k) → validity mask (values as given; Observation::validate checks them). Throws
/// InputError("<name>", ...) for another shape.
observe::ValidityMask to_mask(
    const MaskArray& a, Eigen::Index frames, Eigen::Index k, const std::string& name);

} // namespace elastolearn::python
