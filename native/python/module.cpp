// The `_topstoc` extension module: registers each concept's bindings. Bindings only convert
// arrays, release the GIL and map errors; every algorithm lives in native/src.
#include <stdexcept>

#include "convert.hpp"

namespace {

// The Python class bad input is raised as (topstoc.core.support.errors.TopStocError, set by
// topstoc.core.support.native right after the import; a plain ValueError until then). Owned for the
// interpreter's lifetime: it must not be released after the interpreter has finalised.
PyObject* error_class = nullptr;

}  // namespace

PYBIND11_MODULE(_topstoc, m) {
  m.doc() = "TopStoc native engine: decimation, measurement, topology (see topstoc.core for the Python API)";
  namespace py = pybind11;
  namespace tp = topstoc::python;
  tp::bind_mesh(m);
  tp::bind_mesh_edges(m);
  tp::bind_decimate(m);
  tp::bind_io(m);
  tp::bind_hausdorff(m);
  tp::bind_topology(m);
  tp::bind_loops(m);
  tp::bind_edit(m);
  // The engine names bad input with std::invalid_argument (bindings too): it reaches Python as
  // TopStocError, so one `except TopStocError` catches every error TopStoc raises on purpose.
  py::register_exception_translator([](std::exception_ptr raised) {
    try {
      if (raised) std::rethrow_exception(raised);
    } catch (const std::invalid_argument& error) {
      PyErr_SetString(error_class ? error_class : PyExc_ValueError, error.what());
    }
  });
  m.def(
      "_set_error_class",
      [](py::object cls) {
        if (!PyType_Check(cls.ptr()) || !PyObject_IsSubclass(cls.ptr(), PyExc_ValueError))
          throw py::type_error("the error class must be a subclass of ValueError");
        Py_XDECREF(error_class);
        error_class = cls.release().ptr();
      },
      "Sets the Python class that bad-input errors of the engine are raised as (a ValueError subclass).");
}
