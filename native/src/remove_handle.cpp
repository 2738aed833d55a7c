#include "topstoc/remove_handle.hpp"

#include <numeric>
#include <stdexcept>
#include <string>

namespace topstoc {

namespace {

// Whether the first vertices of all cut sides are still connected after the cut (union-find
// over the triangles' edges).
bool sides_connected(const EditResult& cut) {
  std::vector<int32_t> parent(cut.vertex_source.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t t = 0; t < cut.triangles.size(); t += 3)
    for (int c = 0; c < 2; ++c) {
      const int32_t a = find(cut.triangles[t + c]), b = find(cut.triangles[t + c + 1]);
      if (a != b) parent[a < b ? b : a] = a < b ? a : b;
    }
  for (const CutSide& side : cut.cut_sides)
    if (find(side.vertices.front()) != find(cut.cut_sides.front().vertices.front())) return false;
  return true;
}

}  // namespace

EditResult remove_handle(const double* positions, int32_t num_vertices, const int32_t* triangles,
                         int64_t num_triangles, const int32_t* loop, int32_t loop_size,
                         const RemoveHandleOptions& options) {
  EditResult cut = cut_along_loop(positions, num_vertices, triangles, num_triangles, loop, loop_size);
  std::vector<std::vector<int32_t>> holes;
  for (const CutSide& side : cut.cut_sides) {
    if (!side.closed)
      throw std::invalid_argument("loop vertex " + std::to_string(cut.vertex_source[side.vertices.front()]) +
                                  " lies on the mesh boundary: removing a handle there would merge the cut with "
                                  "that boundary (cut and fill holes separately to do that on purpose)");
    holes.push_back(side.vertices);
  }
  if (!options.allow_separating && !sides_connected(cut))
    throw std::invalid_argument("the loop separates its component (cutting along it splits the surface in two): it "
                                "goes around no handle or tunnel");
  fill_loops_into(cut, holes, options.fill);
  return cut;
}

}  // namespace topstoc
