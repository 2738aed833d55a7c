// Mesh::winding_flips: a consistent orientation of each orientable component, found by
// propagating a flip bit across the edges of two faces (consistent neighbours run along their
// shared edge in opposite directions).
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc {

void Mesh::build_winding_flips() const {
  if (report_.inconsistent_edges == 0) return;
  const int32_t m = num_faces();
  std::vector<int8_t> flip(m, -1);
  std::vector<int32_t> stack, reached;
  for (int32_t start = 0; start < m; ++start) {
    if (flip[start] >= 0) continue;
    flip[start] = 0;
    stack.assign(1, start);
    reached.assign(1, start);
    bool orientable = true;
    while (!stack.empty()) {
      const int32_t f = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int32_t e = face_edges()[3 * size_t(f) + k];
        if (edge_face_count(e) != 2) continue;
        const int32_t o = edge_face_offsets()[e];
        const int32_t g = edge_faces()[o] == f ? edge_faces()[o + 1] : edge_faces()[o];
        const int8_t want = int8_t(flip[f] ^ (runs_forward(f, e) == runs_forward(g, e)));
        if (flip[g] < 0) {
          flip[g] = want;
          stack.push_back(g);
          reached.push_back(g);
        } else if (flip[g] != want) {
          orientable = false;
        }
      }
    }
    if (!orientable)
      for (int32_t f : reached) flip[f] = 0;
  }
  winding_flips_.assign(flip.begin(), flip.end());
}

}  // namespace topstoc
