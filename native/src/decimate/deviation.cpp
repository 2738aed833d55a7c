#include "decimate/deviation.hpp"

#include <algorithm>
#include <cmath>

#include "core/morton_order.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/core/progress.hpp"

namespace topstoc {

namespace {

// out[i] = the squared distance from point(i, xyz) to `surface`, for i in [0, count), in static
// chunks (each thread passes its last hit on as the next query's hint; the answer does not
// depend on the hint, so any team size gives the same bits). point returns false to skip i (0).
template <class Point>
std::vector<double> distances2(const TriangleBvh& surface, int64_t count, Point&& point) {
  std::vector<double> out(size_t(count), 0.0);
  parallel_region(team_for(count, kParallelMinCostly), [&](Team& team) {
    int32_t hint = -1;
    team.for_static(0, count, [&](int64_t i) {
      double p[3];
      if (!point(i, p)) return;
      const ClosestHit hit = surface.closest(p, hint);
      hint = hit.slot;
      out[size_t(i)] = hit.distance2;
    });
  });
  return out;
}

// out[i] = the squared distance from points[3 i ...] to `surface`, the points looked up along a
// Z-order curve (nearby queries pass their hits on as hints; the answers do not depend on it).
std::vector<double> distances2_ordered(const TriangleBvh& surface, const std::vector<double>& points) {
  const int32_t count = int32_t(points.size() / 3);
  const std::vector<int32_t> order = morton_order(points.data(), count);
  const std::vector<double> sorted = distances2(surface, count, [&](int64_t i, double* p) {
    std::copy_n(&points[3 * size_t(order[size_t(i)])], 3, p);
    return true;
  });
  std::vector<double> out(points.size() / 3);
  for (int32_t i = 0; i < count; ++i) out[size_t(order[size_t(i)])] = sorted[size_t(i)];
  return out;
}

// A triangle whose measured points reach kNear times the farthest distance found gets more
// points: where the max lies is measured more finely. (The Lipschitz bound, corner distance
// plus size, flagged nearly every triangle: input sides are about as long as the deviations.)
constexpr double kNear = 0.5;
bool near_top(double measured2, double top2) { return measured2 >= kNear * kNear * top2; }

// Each input vertex to the collapsed surface, kept per first-pass vertex of the vertex; then
// the side middles and centre of each input triangle near the top (near_top), kept per
// first-pass vertex of its corners (every triangle's points cost two to four times the queries).
// Sets out.mean, the mean distance at the input vertices weighted by their areas; stops after
// the vertices (out.complete false) when they show the run is not within `rival`.
void from_input(const Mesh& mesh, const InputSurface& surface_in, const std::vector<int32_t>& label,
                const TriangleBvh& surface, const Rival* rival, Deviation& out) {
  std::vector<double>& out2 = out.vertex2;
  const std::vector<double>& input = surface_in.surface->positions();
  const std::vector<double> at_vertex = distances2(surface, mesh.num_vertices(), [&](int64_t w, double* p) {
    std::copy_n(&input[3 * size_t(w)], 3, p);
    return label[w] >= 0;
  });
  double sum = 0.0, area = 0.0;  // in vertex order: the same bits for any team size
  for (int32_t w = 0; w < mesh.num_vertices(); ++w)
    if (label[w] >= 0) {
      out2[label[w]] = std::max(out2[label[w]], at_vertex[w]);
      sum += surface_in.area[w] * std::sqrt(at_vertex[w]);
      area += surface_in.area[w];
    }
  const double top2 = at_vertex.empty() ? 0.0 : *std::max_element(at_vertex.begin(), at_vertex.end());
  out.mean = area > 0.0 ? sum / area : 0.0;
  if (rival && (out.mean > rival->mean || top2 > rival->top2)) {
    out.complete = false;
    out.top2 = top2;
    return;
  }
  const auto& faces = mesh.faces();
  auto corner = [&](int32_t f, int j) { return &input[3 * size_t(faces[3 * size_t(f) + j])]; };
  std::vector<int32_t> near;
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* q = &faces[3 * size_t(f)];
    if (label[q[0]] < 0 || label[q[1]] < 0 || label[q[2]] < 0) continue;
    const double measured2 = std::max({at_vertex[q[0]], at_vertex[q[1]], at_vertex[q[2]]});
    if (near_top(measured2, top2)) near.push_back(f);
  }
  // The points: the middle of each side of such triangles, once per side (a side between two
  // of them is measured once), then their centres.
  const auto& face_edges = mesh.face_edges();
  const auto& edge_vertices = mesh.edge_vertices();
  std::vector<int32_t> side_index(size_t(mesh.num_edges()), -1), sides;
  for (int32_t f : near)
    for (int j = 0; j < 3; ++j) {
      const int32_t e = face_edges[3 * size_t(f) + j];
      if (side_index[e] < 0) side_index[e] = int32_t(sides.size()), sides.push_back(e);
    }
  const int64_t ns = int64_t(sides.size());
  const std::vector<double> at = distances2(surface, ns + int64_t(near.size()), [&](int64_t i, double* p) {
    if (i < ns) {
      const double *a = &input[3 * size_t(edge_vertices[2 * size_t(sides[i])])],
                   *b = &input[3 * size_t(edge_vertices[2 * size_t(sides[i]) + 1])];
      for (int k = 0; k < 3; ++k) p[k] = 0.5 * (a[k] + b[k]);
      return true;
    }
    const int32_t f = near[size_t(i - ns)];
    const double* c[3] = {corner(f, 0), corner(f, 1), corner(f, 2)};
    for (int k = 0; k < 3; ++k) p[k] = (c[0][k] + c[1][k] + c[2][k]) / 3.0;
    return true;
  });
  for (size_t h = 0; h < near.size(); ++h) {
    const int32_t f = near[h];
    double found2 = at[size_t(ns) + h];
    for (int j = 0; j < 3; ++j) found2 = std::max(found2, at[size_t(side_index[face_edges[3 * size_t(f) + j]])]);
    for (int j = 0; j < 3; ++j) {
      const int32_t v = label[faces[3 * size_t(f) + j]];
      out2[v] = std::max(out2[v], found2);
    }
  }
}

// Twice the area of triangle abc.
double twice_area(const double* a, const double* b, const double* c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// Each live triangle's centre, corners and side middles to the input, the largest kept per
// corner (back2, per collapser vertex), and their mean over the surface (back_mean: each
// triangle's seven distances averaged, weighted by its area). A corner or side shared by
// several triangles is measured once.
void to_input(const TriangleBvh& input, Collapser& collapser, const std::vector<int32_t>& live,
              std::vector<double>& back2, double& back_mean) {
  const size_t faces = live.size() / 3;
  std::vector<int32_t> corners(live);
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  std::vector<std::pair<int32_t, int32_t>> sides;
  sides.reserve(3 * faces);
  for (size_t c = 0; c < live.size(); ++c) {
    const int32_t a = live[c], b = live[c % 3 == 2 ? c - 2 : c + 1];
    sides.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(sides.begin(), sides.end());
  sides.erase(std::unique(sides.begin(), sides.end()), sides.end());
  // The points: the corners, then the side middles, then the centres.
  const int64_t nc = int64_t(corners.size()), ns = int64_t(sides.size());
  std::vector<double> points(3 * size_t(nc + ns + int64_t(faces)));
  parallel_for(int64_t(0), nc + ns + int64_t(faces), kParallelMin, [&](int64_t i) {
    double* p = &points[3 * size_t(i)];
    if (i < nc) {
      std::copy_n(collapser.position(corners[i]), 3, p);
    } else if (i < nc + ns) {
      const double* a = collapser.position(sides[i - nc].first);
      const double* b = collapser.position(sides[i - nc].second);
      for (int k = 0; k < 3; ++k) p[k] = 0.5 * (a[k] + b[k]);
    } else {
      const int32_t* c = &live[3 * size_t(i - nc - ns)];
      const double* q[3] = {collapser.position(c[0]), collapser.position(c[1]), collapser.position(c[2])};
      for (int k = 0; k < 3; ++k) p[k] = (q[0][k] + q[1][k] + q[2][k]) / 3.0;
    }
  });
  const std::vector<double> at = distances2_ordered(input, points);
  auto corner = [&](int32_t v) { return at[std::lower_bound(corners.begin(), corners.end(), v) - corners.begin()]; };
  auto side = [&](int32_t a, int32_t b) {
    const std::pair<int32_t, int32_t> key{std::min(a, b), std::max(a, b)};
    return at[nc + (std::lower_bound(sides.begin(), sides.end(), key) - sides.begin())];
  };
  std::vector<double> best(faces);
  double weighted = 0.0, total_area = 0.0;
  for (size_t t = 0; t < faces; ++t) {
    const int32_t* c = &live[3 * t];
    best[t] = at[nc + ns + int64_t(t)];
    double sum = std::sqrt(best[t]);
    for (int j = 0; j < 3; ++j) {
      const double at_corner2 = corner(c[j]), at_side2 = side(c[j], c[(j + 1) % 3]);
      best[t] = std::max({best[t], at_corner2, at_side2});
      sum += std::sqrt(at_corner2) + std::sqrt(at_side2);
    }
    const double area = twice_area(collapser.position(c[0]), collapser.position(c[1]), collapser.position(c[2]));
    weighted += area * sum / 7.0;
    total_area += area;
  }
  back_mean = total_area > 0.0 ? weighted / total_area : 0.0;
  // Triangles near the top (near_top) get the centres of their three corner quarters too (the
  // points measured split each into four).
  const double top2 = best.empty() ? 0.0 : *std::max_element(best.begin(), best.end());
  auto at_corner = [&](size_t t, int j) { return collapser.position(live[3 * t + size_t(j)]); };
  std::vector<int32_t> near;
  for (size_t t = 0; t < faces; ++t)
    if (near_top(best[t], top2)) near.push_back(int32_t(t));
  const std::vector<double> quarters = distances2(input, 3 * int64_t(near.size()), [&](int64_t i, double* p) {
    const size_t t = size_t(near[size_t(i / 3)]);
    const int j = int(i % 3);
    const double *a = at_corner(t, j), *b = at_corner(t, (j + 1) % 3), *c = at_corner(t, (j + 2) % 3);
    for (int k = 0; k < 3; ++k) p[k] = (4.0 * a[k] + b[k] + c[k]) / 6.0;
    return true;
  });
  for (size_t h = 0; h < near.size(); ++h)
    best[size_t(near[h])] = std::max(best[size_t(near[h])], *std::max_element(&quarters[3 * h], &quarters[3 * h] + 3));
  for (size_t t = 0; t < faces; ++t)
    for (int j = 0; j < 3; ++j) back2[live[3 * t + j]] = std::max(back2[live[3 * t + j]], best[t]);
}

std::vector<double> vertex_areas(const Mesh& mesh, const std::vector<double>& positions) {
  std::vector<double> out(size_t(mesh.num_vertices()), 0.0);
  const auto& faces = mesh.faces();
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* q = &faces[3 * size_t(f)];
    const double third =
        twice_area(&positions[3 * size_t(q[0])], &positions[3 * size_t(q[1])], &positions[3 * size_t(q[2])]) / 6.0;
    for (int j = 0; j < 3; ++j) out[size_t(q[j])] += third;
  }
  return out;
}

}  // namespace

std::shared_ptr<const Surface> normalised_input(const Mesh& mesh, const Collapser& collapser, int64_t step) {
  std::vector<double> positions(3 * size_t(mesh.num_vertices()));
  for (int32_t w = 0; w < mesh.num_vertices(); ++w) collapser.normalise(mesh.position(w), &positions[3 * size_t(w)]);
  const auto& faces = mesh.faces();
  std::vector<int32_t> some;
  if (step == 1) some.assign(faces.data(), faces.data() + faces.size());
  for (int64_t f = 0; step > 1 && f < mesh.num_faces(); f += step)
    some.insert(some.end(), &faces[3 * size_t(f)], &faces[3 * size_t(f) + 3]);
  return std::make_shared<const Surface>(std::move(positions), std::move(some));
}

InputSurface::InputSurface(const Mesh& mesh, std::shared_ptr<const Surface> whole)
    : surface(std::move(whole)), area(vertex_areas(mesh, surface->positions())) {}

Deviation surface_deviation(const Mesh& mesh, const InputSurface& input, const std::vector<int32_t>& label,
                          Collapser& collapser, const std::vector<int32_t>& triangles, const Rival* rival) {
  check_cancelled("deviation");
  const FreeCoresNow team;  // a distance pass's team: the cores free now (the answers do not depend on it)
  const int32_t n = collapser.vertices();
  std::vector<int32_t> survivor(n);
  for (int32_t v = 0; v < n; ++v) survivor[v] = collapser.survivor(v);
  Deviation out;
  for (int32_t v = 0; v < n; ++v) out.vertices += survivor[v] == v;
  std::vector<double> positions(3 * size_t(n));
  std::vector<int32_t> live;
  for (int32_t v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) positions[3 * size_t(v) + i] = collapser.position(v)[i];
  for (size_t t = 0; 3 * t < triangles.size(); ++t)
    if (collapser.face_alive(int32_t(t))) live.insert(live.end(), &triangles[3 * t], &triangles[3 * t] + 3);
  out.vertex2.assign(n, 0.0);
  out.faces = static_cast<int32_t>(live.size() / 3);
  if (out.faces == 0) return out;
  from_input(mesh, input, label, TriangleBvh(positions.data(), live.data(), out.faces), rival, out);
  if (!out.complete) return out;
  std::vector<double> back2(n, 0.0);
  to_input(input.surface->bvh(), collapser, live, back2, out.back_mean);
  for (int32_t v = 0; v < n; ++v) out.vertex2[v] = std::max(out.vertex2[v], back2[survivor[v]]);
  out.top2 = n > 0 ? *std::max_element(out.vertex2.begin(), out.vertex2.end()) : 0.0;
  return out;
}

double farthest_around(const InputSurface& input, const Collapser& collapser, const std::vector<int32_t>& triangles,
                       int32_t v, int k) {
  std::vector<int32_t> around;
  for (size_t t = 0; 3 * t < triangles.size(); ++t) {
    const int32_t* c = &triangles[3 * t];
    if (collapser.face_alive(int32_t(t)) && (c[0] == v || c[1] == v || c[2] == v)) around.push_back(int32_t(t));
  }
  const int64_t per = int64_t(k + 1) * (k + 2) / 2;
  const std::vector<double> at = distances2(input.surface->bvh(), per * int64_t(around.size()), [&](int64_t i, double* p) {
    const int32_t* c = &triangles[3 * size_t(around[size_t(i / per)])];
    triangle_grid_point(collapser.position(c[0]), collapser.position(c[1]), collapser.position(c[2]), k, i % per, p);
    return true;
  });
  return at.empty() ? 0.0 : *std::max_element(at.begin(), at.end());
}

}  // namespace topstoc
