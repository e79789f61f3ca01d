#include "arrays.hpp"

#include <elastolearn/core/error.hpp>

#include <algorithm>
#include <cstring>

namespace elastolearn::python {

namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i)
    s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

[[noreturn]] void wrong_shape(const py::array& a, const std::string& name, const char* expected) {
  throw InputError(
      name, std::string("expected an array of shape ") + expected + ", got " + shape_of(a));
}

} // namespace

py::array_t<double> to_array(const Positions& x) {
  py::array_t<double> a({ static_cast<py::ssize_t>(x.rows()), py::ssize_t(3) });
  std::copy_n(x.data(), x.size(), a.mutable_data());
  return a;
}

py::array_t<double> to_array(const std::vector<Positions>& frames, Eigen::Index n) {
  py::array_t<double> a(
      { static_cast<py::ssize_t>(frames.size()), static_cast<py::ssize_t>(n), py::ssize_t(3) });
  double* out = a.mutable_data();
  for (const Positions& x : frames) {
    ELASTOLEARN_CHECK(x.rows() == n, "frames of different sizes");
    out = std::copy_n(x.data(), x.size(), out);
  }
  return a;
}

py::array_t<double> to_array(const std::vector<VecX>& frames, Eigen::Index n) {
  py::array_t<double> a(
      { static_cast<py::ssize_t>(frames.size()), static_cast<py::ssize_t>(n), py::ssize_t(3) });
  double* out = a.mutable_data();
  for (const VecX& x : frames) {
    ELASTOLEARN_CHECK(x.size() == 3 * n, "frames of different sizes");
    out = std::copy_n(x.data(), x.size(), out);
  }
  return a;
}

template <int Cols>
py::array_t<int> to_array(const Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor>& m) {
  py::array_t<int> a({ static_cast<py::ssize_t>(m.rows()), py::ssize_t(Cols) });
  std::copy_n(m.data(), m.size(), a.mutable_data());
  return a;
}
template py::array_t<int> to_array(const Tets&);
template py::array_t<int> to_array(const Faces&);
template py::array_t<int> to_array(const Edges&);

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<int> to_array(const std::vector<int>& v) {
  py::array_t<int> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<bool> to_array(
    const observe::ValidityMask& valid, Eigen::Index frames, Eigen::Index k) {
  py::array_t<bool> a({ static_cast<py::ssize_t>(frames), static_cast<py::ssize_t>(k) });
  bool* out = a.mutable_data();
  if (valid.size() == 0)
    std::fill_n(out, frames * k, true);
  else
    for (Eigen::Index i = 0; i < valid.size(); ++i)
      out[i] = valid.data()[i] != 0;
  return a;
}

Positions to_positions(const DoubleArray& a, const std::string& name) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    wrong_shape(a, name, "(n, 3)");
  Positions x(a.shape(0), 3);
  std::copy_n(a.data(), x.size(), x.data());
  return x;
}

std::vector<Positions> to_frames(const DoubleArray& a, const std::string& name) {
  if (a.ndim() != 3 || a.shape(2) != 3)
    wrong_shape(a, name, "(T, n, 3)");
  std::vector<Positions> frames(static_cast<size_t>(a.shape(0)), Positions(a.shape(1), 3));
  const double* in = a.data();
  for (Positions& x : frames) {
    std::copy_n(in, x.size(), x.data());
    in += x.size();
  }
  return frames;
}

template <int Cols>
Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor> to_indices(
    const IntArray& a, const std::string& name) {
  if (a.ndim() != 2 || a.shape(1) != Cols || (a.shape(0) == 0 && a.size() != 0))
    wrong_shape(a, name, Cols == 4 ? "(m, 4)" : Cols == 3 ? "(m, 3)" : "(m, 2)");
  Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor> m(a.shape(0), Cols);
  std::copy_n(a.data(), m.size(), m.data());
  return m;
}
template Tets to_indices<4>(const IntArray&, const std::string&);
template Faces to_indices<3>(const IntArray&, const std::string&);
template Edges to_indices<2>(const IntArray&, const std::string&);

std::vector<double> to_doubles(const DoubleArray& a, const std::string& name) {
  if (a.ndim() != 1)
    wrong_shape(a, name, "(k,)");
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

std::vector<int> to_ints(const IntArray& a, const std::string& name) {
  if (a.ndim() != 1)
    wrong_shape(a, name, "(k,)");
  return std::vector<int>(a.data(), a.data() + a.shape(0));
}

observe::ValidityMask to_mask(
    const MaskArray& a, Eigen::Index frames, Eigen::Index k, const std::string& name) {
  if (a.ndim() != 2 || a.shape(0) != frames || a.shape(1) != k) {
    const std::string expected = "(" + std::to_string(frames) + ", " + std::to_string(k) + ")";
    wrong_shape(a, name, expected.c_str());
  }
  observe::ValidityMask valid(frames, k);
  std::copy_n(a.data(), valid.size(), valid.data());
  return valid;
}

} // namespace elastolearn::python
