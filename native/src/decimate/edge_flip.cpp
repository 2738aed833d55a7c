// Edge flips of a collapsed surface (Collapser::flip): the last stage of a tiny result
// (tiny_fit.cpp) turns the diagonal of two triangles where the result spans a gap of the input.
#include <cmath>

#include "decimate/collapser.hpp"

namespace topstoc {

namespace {

// Smallest shape quality (Collapser::shape, squared here) a flipped triangle may have, and the
// largest turn of its normal against the old pair's mean normal (cosine).
constexpr double kFlipShape2 = 0.1 * 0.1;
constexpr double kFlipCos = 0.17;

double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

bool Collapser::flip(int32_t f, int32_t side, Flip& saved) {
  if (!face_alive(f)) return false;
  const int32_t a = tri_[3 * size_t(f) + side], b = tri_[3 * size_t(f) + (side + 1) % 3];
  const int32_t c = tri_[3 * size_t(f) + (side + 2) % 3];
  // The one other live triangle on a-b, running along it b to a (a manifold, oriented edge).
  int32_t g = -1, j = -1;
  for (const int32_t* t = faces_begin(a); t != faces_end(a); ++t) {
    if (*t == f || !face_alive(*t) || !has(*t, b)) continue;
    if (g >= 0) return false;
    g = *t;
  }
  if (g < 0) return false;
  for (int k = 0; k < 3; ++k)
    if (tri_[3 * size_t(g) + k] == b && tri_[3 * size_t(g) + (k + 1) % 3] == a) j = k;
  if (j < 0) return false;
  const int32_t d = tri_[3 * size_t(g) + (j + 2) % 3];
  // Not along a feature (both ends on curves or kept), not across a seam, no edge c-d already.
  const bool a_held = s_.curve[a] >= 0 || s_.locked[a], b_held = s_.curve[b] >= 0 || s_.locked[b];
  if (c == d || (a_held && b_held) || sector_at(f, a) != sector_at(g, a) || sector_at(f, b) != sector_at(g, b))
    return false;
  for (const int32_t* t = faces_begin(c); t != faces_end(c); ++t)
    if (face_alive(*t) && has(*t, d)) return false;
  // Each new triangle faces the way the old pair faces on the whole (a ridge may become a
  // valley: the caller weighs the distance to the input) and is no sliver.
  const int32_t after[2][3] = {{a, d, c}, {d, b, c}};
  double old_f[3], old_g[3], facing[3];
  normal(&tri_[3 * size_t(f)], -1, nullptr, old_f);
  normal(&tri_[3 * size_t(g)], -1, nullptr, old_g);
  const double lf = std::sqrt(dot(old_f, old_f)), lg = std::sqrt(dot(old_g, old_g));
  if (!(lf > 0.0 && lg > 0.0)) return false;
  for (int i = 0; i < 3; ++i) facing[i] = old_f[i] / lf + old_g[i] / lg;
  for (const auto& t : after) {
    double n[3];
    normal(t, -1, nullptr, n);
    const double len = std::sqrt(dot(n, n)), edges = squared_edges(t, -1, nullptr);
    if (!(12.0 * dot(n, n) >= kFlipShape2 * edges * edges) || edges == 0.0) return false;
    if (!(dot(n, facing) > kFlipCos * len * std::sqrt(dot(facing, facing)))) return false;
  }
  saved.f = f, saved.g = g, saved.a = a, saved.b = b, saved.c = c, saved.d = d;
  for (int k = 0; k < 3; ++k) {
    for (int32_t h = 0; h < 2; ++h) {
      const size_t corner = 3 * size_t(h == 0 ? f : g) + k;
      saved.tri[3 * h + k] = tri_[corner];
      saved.source[3 * h + k] = corner_source_[corner];
      saved.sector[3 * h + k] = s_.corner_sector[corner];
    }
  }
  // Each new corner copies the old corner of its vertex (the same sector, checked above).
  const size_t from[2][3] = {{3 * size_t(f) + side, 3 * size_t(g) + (j + 2) % 3, 3 * size_t(f) + (side + 2) % 3},
                             {3 * size_t(g) + (j + 2) % 3, 3 * size_t(g) + j, 3 * size_t(f) + (side + 2) % 3}};
  int32_t source[2][3], sector[2][3];
  for (int h = 0; h < 2; ++h)
    for (int k = 0; k < 3; ++k) source[h][k] = corner_source_[from[h][k]], sector[h][k] = s_.corner_sector[from[h][k]];
  for (int h = 0; h < 2; ++h)
    for (int k = 0; k < 3; ++k) {
      const size_t corner = 3 * size_t(h == 0 ? f : g) + k;
      tri_[corner] = after[h][k], corner_source_[corner] = source[h][k], s_.corner_sector[corner] = sector[h][k];
    }
  remove_face(a, g);
  remove_face(b, f);
  append_faces(c, &g, 1);
  append_faces(d, &f, 1);
  return true;
}

void Collapser::unflip(const Flip& saved) {
  for (int32_t h = 0; h < 2; ++h)
    for (int k = 0; k < 3; ++k) {
      const size_t corner = 3 * size_t(h == 0 ? saved.f : saved.g) + k;
      tri_[corner] = saved.tri[3 * h + k];
      corner_source_[corner] = saved.source[3 * h + k];
      s_.corner_sector[corner] = saved.sector[3 * h + k];
    }
  remove_face(saved.c, saved.g);
  remove_face(saved.d, saved.f);
  append_faces(saved.a, &saved.g, 1);
  append_faces(saved.b, &saved.f, 1);
}

}  // namespace topstoc
