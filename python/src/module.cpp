// The compiled module `elastolearn._elastolearn`; the package `elastolearn` (python/elastolearn)
// re-exports it. Library errors become Python exceptions with the same message: InputError (bad
// input, naming the file or field) → elastolearn.InputError, a ValueError; InternalError → a
// RuntimeError.
#include "objects.hpp"

#include <elastolearn/config.hpp>
#include <elastolearn/core/error.hpp>

PYBIND11_MODULE(_elastolearn, m) {
  namespace py = pybind11;
  using namespace elastolearn::python;
  m.doc() = "elastolearn: data-driven simulation of elastic solids (docs/python.md)";
  py::register_exception<elastolearn::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<elastolearn::InternalError>(m, "InternalError", PyExc_RuntimeError);
  bind_files(m);
  bind_scene(m);
  bind_runs(m);
  m.attr("__version__") = ELASTOLEARN_VERSION;
}
