// Bindings for io (filled in by the io work; empty until then).
#include "convert.hpp"

namespace topstoc::python {

void bind_io(py::module_&) {}

}  // namespace topstoc::python
