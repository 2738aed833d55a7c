// Bindings for loops (filled in by the loops work; empty until then).
#include "convert.hpp"

namespace topstoc::python {

void bind_loops(py::module_&) {}

}  // namespace topstoc::python
