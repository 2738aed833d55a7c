#include "topstoc/edit/hole_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace topstoc {

namespace {

using Vec = std::array<double, 3>;

Vec operator-(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec operator+(const Vec& a, const Vec& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec operator*(double s, const Vec& a) { return {s * a[0], s * a[1], s * a[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec& a) { return std::sqrt(dot(a, a)); }
Vec unit(const Vec& a) {
  const double n = norm(a);
  return n > 0 ? (1.0 / n) * a : Vec{0, 0, 0};
}

// Eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix (cyclic Jacobi rotations).
Vec smallest_eigenvector(double m[3][3]) {
  double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    const double diag = m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2];
    if (off <= 1e-30 * diag || off == 0.0) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (m[p][q] == 0.0) continue;
        const double theta = (m[q][q] - m[p][p]) / (2 * m[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // m = J^T m J
          const double mkp = m[k][p], mkq = m[k][q];
          m[k][p] = c * mkp - s * mkq;
          m[k][q] = s * mkp + c * mkq;
        }
        for (int k = 0; k < 3; ++k) {
          const double mpk = m[p][k], mqk = m[q][k];
          m[p][k] = c * mpk - s * mqk;
          m[q][k] = s * mpk + c * mqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (m[i][i] < m[best][best]) best = i;
  return {v[0][best], v[1][best], v[2][best]};
}

class Filler {
 public:
  Filler(const Hole& hole, const HoleTriangulationOptions& options)
      : hole_(hole), options_(options), k_(static_cast<int32_t>(hole.points.size() / 3)) {}

  HoleTriangulation run() {
    std::vector<int32_t> all(k_);
    for (int32_t i = 0; i < k_; ++i) all[i] = i;
    const Vec newell = unit(newell_normal(all));
    out_.normal[0] = newell[0], out_.normal[1] = newell[1], out_.normal[2] = newell[2];
    fill(all, 0, true);
    return std::move(out_);
  }

 private:
  Vec point(int32_t i) const {
    if (i < k_) return {hole_.points[3 * size_t(i)], hole_.points[3 * size_t(i) + 1], hole_.points[3 * size_t(i) + 2]};
    const size_t j = 3 * size_t(i - k_);
    return {out_.added_points[j], out_.added_points[j + 1], out_.added_points[j + 2]};
  }

  // Normal of the surface beyond the piece side from a to b: known only for the hole's own sides.
  Vec side_normal(int32_t a, int32_t b) const {
    if ((a + 1) % k_ != b || hole_.side_normals.empty()) return {0, 0, 0};
    return {hole_.side_normals[3 * size_t(a)], hole_.side_normals[3 * size_t(a) + 1],
            hole_.side_normals[3 * size_t(a) + 2]};
  }

  bool forbidden(int32_t a, int32_t b) const {
    if ((a + 1) % k_ == b || (b + 1) % k_ == a) return false;  // a side of the hole
    return hole_.forbidden && hole_.forbidden(a, b);
  }

  void use(FillMethod method) {
    if (int32_t(method) > int32_t(out_.method)) out_.method = method;
  }

  // Area vector of the closed polygon (twice the area, direction by the right-hand rule).
  Vec newell_normal(const std::vector<int32_t>& c) const {
    const size_t n = c.size();
    Vec centre{0, 0, 0};
    for (int32_t i : c) centre = centre + point(i);
    centre = (1.0 / double(n)) * centre;
    Vec sum{0, 0, 0};
    for (size_t i = 0; i < n; ++i) sum = sum + cross(point(c[i]) - centre, point(c[(i + 1) % n]) - centre);
    return sum;
  }

  void fill(const std::vector<int32_t>& c, int depth, bool top) {
    if (c.size() == 3 && !degenerate(c[0], c[1], c[2])) {
      out_.triangles.push_back({c[0], c[1], c[2]});
      return;
    }
    if (options_.planar && planar(c, top)) return;
    if (int32_t(c.size()) <= options_.max_dp_corners && minimum_weight(c)) {
      use(FillMethod::MinimumWeight);
      return;
    }
    if (c.size() > 3 && depth < 64 && split(c, depth)) return;
    fan(c);
  }

  bool degenerate(int32_t a, int32_t b, int32_t c) const {
    const Vec pa = point(a), pb = point(b), pc = point(c);
    const double area2 = norm(cross(pb - pa, pc - pa));
    const double scale = std::max({dot(pb - pa, pb - pa), dot(pc - pa, pc - pa), dot(pc - pb, pc - pb)});
    return !(area2 > 1e-12 * scale);
  }

  // Candidate planes: Newell, least squares, the surrounding surface's mean normal. `reference`
  // receives the direction the others are oriented by (Newell, or the surrounding normal).
  std::vector<Vec> principal_normals(const std::vector<int32_t>& c, Vec& reference) const {
    const size_t n = c.size();
    std::vector<Vec> normals;
    auto add = [&](const Vec& v) {
      const Vec u = unit(v);
      if (norm(u) == 0.0) return;
      for (const Vec& w : normals)
        if (dot(u, w) > 1.0 - 1e-9) return;
      normals.push_back(u);
    };
    const Vec newell = newell_normal(c);
    double perimeter = 0;
    for (size_t i = 0; i < n; ++i) perimeter += norm(point(c[(i + 1) % n]) - point(c[i]));
    const bool has_area = norm(newell) > 1e-9 * perimeter * perimeter;
    if (has_area) add(newell);
    Vec around{0, 0, 0};
    for (size_t i = 0; i < n; ++i) around = around + side_normal(c[i], c[(i + 1) % n]);
    Vec centre{0, 0, 0};
    for (int32_t i : c) centre = centre + point(i);
    centre = (1.0 / double(n)) * centre;
    double cov[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int32_t i : c) {
      const Vec d = point(i) - centre;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) cov[a][b] += d[a] * d[b];
    }
    Vec least = smallest_eigenvector(cov);
    reference = has_area ? newell : around;
    if (dot(least, reference) < 0) least = -1.0 * least;
    if (norm(reference) > 0) add(least);
    add(around);
    return normals;
  }

  // A spread of directions over the hemisphere around `reference` (a Fibonacci lattice, nearest
  // first): any direction along which the boundary projects to a simple polygon gives an
  // embedded patch.
  static std::vector<Vec> spread_normals(const Vec& reference) {
    std::vector<Vec> normals;
    if (norm(reference) == 0.0) return normals;
    const Vec r = unit(reference);
    const int axis = std::abs(r[0]) <= std::abs(r[1]) && std::abs(r[0]) <= std::abs(r[2]) ? 0
                     : std::abs(r[1]) <= std::abs(r[2])                                    ? 1
                                                                                           : 2;
    Vec e{0, 0, 0};
    e[axis] = 1;
    const Vec u = unit(cross(r, e)), v = cross(r, u);
    const int count = 200;
    for (int i = 0; i < count; ++i) {
      const double z = 1.0 - (i + 0.5) / count, radius = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double phi = i * 2.399963229728653;  // golden angle
      normals.push_back(radius * std::cos(phi) * u + radius * std::sin(phi) * v + z * r);
    }
    return normals;
  }

  bool planar(const std::vector<int32_t>& c, bool top) {
    Vec reference{0, 0, 0};
    for (const Vec& normal : principal_normals(c, reference))
      if (planar_along(c, normal, top)) return true;
    for (const Vec& normal : spread_normals(reference))
      if (planar_along(c, normal, top)) return true;
    return false;
  }

  bool planar_along(const std::vector<int32_t>& c, const Vec& normal, bool top) {
    const size_t n = c.size();
    // Right-handed frame (u, v, normal): counter-clockwise around normal is positive in 2D.
    const int axis = std::abs(normal[0]) <= std::abs(normal[1]) && std::abs(normal[0]) <= std::abs(normal[2]) ? 0
                     : std::abs(normal[1]) <= std::abs(normal[2])                                          ? 1
                                                                                                           : 2;
    Vec e{0, 0, 0};
    e[axis] = 1;
    const Vec u = unit(cross(normal, e)), v = cross(normal, u);
    std::vector<double> xy(2 * n);
    for (size_t i = 0; i < n; ++i) {
      const Vec p = point(c[i]);
      xy[2 * i] = dot(p, u);
      xy[2 * i + 1] = dot(p, v);
    }
    if (!(polygon_area(xy) > 0) || !polygon_is_simple(xy)) return false;
    std::vector<std::array<int32_t, 3>> local;
    if (!triangulate_polygon(xy, [&](int32_t a, int32_t b) { return forbidden(c[a], c[b]); }, local)) return false;
    for (const auto& t : local) out_.triangles.push_back({c[t[0]], c[t[1]], c[t[2]]});
    if (top) out_.normal[0] = normal[0], out_.normal[1] = normal[1], out_.normal[2] = normal[2];
    return true;
  }

  // Liepa's dynamic programme: the best triangulation of corners i..j closed by the chord (i, j)
  // has the largest smallest-cosine of its dihedral angles (between neighbouring patch
  // triangles and against the surface beyond the hole's sides), then the least area.
  bool minimum_weight(const std::vector<int32_t>& c) {
    const int32_t n = static_cast<int32_t>(c.size());
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const size_t cells = size_t(n) * size_t(n);
    std::vector<double> cosine(cells, -kInf), area(cells, kInf);
    std::vector<int32_t> apex(cells, -1);
    std::vector<Vec> normal(cells, Vec{0, 0, 0});
    auto at = [n](int32_t i, int32_t j) { return size_t(i) * size_t(n) + size_t(j); };
    for (int32_t i = 0; i + 1 < n; ++i) cosine[at(i, i + 1)] = 1.0, area[at(i, i + 1)] = 0.0;
    // Cosine of the dihedral angle against a neighbour's unit normal (1 when unknown).
    auto fold = [](const Vec& a, const Vec& b) { return norm(b) == 0.0 ? 1.0 : dot(a, b); };
    // Normal of the triangle beyond the side or chord (i, j) in the sub-solution, or of the
    // surface beyond a hole side.
    auto beyond = [&](int32_t i, int32_t j) { return j == i + 1 ? side_normal(c[i], c[j]) : normal[at(i, j)]; };
    std::vector<Vec> points(n);
    for (int32_t i = 0; i < n; ++i) points[i] = point(c[i]);
    for (int32_t span = 2; span < n; ++span)
      for (int32_t i = 0; i + span < n; ++i) {
        const int32_t j = i + span;
        const bool closing = i == 0 && j == n - 1;  // the chord (0, n - 1) is the piece's last side
        if (!closing && forbidden(c[i], c[j])) continue;
        double best_cosine = -kInf, best_area = kInf;
        for (int32_t m = i + 1; m < j; ++m) {
          if (!std::isfinite(area[at(i, m)]) || !std::isfinite(area[at(m, j)])) continue;
          const Vec twice = cross(points[m] - points[i], points[j] - points[i]);
          const double scale = std::max({dot(points[m] - points[i], points[m] - points[i]),
                                         dot(points[j] - points[i], points[j] - points[i]),
                                         dot(points[j] - points[m], points[j] - points[m])});
          const double length = norm(twice);
          if (!(length > 1e-12 * scale)) continue;  // degenerate
          const Vec nt = (1.0 / length) * twice;
          double worst = std::min({cosine[at(i, m)], cosine[at(m, j)], fold(nt, beyond(i, m)), fold(nt, beyond(m, j))});
          if (closing) worst = std::min(worst, fold(nt, side_normal(c[j], c[i])));
          const double total = area[at(i, m)] + area[at(m, j)] + 0.5 * length;
          if (worst > best_cosine + 1e-12 || (worst >= best_cosine - 1e-12 && total < best_area)) {
            best_cosine = worst;
            best_area = total;
            apex[at(i, j)] = m;
            normal[at(i, j)] = nt;
          }
        }
        cosine[at(i, j)] = best_cosine;
        area[at(i, j)] = best_area;
      }
    if (!std::isfinite(area[at(0, n - 1)])) return false;
    std::vector<std::array<int32_t, 2>> stack{{0, n - 1}};
    while (!stack.empty()) {
      const auto [i, j] = stack.back();
      stack.pop_back();
      if (j - i < 2) continue;
      const int32_t m = apex[at(i, j)];
      out_.triangles.push_back({c[i], c[m], c[j]});
      stack.push_back({i, m});
      stack.push_back({m, j});
    }
    return true;
  }

  // Cuts along the chord that is shortest relative to the boundary it shortcuts, so that both
  // halves are rounder (and more nearly planar) than the whole.
  bool split(const std::vector<int32_t>& c, int depth) {
    const int32_t n = static_cast<int32_t>(c.size());
    std::vector<double> arc(n + 1, 0.0);  // arc[i]: boundary length from corner 0 to corner i
    for (int32_t i = 0; i < n; ++i) arc[i + 1] = arc[i] + norm(point(c[(i + 1) % n]) - point(c[i]));
    const int32_t least = std::max(2, n / 4);
    double best = std::numeric_limits<double>::infinity();
    int32_t best_a = -1, best_b = -1;
    for (int32_t a = 0; a < n; ++a)
      for (int32_t b = a + least; b <= a + n - least && b < n; ++b) {
        if (forbidden(c[a], c[b])) continue;
        const double along = std::min(arc[b] - arc[a], arc[n] - (arc[b] - arc[a]));
        const double cost = norm(point(c[b]) - point(c[a])) / along;
        if (cost < best) best = cost, best_a = a, best_b = b;
      }
    if (best_a < 0) return false;
    use(FillMethod::Split);
    std::vector<int32_t> first(c.begin() + best_a, c.begin() + best_b + 1);
    std::vector<int32_t> second(c.begin() + best_b, c.end());
    second.insert(second.end(), c.begin(), c.begin() + best_a + 1);
    fill(first, depth + 1, false);
    fill(second, depth + 1, false);
    return true;
  }

  void fan(const std::vector<int32_t>& c) {
    use(FillMethod::Fan);
    Vec centre{0, 0, 0};
    for (int32_t i : c) centre = centre + point(i);
    centre = (1.0 / double(c.size())) * centre;
    const int32_t id = k_ + static_cast<int32_t>(out_.added_points.size() / 3);
    out_.added_points.insert(out_.added_points.end(), centre.begin(), centre.end());
    for (size_t i = 0; i < c.size(); ++i) out_.triangles.push_back({c[i], c[(i + 1) % c.size()], id});
  }

  const Hole& hole_;
  const HoleTriangulationOptions& options_;
  const int32_t k_;
  HoleTriangulation out_;
};

}  // namespace

const char* fill_method_name(FillMethod method) {
  switch (method) {
    case FillMethod::Planar: return "planar";
    case FillMethod::MinimumWeight: return "minimum_weight";
    case FillMethod::Split: return "split";
    case FillMethod::Fan: return "fan";
  }
  return "unknown";
}

HoleTriangulation triangulate_hole(const Hole& hole, const HoleTriangulationOptions& options) {
  return Filler(hole, options).run();
}

}  // namespace topstoc
