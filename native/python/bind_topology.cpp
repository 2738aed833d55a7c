// Bindings for topology: invariants per component and generator edges, as plain arrays.
// topstoc.core.api.topology turns them into dataclasses.
#include <stdexcept>

#include "convert.hpp"
#include "topstoc/topology/complex.hpp"
#include "topstoc/topology/generators.hpp"
#include "topstoc/topology/topology.hpp"

namespace topstoc::python {

namespace {

// One array per component field (columnar: cheap even with many isolated vertices).
py::dict component_columns(const std::vector<ComponentTopology>& comps) {
  const size_t c = comps.size();
  std::vector<int8_t> kind(c), closed(c), manifold(c), orientable(c), oriented(c);
  std::vector<int32_t> first(c), vertices(c), edges(c), triangles(c), betti(3 * c), boundary_edges(c),
      nm_edges(c), nm_vertices(c), loops(c), paths(c), genus(c), crosscaps(c);
  std::vector<int64_t> euler(c);
  for (size_t i = 0; i < c; ++i) {
    const auto& x = comps[i];
    kind[i] = static_cast<int8_t>(x.kind);
    closed[i] = x.closed;
    manifold[i] = x.manifold;
    orientable[i] = x.orientable;
    oriented[i] = x.consistently_oriented;
    first[i] = x.first_vertex;
    vertices[i] = x.vertices;
    edges[i] = x.edges;
    triangles[i] = x.triangles;
    euler[i] = x.euler;
    for (int d = 0; d < 3; ++d) betti[3 * i + d] = x.betti[d];
    boundary_edges[i] = x.boundary_edges;
    nm_edges[i] = x.nonmanifold_edges;
    nm_vertices[i] = x.nonmanifold_vertices;
    loops[i] = x.boundary_loops;
    paths[i] = x.boundary_paths;
    genus[i] = x.genus;
    crosscaps[i] = x.crosscaps;
  }
  py::dict d;
  d["kind"] = to_array(std::move(kind));
  d["first_vertex"] = to_array(std::move(first));
  d["vertices"] = to_array(std::move(vertices));
  d["edges"] = to_array(std::move(edges));
  d["triangles"] = to_array(std::move(triangles));
  d["euler"] = to_array(std::move(euler));
  d["betti"] = to_array(std::move(betti), 3);
  d["boundary_edges"] = to_array(std::move(boundary_edges));
  d["nonmanifold_edges"] = to_array(std::move(nm_edges));
  d["nonmanifold_vertices"] = to_array(std::move(nm_vertices));
  d["boundary_loops"] = to_array(std::move(loops));
  d["boundary_paths"] = to_array(std::move(paths));
  d["closed"] = to_array(std::move(closed));
  d["manifold"] = to_array(std::move(manifold));
  d["orientable"] = to_array(std::move(orientable));
  d["consistently_oriented"] = to_array(std::move(oriented));
  d["genus"] = to_array(std::move(genus));
  d["crosscaps"] = to_array(std::move(crosscaps));
  return d;
}

py::dict generator_dict(ComponentGenerators&& g) {
  py::dict d;
  d["component"] = g.component;
  d["genus"] = g.genus;
  d["root"] = g.root;
  d["edges"] = to_array(std::move(g.edges), 2);
  d["loop_offsets"] = to_array(std::move(g.loop_offsets));
  d["loop_vertices"] = to_array(std::move(g.loop_vertices));
  d["cut_edges"] = to_array(std::move(g.cut_edges), 2);
  return d;
}

}  // namespace

void bind_topology(py::module_& m) {
  m.def(
      "topology",
      [](const py::handle& vertices, const py::handle& triangles, const py::handle& edges, bool with_generators) {
        const auto positions = positions_array(vertices, "vertices");  // read only: no copy
        const auto tris = indices_array(triangles, 3, "triangles");  // read only: no copy
        std::vector<int32_t> wires;
        if (!edges.is_none()) wires = indices_from(edges, 2, "edges");
        if (positions.shape(0) > INT32_MAX) throw std::invalid_argument("more than 2^31 vertices");
        const double* coordinates = positions.data();
        const auto num_vertices = static_cast<int32_t>(positions.shape(0));
        TopologyReport report;
        std::vector<ComponentGenerators> generators;
        {
          EngineCall call;
          // Kept from call to call (per thread): rebuilding into it reuses its memory, which
          // saves the page faults and zeroing of fresh pages (about 40% of the time on a million
          // triangles). It holds on to that memory (about 55 bytes per triangle) in between.
          thread_local SimplicialComplex complex;
          build_complex(complex, coordinates, num_vertices, tris.data(), tris.shape(0), wires.data(),
                        int64_t(wires.size() / 2));
          report = analyze_topology(complex);
          if (with_generators) generators = compute_generators(complex, report);
        }
        py::dict d;
        d["betti"] = copy_array(std::vector<int32_t>(report.betti, report.betti + 3));
        d["num_vertices"] = report.num_vertices;
        d["num_edges"] = report.num_edges;
        d["num_triangles"] = report.num_triangles;
        d["collapsed_triangles"] = report.collapsed_triangles;
        d["duplicate_triangles"] = report.duplicate_triangles;
        d["components"] = component_columns(report.components);
        d["vertex_component"] = to_array(std::move(report.vertex_component));
        d["boundary_offsets"] = to_array(std::move(report.boundary_offsets));
        d["boundary_vertices"] = to_array(std::move(report.boundary_vertices));
        d["boundary_component"] = to_array(std::move(report.boundary_component));
        d["boundary_closed"] = to_array(std::move(report.boundary_closed));
        d["nonmanifold_edges"] = to_array(std::move(report.nonmanifold_edges), 2);
        d["nonmanifold_edge_triangles"] = to_array(std::move(report.nonmanifold_edge_triangles));
        d["nonmanifold_vertices"] = to_array(std::move(report.nonmanifold_vertices));
        py::list gens;
        for (auto& g : generators) gens.append(generator_dict(std::move(g)));
        d["generators"] = gens;
        return d;
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("edges") = py::none(), py::arg("generators") = false,
      "Invariants per connected component of the simplicial complex spanned by vertices (n, 3), "
      "triangles (m, 3) and optional extra edges (k, 2), in the caller's vertex ids; with generators=True "
      "also the 2g generator edges and loops of each closed orientable manifold component. Plain arrays; "
      "see topstoc.core.api.topology for the documented Python API.");
}

}  // namespace topstoc::python
