#include "topstoc/decimate/verify.hpp"


#include <algorithm>
#include <atomic>
#include <array>
#include <cmath>

#include "../core/union_find.hpp"
#include "topstoc/core/buffer.hpp"
#include "topstoc/core/parallel.hpp"
#include "link_arcs.hpp"
#include "pinched_fans.hpp"

namespace topstoc {

namespace {

// The link of every output vertex as arcs, stored contiguously per vertex (CSR): triangle
// (a, b, c) gives a the arc b -> c, b the arc c -> a and c the arc a -> b, in triangle order.
// Triangles with a repeated corner give none. The vertex pass then reads one short run per
// vertex instead of its triangles scattered over the triangle array. Each thread owns a range
// of vertices: it reads every triangle and writes only the arcs of its own vertices, so the
// order does not depend on the number of threads.
struct VertexArcs {
  struct Arc {
    int32_t from, to;
  };
  Buffer<int32_t> offsets;
  Buffer<Arc> arcs;
  VertexArcs(int32_t n, const std::vector<int32_t>& tris) : offsets(n + 1) {
    const int64_t t = int64_t(tris.size() / 3);
    auto valid = [&](int64_t i) {
      const int32_t* c = &tris[3 * i];
      return c[0] != c[1] && c[1] != c[2] && c[2] != c[0];
    };
    const bool parallel = t >= kParallelMin;
    const int threads = parallel ? max_threads() : 1;
    std::vector<int64_t> range_arcs(threads + 1, 0);
    Buffer<int32_t> fill(n);  // per vertex: where its next arc goes
    parallel_region(threads, [&](Team& running) {
      const int me = running.index(), team = running.size();
      const int32_t lo = int32_t(int64_t(n) * me / team), hi = int32_t(int64_t(n) * (me + 1) / team);
      // Counts: offsets[v + 1] holds v's (each range writes its own slots lo + 1 .. hi).
      for (int32_t v = lo; v < hi; ++v) offsets[v + 1] = 0;
      for (int64_t i = 0; i < t; ++i)
        if (valid(i))
          for (int j = 0; j < 3; ++j) {
            const int32_t v = tris[3 * i + j];
            if (v >= lo && v < hi) ++offsets[v + 1];
          }
      int64_t sum = 0;
      for (int32_t v = lo; v < hi; ++v) sum += offsets[v + 1];
      range_arcs[me + 1] = sum;
      running.barrier();
      running.single([&] {
        for (int r = 0; r < team; ++r) range_arcs[r + 1] += range_arcs[r];
        arcs.resize(range_arcs[team]);
        offsets[0] = 0;
      });
      // Ends: offsets[v + 1] is where v's arcs end and v + 1's start.
      int64_t end = range_arcs[me];
      for (int32_t v = lo; v < hi; ++v) offsets[v + 1] = int32_t(end += offsets[v + 1]);
      running.barrier();
      for (int32_t v = lo; v < hi; ++v) fill[v] = offsets[v];
      for (int64_t i = 0; i < t; ++i) {
        if (!valid(i)) continue;
        const int32_t* c = &tris[3 * i];
        for (int j = 0; j < 3; ++j)
          if (c[j] >= lo && c[j] < hi) arcs[fill[c[j]]++] = {c[(j + 1) % 3], c[(j + 2) % 3]};
      }
    });
  }
};

void add_count(std::string& text, int32_t count, const char* what) {
  if (count == 0) return;
  if (!text.empty()) text += ", ";
  text += std::to_string(count) + " " + what;
}

}  // namespace

std::string OutputCheck::describe() const {
  std::string text;
  add_count(text, nonfinite, "vertices with non-finite coordinates");
  add_count(text, repeated_corner, "triangles with a repeated corner");
  add_count(text, duplicate, "duplicate triangles");
  add_count(text, nonmanifold_edges, "non-manifold edges");
  add_count(text, nonmanifold_vertices, "non-manifold vertices");
  add_count(text, inconsistent_edges, "inconsistently oriented edges");
  add_count(text, mixed_triangles, "triangles joining different input components");
  add_count(text, lost_components, "input components lost");
  add_count(text, split_components, "input components split apart");
  add_count(text, euler_changed, "components whose Euler characteristic changed");
  add_count(text, boundary_loops_changed, "components whose boundary loops changed");
  add_count(text, pinched_fans_changed, "pinched vertices whose fans changed");
  return text;
}

std::vector<int32_t> component_boundary_loops(const Mesh& mesh, const FeatureLayout& layout) {
  std::vector<int32_t> loops(mesh.num_components(), 0);
  for (size_t i = 0; i + 1 < layout.boundary_loop_offsets.size(); ++i)
    ++loops[mesh.component()[layout.boundary_loop_vertices[layout.boundary_loop_offsets[i]]]];
  return loops;
}

namespace {

// Issues found at output vertices, counted per thread (summed by the OpenMP reduction).
struct LinkIssues {
  int32_t duplicate = 0, nonmanifold_edges = 0, inconsistent_edges = 0, nonmanifold_vertices = 0;
};

// One run of check_output: the output, the input components it must match, and what each
// stage leaves for the next. The stages run in the order of run().
class OutputChecker {
 public:
  OutputChecker(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& kept,
                const std::vector<double>& positions, const std::vector<int32_t>& triangles)
      : mesh(mesh), layout(layout), kept(kept), positions(positions), triangles(triangles),
        n(static_cast<int32_t>(kept.size())), t(static_cast<int32_t>(triangles.size() / 3)),
        num_components(mesh.num_components()), pinched(find_pinched_vertices(mesh)), pieces(n), boundary(n) {}

  OutputCheck run() {
    count_nonfinite();
    find_surface_components();
    check_triangles();
    check_vertex_links();
    compare_components();
    check.pinched_fans_changed = changed_pinched_fans(mesh, pinched, kept, triangles);
    return check;
  }

 private:
  const Mesh& mesh;
  const FeatureLayout& layout;
  const std::vector<int32_t>& kept;
  const std::vector<double>& positions;
  const std::vector<int32_t>& triangles;
  const int32_t n, t, num_components;
  const PinchedVertices pinched;
  OutputCheck check;
  std::vector<uint8_t> manifold;        // per input component: in the guarantee's domain
  std::vector<int32_t> component_of;    // per output vertex
  std::vector<int32_t> triangles_in;    // per component
  std::vector<int64_t> euler;           // per component: V - E + F of the output piece
  SharedUnionFind pieces, boundary;     // output vertices joined by edges, by boundary edges
  std::vector<uint8_t> on_boundary, used;

  void count_nonfinite() {
    check.nonfinite = parallel_count<int32_t>(0, n, kParallelMin, [&](int32_t v) {
      return !std::isfinite(positions[3 * size_t(v)]) || !std::isfinite(positions[3 * size_t(v) + 1]) ||
             !std::isfinite(positions[3 * size_t(v) + 2]);
    });
  }

  // Which input components are manifold, oriented surfaces (the guarantee's domain), allowing
  // pinched vertices: their fans are compared one by one at the end.
  void find_surface_components() {
    manifold.assign(num_components, 1);
    const MeshReport& report = mesh.report();
    if (report.nonmanifold_vertices + report.nonmanifold_edges + report.inconsistent_edges > 0)  // else all are
      for (int32_t v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.component()[v] >= 0 && !mesh.manifold_vertex()[v]) manifold[mesh.component()[v]] = 0;
    for (int32_t comp = 0; comp < num_components && pinched.count > 0; ++comp)
      if (pinched.pinched_surface[comp]) manifold[comp] = 1;
    component_of.resize(n);
    parallel_for(0, n, kParallelMin, [&](int32_t v) { component_of[v] = mesh.component()[kept[v]]; });
  }

  // Per triangle: repeated corners, mixed components, zero area; triangles per component
  // (counted per thread, summed after: integers, so the order does not matter).
  void check_triangles() {
    triangles_in.assign(num_components, 0);
    euler.assign(num_components, 0);
    int32_t repeated_corner = 0, mixed_triangles = 0, zero_area = 0;
    parallel_region(team_for(t, kParallelMin), [&](Team& team) {
      std::vector<int32_t> mine(num_components, 0);
      int32_t my_repeated = 0, my_mixed = 0, my_zero = 0;
      team.for_static(0, t, [&](int32_t i) {
        const int32_t* c = &triangles[3 * size_t(i)];
        if (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) {
          ++my_repeated;
          return;
        }
        const int32_t comp = component_of[c[0]];
        if (component_of[c[1]] != comp || component_of[c[2]] != comp) ++my_mixed;
        ++mine[comp];
        if (has_zero_area(c)) ++my_zero;
      });
      team.critical([&] {
        repeated_corner += my_repeated, mixed_triangles += my_mixed, zero_area += my_zero;
        for (int32_t comp = 0; comp < num_components; ++comp) triangles_in[comp] += mine[comp];
      });
    });
    check.repeated_corner = repeated_corner;
    check.mixed_triangles = mixed_triangles;
    check.zero_area = zero_area;
    for (int32_t comp = 0; comp < num_components; ++comp) euler[comp] += triangles_in[comp];
    for (int32_t comp = 0; comp < num_components; ++comp)
      if (triangles_in[comp] == 0) ++check.lost_components;
  }

  // Zero area relative to the longest edge.
  bool has_zero_area(const int32_t* c) const {
    const double* p[3] = {&positions[3 * size_t(c[0])], &positions[3 * size_t(c[1])], &positions[3 * size_t(c[2])]};
    double u[3], w[3], longest = 0;
    for (int a = 0; a < 3; ++a) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
    for (int j = 0; j < 3; ++j) {
      double d = 0;
      for (int a = 0; a < 3; ++a) d += (p[(j + 1) % 3][a] - p[j][a]) * (p[(j + 1) % 3][a] - p[j][a]);
      longest = std::max(longest, d);
    }
    const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2], cz = u[0] * w[1] - u[1] * w[0];
    return !(std::sqrt(cx * cx + cy * cy + cz * cz) > 1e-9 * longest);
  }

  // Per vertex: its link gives the edges (each counted at its lower end), their triangle
  // counts and directions, duplicates, the fan, and the boundary. Vertices share only the sets
  // they join (union-finds whose roots do not depend on the order of joins) and the counts, so
  // they run on all threads and the result does not depend on how many.
  void check_vertex_links() {
    const VertexArcs around(n, triangles);
    on_boundary.assign(n, 0);
    used.assign(n, 0);
    int32_t duplicate = 0, nonmanifold_edges = 0, inconsistent_edges = 0, nonmanifold_vertices = 0;
    std::atomic<int64_t> next_vertex{0};
    parallel_region(team_for(n, kParallelMinCostly), [&](Team& team) {
      LinkArcs link;
      std::vector<std::array<int32_t, 2>> corner_pairs;
      std::vector<int64_t> my_euler(num_components, 0);
      LinkIssues mine;
      team.for_dynamic(next_vertex, n, 512, [&](int32_t v) {
        const int32_t count = around.offsets[v + 1] - around.offsets[v];
        const VertexArcs::Arc* arcs = around.arcs.data() + around.offsets[v];
        if (one_cycle(arcs, count) && manifold[component_of[v]]) {
          // The common case, one closed fan (link_arcs.hpp): each neighbour edge has two
          // triangles, one each way, and no triangle repeats; only the edges are counted.
          used[v] = 1;
          int64_t& euler_v = my_euler[component_of[v]];
          ++euler_v;
          for (int32_t i = 0; i < count; ++i)
            if (arcs[i].from > v) --euler_v, pieces.unite(v, arcs[i].from);
          return;
        }
        check_link(v, arcs, count, link, corner_pairs, my_euler, mine);
      });
      team.critical([&] {
        duplicate += mine.duplicate, nonmanifold_edges += mine.nonmanifold_edges;
        inconsistent_edges += mine.inconsistent_edges, nonmanifold_vertices += mine.nonmanifold_vertices;
        for (int32_t comp = 0; comp < num_components; ++comp) euler[comp] += my_euler[comp];
      });
    });
    check.duplicate += duplicate;
    check.nonmanifold_edges += nonmanifold_edges;
    check.inconsistent_edges += inconsistent_edges;
    check.nonmanifold_vertices += nonmanifold_vertices;
  }

  // Any other vertex: its link's arcs one by one (`count` of them from `arcs`).
  void check_link(int32_t v, const VertexArcs::Arc* arcs, int32_t count, LinkArcs& link,
                  std::vector<std::array<int32_t, 2>>& corner_pairs, std::vector<int64_t>& my_euler,
                  LinkIssues& issues) {
    link.clear();
    corner_pairs.clear();
    for (int32_t i = 0; i < count; ++i) {
      const int32_t a = arcs[i].from, b = arcs[i].to;
      link.add(a, b);
      if (v < a && v < b) {
        // A triangle over the same three vertices as an earlier one (at its lowest corner).
        const std::array<int32_t, 2> pair = {std::min(a, b), std::max(a, b)};
        issues.duplicate += std::count(corner_pairs.begin(), corner_pairs.end(), pair) > 0;
        corner_pairs.push_back(pair);
      }
    }
    if (link.arcs == 0) return;
    used[v] = 1;
    const int32_t comp = component_of[v];
    ++my_euler[comp];
    bool crowded = false;
    for (const auto& nb : link.neighbours) {
      const int32_t triangles_at = nb.in + nb.out;
      if (nb.id > v) --my_euler[comp], pieces.unite(v, nb.id);  // each edge once
      if (triangles_at > 2 || nb.in > 1 || nb.out > 1) crowded = true;
      if (!manifold[comp]) continue;
      if (nb.id > v && triangles_at > 2) ++issues.nonmanifold_edges;
      if (nb.id > v && triangles_at <= 2 && (nb.in > 1 || nb.out > 1)) ++issues.inconsistent_edges;
      if (triangles_at == 1) {
        on_boundary[v] = 1;
        boundary.unite(v, nb.id);
      }
    }
    const bool pinched_input = pinched.count > 0 && pinched.pinched[kept[v]];
    if (manifold[comp] && !crowded && !pinched_input && !link.single_fan()) ++issues.nonmanifold_vertices;
  }

  // Per component: split into pieces, Euler characteristic and boundary loops against the input.
  void compare_components() {
    std::vector<int32_t> roots(num_components, -1), loops(num_components, 0);
    for (int32_t v = 0; v < n; ++v) {
      if (!used[v]) continue;
      const int32_t comp = component_of[v];
      const int32_t root = pieces.find(v);
      if (roots[comp] < 0) {
        roots[comp] = root;
      } else if (roots[comp] != root) {
        roots[comp] = -2;  // counted once below
      }
      if (on_boundary[v] && boundary.find(v) == v) ++loops[comp];
    }
    auto input_loops = component_boundary_loops(mesh, layout);
    if (pinched.count > 0) {
      // Loops touching at a pinch are one group of boundary edges, as counted on the output.
      const auto groups = boundary_edge_groups(mesh);
      for (int32_t comp = 0; comp < num_components; ++comp)
        if (pinched.pinched_surface[comp]) input_loops[comp] = groups[comp];
    }
    for (int32_t comp = 0; comp < num_components; ++comp) {
      if (roots[comp] == -2) ++check.split_components;
      if (!manifold[comp] || triangles_in[comp] == 0) continue;
      if (euler[comp] != mesh.component_euler()[comp]) ++check.euler_changed;
      if (loops[comp] != input_loops[comp]) ++check.boundary_loops_changed;
    }
  }
};

}  // namespace

OutputCheck check_output(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& kept,
                         const std::vector<double>& positions, const std::vector<int32_t>& triangles) {
  return OutputChecker(mesh, layout, kept, positions, triangles).run();
}

}  // namespace topstoc
