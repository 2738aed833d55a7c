// Bindings for topology (filled in by the topology work; empty until then).
#include "convert.hpp"

namespace topstoc::python {

void bind_topology(py::module_&) {}

}  // namespace topstoc::python
