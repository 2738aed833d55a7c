// Bindings for hausdorff (filled in by the hausdorff work; empty until then).
#include "convert.hpp"

namespace topstoc::python {

void bind_hausdorff(py::module_&) {}

}  // namespace topstoc::python
