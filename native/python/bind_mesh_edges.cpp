// Binding for the edges of a triangle list (what Blender's edge and loop arrays hold).
#include "convert.hpp"
#include "topstoc/core/mesh_edges.hpp"

namespace topstoc::python {

void bind_mesh_edges(py::module_& m) {
  m.def(
      "mesh_edges",
      [](const py::handle& triangles, int32_t num_vertices) {
        auto tris = indices_from(triangles, 3, "triangles");
        MeshEdges edges;
        {
          EngineCall call;
          edges = mesh_edges(tris.data(), int64_t(tris.size() / 3), num_vertices);
        }
        return py::make_tuple(to_array(std::move(edges.vertices), 2), to_array(std::move(edges.corner_edge), 3));
      },
      py::arg("triangles"), py::arg("num_vertices"),
      "(edges (k, 2) int32 unique vertex pairs, lower id first, by lower vertex then first corner; corner_edge (m, 3) int32: the edge from "
      "each triangle corner to the next).");
}

}  // namespace topstoc::python
