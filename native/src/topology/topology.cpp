#include "topstoc/topology/topology.hpp"

#include <phat/algorithms/twist_reduction.h>
#include <phat/boundary_matrix.h>
#include <phat/compute_persistence_pairs.h>
#include <phat/representations/default_representations.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/union_find.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

// Walks around a vertex through the twins of its sides (FanCursor), orientation-free.
struct Walker {
  const SimplicialComplex& k;

  // Number of triangles in the fan of v that contains side x0 (starting at v): triangles joined
  // across edges at v with exactly two triangles. `limit` (v's triangle count) guards the walk.
  int32_t fan_size(int32_t x0, int32_t limit) const {
    const int32_t t0 = x0 / 3;
    int32_t size = 1;
    for (int direction = 0; direction < 2; ++direction) {
      FanCursor at{x0, true};
      if (direction == 1) at.turn();
      while (size <= limit && at.cross(k)) {
        if (at.side / 3 == t0) return size;  // the fan is a full cycle around v
        ++size;
        at.turn();
      }
    }
    return size;
  }

  // From boundary side `at` (at.side has no twin) turn around the vertex to the next side with
  // no twin: returns true with `at` on it, or false when the fan ends at an edge of three or
  // more triangles.
  bool next_boundary_side(FanCursor& at, int32_t limit) const {
    at.turn();
    for (int32_t steps = 0; steps <= limit; ++steps) {
      const int32_t code = k.side_twin[at.side];
      if (code == SimplicialComplex::kOpenSide) return true;
      if (code == SimplicialComplex::kFinSide) return false;
      at.cross(k);
      at.turn();
    }
    return false;
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

// One run of analyze_topology: the complex, the per-triangle and per-vertex facts each stage
// leaves for the next, and the report being filled. The stages run in the order of run().
class TopologyAnalysis {
 public:
  explicit TopologyAnalysis(const SimplicialComplex& k)
      : k(k), walk{k}, caller(k.vertex_source), n(k.num_vertices), num_triangles(k.num_triangles()),
        num_sides(k.num_sides()), sheets(num_triangles) {}

  TopologyReport run() {
    out.num_vertices = n;
    out.num_edges = k.num_edges;
    out.num_triangles = num_triangles;
    out.collapsed_triangles = k.collapsed_triangles;
    out.duplicate_triangles = k.duplicate_triangles;
    join_sheets_and_walk_fans();
    name_components();
    number_components();
    count_triangles_and_closed_sheets();
    if (!column_component.empty()) constrain_sheets_at_fins();
    list_nonmanifold_edges();
    list_nonmanifold_vertices();
    trace_boundary_curves();
    classify_components();
    for (const auto& c : out.components)
      for (int d = 0; d < 3; ++d) out.betti[d] += c.betti[d];
    return std::move(out);
  }

 private:
  static constexpr uint8_t kFlipped = 1, kConflict = 2;

  const SimplicialComplex& k;
  const Walker walk;
  const std::vector<int32_t>& caller;
  const int32_t n, num_triangles, num_sides;
  TopologyReport out;
  ParityUnionFind sheets;
  std::vector<uint8_t> sheet_open;      // a sheet with a boundary edge
  std::vector<uint8_t> triangle_flags;  // kFlipped, kConflict
  std::vector<uint8_t> split_fan;       // a vertex with triangles that are not one fan
  std::vector<int32_t> component_name;  // per internal vertex, before numbering
  std::vector<int32_t> component_of;    // per internal vertex
  int32_t num_components = 0;
  std::vector<uint8_t> component_fins, component_conflict, component_flipped;
  std::vector<int32_t> closed_sheets;    // per component: beta2
  std::vector<int32_t> sheet_column;     // per sheet root of a component with fins: its Z2 column
  std::vector<int32_t> column_component;
  std::vector<uint8_t> bad_vertex;       // an end of a non-manifold edge

  int32_t sheet_name(int32_t t) { return k.triangles[3 * size_t(sheets.find(t))]; }

  // Two independent passes, run side by side. Sheets: triangles joined across edges with
  // exactly two triangles, with a parity that says whether two triangles must be flipped
  // relative to each other to agree (a triangle on a flipped edge or on a parity conflict is
  // flagged; its component is found afterwards). Fans: whether the triangles at each vertex
  // are one fan, walking around it.
  void join_sheets_and_walk_fans() {
    sheet_open.assign(num_triangles, 0);
    triangle_flags.assign(num_triangles, 0);
    split_fan.assign(n, 0);
    parallel_invoke(
        num_sides >= kParallelMinimum, [&] { join_sheets(); },
        [&] {
          for (int32_t v = 0; v < n; ++v) {
            const int32_t triangles = k.vertex_triangles[v];
            split_fan[v] = triangles > 0 && walk.fan_size(k.vertex_side[v], triangles) != triangles;
          }
        });
  }

  void join_sheets() {
    bool any_open_side = false;
    for (int32_t s = 0; s < num_sides; ++s) {
      const int32_t code = k.side_twin[s];
      if (code < 0) {
        any_open_side |= code == SimplicialComplex::kOpenSide;
        continue;
      }
      if ((code >> 1) < s) continue;  // each shared edge once
      const uint8_t same_direction = code & 1;
      if (same_direction) triangle_flags[s / 3] |= kFlipped;
      if (sheets.unite(s / 3, (code >> 1) / 3, same_direction) == ParityUnionFind::Join::conflict)
        triangle_flags[s / 3] |= kConflict;
    }
    if (any_open_side)
      for (int32_t s = 0; s < num_sides; ++s)
        if (k.side_twin[s] == SimplicialComplex::kOpenSide) sheet_open[sheets.find(s / 3)] = 1;
  }

  // Components, from the sheets rather than a union-find over every edge: a sheet is
  // connected, and the triangles of a vertex that are one fan lie in one sheet, so a vertex
  // belongs with the sheet of any of its triangles, named here by a corner of the sheet's root
  // triangle (two sheets named alike share that vertex, so they are connected). Sheets meet at
  // vertices with split fans (every vertex of an edge with three or more triangles is one) and
  // through lone wires; only then are names joined, in a union-find over vertices.
  void name_components() {
    component_name.resize(n);  // in internal order: the finds walk the sheets in memory order
    for (int32_t v = 0; v < n; ++v) component_name[v] = k.vertex_triangles[v] ? sheet_name(k.vertex_side[v] / 3) : v;
    const bool any_split_fan = std::find(split_fan.begin(), split_fan.end(), 1) != split_fan.end();
    if (!any_split_fan && k.wire_edges.empty()) return;
    UnionFind joined(n);
    for (size_t i = 0; i < k.wire_edges.size(); i += 2)
      joined.unite(component_name[k.wire_edges[i]], component_name[k.wire_edges[i + 1]]);
    if (any_split_fan)
      for (int32_t s = 0; s < num_sides; ++s)
        if (split_fan[k.side_start(s)]) joined.unite(component_name[k.side_start(s)], sheet_name(s / 3));
    for (int32_t v = 0; v < n; ++v) component_name[v] = joined.find(component_name[v]);
  }

  // Components numbered by their smallest caller id (walking the caller's ids in order), with
  // their vertices, fin and wire edges counted.
  void number_components() {
    out.vertex_component.assign(n, -1);
    component_of.assign(n, -1);
    std::vector<int32_t> label(n, -1);
    for (int32_t id = 0; id < n; ++id) {
      const int32_t v = k.vertex_index[id];
      const int32_t r = component_name[v];
      if (label[r] < 0) {
        label[r] = static_cast<int32_t>(out.components.size());
        out.components.emplace_back();
        out.components.back().first_vertex = id;
      }
      out.vertex_component[id] = component_of[v] = label[r];
    }
    auto& comps = out.components;
    num_components = static_cast<int32_t>(comps.size());
    component_fins.assign(num_components, 0);
    for (size_t i = 0; i < k.fin_edges.size(); i += 2) {
      ++comps[component_of[k.fin_edges[i]]].edges;
      component_fins[component_of[k.fin_edges[i]]] = 1;
    }
    for (size_t i = 0; i < k.wire_edges.size(); i += 2) ++comps[component_of[k.wire_edges[i]]].edges;
    for (int32_t v = 0; v < n; ++v) ++comps[component_of[v]].vertices;
  }

  // Per triangle: counts, and the closed sheets (beta2 before the constraints at fins). Sheets
  // of components with fins become columns of the Z2 system below.
  void count_triangles_and_closed_sheets() {
    auto& comps = out.components;
    closed_sheets.assign(num_components, 0);
    component_conflict.assign(num_components, 0);
    component_flipped.assign(num_components, 0);
    for (int32_t t = 0; t < num_triangles; ++t) {
      const int32_t ci = component_of[k.triangles[3 * size_t(t)]];
      auto& c = comps[ci];
      ++c.triangles;
      if (triangle_flags[t] & kFlipped) component_flipped[ci] = 1;
      if (triangle_flags[t] & kConflict) component_conflict[ci] = 1;
      for (int32_t s = 3 * t; s < 3 * t + 3; ++s) {
        if (k.side_twin[s] == SimplicialComplex::kOpenSide) ++c.boundary_edges;
        if (k.represents_edge(s)) ++c.edges;
      }
      if (!sheets.is_root(t) || sheet_open[t]) continue;
      ++closed_sheets[ci];
      if (component_fins[ci]) {
        if (sheet_column.empty()) sheet_column.assign(num_triangles, -1);
        sheet_column[t] = static_cast<int32_t>(column_component.size());
        column_component.push_back(ci);
      }
    }
    for (auto& c : comps) {
      c.euler = int64_t(c.vertices) - c.edges + c.triangles;
      c.kind = c.triangles > 0 ? ComponentKind::surface : (c.edges > 0 ? ComponentKind::graph : ComponentKind::vertex);
    }
  }

  // One row per edge of three or more triangles; a sheet meeting it an odd number of times
  // has a 1 there. Each independent column closes one sheet fewer.
  void constrain_sheets_at_fins() {
    std::vector<std::vector<phat::index>> columns(column_component.size());
    const int64_t rows = static_cast<int64_t>(k.fin_offsets.size()) - 1;
    for (int64_t row = 0; row < rows; ++row)
      for (int32_t i = k.fin_offsets[row]; i < k.fin_offsets[row + 1]; ++i) {
        const int32_t col = sheet_column[sheets.find(k.fin_sides[i] / 3)];
        if (col >= 0) columns[col].push_back(row);
      }
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
    for (size_t col = 0; col < columns.size(); ++col)
      if (pivot[col]) --closed_sheets[column_component[col]];
  }

  // Non-manifold edges (no triangle, or three and more) in surface components, in caller ids.
  void list_nonmanifold_edges() {
    auto& comps = out.components;
    bad_vertex.assign(n, 0);
    std::vector<std::array<int32_t, 3>> bad_edges;  // (lower, higher, triangles)
    for (size_t i = 0; i < k.fin_edges.size(); i += 2)
      bad_edges.push_back({k.fin_edges[i], k.fin_edges[i + 1], k.fin_offsets[i / 2 + 1] - k.fin_offsets[i / 2]});
    for (size_t i = 0; i < k.wire_edges.size(); i += 2)
      if (comps[component_of[k.wire_edges[i]]].kind == ComponentKind::surface)
        bad_edges.push_back({k.wire_edges[i], k.wire_edges[i + 1], 0});
    for (auto& [a, b, count] : bad_edges) {
      bad_vertex[a] = bad_vertex[b] = 1;
      ++comps[component_of[a]].nonmanifold_edges;
      a = caller[a];
      b = caller[b];
      if (a > b) std::swap(a, b);
    }
    std::sort(bad_edges.begin(), bad_edges.end());
    for (const auto& [a, b, count] : bad_edges) {
      out.nonmanifold_edges.push_back(a);
      out.nonmanifold_edges.push_back(b);
      out.nonmanifold_edge_triangles.push_back(count);
    }
  }

  // Non-manifold vertices: ends of non-manifold edges and vertices whose fan is split.
  void list_nonmanifold_vertices() {
    for (int32_t v = 0; v < n; ++v)
      if (bad_vertex[v] || split_fan[v]) {
        out.nonmanifold_vertices.push_back(caller[v]);
        ++out.components[component_of[v]].nonmanifold_vertices;
      }
    std::sort(out.nonmanifold_vertices.begin(), out.nonmanifold_vertices.end());
  }

  // Boundary curves: from each unvisited boundary side, turn around the fans at its ends.
  void trace_boundary_curves() {
    std::vector<uint8_t> visited;
    int64_t boundary_edges = 0;  // closed surfaces (the common case) skip the scan
    for (const auto& c : out.components) boundary_edges += c.boundary_edges;
    for (int32_t s0 = 0; s0 < (boundary_edges ? num_sides : 0); ++s0) {
      if (k.side_twin[s0] != SimplicialComplex::kOpenSide) continue;
      if (visited.empty()) visited.assign(num_sides, 0);
      if (visited[s0]) continue;
      visited[s0] = 1;
      const size_t start = out.boundary_vertices.size();
      out.boundary_vertices.push_back(k.side_start(s0));
      const bool closed = follow_boundary_forward(s0, visited);
      if (!closed) prepend_boundary_backward(s0, start, visited);
      for (size_t i = start; i < out.boundary_vertices.size(); ++i)
        out.boundary_vertices[i] = caller[out.boundary_vertices[i]];
      const int32_t c = component_of[k.side_start(s0)];
      out.boundary_offsets.push_back(static_cast<int32_t>(out.boundary_vertices.size()));
      out.boundary_component.push_back(c);
      out.boundary_closed.push_back(closed ? 1 : 0);
      ++(closed ? out.components[c].boundary_loops : out.components[c].boundary_paths);
    }
  }

  // Follows the boundary forward from the end of side s0, appending its vertices; returns
  // whether the curve closes at s0. `at` stands on the boundary side just followed, at its far end.
  bool follow_boundary_forward(int32_t s0, std::vector<uint8_t>& visited) {
    FanCursor at{s0, false};
    while (true) {
      const int32_t vertex = at.starts_at_vertex ? k.side_start(at.side) : k.side_end(at.side);
      if (!walk.next_boundary_side(at, k.vertex_triangles[vertex])) {
        out.boundary_vertices.push_back(vertex);
        return false;
      }
      if (at.side == s0) return true;
      out.boundary_vertices.push_back(vertex);
      if (visited[at.side]) return false;
      visited[at.side] = 1;
      at.starts_at_vertex = !at.starts_at_vertex;  // move to the side's other end
    }
  }

  // An open curve: extends it backwards from the start of s0 as well, and puts that part first
  // (at `start`, where the curve's vertices begin).
  void prepend_boundary_backward(int32_t s0, size_t start, std::vector<uint8_t>& visited) {
    std::vector<int32_t> backward;
    FanCursor at{s0, true};
    while (true) {
      const int32_t vertex = at.starts_at_vertex ? k.side_start(at.side) : k.side_end(at.side);
      if (!walk.next_boundary_side(at, k.vertex_triangles[vertex]) || visited[at.side]) break;
      visited[at.side] = 1;
      at.starts_at_vertex = !at.starts_at_vertex;
      backward.push_back(at.starts_at_vertex ? k.side_start(at.side) : k.side_end(at.side));
    }
    out.boundary_vertices.insert(out.boundary_vertices.begin() + start, backward.rbegin(), backward.rend());
  }

  // Per component: Betti numbers and the surface classification.
  void classify_components() {
    for (int32_t i = 0; i < num_components; ++i) {
      auto& c = out.components[i];
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
      if (!c.manifold) continue;
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
};

}  // namespace

TopologyReport analyze_topology(const SimplicialComplex& k) { return TopologyAnalysis(k).run(); }

TopologyReport analyze_topology(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges) {
  return analyze_topology(build_complex(positions, num_vertices, triangles, num_triangles, edges, num_edges));
}

}  // namespace topstoc
