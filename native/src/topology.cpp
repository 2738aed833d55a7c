#include "topstoc/topology.hpp"

#include <phat/algorithms/twist_reduction.h>
#include <phat/boundary_matrix.h>
#include <phat/compute_persistence_pairs.h>
#include <phat/representations/default_representations.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "topstoc/union_find.hpp"

namespace topstoc {

namespace {

// Walking around a vertex: a triangle's two edges at a vertex, and the triangle across an edge
// shared by exactly two triangles. Orientation-free, so they work on non-orientable surfaces.
struct Walker {
  const SimplicialComplex& k;

  int corner_of(int32_t t, int32_t v) const {
    const int32_t* tri = &k.triangles[3 * size_t(t)];
    return tri[0] == v ? 0 : (tri[1] == v ? 1 : 2);
  }
  // The edge of triangle t at vertex v other than e.
  int32_t other_edge_at(int32_t t, int32_t v, int32_t e) const {
    const int c = corner_of(t, v);
    const int32_t leaving = k.triangle_edges[3 * size_t(t) + c];
    const int32_t arriving = k.triangle_edges[3 * size_t(t) + (c + 2) % 3];
    return leaving == e ? arriving : leaving;
  }
  // The other triangle on edge e (which has exactly two).
  int32_t across(int32_t e, int32_t t) const {
    const int32_t s0 = k.edge_sides[k.edge_side_offsets[e]], s1 = k.edge_sides[k.edge_side_offsets[e] + 1];
    return s0 / 3 == t ? s1 / 3 : s0 / 3;
  }
  int32_t other_end(int32_t e, int32_t v) const {
    return k.edges[2 * size_t(e)] == v ? k.edges[2 * size_t(e) + 1] : k.edges[2 * size_t(e)];
  }
  int32_t count(int32_t e) const { return k.edge_triangle_count(e); }

  // Number of triangles in the fan of v that contains t0 (triangles joined across edges at v
  // with exactly two triangles). `limit` (v's triangle count) guards the walk.
  int32_t fan_size(int32_t v, int32_t t0, int32_t limit) const {
    const int c = corner_of(t0, v);
    const int32_t ends[2] = {k.triangle_edges[3 * size_t(t0) + c], k.triangle_edges[3 * size_t(t0) + (c + 2) % 3]};
    int32_t size = 1;
    for (int32_t e : ends) {
      int32_t t = t0;
      while (size <= limit && count(e) == 2) {
        const int32_t next = across(e, t);
        if (next == t0) return size;  // the fan is a full cycle around v
        ++size;
        t = next;
        e = other_edge_at(t, v, e);
      }
    }
    return size;
  }

  // Arriving at v along boundary edge e of triangle t: the next boundary edge around v's fan, or
  // -1 when the fan ends at an edge with three or more triangles.
  int32_t next_boundary_edge(int32_t v, int32_t t, int32_t e, int32_t limit) const {
    for (int32_t steps = 0; steps <= limit; ++steps) {
      const int32_t o = other_edge_at(t, v, e);
      if (count(o) == 1) return o;
      if (count(o) != 2) return -1;
      t = across(o, t);
      e = o;
    }
    return -1;
  }
};

// Rank over Z2 of a sparse matrix given as columns of row indices (each sorted, no repeats),
// by PHAT's twist reduction on bit-tree columns: rows become 0-cells, columns 1-cells, and the
// rank is the number of persistence pairs. Returns, per column, whether it is a pivot column
// (independent of the ones before it).
std::vector<uint8_t> z2_pivot_columns(int64_t num_rows, const std::vector<std::vector<phat::index>>& columns) {
  phat::boundary_matrix<phat::bit_tree_pivot_column> matrix;
  const int64_t num_columns = static_cast<int64_t>(columns.size());
  matrix.set_num_cols(num_rows + num_columns);
  for (int64_t r = 0; r < num_rows; ++r) matrix.set_dim(r, 0);
  for (int64_t c = 0; c < num_columns; ++c) {
    matrix.set_dim(num_rows + c, 1);
    matrix.set_col(num_rows + c, columns[c]);
  }
  phat::persistence_pairs pairs;
  phat::compute_persistence_pairs<phat::twist_reduction>(pairs, matrix);
  std::vector<uint8_t> pivot(num_columns, 0);
  for (phat::index i = 0; i < pairs.get_num_pairs(); ++i) pivot[pairs.get_pair(i).second - num_rows] = 1;
  return pivot;
}

}  // namespace

TopologyReport analyze_topology(const SimplicialComplex& k) {
  const int32_t n = k.num_vertices, num_edges = k.num_edges(), num_triangles = k.num_triangles();
  const Walker walk{k};
  TopologyReport out;
  out.num_vertices = n;
  out.num_edges = num_edges;
  out.num_triangles = num_triangles;
  out.collapsed_triangles = k.collapsed_triangles;
  out.duplicate_triangles = k.duplicate_triangles;

  // Components: union-find over edges, numbered by their smallest vertex.
  {
    UnionFind vertices(n);
    for (int32_t e = 0; e < num_edges; ++e) vertices.unite(k.edges[2 * size_t(e)], k.edges[2 * size_t(e) + 1]);
    out.vertex_component.assign(n, -1);
    std::vector<int32_t> label(n, -1);
    for (int32_t v = 0; v < n; ++v) {
      const int32_t r = vertices.find(v);
      if (label[r] < 0) {
        label[r] = static_cast<int32_t>(out.components.size());
        out.components.emplace_back();
        out.components.back().first_vertex = v;
      }
      out.vertex_component[v] = label[r];
    }
  }
  const auto& component_of = out.vertex_component;
  auto& comps = out.components;
  const int32_t num_components = static_cast<int32_t>(comps.size());
  for (int32_t v = 0; v < n; ++v) ++comps[component_of[v]].vertices;
  for (int32_t e = 0; e < num_edges; ++e) ++comps[component_of[k.edges[2 * size_t(e)]]].edges;
  for (int32_t t = 0; t < num_triangles; ++t) ++comps[component_of[k.triangles[3 * size_t(t)]]].triangles;
  for (auto& c : comps) {
    c.euler = int64_t(c.vertices) - c.edges + c.triangles;
    c.kind = c.triangles > 0 ? ComponentKind::surface : (c.edges > 0 ? ComponentKind::graph : ComponentKind::vertex);
  }

  // Sheets and orientation: triangles joined across edges with exactly two triangles; the parity
  // says whether two triangles must be flipped relative to each other to agree.
  ParityUnionFind sheets(num_triangles);
  std::vector<uint8_t> component_conflict(num_components, 0), component_flipped(num_components, 0);
  std::vector<uint8_t> component_fins(num_components, 0);
  for (int32_t e = 0; e < num_edges; ++e) {
    const int32_t count = k.edge_triangle_count(e);
    const int32_t c = component_of[k.edges[2 * size_t(e)]];
    if (count == 1) ++comps[c].boundary_edges;
    if (count >= 3) component_fins[c] = 1;
    if (count != 2) continue;
    const int32_t s0 = k.edge_sides[k.edge_side_offsets[e]], s1 = k.edge_sides[k.edge_side_offsets[e] + 1];
    // Two triangles agree when they traverse their shared edge in opposite directions.
    const bool same_direction = (k.triangles[s0] == k.edges[2 * size_t(e)]) == (k.triangles[s1] == k.edges[2 * size_t(e)]);
    if (same_direction) component_flipped[c] = 1;
    if (sheets.unite(s0 / 3, s1 / 3, same_direction ? 1 : 0) == ParityUnionFind::Join::conflict)
      component_conflict[c] = 1;
  }
  // A sheet with a boundary edge can never be part of a 2-cycle.
  std::vector<uint8_t> sheet_open(num_triangles, 0);
  for (int32_t e = 0; e < num_edges; ++e)
    if (k.edge_triangle_count(e) == 1) sheet_open[sheets.find(k.edge_sides[k.edge_side_offsets[e]] / 3)] = 1;

  // beta2: closed sheets, minus the rank of the parity constraints at edges of 3+ triangles.
  std::vector<int32_t> closed_sheets(num_components, 0);
  std::vector<int32_t> sheet_column(num_triangles, -1);
  int32_t free_fin_sheets = 0;
  for (int32_t t = 0; t < num_triangles; ++t) {
    if (sheets.find(t) != t || sheet_open[t]) continue;
    const int32_t c = component_of[k.triangles[3 * size_t(t)]];
    ++closed_sheets[c];
    if (component_fins[c]) sheet_column[t] = free_fin_sheets++;
  }
  if (free_fin_sheets > 0) {
    std::vector<std::vector<phat::index>> columns(free_fin_sheets);
    std::vector<int32_t> column_component(free_fin_sheets);
    int64_t rows = 0;
    for (int32_t e = 0; e < num_edges; ++e) {
      if (k.edge_triangle_count(e) < 3) continue;
      for (int32_t i = k.edge_side_offsets[e]; i < k.edge_side_offsets[e + 1]; ++i) {
        const int32_t col = sheet_column[sheets.find(k.edge_sides[i] / 3)];
        if (col >= 0) columns[col].push_back(rows);
      }
      ++rows;
    }
    for (int32_t t = 0; t < num_triangles; ++t)
      if (sheet_column[t] >= 0) column_component[sheet_column[t]] = component_of[k.triangles[3 * size_t(t)]];
    // A sheet that meets an edge an even number of times adds nothing to its constraint.
    for (auto& col : columns) {
      std::vector<phat::index> odd;
      for (size_t i = 0; i < col.size();) {
        size_t j = i;
        while (j < col.size() && col[j] == col[i]) ++j;
        if ((j - i) % 2 == 1) odd.push_back(col[i]);
        i = j;
      }
      col.swap(odd);
    }
    const auto pivot = z2_pivot_columns(rows, columns);
    for (int32_t col = 0; col < free_fin_sheets; ++col)
      if (pivot[col]) --closed_sheets[column_component[col]];
  }

  // Non-manifold edges (no triangle, or three and more) and vertices, in surface components.
  std::vector<int32_t> vertex_triangles(n, 0), vertex_some_triangle(n, -1);
  for (int32_t t = 0; t < num_triangles; ++t)
    for (int c = 0; c < 3; ++c) {
      const int32_t v = k.triangles[3 * size_t(t) + c];
      if (vertex_triangles[v]++ == 0) vertex_some_triangle[v] = t;
    }
  std::vector<uint8_t> bad_vertex(n, 0);
  for (int32_t e = 0; e < num_edges; ++e) {
    const int32_t count = k.edge_triangle_count(e);
    const int32_t a = k.edges[2 * size_t(e)], b = k.edges[2 * size_t(e) + 1];
    if (comps[component_of[a]].kind != ComponentKind::surface || count == 1 || count == 2) continue;
    out.nonmanifold_edges.push_back(a);
    out.nonmanifold_edges.push_back(b);
    out.nonmanifold_edge_triangles.push_back(count);
    ++comps[component_of[a]].nonmanifold_edges;
    bad_vertex[a] = bad_vertex[b] = 1;
  }
#pragma omp parallel for schedule(dynamic, 4096)
  for (int32_t v = 0; v < n; ++v) {
    if (bad_vertex[v] || vertex_triangles[v] == 0) continue;
    if (walk.fan_size(v, vertex_some_triangle[v], vertex_triangles[v]) != vertex_triangles[v]) bad_vertex[v] = 1;
  }
  for (int32_t v = 0; v < n; ++v)
    if (bad_vertex[v]) {
      out.nonmanifold_vertices.push_back(v);
      ++comps[component_of[v]].nonmanifold_vertices;
    }

  // Boundary curves: from each unvisited boundary edge, walk around the fans at its ends.
  std::vector<uint8_t> visited(num_edges, 0);
  std::vector<int32_t> backward;
  for (int32_t e0 = 0; e0 < num_edges; ++e0) {
    if (k.edge_triangle_count(e0) != 1 || visited[e0]) continue;
    visited[e0] = 1;
    const int32_t s0 = k.edge_sides[k.edge_side_offsets[e0]], t0 = s0 / 3;
    const int32_t a = k.triangles[s0], b = k.triangles[3 * size_t(t0) + (s0 % 3 + 1) % 3];
    const size_t start = out.boundary_vertices.size();
    out.boundary_vertices.push_back(a);
    int32_t e = e0, t = t0, at = b;
    bool closed = false;
    while (true) {
      const int32_t next = walk.next_boundary_edge(at, t, e, vertex_triangles[at]);
      if (next == e0) {
        closed = true;
        break;
      }
      out.boundary_vertices.push_back(at);
      if (next < 0 || visited[next]) break;
      visited[next] = 1;
      e = next;
      t = k.edge_sides[k.edge_side_offsets[next]] / 3;
      at = walk.other_end(next, at);
    }
    if (!closed) {
      // An open curve: extend it backwards from a as well, then put that part in front.
      backward.clear();
      e = e0, t = t0, at = a;
      while (true) {
        const int32_t next = walk.next_boundary_edge(at, t, e, vertex_triangles[at]);
        if (next < 0 || visited[next]) break;
        visited[next] = 1;
        at = walk.other_end(next, at);
        backward.push_back(at);
        e = next;
        t = k.edge_sides[k.edge_side_offsets[next]] / 3;
      }
      out.boundary_vertices.insert(out.boundary_vertices.begin() + start, backward.rbegin(), backward.rend());
    }
    const int32_t c = component_of[a];
    out.boundary_offsets.push_back(static_cast<int32_t>(out.boundary_vertices.size()));
    out.boundary_component.push_back(c);
    out.boundary_closed.push_back(closed ? 1 : 0);
    ++(closed ? comps[c].boundary_loops : comps[c].boundary_paths);
  }

  // Per component: Betti numbers and the surface classification.
  for (int32_t i = 0; i < num_components; ++i) {
    auto& c = comps[i];
    c.betti[0] = 1;
    c.betti[2] = closed_sheets[i];
    const int64_t beta1 = 1 + int64_t(c.betti[2]) - c.euler;
    if (beta1 < 0 || c.betti[2] < 0)
      throw std::logic_error("topology: inconsistent Betti numbers in component " + std::to_string(i));
    c.betti[1] = static_cast<int32_t>(beta1);
    if (c.kind != ComponentKind::surface) continue;
    c.closed = c.boundary_edges == 0;
    c.manifold = c.nonmanifold_edges == 0 && c.nonmanifold_vertices == 0;
    c.consistently_oriented = component_flipped[i] ? 0 : 1;
    if (!component_fins[i]) c.orientable = component_conflict[i] ? 0 : 1;
    if (c.manifold) {
      const int64_t deficit = 2 - c.euler - c.boundary_loops;  // 2g (orientable) or the cross-caps
      if (c.orientable) {
        if (deficit < 0 || deficit % 2 != 0)
          throw std::logic_error("topology: odd Euler deficit on orientable component " + std::to_string(i));
        c.genus = static_cast<int32_t>(deficit / 2);
      } else {
        c.crosscaps = static_cast<int32_t>(deficit);
      }
    }
  }
  for (const auto& c : comps)
    for (int d = 0; d < 3; ++d) out.betti[d] += c.betti[d];
  return out;
}

TopologyReport analyze_topology(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges) {
  return analyze_topology(build_complex(positions, num_vertices, triangles, num_triangles, edges, num_edges));
}

}  // namespace topstoc
