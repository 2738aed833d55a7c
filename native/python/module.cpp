// The `_topstoc` extension module: registers each concept's bindings. Bindings only convert
// arrays, release the GIL and map errors; every algorithm lives in native/src.
#include "convert.hpp"

PYBIND11_MODULE(_topstoc, m) {
  m.doc() = "TopStoc native engine: decimation, measurement, topology (see topstoc.core for the Python API)";
  namespace tp = topstoc::python;
  tp::bind_mesh(m);
  tp::bind_mesh_edges(m);
  tp::bind_decimate(m);
  tp::bind_io(m);
  tp::bind_hausdorff(m);
  tp::bind_topology(m);
  tp::bind_loops(m);
  tp::bind_edit(m);
}
