// Bindings for topology editing: delete faces, cut along a loop, boundary loops, fill holes,
// remove a handle. Arrays in, a dict of arrays out (see addon/core/api/edit.py for the Python API).
#include <pybind11/stl.h>

#include <stdexcept>

#include "convert.hpp"
#include "topstoc/edit/edit.hpp"
#include "topstoc/edit/fill_holes.hpp"
#include "topstoc/edit/remove_handle.hpp"

namespace topstoc::python {

namespace {

struct Arrays {
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  int32_t num_vertices() const { return static_cast<int32_t>(positions.size() / 3); }
  int64_t num_triangles() const { return int64_t(triangles.size() / 3); }
};

Arrays arrays_from(const py::handle& vertices, const py::handle& triangles) {
  Arrays a{positions_from(vertices, "vertices"), indices_from(triangles, 3, "triangles")};
  if (a.positions.size() / 3 > size_t(INT32_MAX)) throw std::invalid_argument("mesh is too large: more than 2^31 vertices");
  return a;
}

FillOptions fill_options(bool planar, int32_t max_dp_corners, bool refine, bool fair) {
  if (max_dp_corners < 3) throw std::invalid_argument("max_dp_corners must be at least 3, got " + std::to_string(max_dp_corners));
  FillOptions o;
  o.triangulation.planar = planar;
  o.triangulation.max_dp_corners = max_dp_corners;
  o.refine = refine;
  o.fair = fair;
  return o;
}

py::dict result_dict(EditResult&& r) {
  py::dict d;
  d["vertices"] = to_array(std::move(r.vertices), 3);
  d["triangles"] = to_array(std::move(r.triangles), 3);
  d["vertex_source"] = to_array(std::move(r.vertex_source));
  d["face_source"] = to_array(std::move(r.face_source));
  d["corner_source"] = to_array(std::move(r.corner_source), 3);
  py::list sides;
  for (CutSide& s : r.cut_sides) {
    py::dict side;
    side["vertices"] = to_array(std::move(s.vertices));
    side["closed"] = s.closed;
    sides.append(side);
  }
  d["cut_sides"] = sides;
  py::list patches;
  for (FilledHole& p : r.patches) {
    py::dict patch;
    patch["hole"] = p.hole;
    patch["boundary"] = to_array(std::move(p.boundary));
    patch["first_triangle"] = p.first_triangle;
    patch["num_triangles"] = p.num_triangles;
    patch["first_vertex"] = p.first_vertex;
    patch["num_vertices"] = p.num_vertices;
    patch["method"] = fill_method_name(p.method);
    patch["refined"] = p.refined;
    patch["faired"] = p.faired;
    patch["normal"] = copy_array(std::vector<double>(p.normal, p.normal + 3));
    patches.append(patch);
  }
  d["patches"] = patches;
  return d;
}

// Edits that cut: deleting faces, cutting along a loop, and the boundary loops they leave.
void bind_cuts(py::module_& m) {
  m.def(
      "delete_faces",
      [](const py::handle& vertices, const py::handle& triangles, const py::handle& faces) {
        Arrays a = arrays_from(vertices, triangles);
        const auto ids = ids_from(faces, -1, "faces");
        EditResult r;
        {
          EngineCall call;
          r = delete_faces(a.positions.data(), a.num_vertices(), a.triangles.data(), a.num_triangles(), ids.data(),
                           int64_t(ids.size()));
        }
        return result_dict(std::move(r));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("faces"),
      "Deletes triangles and the vertices only they used; returns new arrays and source maps.");

  m.def(
      "cut_along_loop",
      [](const py::handle& vertices, const py::handle& triangles, const py::handle& loop) {
        Arrays a = arrays_from(vertices, triangles);
        const auto ids = ids_from(loop, -1, "loop");
        EditResult r;
        {
          EngineCall call;
          r = cut_along_loop(a.positions.data(), a.num_vertices(), a.triangles.data(), a.num_triangles(), ids.data(),
                             static_cast<int32_t>(ids.size()));
        }
        return result_dict(std::move(r));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("loop"),
      "Cuts the surface open along a closed edge loop (vertex ids in order).");

  m.def(
      "boundary_loops",
      [](const py::handle& triangles, int32_t num_vertices) {
        const auto t = indices_from(triangles, 3, "triangles");
        std::vector<BoundaryLoop> loops;
        {
          EngineCall call;
          loops = boundary_loops(t.data(), int64_t(t.size() / 3), num_vertices);
        }
        py::list out;
        for (BoundaryLoop& loop : loops) out.append(py::make_tuple(to_array(std::move(loop.vertices)), loop.nonmanifold_vertex, loop.lone_triangle));
        return out;
      },
      py::arg("triangles"), py::arg("num_vertices"),
      "Boundary loops as (vertex ids, first non-manifold vertex or -1, lone triangle), by lowest vertex.");
}

// Edits that fill: holes chosen by index, holes given as loops, and removing a handle.
void bind_fills(py::module_& m) {
  m.def(
      "fill_holes",
      [](const py::handle& vertices, const py::handle& triangles, const py::handle& holes, int32_t max_edges,
         bool skip_unfillable, bool weld_pinches, bool planar, int32_t max_dp_corners, bool refine, bool fair) {
        Arrays a = arrays_from(vertices, triangles);
        HoleSelection selection;
        selection.holes = ids_from(holes, -1, "holes");
        if (!holes.is_none() && selection.holes.empty())
          throw std::invalid_argument("holes is empty: pass None to fill every hole");
        selection.max_edges = max_edges;
        selection.skip_unfillable = skip_unfillable;
        selection.weld_pinches = weld_pinches;
        const FillOptions options = fill_options(planar, max_dp_corners, refine, fair);
        EditResult r;
        {
          EngineCall call;
          r = fill_holes(a.positions.data(), a.num_vertices(), a.triangles.data(), a.num_triangles(), selection,
                         options);
        }
        return result_dict(std::move(r));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("holes") = py::none(), py::arg("max_edges") = 0,
      py::arg("skip_unfillable") = false, py::arg("weld_pinches") = true, py::arg("planar") = true,
      py::arg("max_dp_corners") = 300, py::arg("refine") = false, py::arg("fair") = false,
      "Fills boundary loops chosen by index into boundary_loops() (None: all, up to max_edges edges).");

  m.def(
      "fill_loops",
      [](const py::handle& vertices, const py::handle& triangles, const std::vector<py::handle>& loops, bool planar,
         int32_t max_dp_corners, bool refine, bool fair) {
        Arrays a = arrays_from(vertices, triangles);
        std::vector<std::vector<int32_t>> holes;
        for (const auto& loop : loops) holes.push_back(ids_from(loop, -1, "loop"));
        const FillOptions options = fill_options(planar, max_dp_corners, refine, fair);
        EditResult r;
        {
          EngineCall call;
          r = fill_loops(a.positions.data(), a.num_vertices(), a.triangles.data(), a.num_triangles(), holes, options);
        }
        return result_dict(std::move(r));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("loops"), py::arg("planar") = true,
      py::arg("max_dp_corners") = 300, py::arg("refine") = false, py::arg("fair") = false,
      "Fills holes given as boundary cycles of vertex ids.");

  m.def(
      "remove_handle",
      [](const py::handle& vertices, const py::handle& triangles, const py::handle& loop, bool allow_separating,
         double separation, bool planar, int32_t max_dp_corners, bool refine, bool fair,
         bool allow_self_intersections, bool step_down) {
        if (!(separation >= 0.0 && separation < 1.0))
          throw std::invalid_argument("separation must lie in [0, 1), got " + std::to_string(separation));
        Arrays a = arrays_from(vertices, triangles);
        const auto ids = ids_from(loop, -1, "loop");
        RemoveHandleOptions options;
        options.fill = fill_options(planar, max_dp_corners, refine, fair);
        options.allow_separating = allow_separating;
        options.separation = separation;
        options.allow_self_intersections = allow_self_intersections;
        options.step_down = step_down;
        EditResult r;
        {
          EngineCall call;
          r = remove_handle(a.positions.data(), a.num_vertices(), a.triangles.data(), a.num_triangles(), ids.data(),
                            static_cast<int32_t>(ids.size()), options);
        }
        return result_dict(std::move(r));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("loop"), py::arg("allow_separating") = false,
      py::arg("separation") = 0.25, py::arg("planar") = true, py::arg("max_dp_corners") = 300, py::arg("refine") = false, py::arg("fair") = false,
      py::arg("allow_self_intersections") = false, py::arg("step_down") = false,
      "Cuts along a handle or tunnel loop and fills both holes: the genus drops by one.");
}

}  // namespace

void bind_edit(py::module_& m) {
  bind_cuts(m);
  bind_fills(m);
}

}  // namespace topstoc::python
