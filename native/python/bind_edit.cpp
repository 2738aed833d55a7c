// Bindings for edit (filled in by the edit work; empty until then).
#include "convert.hpp"

namespace topstoc::python {

void bind_edit(py::module_&) {}

}  // namespace topstoc::python
