// Closest points on a triangle mesh: a bounding volume hierarchy over its triangles.
//
// Used by the Hausdorff measurement (hausdorff.hpp) to find, for millions of sample points, the
// nearest point of the other surface. The query is exact: it returns the triangle of smallest
// distance (ties broken by the lower triangle id), whatever hint it is given, so parallel and
// serial callers get the same answer. Degenerate (zero-area) triangles are handled as the
// segments or points they are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace topstoc {

/// Closest point of triangle (a, b, c) to p: writes it to `closest` and returns the squared
/// distance. Works for degenerate triangles (collinear corners, repeated points).
double closest_point_on_triangle(const double* p, const double* a, const double* b, const double* c,
                                 double* closest);

/// Result of a closest-point query.
struct ClosestHit {
  double distance2 = 0.0;   ///< squared distance to the closest point
  double point[3] = {0, 0, 0};
  int32_t triangle = -1;    ///< caller's triangle id
  int32_t slot = -1;        ///< internal position of that triangle: pass it back as a hint
};

class TriangleBvh {
 public:
  /// positions: 3 per vertex; triangles: 3 vertex ids per triangle, all in [0, num_vertices).
  /// The caller validates the input (see hausdorff.hpp's Surface); num_triangles >= 1.
  TriangleBvh(const double* positions, const int32_t* triangles, int64_t num_triangles);

  /// Closest point of the mesh to p. `hint_slot` (a previous hit's slot, or -1) only speeds the
  /// search up: nearby queries usually have nearby answers. `within2` >= 0: stop at the first
  /// triangle found within that squared distance (its point, attained, not the closest); a point
  /// farther than that from every triangle gets the same exact answer as without it.
  ClosestHit closest(const double* p, int32_t hint_slot = -1, double within2 = -1.0) const;
  /// The same exact lookup, adding the triangles it measured (its work) to `tested`.
  ClosestHit closest_counted(const double* p, int32_t hint_slot, int64_t& tested) const;

  int64_t num_triangles() const { return int64_t(triangle_ids_.size()); }
  int64_t num_nodes() const { return int64_t(nodes_.size()); }
  /// Whether the nodes carry slabs (see Slab): only where many triangles are slivers.
  bool has_slabs() const { return !slabs_.empty(); }

  struct Node {
    double lo[3], hi[3];
    int32_t first;  ///< leaf: first slot; inner: index of the second child (the first follows the node)
    int32_t count;  ///< leaf: number of triangles (> 0); inner: 0
  };
  /// Node i (0 is the root; an inner node's children are i + 1 and first), for walks over the tree.
  const Node& node(int32_t i) const { return nodes_[std::size_t(i)]; }
  /// The 9 corner coordinates of the triangle in a slot, and its caller's id.
  const double* slot_corners(int32_t slot) const { return &corners_[9 * std::size_t(slot)]; }
  int32_t slot_triangle(int32_t slot) const { return triangle_ids_[std::size_t(slot)]; }

 private:
  template <bool kCounted>
  ClosestHit search(const double* p, int32_t hint_slot, double within2, int64_t* tested) const;
  struct BuildItem;
  /// Builds the subtree over items [begin, end), which it reorders, into the nodes from `index`
  /// on; returns the index past its last node.
  int32_t build(int32_t begin, int32_t end, int32_t index, const std::vector<double>& corners, BuildItem* items);

  /// Per node, where slivers are common (a fan's centre, a cone's apex): the node's corners lie
  /// between lo and hi along a unit normal of its triangles. The slivers' axis-aligned boxes all
  /// reach the centre and overlap; the slab is thin across them, so a query prunes the far ones.
  /// Where every triangle of the node has a corner at `apex` (a sector of one fan), they also lie
  /// in the circular cone from it around `axis` of half-angle acos(cos_half) < 90 degrees: a
  /// query beside the sector prunes it even in the fan's own plane, where the slab cannot
  /// (cos_half = -2: no such cone).
  struct Slab {
    double normal[3];
    double lo, hi;
    double apex[3], axis[3];
    double cos_half = -2.0, sin_half = 0.0;
  };
  void build_slabs();
  void build_cone(Slab& slab, const double* apex, int32_t first, int32_t end) const;
  double slab_distance2(const double* p, int32_t node, bool cones) const;
  static double cone_gap(const double* p, const Slab& slab);

  std::vector<Node> nodes_;
  std::vector<Slab> slabs_;              ///< empty, or one per node
  std::vector<double> corners_;          ///< 9 coordinates per slot, in leaf order
  std::vector<int32_t> triangle_ids_;    ///< caller's triangle id per slot
  double coordinate_scale_ = 0.0;        ///< the largest coordinate's magnitude (search's margin)
};

}  // namespace topstoc
