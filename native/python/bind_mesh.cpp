// Bindings for the prepared mesh and its feature layout.
#include <pybind11/stl.h>

#include "caller_order.hpp"
#include "convert.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/core/digest.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc::python {

namespace {

py::dict report_dict(const MeshReport& r) {
  py::dict d;
  d["input_vertices"] = r.input_vertices;
  d["input_triangles"] = r.input_triangles;
  d["degenerate_triangles"] = r.degenerate_triangles;
  d["duplicate_triangles"] = r.duplicate_triangles;
  d["zero_area_triangles"] = r.zero_area_triangles;
  d["isolated_vertices"] = r.isolated_vertices;
  d["boundary_edges"] = r.boundary_edges;
  d["nonmanifold_edges"] = r.nonmanifold_edges;
  d["nonmanifold_vertices"] = r.nonmanifold_vertices;
  d["inconsistent_edges"] = r.inconsistent_edges;
  d["components"] = r.components;
  d["dropped_triangles"] = copy_array(r.dropped_triangles);
  return d;
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<Mesh, std::shared_ptr<Mesh>>(m, "Mesh", "Prepared triangle mesh (validated, with adjacency and weights).")
      .def(py::init([](const py::handle& vertices, const py::handle& triangles, const py::object& progress) {
             // The caller's buffers are read in place when they already are float64 and int32.
             const auto positions = positions_array(vertices, "vertices");
             const auto tris = indices_array(triangles, 3, "triangles");
             auto callback = progress_from(progress);
             EngineCall call;
             return std::make_shared<Mesh>(positions.data(), int64_t(positions.size() / 3), tris.data(),
                                           int64_t(tris.size() / 3), callback);
           }),
           py::arg("vertices"), py::arg("triangles"), py::arg("progress") = py::none(),
           "progress(fraction, stage) hears each preparation step; returning False raises Cancelled.")
      .def_property_readonly("num_vertices", &Mesh::num_vertices)
      .def_property_readonly("num_faces", &Mesh::num_faces)
      .def_property_readonly(
          "loose_faces",
          [](const Mesh& mesh) {
            int32_t count = 0;
            for (int32_t f = 0; f < mesh.num_faces(); ++f) count += mesh.loose_face(f);
            return count;
          },
          "Faces that are pieces of their own (Mesh::loose_face: each corner in no other face).")
      .def_property_readonly("num_edges", &Mesh::num_edges)
      .def_property_readonly("diagonal", &Mesh::diagonal)
      .def_property_readonly("mean_weight", &Mesh::mean_weight)
      // Everything below is in the caller's vertex ids and order.
      .def_property_readonly("weights", [](const Mesh& mesh) { return to_array(by_caller(mesh, mesh.weights(), 1)); })
      .def_property_readonly("normals", [](const Mesh& mesh) { return to_array(by_caller(mesh, mesh.normals(), 3), 3); })
      .def_property_readonly("component", [](const Mesh& mesh) { return to_array(by_caller(mesh, mesh.component(), 1)); })
      .def_property_readonly("faces", [](const Mesh& mesh) { return to_array(caller_ids(mesh, mesh.faces()), 3); })
      .def_property_readonly("face_source", [](const Mesh& mesh) { return copy_array(mesh.face_source()); })
      // The caller's arrays as given (float64 positions; triangles with the dropped ones).
      .def_property_readonly("caller_vertices",
                             [](const Mesh& mesh) { return to_array(by_caller(mesh, mesh.positions(), 3), 3); })
      .def_property_readonly("caller_triangles", [](const Mesh& mesh) { return to_array(mesh.caller_triangles(), 3); })
      .def_property_readonly("edges", [](const Mesh& mesh) { return to_array(caller_ids(mesh, mesh.edge_vertices()), 2); })
      .def_property_readonly("report", [](const Mesh& mesh) { return report_dict(mesh.report()); });

  py::class_<FeatureLayout, std::shared_ptr<FeatureLayout>>(
      m, "FeatureLayout", "Edges no cluster may cross (boundaries, region borders, flagged edges) and their curves.")
      .def_property_readonly("feature_edges",
                             [](const FeatureLayout& l) {
                               int32_t count = 0;
                               for (auto x : l.edge_feature) count += x;
                               return count;
                             })
      .def_property_readonly("region_border_edges", [](const FeatureLayout& l) { return l.region_border_edges; })
      .def_property_readonly("flagged_edges", [](const FeatureLayout& l) { return l.flagged_edges; })
      .def_property_readonly("crease_edges", [](const FeatureLayout& l) { return l.crease_edges; })
      .def_property_readonly("corners",
                             [](const FeatureLayout& l) {
                               int32_t count = 0;
                               for (auto x : l.vertex_corner) count += x;
                               return count;
                             })
      .def_property_readonly("num_curves", &FeatureLayout::num_curves)
      // (Empty tables mean all zero: see features.hpp.)
      .def_property_readonly("edge_feature",
                             [](const FeatureLayout& l) {
                               return copy_array(l.edge_feature.empty() ? std::vector<uint8_t>(l.num_edges, 0)
                                                                        : l.edge_feature);
                             })
      .def_property_readonly("vertex_feature", [](const FeatureLayout& l) {
        return copy_array(l.vertex_feature.empty() ? std::vector<uint8_t>(l.num_vertices, 0) : l.vertex_feature);
      });

  m.def(
      "content_digest",
      [](const py::buffer& data) {
        const py::buffer_info info = data.request();
        if (!PyBuffer_IsContiguous(info.view(), 'C'))
          throw std::invalid_argument("content_digest needs a contiguous buffer (np.ascontiguousarray)");
        std::array<uint64_t, 2> digest;
        {
          EngineCall call;
          digest = content_digest(info.ptr, size_t(info.size) * size_t(info.itemsize));
        }
        return py::bytes(reinterpret_cast<const char*>(digest.data()), sizeof digest);
      },
      py::arg("data"), "16-byte digest of a contiguous buffer's bytes (not cryptographic; for caches).");

  m.def(
      "build_feature_layout",
      [](const Mesh& mesh, const py::handle& regions, const py::handle& borders, double feature_angle) {
        auto region_ids = ids_from(regions, mesh.report().input_triangles, "regions");
        std::vector<int32_t> edges;
        if (!borders.is_none()) edges = indices_from(borders, 2, "borders");
        EngineCall call;
        // pybind11 holders cannot be shared_ptr<const T>; Python never mutates the layout.
        return std::const_pointer_cast<FeatureLayout>(
            build_feature_layout(mesh, region_ids.empty() ? nullptr : region_ids.data(), int64_t(region_ids.size()),
                                 edges.data(), int64_t(edges.size() / 2), feature_angle));
      },
      py::arg("mesh"), py::arg("regions") = py::none(), py::arg("borders") = py::none(),
      py::arg("feature_angle") = 0.0,
      "Feature layout from per-triangle region ids (caller's order), flagged edges (vertex pairs) and a crease "
      "angle in radians (0 = off).");
}

}  // namespace topstoc::python
