#include "topstoc/edit/remove_handle.hpp"
#include "topstoc/core/self_intersections.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

// Pulls the copies of the cut loop apart (see RemoveHandleOptions::separation).
void separate_sides(EditResult& cut, double fraction) {
  const size_t n = cut.vertex_source.size();
  std::vector<uint8_t> on_side(n, 0);
  std::vector<int32_t> side_vertices;
  for (const CutSide& side : cut.cut_sides)
    for (int32_t v : side.vertices) on_side[v] = 1, side_vertices.push_back(v);
  // Mean of every side vertex's neighbours off the cut (they all lie in its own sector).
  std::vector<double> sum(3 * n, 0.0);
  std::vector<int32_t> count(n, 0), touching;
  const size_t m = cut.triangles.size() / 3;
  for (size_t t = 0; t < m; ++t) {
    const int32_t* c = &cut.triangles[3 * t];
    if (!on_side[c[0]] && !on_side[c[1]] && !on_side[c[2]]) continue;
    touching.push_back(static_cast<int32_t>(t));
    for (int i = 0; i < 3; ++i) {
      if (!on_side[c[i]]) continue;
      for (int j = 1; j < 3; ++j) {
        const int32_t w = c[(i + j) % 3];
        if (on_side[w]) continue;
        for (int a = 0; a < 3; ++a) sum[3 * size_t(c[i]) + a] += cut.vertices[3 * size_t(w) + a];
        ++count[c[i]];
      }
    }
  }
  const std::vector<double> before = cut.vertices;
  auto normal = [](const std::vector<double>& p, const int32_t* c, double* out) {
    const double *a = &p[3 * size_t(c[0])], *b = &p[3 * size_t(c[1])], *d = &p[3 * size_t(c[2])];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    out[0] = u[1] * w[2] - u[2] * w[1], out[1] = u[2] * w[0] - u[0] * w[2], out[2] = u[0] * w[1] - u[1] * w[0];
  };
  // Move, then halve the move of every vertex of a triangle that turned over or lost most of its
  // area, a few times; what still fails stays where it was.
  std::vector<double> step(n, fraction);
  for (int round = 0; round < 6; ++round) {
    for (int32_t v : side_vertices) {
      const double s = count[v] ? step[v] : 0.0;
      for (int a = 0; a < 3; ++a) {
        const size_t i = 3 * size_t(v) + a;
        cut.vertices[i] = count[v] ? before[i] + s * (sum[i] / count[v] - before[i]) : before[i];
      }
    }
    bool bad = false;
    for (int32_t t : touching) {
      const int32_t* c = &cut.triangles[3 * size_t(t)];
      double old_normal[3], new_normal[3];
      normal(before, c, old_normal);
      normal(cut.vertices, c, new_normal);
      const double old_area = std::sqrt(old_normal[0] * old_normal[0] + old_normal[1] * old_normal[1] +
                                        old_normal[2] * old_normal[2]);
      const double agree = old_normal[0] * new_normal[0] + old_normal[1] * new_normal[1] + old_normal[2] * new_normal[2];
      if (agree > 0.25 * old_area * old_area) continue;
      bad = true;
      for (int i = 0; i < 3; ++i) step[c[i]] = round < 5 ? step[c[i]] * 0.5 : 0.0;
    }
    if (!bad) break;
  }
}

// Whether two of the edit's patches cross each other: the faired caps of a thin handle bulge
// into each other, the usual failure, and testing only the pairs across two patches (few boxes
// meet) settles it far sooner than the full test. A pair found is one of the full answer's (the
// pair test looks at the two triangles only), so false says nothing.
bool patches_cross(const EditResult& r) {
  const double* p = r.vertices.data();
  auto box = [&](int32_t t, double* b) {
    const int32_t* c = &r.triangles[3 * size_t(t)];
    for (int k = 0; k < 3; ++k) {
      b[k] = std::min({p[3 * size_t(c[0]) + k], p[3 * size_t(c[1]) + k], p[3 * size_t(c[2]) + k]});
      b[3 + k] = std::max({p[3 * size_t(c[0]) + k], p[3 * size_t(c[1]) + k], p[3 * size_t(c[2]) + k]});
    }
  };
  auto distinct = [&](int32_t t) {
    const int32_t* c = &r.triangles[3 * size_t(t)];
    return c[0] != c[1] && c[1] != c[2] && c[0] != c[2];
  };
  for (size_t a = 0; a < r.patches.size(); ++a)
    for (size_t b = a + 1; b < r.patches.size(); ++b) {
      const FilledHole &pa = r.patches[a], &pb = r.patches[b];
      if (int64_t(pa.num_triangles) * pb.num_triangles > 4000000) continue;  // left to the full test
      for (int32_t s = pa.first_triangle; s < pa.first_triangle + pa.num_triangles; ++s) {
        double bs[6];
        box(s, bs);
        for (int32_t t = pb.first_triangle; t < pb.first_triangle + pb.num_triangles; ++t) {
          double bt[6];
          box(t, bt);
          bool overlap = true;
          for (int k = 0; k < 3; ++k) overlap = overlap && bs[k] <= bt[3 + k] && bt[k] <= bs[3 + k];
          if (overlap && distinct(s) && distinct(t) &&
              triangles_intersect(p, &r.triangles[3 * size_t(s)], &r.triangles[3 * size_t(t)]))
            return true;
        }
      }
    }
  return false;
}

// Whether a triangle the edit created or moved (a patch triangle, or one touching a moved copy
// of the loop) intersects any other triangle of the result. Intersections among untouched input
// triangles were there before and are not the edit's doing.
bool edit_intersects(const EditResult& r) {
  if (patches_cross(r)) return true;
  const int32_t n = static_cast<int32_t>(r.vertex_source.size());
  const int32_t m = static_cast<int32_t>(r.triangles.size() / 3);
  std::vector<uint8_t> moved(n, 0);
  for (const CutSide& side : r.cut_sides)
    for (int32_t v : side.vertices) moved[v] = 1;
  for (int32_t v = 0; v < n; ++v)
    if (r.vertex_source[v] < 0) moved[v] = 1;
  std::vector<uint8_t> touched(m, 0);
  for (int32_t t = 0; t < m; ++t) {
    const int32_t* c = &r.triangles[3 * size_t(t)];
    touched[t] = r.face_source[t] < 0 || moved[c[0]] || moved[c[1]] || moved[c[2]];
  }
  return !self_intersections(r.vertices.data(), n, r.triangles.data(), m, 1, touched.data()).empty();
}

struct Attempt {
  double separation;
  bool refine, fair;
  bool operator==(const Attempt& o) const { return separation == o.separation && refine == o.refine && fair == o.fair; }
};

// The candidates remove_handle tries for one fill, in order: the copies pulled apart more or
// less, with the fill asked for and with a refined, faired one.
std::vector<Attempt> attempts(double s0, bool refine, bool fair) {
  return {{s0, refine, fair},          {s0, true, true},           {0.5 * s0, true, true},
          {std::min(0.45, 1.6 * s0), true, true}, {0.5 * s0, refine, fair}, {0.1 * s0, true, true},
          {std::min(0.45, 1.6 * s0), refine, fair}};
}

// The fills asked for: options.fill, then with step_down the coarser ones (refined, then flat).
std::vector<std::pair<bool, bool>> fills(const RemoveHandleOptions& options) {
  const bool refine = options.fill.refine || options.fill.fair, fair = options.fill.fair;
  std::vector<std::pair<bool, bool>> out{{options.fill.refine, fair}};
  if (options.step_down && fair) out.emplace_back(true, false);
  if (options.step_down && refine) out.emplace_back(false, false);
  return out;
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
  // An edit must never make the surface self-intersect: a patch that crosses the surface
  // (a hole whose loop is far from planar, two patches too close) is tried again with the
  // copies pulled apart more or less and with a refined, faired patch; the first candidate
  // free of intersections wins. (Found when removing the handles of a genus-6 part one by
  // one: the fourth patch crossed the surface and TetGen refused the next step.)
  std::vector<Attempt> tried;
  for (const auto& [refine, fair] : fills(options)) {
    for (const Attempt& attempt : attempts(options.separation, refine, fair)) {
      if (std::find(tried.begin(), tried.end(), attempt) != tried.end()) continue;  // same result again
      tried.push_back(attempt);
      EditResult candidate = cut;
      if (attempt.separation > 0) separate_sides(candidate, attempt.separation);
      FillOptions fill = options.fill;
      fill.refine = attempt.refine;
      fill.fair = attempt.fair;
      fill_loops_into(candidate, holes, fill);
      if (options.allow_self_intersections || !edit_intersects(candidate)) return candidate;
    }
  }
  throw std::invalid_argument("removing the handle along this loop would make the surface intersect itself (every "
                              "fill patch tried crosses the surface); try a shorter or flatter loop around it");
}

}  // namespace topstoc
