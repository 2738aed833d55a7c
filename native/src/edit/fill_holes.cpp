#include "topstoc/edit/fill_holes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "topstoc/core/incidence.hpp"
#include "topstoc/core/parallel.hpp"
#include "edit/patch_fairing.hpp"

namespace topstoc {

namespace {

// The worst aspect ratio a faired patch's triangle may have before lift_slivers reshapes it.
constexpr double kMaxFairedAspect = 5.0;

std::string hole_name(size_t h) { return "hole " + std::to_string(h); }

uint64_t pair_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

// Why v cannot be on a fillable boundary, or empty.
std::string nonmanifold_reason(const VertexTriangles& around, const std::vector<StarEdge>& star, int32_t v) {
  int32_t boundary = 0;
  for (const StarEdge& e : star) {
    if (e.count > 2)
      return "edge (" + std::to_string(v) + ", " + std::to_string(e.other) + ") has " + std::to_string(e.count) +
             " triangles";
    boundary += e.count == 1;
  }
  if (boundary > 2) return "it lies on " + std::to_string(boundary / 2) + " boundary loops";
  std::vector<int32_t> fan;
  const int32_t fans = vertex_sectors(around, star, v, [](int32_t) { return false; }, fan);
  if (fans > 1) return "its triangles form " + std::to_string(fans) + " fans joined only at the vertex";
  if (boundary != 2) return "it has " + std::to_string(boundary) + " boundary edges";
  return {};
}

// Everything triangulate_hole needs for one hole, plus what the result needs back.
struct PreparedHole {
  std::vector<int32_t> vertices;      // patch order
  std::vector<int32_t> side_corner;   // per vertex i: an input corner 3t + c at vertex i next to the hole
  std::vector<uint64_t> existing;     // sorted corner pairs joined by an existing edge
  Hole hole;
  PatchRing ring;                     // for refinement and fairing
};

void unit_normal(const double* positions, const int32_t* tri, double* out) {
  const double* a = positions + 3 * size_t(tri[0]);
  const double* b = positions + 3 * size_t(tri[1]);
  const double* c = positions + 3 * size_t(tri[2]);
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int i = 0; i < 3; ++i) out[i] = len > 0 ? n[i] / len : 0.0;
}

}  // namespace

std::vector<BoundaryLoop> boundary_loops(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices) {
  check_triangles(triangles, num_triangles, num_vertices, /*allow_repeated=*/false);
  const VertexTriangles around = vertex_triangles(triangles, num_triangles, num_vertices);
  // A triangle side is on the boundary when no other triangle holds both its ends.
  std::vector<uint8_t> boundary_side(3 * size_t(num_triangles), 0);
  parallel_for(0, num_triangles, parallel_if(num_triangles > 400000), [&](int64_t t) {  // threads cost more below
    for (int c = 0; c < 3; ++c) {
      const int32_t a = triangles[3 * t + c], b = triangles[3 * t + (c + 1) % 3];
      bool shared = false;
      for (int32_t i = around.begin(a); i < around.end(a) && !shared; ++i) {
        const int32_t u = around.list[i];
        const int32_t* x = triangles + 3 * size_t(u);
        shared = u != t && (x[0] == b || x[1] == b || x[2] == b);
      }
      boundary_side[3 * t + c] = !shared;
    }
  });
  // Boundary neighbours of every vertex (CSR), and whether the triangle runs towards each.
  std::vector<int32_t> offsets(size_t(num_vertices) + 1, 0);
  for (int64_t t = 0; t < num_triangles; ++t)
    for (int c = 0; c < 3; ++c)
      if (boundary_side[3 * t + c]) ++offsets[triangles[3 * t + c] + 1], ++offsets[triangles[3 * t + (c + 1) % 3] + 1];
  for (int32_t v = 0; v < num_vertices; ++v) offsets[v + 1] += offsets[v];
  std::vector<int32_t> neighbour(offsets[num_vertices]), cursor(offsets.begin(), offsets.end() - 1);
  std::vector<uint8_t> runs_out(offsets[num_vertices]);  // the triangle runs v -> neighbour
  for (int64_t t = 0; t < num_triangles; ++t)
    for (int c = 0; c < 3; ++c)
      if (boundary_side[3 * t + c]) {
        const int32_t a = triangles[3 * t + c], b = triangles[3 * t + (c + 1) % 3];
        neighbour[cursor[a]] = b, runs_out[cursor[a]++] = 1;
        neighbour[cursor[b]] = a, runs_out[cursor[b]++] = 0;
      }
  // Which boundary vertices are not manifold.
  std::vector<uint8_t> bad(num_vertices, 0);
  std::vector<StarEdge> star;
  for (int32_t v = 0; v < num_vertices; ++v) {
    if (offsets[v + 1] == offsets[v]) continue;
    vertex_star(around, triangles, v, star);
    bad[v] = !nonmanifold_reason(around, star, v).empty();
  }
  std::vector<uint8_t> used(neighbour.size(), 0);
  auto mark_used = [&](int32_t v, int32_t slot) {
    used[slot] = 1;
    const int32_t w = neighbour[slot];
    for (int32_t j = offsets[w]; j < offsets[w + 1]; ++j)
      if (neighbour[j] == v && !used[j]) {
        used[j] = 1;
        break;
      }
  };
  std::vector<BoundaryLoop> loops;
  for (int32_t start = 0; start < num_vertices; ++start)
    for (int32_t first = offsets[start]; first < offsets[start + 1]; ++first) {
      if (used[first]) continue;
      BoundaryLoop loop;
      int32_t v = start, slot = first, votes = 0;
      for (;;) {
        loop.vertices.push_back(v);
        if (bad[v] && loop.nonmanifold_vertex < 0) loop.nonmanifold_vertex = v;
        mark_used(v, slot);
        votes += runs_out[slot] ? 1 : -1;
        v = neighbour[slot];
        if (v == start) break;
        slot = -1;
        for (int32_t j = offsets[v]; j < offsets[v + 1] && slot < 0; ++j)
          if (!used[j]) slot = j;
        if (slot < 0) {  // a dead end: only at a non-manifold vertex
          loop.vertices.push_back(v);
          if (loop.nonmanifold_vertex < 0) loop.nonmanifold_vertex = v;
          break;
        }
      }
      // Walked against the triangles: turn round, keeping the lowest vertex first.
      if (votes < 0) std::reverse(loop.vertices.begin() + 1, loop.vertices.end());
      if (loop.vertices.size() == 3) {  // three boundary sides of one triangle?
        const int32_t v = loop.vertices[0];
        for (int32_t i = around.begin(v); i < around.end(v) && !loop.lone_triangle; ++i) {
          const int32_t* x = triangles + 3 * size_t(around.list[i]);
          int32_t on_loop = 0;
          for (int c = 0; c < 3; ++c) on_loop += x[c] == loop.vertices[1] || x[c] == loop.vertices[2];
          const int64_t t = around.list[i];
          loop.lone_triangle = on_loop == 2 && boundary_side[3 * t] && boundary_side[3 * t + 1] && boundary_side[3 * t + 2];
        }
      }
      loops.push_back(std::move(loop));
    }
  return loops;
}

namespace {

// Where a vertex sits in one hole: sorted (vertex, index) pairs.
class HoleIndex {
 public:
  explicit HoleIndex(const std::vector<int32_t>& loop) {
    for (int32_t i = 0; i < int32_t(loop.size()); ++i) entries_.push_back({loop[i], i});
    std::sort(entries_.begin(), entries_.end());
  }
  int32_t find(int32_t v) const {
    auto it = std::lower_bound(entries_.begin(), entries_.end(), std::array<int32_t, 2>{v, INT32_MIN});
    return it != entries_.end() && (*it)[0] == v ? (*it)[1] : -1;
  }

 private:
  std::vector<std::array<int32_t, 2>> entries_;
};

// One fill_impl run: the holes checked, each oriented and prepared against its triangles,
// patched independently (in parallel), and the patches appended to r.
class HoleFilling {
 public:
  HoleFilling(EditResult& r, const std::vector<std::vector<int32_t>>& holes, const FillOptions& options,
              const std::vector<uint8_t>* pinch)
      : r(r), holes(holes), options(options), pinch(pinch), positions(r.vertices.data()), triangles(r.triangles.data()),
        num_vertices(static_cast<int32_t>(r.vertex_source.size())), num_triangles(int64_t(r.face_source.size())),
        count(holes.size()) {}

  void run() {
    const std::vector<int32_t> all = check_holes();
    check_positions(positions, num_vertices, &all);
    std::vector<uint8_t> on_hole(num_vertices, 0);
    for (int32_t v : all) on_hole[v] = 1;
    const VertexTriangles around = vertex_triangles(triangles, num_triangles, num_vertices, on_hole.data());
    // Validate every hole and orient it against its triangles (serially: errors are thrown here).
    prepared.resize(count);
    for (size_t h = 0; h < count; ++h) prepare(h, oriented(h, around), around);
    triangulate_all();
    append_patches();
  }

 private:
  EditResult& r;
  const std::vector<std::vector<int32_t>>& holes;
  const FillOptions& options;
  const std::vector<uint8_t>* pinch;
  const double* positions;
  const int32_t* triangles;
  const int32_t num_vertices;
  const int64_t num_triangles;
  const size_t count;
  std::vector<PreparedHole> prepared;
  std::vector<HoleTriangulation> patches;
  std::vector<StarEdge> star;

  bool pinched(int32_t v) const { return pinch && (*pinch)[v]; }

  // Every hole's vertices valid, none twice in a hole, none on two holes unless pinched;
  // returns them all.
  std::vector<int32_t> check_holes() const {
    std::vector<int32_t> hole_of(num_vertices, -1);
    std::vector<int32_t> all;
    for (size_t h = 0; h < count; ++h) {
      const auto& loop = holes[h];
      if (loop.size() < 3)
        throw std::invalid_argument(hole_name(h) + " has " + std::to_string(loop.size()) + " vertices; a hole needs 3");
      for (size_t i = 0; i < loop.size(); ++i) {
        const int32_t v = loop[i];
        if (v < 0 || v >= num_vertices)
          throw std::invalid_argument(hole_name(h) + " entry " + std::to_string(i) + " is vertex " + std::to_string(v) +
                                      ", outside [0, " + std::to_string(num_vertices) + ")");
        if (hole_of[v] == int32_t(h))
          throw std::invalid_argument(hole_name(h) + " visits vertex " + std::to_string(v) + " twice");
        if (hole_of[v] >= 0 && !pinched(v))
          throw std::invalid_argument("vertex " + std::to_string(v) + " is on " + hole_name(hole_of[v]) + " and " +
                                      hole_name(h));
        hole_of[v] = static_cast<int32_t>(h);
        all.push_back(v);
      }
    }
    return all;
  }

  // Hole h's loop, checked to run along boundary edges past manifold vertices, and oriented so
  // that the patch runs each side against the triangle beyond it.
  std::vector<int32_t> oriented(size_t h, const VertexTriangles& around) {
    std::vector<int32_t> loop = holes[h];
    const int32_t k = static_cast<int32_t>(loop.size());
    int32_t votes = 0;
    for (int32_t i = 0; i < k; ++i) {
      const int32_t v = loop[i], next = loop[(i + 1) % k];
      vertex_star(around, triangles, v, star);
      const StarEdge* e = find_star_edge(star, next);
      if (!e || e->count != 1)
        throw std::invalid_argument(hole_name(h) + ": vertices " + std::to_string(v) + " and " + std::to_string(next) +
                                    " are not joined by a boundary edge (" +
                                    (e ? "their edge has " + std::to_string(e->count) + " triangles" : "no edge") + ")");
      if (!pinched(v)) {
        const std::string reason = nonmanifold_reason(around, star, v);
        if (!reason.empty())
          throw std::invalid_argument(hole_name(h) + " touches non-manifold vertex " + std::to_string(v) + ": " + reason);
      }
      votes += e->outgoing[0] ? 1 : -1;
    }
    if (votes > 0) std::reverse(loop.begin(), loop.end());
    return loop;
  }

  // The triangulation's input for hole h: points, the normals of the triangles along it, the
  // corners to copy attributes from, the ring around it and the edges that already exist.
  void prepare(size_t h, const std::vector<int32_t>& loop, const VertexTriangles& around) {
    const int32_t k = static_cast<int32_t>(loop.size());
    const HoleIndex index(loop);
    PreparedHole& p = prepared[h];
    p.vertices = loop;
    p.side_corner.resize(k);
    p.hole.points.resize(3 * size_t(k));
    p.hole.side_normals.resize(3 * size_t(k));
    p.ring.outer.resize(k);
    std::vector<int32_t> side_triangle(k);
    for (int32_t i = 0; i < k; ++i) {
      const int32_t v = loop[i], next = loop[(i + 1) % k], prev = loop[(i + k - 1) % k];
      vertex_star(around, triangles, v, star);
      const int32_t t = find_star_edge(star, next)->triangle[0];
      side_triangle[i] = t;
      const int32_t* tri = triangles + 3 * size_t(t);
      p.side_corner[i] = static_cast<int32_t>(3 * t + (tri[0] == v ? 0 : tri[1] == v ? 1 : 2));
      unit_normal(positions, tri, &p.hole.side_normals[3 * size_t(i)]);
      std::copy(positions + 3 * size_t(v), positions + 3 * size_t(v) + 3, &p.hole.points[3 * size_t(i)]);
      for (const StarEdge& s : star) {
        const int32_t j = index.find(s.other);
        if (j >= 0) p.existing.push_back(pair_key(i, j));
        if (s.other == next || s.other == prev) continue;  // along the hole: in the patch
        const double* q = positions + 3 * size_t(s.other);
        p.ring.outer[i].push_back({q[0], q[1], q[2]});
      }
    }
    if (k == 3 && side_triangle[0] == side_triangle[1] && side_triangle[1] == side_triangle[2])
      throw std::invalid_argument(hole_name(h) + " is the border of the lone triangle " + std::to_string(side_triangle[0]) +
                                  ": filling it would duplicate that triangle");
    std::sort(p.existing.begin(), p.existing.end());
    p.existing.erase(std::unique(p.existing.begin(), p.existing.end()), p.existing.end());
    const std::vector<uint64_t>* existing = &p.existing;
    p.hole.forbidden = [existing](int32_t a, int32_t b) {
      return std::binary_search(existing->begin(), existing->end(), pair_key(a, b));
    };
  }

  // Triangulate (and optionally refine and fair) every hole independently.
  void triangulate_all() {
    patches.resize(count);
    parallel_for_dynamic(0, int64_t(count), 1, parallel_if(count >= 16), [&](int64_t h) {
      PreparedHole& p = prepared[h];
      patches[h] = triangulate_hole(p.hole, options.triangulation);
      if (options.refine || options.fair) {
        PatchMesh patch{p.hole.points, patches[h].added_points, patches[h].triangles};
        refine_patch(patch, p.ring, p.hole.forbidden);
        if (options.fair) fair_patch(patch, p.ring), lift_slivers(patch, p.ring, kMaxFairedAspect);
        patches[h].added_points = std::move(patch.added);
        patches[h].triangles = std::move(patch.triangles);
      }
    });
  }

  // The patches' vertices and triangles appended to r, in hole order, with their records.
  void append_patches() {
    for (size_t h = 0; h < count; ++h) {
      const PreparedHole& p = prepared[h];
      const HoleTriangulation& patch = patches[h];
      const int32_t k = static_cast<int32_t>(p.vertices.size());
      FilledHole filled;
      filled.hole = static_cast<int32_t>(h);
      filled.boundary = p.vertices;
      filled.first_triangle = static_cast<int32_t>(r.face_source.size());
      filled.num_triangles = static_cast<int32_t>(patch.triangles.size());
      filled.first_vertex = static_cast<int32_t>(r.vertex_source.size());
      filled.num_vertices = static_cast<int32_t>(patch.added_points.size() / 3);
      filled.method = patch.method;
      filled.refined = options.refine || options.fair;
      filled.faired = options.fair;
      std::copy(patch.normal, patch.normal + 3, filled.normal);
      r.vertices.insert(r.vertices.end(), patch.added_points.begin(), patch.added_points.end());
      r.vertex_source.insert(r.vertex_source.end(), size_t(filled.num_vertices), -1);
      for (const auto& t : patch.triangles) {
        r.face_source.push_back(-1);
        for (int32_t corner : t) {
          const bool existing = corner < k;
          r.triangles.push_back(existing ? p.vertices[corner] : filled.first_vertex + corner - k);
          const int32_t source = existing ? r.corner_source[p.side_corner[corner]] : -1;
          r.corner_source.push_back(source);
        }
      }
      r.patches.push_back(std::move(filled));
    }
  }
};

// Fills holes of the mesh held in r in place (see fill_loops_into). Vertices flagged in `pinch`
// may lie on several holes and need not be manifold yet: welded pinch points, which the
// patches make manifold.
void fill_impl(EditResult& r, const std::vector<std::vector<int32_t>>& holes, const FillOptions& options,
               const std::vector<uint8_t>* pinch) {
  HoleFilling(r, holes, options, pinch).run();
}

// The unedited mesh as an edit result: copies, identity maps.
EditResult unedited(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles) {
  EditResult r;
  r.vertices.assign(positions, positions + 3 * size_t(num_vertices));
  r.triangles.assign(triangles, triangles + 3 * num_triangles);
  r.vertex_source.resize(num_vertices);
  for (int32_t v = 0; v < num_vertices; ++v) r.vertex_source[v] = v;
  r.face_source.resize(size_t(num_triangles));
  r.corner_source.resize(3 * size_t(num_triangles));
  for (int64_t t = 0; t < num_triangles; ++t) r.face_source[t] = static_cast<int32_t>(t);
  for (int64_t c = 0; c < 3 * num_triangles; ++c) r.corner_source[c] = static_cast<int32_t>(c);
  return r;
}

// Pinch welding: vertices of one loop at exactly the same position are merged into the lowest
// of them, unless that would collapse a triangle or make an edge non-manifold.
struct Welding {
  std::vector<int32_t> target;   // per vertex: the vertex it is merged into, or -1
  std::vector<uint8_t> pinch;    // per vertex: a merge target
  std::vector<int32_t> triangles;
  bool any = false;
};

Welding weld_pinches(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                     const std::vector<std::vector<int32_t>>& loops) {
  Welding w;
  w.target.assign(num_vertices, -1);
  std::vector<std::vector<int32_t>> groups;
  for (const auto& loop : loops) {
    std::vector<int32_t> order = loop;
    auto less = [&](int32_t a, int32_t b) {
      const double *p = positions + 3 * size_t(a), *q = positions + 3 * size_t(b);
      return std::lexicographical_compare(p, p + 3, q, q + 3);
    };
    std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return less(a, b) || (!less(b, a) && a < b); });
    for (size_t i = 0; i < order.size();) {
      size_t j = i + 1;
      while (j < order.size() && !less(order[i], order[j])) ++j;
      if (j - i > 1) groups.emplace_back(order.begin() + i, order.begin() + j);
      i = j;
    }
  }
  if (groups.empty()) return w;
  std::vector<uint8_t> accepted(groups.size(), 1);
  std::vector<StarEdge> star;
  for (;;) {  // weld, check every pinch, drop the groups that fail, until none fails
    std::fill(w.target.begin(), w.target.end(), -1);
    w.pinch.assign(num_vertices, 0);
    for (size_t g = 0; g < groups.size(); ++g) {
      if (!accepted[g]) continue;
      w.pinch[groups[g][0]] = 1;
      for (size_t i = 1; i < groups[g].size(); ++i) w.target[groups[g][i]] = groups[g][0];
    }
    w.triangles.assign(triangles, triangles + 3 * num_triangles);
    for (int32_t& v : w.triangles)
      if (w.target[v] >= 0) v = w.target[v];
    const VertexTriangles around = vertex_triangles(w.triangles.data(), num_triangles, num_vertices, w.pinch.data());
    bool dropped = false;
    for (size_t g = 0; g < groups.size(); ++g) {
      if (!accepted[g]) continue;
      const int32_t v = groups[g][0];
      bool ok = true;
      for (int32_t i = around.begin(v); i < around.end(v) && ok; ++i) {
        const int32_t* c = &w.triangles[3 * size_t(around.list[i])];
        ok = c[0] != c[1] && c[1] != c[2] && c[2] != c[0];
      }
      if (ok) {
        vertex_star(around, w.triangles.data(), v, star);
        for (const StarEdge& e : star) ok = ok && e.count <= 2;
      }
      if (!ok) accepted[g] = 0, dropped = true;
    }
    if (!dropped) break;
  }
  w.any = std::find(accepted.begin(), accepted.end(), 1) != accepted.end();
  return w;
}

// Splits a closed walk into simple cycles at repeated vertices (its lobes), longest runs kept
// whole: each time the walk returns to a vertex, the cycle since then is cut off.
std::vector<std::vector<int32_t>> lobes_of(const std::vector<int32_t>& walk, std::vector<int32_t>& slot) {
  std::vector<std::vector<int32_t>> lobes;
  std::vector<int32_t> stack;
  for (int32_t v : walk) {
    if (slot[v] >= 0) {
      const int32_t s = slot[v];
      lobes.emplace_back(stack.begin() + s, stack.end());
      for (size_t i = s + 1; i < stack.size(); ++i) slot[stack[i]] = -1;
      stack.resize(s + 1);
    } else {
      slot[v] = static_cast<int32_t>(stack.size());
      stack.push_back(v);
    }
  }
  for (int32_t v : stack) slot[v] = -1;
  lobes.push_back(std::move(stack));
  // A lobe of two vertices closed up when its two edges were welded into one.
  lobes.erase(std::remove_if(lobes.begin(), lobes.end(), [](const auto& l) { return l.size() < 3; }), lobes.end());
  return lobes;
}

}  // namespace

EditResult fill_loops(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                      const std::vector<std::vector<int32_t>>& holes, const FillOptions& options) {
  check_triangles(triangles, num_triangles, num_vertices, /*allow_repeated=*/false);
  EditResult r = unedited(positions, num_vertices, triangles, num_triangles);
  fill_impl(r, holes, options, nullptr);
  return r;
}

void fill_loops_into(EditResult& mesh, const std::vector<std::vector<int32_t>>& holes, const FillOptions& options) {
  fill_impl(mesh, holes, options, nullptr);
}

EditResult fill_holes(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                      const HoleSelection& selection, const FillOptions& options) {
  const std::vector<BoundaryLoop> loops = boundary_loops(triangles, num_triangles, num_vertices);
  std::vector<int32_t> chosen;
  if (selection.holes.empty()) {
    for (int32_t i = 0; i < int32_t(loops.size()); ++i)
      if (selection.max_edges <= 0 || int32_t(loops[i].vertices.size()) <= selection.max_edges) chosen.push_back(i);
  } else {
    for (int32_t i : selection.holes) {
      if (i < 0 || i >= int32_t(loops.size()))
        throw std::invalid_argument("hole index " + std::to_string(i) + " is out of range: the mesh has " +
                                    std::to_string(loops.size()) + " boundary loops");
      chosen.push_back(i);
    }
    std::sort(chosen.begin(), chosen.end());
    chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
  }
  std::vector<std::vector<int32_t>> holes;
  std::vector<int32_t> index;
  for (int32_t i : chosen) {
    const BoundaryLoop& loop = loops[i];
    if (!loop.fillable()) {
      if (selection.skip_unfillable) continue;
      if (loop.lone_triangle)
        throw std::invalid_argument("boundary loop " + std::to_string(i) +
                                    " is the border of a lone triangle: filling it would duplicate that triangle "
                                    "(delete the triangle or skip such loops)");
      throw std::invalid_argument("boundary loop " + std::to_string(i) + " touches non-manifold vertex " +
                                  std::to_string(loop.nonmanifold_vertex) +
                                  ": it cannot be filled (repair the vertex or skip such loops)");
    }
    holes.push_back(loop.vertices);
    index.push_back(i);
  }
  std::vector<int32_t> on_holes;
  for (const auto& hole : holes) on_holes.insert(on_holes.end(), hole.begin(), hole.end());
  check_positions(positions, num_vertices, &on_holes);  // welding compares them
  Welding welding;
  if (selection.weld_pinches) welding = weld_pinches(positions, num_vertices, triangles, num_triangles, holes);
  if (!welding.any) {
    EditResult r = unedited(positions, num_vertices, triangles, num_triangles);
    fill_impl(r, holes, options, nullptr);
    for (FilledHole& p : r.patches) p.hole = index[p.hole];
    return r;
  }
  // Fill the lobes of the welded loops, then drop the welded-away duplicates.
  std::vector<std::vector<int32_t>> lobes;
  std::vector<int32_t> lobe_hole;
  std::vector<int32_t> slot(num_vertices, -1);
  for (size_t h = 0; h < holes.size(); ++h) {
    std::vector<int32_t> walk = holes[h];
    for (int32_t& v : walk)
      if (welding.target[v] >= 0) v = welding.target[v];
    for (auto& lobe : lobes_of(walk, slot)) {
      lobes.push_back(std::move(lobe));
      lobe_hole.push_back(index[h]);
    }
  }
  EditResult r = unedited(positions, num_vertices, welding.triangles.data(), num_triangles);
  fill_impl(r, lobes, options, &welding.pinch);
  for (FilledHole& p : r.patches) p.hole = lobe_hole[p.hole];
  std::vector<int32_t> new_id(r.vertex_source.size(), -1);
  int32_t next = 0;
  for (size_t v = 0; v < r.vertex_source.size(); ++v) {
    if (v < size_t(num_vertices) && welding.target[v] >= 0) continue;
    new_id[v] = next;
    r.vertex_source[next] = r.vertex_source[v];
    std::copy(&r.vertices[3 * v], &r.vertices[3 * v] + 3, &r.vertices[3 * size_t(next)]);
    ++next;
  }
  const int32_t removed = static_cast<int32_t>(r.vertex_source.size()) - next;
  r.vertex_source.resize(next);
  r.vertices.resize(3 * size_t(next));
  for (int32_t& v : r.triangles) v = new_id[v];
  for (FilledHole& p : r.patches) {
    for (int32_t& v : p.boundary) v = new_id[v];
    p.first_vertex -= removed;
  }
  return r;
}

}  // namespace topstoc
