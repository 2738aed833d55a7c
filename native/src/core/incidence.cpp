#include "topstoc/core/incidence.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "topstoc/core/validate.hpp"

namespace topstoc {

void check_positions(const double* positions, int32_t num_vertices, const std::vector<int32_t>* vertices) {
  if (vertices) {
    for (int32_t v : *vertices) require_finite_position(positions, v);
  } else {
    require_finite_positions(positions, num_vertices);
  }
}

void check_triangles(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices, bool allow_repeated) {
  if (num_triangles > INT32_MAX / 3) throw std::invalid_argument("mesh is too large: more than 2^31 / 3 triangles");
  require_indices_in_range(triangles, num_triangles, 3, num_vertices, "triangle");
  for (int64_t t = 0; t < num_triangles; ++t) {
    const int32_t* c = triangles + 3 * t;
    if (!allow_repeated && (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]))
      throw std::invalid_argument("triangle " + std::to_string(t) + " (" + std::to_string(c[0]) + ", " +
                                  std::to_string(c[1]) + ", " + std::to_string(c[2]) +
                                  ") repeats a vertex: delete degenerate triangles first");
  }
}

VertexTriangles vertex_triangles(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices,
                                 const uint8_t* only) {
  VertexTriangles out;
  out.offsets.assign(size_t(num_vertices) + 1, 0);
  for (int64_t i = 0; i < 3 * num_triangles; ++i) {
    const int32_t v = triangles[i];
    if (!only || only[v]) ++out.offsets[v + 1];
  }
  for (int32_t v = 0; v < num_vertices; ++v) out.offsets[v + 1] += out.offsets[v];
  out.list.resize(out.offsets[num_vertices]);
  std::vector<int32_t> cursor(out.offsets.begin(), out.offsets.end() - 1);
  // Triangles are visited in increasing order, so every list comes out sorted. A triangle with
  // a repeated vertex is listed once per corner; callers reject those before looking at stars.
  for (int64_t t = 0; t < num_triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t v = triangles[3 * t + k];
      if (!only || only[v]) out.list[cursor[v]++] = static_cast<int32_t>(t);
    }
  return out;
}

void vertex_star(const VertexTriangles& around, const int32_t* triangles, int32_t v, std::vector<StarEdge>& star) {
  star.clear();
  // Each triangle of v contributes its two edges at v: v -> next (outgoing) and prev -> v.
  struct Side {
    int32_t other, triangle;
    bool outgoing;
  };
  thread_local std::vector<Side> sides;  // reused: stars are asked for in tight loops
  sides.clear();
  for (int32_t i = around.begin(v); i < around.end(v); ++i) {
    const int32_t t = around.list[i];
    const int32_t* c = triangles + 3 * size_t(t);
    const int k = c[0] == v ? 0 : c[1] == v ? 1 : 2;
    sides.push_back({c[(k + 1) % 3], t, true});
    sides.push_back({c[(k + 2) % 3], t, false});
  }
  std::sort(sides.begin(), sides.end(), [](const Side& a, const Side& b) {
    return a.other != b.other ? a.other < b.other : a.triangle < b.triangle;
  });
  for (const Side& s : sides) {
    if (star.empty() || star.back().other != s.other) star.push_back(StarEdge{s.other, 0, {-1, -1}, {false, false}});
    StarEdge& e = star.back();
    if (e.count < 2) {
      e.triangle[e.count] = s.triangle;
      e.outgoing[e.count] = s.outgoing;
    }
    ++e.count;
  }
}

const StarEdge* find_star_edge(const std::vector<StarEdge>& star, int32_t other) {
  auto it = std::lower_bound(star.begin(), star.end(), other,
                             [](const StarEdge& e, int32_t value) { return e.other < value; });
  return it != star.end() && it->other == other ? &*it : nullptr;
}

}  // namespace topstoc
