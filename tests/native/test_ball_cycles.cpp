// BallCycles, the loop selection's per-tree filter, against Gaussian elimination on the cycles'
// classes: on a whole shortest-path tree it keeps exactly the greedy basis (shortest first, each
// cycle independent of the shorter ones kept); on a tree cut to a ball it may keep more, never
// fewer.
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "topology/ball_cycles.hpp"
#include "topology/homology.hpp"
#include "topology/shortest_paths.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/io/io.hpp"

using namespace topstoc;

namespace {

struct Cycle {
  double bound;
  int32_t edge;
  Z2Vector cls;
};

// Fundamental cycles of the edges outside the tree between settled vertices, shortest first
// (through the root), with their classes.
std::vector<Cycle> tree_cycles(const ClosedSurface& s, const SurfaceHomology& h, const ShortestPaths& sp,
                               const std::vector<double>& weight) {
  std::vector<Z2Vector> prefix(s.num_vertices(), Z2Vector(h.dimension()));
  for (int32_t v : sp.settled())
    if (sp.parent(v) >= 0) {
      prefix[v] = prefix[sp.parent(v)];
      h.add_edge(prefix[v], sp.parent_edge(v));
    }
  std::vector<Cycle> cycles;
  for (int32_t e = 0; e < s.num_edges(); ++e) {
    const int32_t a = s.edge_vertices[2 * size_t(e)], b = s.edge_vertices[2 * size_t(e) + 1];
    if (!sp.is_settled(a) || !sp.is_settled(b) || sp.parent_edge(a) == e || sp.parent_edge(b) == e) continue;
    Z2Vector cls = prefix[a];
    cls.add(prefix[b]);
    h.add_edge(cls, e);
    cycles.push_back({sp.distance(a) + weight[e] + sp.distance(b), e, std::move(cls)});
  }
  std::sort(cycles.begin(), cycles.end(),
            [](const Cycle& x, const Cycle& y) { return std::tie(x.bound, x.edge) < std::tie(y.bound, y.edge); });
  return cycles;
}

void check_surface(const std::string& name) {
  const MeshFile file = read_mesh_path(std::string(TOPSTOC_TEST_DATA "/genus_positive/") + name);
  const Mesh mesh(file.vertices, file.triangles.data(), file.num_triangles());
  const ClosedSurface s = extract_surface(mesh, component_vertices(mesh)[0]);
  const SurfaceHomology h(s);
  REQUIRE(h.dimension() >= 4);
  std::vector<double> weight(s.num_edges());
  double mean = 0;
  for (int32_t e = 0; e < s.num_edges(); ++e) mean += (weight[e] = s.edge_length(e)) / s.num_edges();
  ShortestPaths sp(s, weight);
  BallCycles ball(s);
  std::mt19937 random(7);
  for (int trial = 0; trial < 12; ++trial) {
    const int32_t root = int32_t(random() % uint32_t(s.num_vertices()));
    const bool whole = trial % 2 == 0;
    sp.run({root}, [](int32_t) { return true; }, [](int32_t) { return true; }, -1,
           whole ? ShortestPaths::kInfinity : mean * (3 + 2 * trial));
    const auto cycles = tree_cycles(s, h, sp, weight);
    // Three groups, as the selection has: two candidate lists and the cycles in neither.
    std::vector<int32_t> edges;
    std::vector<int8_t> group;
    for (const auto& c : cycles) edges.push_back(c.edge), group.push_back(int8_t(int(random() % 3) - 1));
    ball.start(sp, edges, group);
    for (int8_t g : {int8_t(0), int8_t(1)}) {
      std::vector<int32_t> candidates;
      Z2Basis basis(h.dimension());
      std::vector<uint8_t> expected, keep;
      for (size_t i = 0; i < cycles.size(); ++i)
        if (group[i] == g) {
          candidates.push_back(cycles[i].edge);
          expected.push_back(basis.insert(cycles[i].cls));
        }
      ball.independent(g, candidates, keep);
      REQUIRE(keep.size() == expected.size());
      CAPTURE(name);
      CAPTURE(trial);
      if (whole) CHECK(keep == expected);
      for (size_t i = 0; i < keep.size(); ++i)
        if (expected[i]) CHECK(keep[i]);
    }
  }
}

}  // namespace

TEST_CASE("ball cycles: union-find on the faces keeps the greedy basis that elimination keeps") {
  for (const char* name : {"cgal_3torus.off", "cgal_eight.off", "cgal_couplingdown.off"}) check_surface(name);
}
