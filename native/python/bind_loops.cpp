// Bindings for handle and tunnel loops and for the inside/outside tetrahedralization.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <stdexcept>

#include "convert.hpp"
#include "topstoc/core/validate.hpp"
#include "topstoc/topology/loops.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/core/self_intersections.hpp"
#include "topstoc/topology/tetrahedralize.hpp"

namespace topstoc::python {

namespace {

py::dict loop_dict(const HandleTunnelLoop& loop) {
  py::dict d;
  d["kind"] = loop.handle ? "handle" : "tunnel";
  d["vertices"] = copy_array(loop.vertices);
  d["generator"] = py::make_tuple(loop.generator[0], loop.generator[1]);
  d["length"] = loop.length;
  d["initial_length"] = loop.initial_length;
  d["initial_vertices"] = copy_array(loop.initial_vertices);
  return d;
}

py::dict result_dict(const LoopsResult& r) {
  py::list components;
  for (const auto& c : r.components) {
    py::dict d;
    d["first_vertex"] = c.first_vertex;
    d["vertices"] = c.vertices;
    d["edges"] = c.edges;
    d["faces"] = c.faces;
    d["boundary_loops"] = c.boundary_loops;
    d["genus"] = c.genus;
    d["status"] = c.status;
    d["detail"] = c.detail;
    d["route"] = c.route;
    d["analysed_vertices"] = c.analysed_vertices;
    d["tetrahedra"] = c.tetrahedra;
    py::list handles, tunnels;
    for (const auto& loop : c.handles) handles.append(loop_dict(loop));
    for (const auto& loop : c.tunnels) tunnels.append(loop_dict(loop));
    d["handles"] = handles;
    d["tunnels"] = tunnels;
    components.append(d);
  }
  py::dict seconds;
  seconds["prepare"] = r.seconds_prepare;
  seconds["decimate"] = r.seconds_decimate;
  seconds["self_intersections"] = r.seconds_intersections;
  seconds["tetrahedralize"] = r.seconds_tetrahedralize;
  seconds["persistence"] = r.seconds_persistence;
  seconds["select"] = r.seconds_select;
  seconds["map"] = r.seconds_map;
  seconds["shorten"] = r.seconds_shorten;
  seconds["verify"] = r.seconds_verify;
  py::dict d;
  d["components"] = components;
  d["coarse_target"] = r.coarse_target;
  d["coarse_rounds"] = r.coarse_rounds;
  d["coarse_samples_added"] = r.coarse_samples_added;
  d["seconds"] = seconds;
  return d;
}

}  // namespace

void bind_loops(py::module_& m) {
  py::register_exception<Cancelled>(m, "Cancelled", PyExc_RuntimeError);

  m.def(
      "handle_tunnel_loops",
      [](const Mesh& mesh, int32_t coarse_vertices, int32_t full_route_faces, int32_t max_full_faces, bool shorten,
         bool count_edges, int32_t max_roots, uint64_t seed, const py::object& progress) {
        LoopParams params;
        params.coarse_vertices = coarse_vertices;
        params.full_route_faces = full_route_faces;
        params.max_full_faces = max_full_faces;
        params.shorten = shorten;
        params.count_edges = count_edges;
        params.max_roots = max_roots;
        params.seed = seed;
        params.progress = progress_from(progress);
        LoopsResult r;
        {
          EngineCall call;
          r = compute_loops(mesh, params);
        }
        return result_dict(r);
      },
      py::arg("mesh"), py::arg("coarse_vertices") = -1, py::arg("full_route_faces") = 20000,
      py::arg("max_full_faces") = 400000, py::arg("shorten") = true, py::arg("count_edges") = false,
      py::arg("max_roots") = 0, py::arg("seed") = 1, py::arg("progress") = py::none(),
      "Handle and tunnel loops of every closed orientable component (see topstoc.core.api.loops).");

  m.def(
      "shorten_loop",
      [](const Mesh& mesh, const py::handle& loop, bool count_edges, int32_t max_window) {
        auto ids = ids_from(loop, -1, "loop");
        LoopParams params;
        params.count_edges = count_edges;
        std::vector<int32_t> out;
        {
          EngineCall call;
          out = shorten_loop(mesh, ids, params, max_window);
        }
        return to_array(std::move(out));
      },
      py::arg("mesh"), py::arg("loop"), py::arg("count_edges") = false, py::arg("max_window") = 192,
      "Shortens a simple closed edge loop on a closed manifold component, keeping its homotopy class.");

  m.def(
      "self_intersections",
      [](const py::handle& vertices, const py::handle& triangles) {
        auto p = positions_from(vertices, "vertices");
        auto t = indices_from(triangles, 3, "triangles");
        const int64_t n = int64_t(p.size() / 3);
        require_indices_in_range(t.data(), int64_t(t.size() / 3), 3, n, "triangle");
        std::vector<std::pair<int32_t, int32_t>> pairs;
        {
          EngineCall call;
          pairs = self_intersections(p.data(), int32_t(n), t.data(), int32_t(t.size() / 3));
        }
        std::vector<int32_t> flat;
        for (const auto& [a, b] : pairs) flat.insert(flat.end(), {a, b});
        return to_array(std::move(flat), 2);
      },
      py::arg("vertices"), py::arg("triangles"),
      "Pairs of triangles (i <= j) that intersect other than in shared vertices or a shared edge; (i, i) marks "
      "a zero-area triangle. Exact orientation tests.");

  m.def(
      "tetrahedralize_surface",
      [](const py::handle& vertices, const py::handle& triangles) {
        auto p = positions_from(vertices, "vertices");
        auto t = indices_from(triangles, 3, "triangles");
        const int64_t n = int64_t(p.size() / 3);
        require_indices_in_range(t.data(), int64_t(t.size() / 3), 3, n, "triangle");
        std::vector<uint8_t> used(n, 0);
        for (int32_t v : t) used[v] = 1;
        for (int64_t v = 0; v < n; ++v)
          if (!used[v]) throw std::invalid_argument("vertex " + std::to_string(v) + " is in no triangle");
        TetMesh tets;
        {
          EngineCall call;
          tets = tetrahedralize_surface(p.data(), int32_t(n), t.data(), int32_t(t.size() / 3));
        }
        py::dict d;
        d["points"] = to_array(std::move(tets.points), 3);
        d["tets"] = to_array(std::move(tets.tets), 4);
        d["inside"] = to_array(std::move(tets.inside));
        d["perturbed"] = tets.perturbed;
        return d;
      },
      py::arg("vertices"), py::arg("triangles"),
      "TetGen tetrahedralization of the inside and outside of a closed surface inside a box: points (the "
      "surface's first, then box corners and Steiner points), tets (k, 4), inside (k,) flags and perturbed (TetGen "
      "ran on slightly moved surface vertices; false when it refused them and the exact positions were used).");
}

}  // namespace topstoc::python
