// Handle and tunnel loops do not depend on the team size: the loops are shortened on a team
// (one LoopTightener per member, loops taken by whichever member is free), on the full route
// and on the coarse route (where the coarse loops are tightened on a team too).
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/io/io.hpp"
#include "topstoc/topology/loops.hpp"
#include "with_threads.hpp"

using namespace topstoc;

namespace {

// Every loop of every component, before and after shortening, in result order.
std::vector<std::vector<int32_t>> all_loops(const LoopsResult& r) {
  std::vector<std::vector<int32_t>> loops;
  for (const auto& c : r.components)
    for (const auto* kind : {&c.handles, &c.tunnels})
      for (const auto& loop : *kind) {
        loops.push_back(loop.initial_vertices);
        loops.push_back(loop.vertices);
      }
  return loops;
}

void check_team_sizes(const std::string& name, int32_t coarse_vertices, int32_t genus) {
  const MeshFile file = read_mesh_path(std::string(TOPSTOC_TEST_DATA "/genus_positive/") + name);
  const Mesh mesh(file.vertices, file.triangles.data(), file.num_triangles());
  LoopParams params;
  params.coarse_vertices = coarse_vertices;
  const LoopsResult one = with_threads(1, [&] { return compute_loops(mesh, params); });
  REQUIRE(one.components.size() == 1);
  CHECK(one.components[0].genus == genus);
  CHECK(one.components[0].route == (coarse_vertices > 0 ? "coarse" : "full"));
  const auto expected = all_loops(one);
  REQUIRE(expected.size() == 4 * size_t(genus));
  // The shortening changed something, so the team had work whose order could matter.
  bool moved = false;
  for (size_t i = 0; i < expected.size(); i += 2) moved = moved || expected[i] != expected[i + 1];
  CHECK(moved);
  for (int threads : {2, 3}) CHECK(all_loops(with_threads(threads, [&] { return compute_loops(mesh, params); })) == expected);
}

}  // namespace

TEST_CASE("loops on a team: full route") { check_team_sizes("cgal_couplingdown.off", 0, 9); }

TEST_CASE("loops on a team: coarse route") { check_team_sizes("cgal_couplingdown.off", 800, 9); }
