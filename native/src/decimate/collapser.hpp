// Greedy edge collapses on a triangle soup with flat, allocation-free bookkeeping (refine.cpp
// sets it up; docs/design.md §2.10).
//
// Each vertex keeps its cheapest allowed collapse in an indexed heap. Costs are quadric errors
// (vertex_quadrics.hpp), a move along a feature curve at least its span cost (how far the input
// curve points the new edge stands for lie from it: CollapseSetup::curve_order), times a guidance
// weight; an edge between two free vertices collapses to
// the point minimising the summed quadric, any other edge moves one end onto the other, so
// border vertices stay input vertices on their curve. After a collapse only the survivor's
// collapses are recomputed in full; a neighbour whose queued collapse went to the removed vertex
// or the survivor keeps its old cost as a lower bound and is recomputed when it reaches the top
// (lazy evaluation: far fewer cost evaluations). Collapses are taken in batches of independent
// ones from the top of the queue, so the order is greedy among independent collapses, not
// strictly one at a time; a batch depends only on the queue, so serial = parallel.
//
// Vertex-to-face lists live in one pool (a CSR with slack: a list that outgrows its slot moves
// to the end of the pool), neighbour sets are found with a stamp per vertex instead of sorting,
// so a collapse allocates nothing.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "decimate/cost_cache.hpp"
#include "decimate/indexed_heap.hpp"
#include "decimate/vertex_quadrics.hpp"
#include "core/per_thread.hpp"

namespace topstoc {

/// Per vertex of `triangles` (corner ids below num_vertices), whether it is a corner of a triangle
/// that is a component of its own (its corners in no other triangle: no collapse can keep it);
/// empty when no triangle is.
std::vector<uint8_t> lone_corners(const std::vector<int32_t>& triangles, size_t num_vertices);

/// What the collapses know about each vertex. Positions are normalised (centred on the bounding
/// box and divided by its half extent) so that quadrics neither overflow nor underflow; `world`
/// holds the caller's coordinates, which stay exact for every vertex that does not move.
/// A field added here joins start_key (collapse_snapshots.cpp), which tells kept states apart.
struct CollapseSetup {
  VertexQuadrics quadrics{0, 0};
  std::vector<double> positions;      ///< normalised, 3 per vertex
  std::vector<double> world;          ///< caller's coordinates, 3 per vertex
  double center[3] = {0, 0, 0}, extent = 1.0;
  std::vector<double> weight;         ///< cost multiplier per vertex (guidance)
  std::vector<uint8_t> locked;        ///< never moves, never removed
  std::vector<int32_t> curve;         ///< feature curve of the vertex (it moves only along it), or -1
  std::vector<int32_t> curve_size;    ///< per curve: its vertices that may move (locked ends not counted)
  std::vector<uint8_t> curve_closed;  ///< per curve
  /// Per open curve: its ends that are locked (0-2; empty: 2 each). With curve_size it says how
  /// many edges the curve has left, and an open curve keeps at least one.
  std::vector<int32_t> curve_locked_ends;
  /// Per vertex: the end of an open non-manifold curve that no other feature edge meets (where
  /// two sheets stop touching); it moves along the curve onto its neighbour, which becomes the end.
  std::vector<uint8_t> dead_end;
  std::vector<uint8_t> on_boundary;   ///< per vertex: on a mesh boundary's curve, one sector (a fit may move it)
  std::vector<int32_t> corner_sector; ///< per corner: the sector (side of the borders) of its vertex
  std::vector<int32_t> bin, quota;    ///< per vertex its guidance bin; per bin the vertices to keep
  bool optimal_placement = true;      ///< off: every collapse is a half-edge collapse
  /// Per vertex: the squared shape of the thinnest input triangle it stands for (a survivor
  /// takes the lower of its two); a move may leave a triangle that thin, where the triangle
  /// keeps its plane (with input_floor_flat_only) and the vertex has at most kWideFan faces.
  /// Empty: no such floor.
  std::vector<double> input_floor2;
  bool input_floor_flat_only = true;
  /// Each feature curve's vertices in order (FeatureLayout's curves, an open one's corners at its
  /// ends), curve_offsets[c] to curve_offsets[c + 1], their starting positions (normalised, 3
  /// each) in curve_points; per vertex its place there (-1: not a curve vertex, or a corner).
  /// A collapse along a curve then costs at least span_weight times the new edge's squared
  /// length times the squared distance of the farthest input curve point it stands for from that
  /// edge. Empty: the quadric alone.
  std::vector<int32_t> curve_order, curve_offsets, curve_slot;
  std::vector<double> curve_points;
  double span_weight = 0.0;
};

/// Which thin triangles Collapser::remove_thin takes, and how (zero-area ones always go).
struct ThinRules {
  bool fans_only = false;             ///< only those with a corner of more than Collapser::kWideFan faces
  bool border_moves_by_cost = false;  ///< a border (feature-curve) vertex's moves: cheapest first
};

class Collapser {
 public:
  /// A vertex with more faces than this is a fan's centre: its collapses are checked by
  /// allowed_wide (its walks last), its floor is kept as a bound, and the sliver clean-up thins
  /// its fan a round at a time. (An input vertex as wide keeps its fan's slivers out of the
  /// input floors: refine.cpp input_shape_floors.)
  static constexpr int32_t kWideFan = 64;

  /// triangles and corner_source (3 per face) are updated in place as corners are renamed.
  Collapser(std::vector<int32_t>& triangles, std::vector<int32_t>& corner_source, CollapseSetup setup);

  /// Where collapses stop: at this many vertices, or (faces > 0) at this many triangles.
  struct Stop {
    int32_t vertices = 0, faces = 0;
  };
  /// Collapses an edge of every zero-area triangle, and of every triangle with a shape quality
  /// below min_shape (as `rules` say), where a collapse is allowed, until `keep` is reached.
  int32_t remove_thin(double min_shape, Stop keep, ThinRules rules = {});
  /// Called with the state and the collapses made so far where a run's batches start to
  /// depend on its target (they shrink near it), or at its end when they never did: up to there
  /// a run to any lower vertex target goes the same way.
  using BeforeTail = std::function<void(const Collapser&, int32_t)>;
  /// Collapses in cost order until `target` is reached or no collapse is allowed; before_tail
  /// (vertex targets only) hears the state where the target starts to matter.
  int32_t run(Stop target, const BeforeTail& before_tail = {});
  /// Works on these arrays from now on (a copy's own copies of the arrays it was taken with).
  void use_arrays(std::vector<int32_t>& triangles, std::vector<int32_t>& corner_source);
  /// The vertices each guidance bin keeps (CollapseSetup::quota), for a copy resumed toward
  /// another target.
  void set_quota(std::vector<int32_t> quota);
  /// Scratch for each of the engine's threads now (a copy made on a team of another size:
  /// scratch holds no state between steps, so the result does not change).
  void fit_threads();
  /// Replaces every vertex's cost weight and costs every queued collapse anew: a copy of a
  /// collapser taken part-way continues under other weights (the max-aware refinement).
  void reweigh(std::vector<double> weight);
  /// Costs every live vertex's collapses anew under the same weights (after set_shape_limits
  /// loosened the checks, so that vertices whose every collapse was refused queue again).
  void requeue() { reweigh(s_.weight); }
  /// Collapses and moves may not leave a triangle thinner than this shape quality (shape();
  /// 0.1 is an aspect ratio of about 5-10 by the thesis' measure) or, one that was thinner
  /// already, thinner than half of it; either may go lower only as far as the thinnest triangle
  /// around the move was (shape_floor2). Nor may a triangle's normal turn by more than the angle
  /// of cosine kMinTurnCos (about 80 degrees).
  static constexpr double kMinShape = 0.1, kMinTurnCos = 0.17;
  /// Other limits from now on (the reruns of a result stopped above its target by the
  /// topology loosen them; the fit restores them). Flips and area loss stay refused.
  /// From now on no collapse is refused for the triangles it leaves (no flip, fold or sliver
  /// check): how far the topology alone would let a run go (refine.cpp's held_by_folds).
  void drop_shape_checks() { shape_checks_ = false; }
  void set_shape_limits(double min_shape, double min_turn_cos) {
    min_shape_ = min_shape;
    fold2_ = min_turn_cos * min_turn_cos;
  }
  /// Lets a run that stopped because every collapse left failed its checks try them all again
  /// (after set_shape_limits loosened them): the next run() queues every vertex anew.
  void reopen() {
    use_quota_ = false;
    rescue_ = false;
  }
  /// Makes the next collapse (one vertex fewer) and returns the vertex it removed, or -1 when
  /// none is left.
  int32_t collapse_one() { return run({alive_vertices_ - 1, 0}) > 0 ? last_removed_ : -1; }
  /// u stays from now on (the caller refused its collapse): it is not queued again, though its
  /// neighbours may still collapse into it.
  void hold(int32_t u) {
    if (held_.empty()) held_.assign(target_.size(), 0);
    held_[u] = 1;
    settle(u, Best());
  }
  /// A check of the triangles a collapse leaves around its survivor (`triangles` of them, 9
  /// normalised coordinates each, the survivor at its placement), called on any thread: false
  /// refuses the collapse as allowed()'s own checks do.
  using FanCheck = std::function<bool(const double* corners, int32_t triangles)>;
  /// From now on (empty: no longer) a collapse must also pass `check`.
  void set_fan_check(FanCheck check) { fan_check_ = std::move(check); }
  /// Moves every free vertex to its quadric's minimum along the directions it constrains, at
  /// most radius2[v] (squared, normalised) away, where no triangle folds or becomes a sliver.
  int32_t refit(const std::vector<double>& radius2);

  /// Moves free vertex v to x (normalised) when no triangle around it folds, loses area or
  /// becomes a sliver; false (nothing moved) otherwise.
  bool try_move(int32_t v, const double* x);
  /// Puts v back where it was (normalised and caller's coordinates, as read before a move).
  void restore(int32_t v, const double* position, const double* world);

  /// For tests: checks every wide vertex's kept flatness and the costs its evaluation reads
  /// (kept or fresh) against a walk of its star and a fresh cost. Returns how many it checked,
  /// or -1 at the first that differs.
  int64_t check_kept_state() const;

  int32_t live_faces() const { return alive_faces_; }
  /// The sum over live vertices of their quadric's error where they stand (normalised, no
  /// guidance weight): how far the result lies from the input planes it stands for.
  double quadric_error() const;
  int32_t live_vertices() const { return alive_vertices_; }
  /// Whether some live vertex may still be removed (neither locked nor a lone triangle's corner).
  bool has_free_vertex() const;
  /// Batches run() has taken so far (its collapses were reserved, checked and costed together).
  int64_t batches() const { return ring_stamp_; }
  /// Collapses run() has taken from the queue into its batches (those that waited went back).
  int64_t taken() const { return taken_; }
  /// Triangles around the ends of the collapses the batches tried to reserve (mark_ring walks them
  /// until one touches the batch).
  int64_t ring_faces() const { return ring_faces_; }
  /// The triangles as the collapses renamed them (dead ones included: see face_alive).
  const std::vector<int32_t>& triangles() const { return *tri_; }
  /// The corner sources as the collapses renamed the corners.
  const std::vector<int32_t>& corner_source() const { return *corner_source_; }
  int32_t zero_area_faces() const;
  std::vector<int32_t> zero_area_face_list() const;
  /// Moves v to the input position `world` when no triangle around it folds, loses area or
  /// becomes a sliver and triangle `face` gains area; false (nothing moved) otherwise.
  bool place(int32_t v, const double* world, int32_t face);
  bool zero_area(int32_t t) const;
  bool face_alive(int32_t t) const { return alive_face_[t] != 0; }
  bool vertex_alive(int32_t v) const { return merged_into_[v] < 0; }
  int32_t survivor(int32_t v);
  const double* world(int32_t v) const { return &s_.world[3 * size_t(v)]; }
  const double* position(int32_t v) const { return &s_.positions[3 * size_t(v)]; }
  bool is_free(int32_t v) const { return s_.curve[v] < 0 && !s_.locked[v]; }
  /// On a boundary of the mesh (an open scan's rim).
  bool on_mesh_boundary(int32_t v) const { return !s_.on_boundary.empty() && s_.on_boundary[v]; }
  /// Free, or an unlocked vertex of a mesh boundary (which has no other side to keep).
  bool fittable(int32_t v) const { return is_free(v) || (!s_.locked[v] && on_mesh_boundary(v)); }
  int32_t vertices() const { return static_cast<int32_t>(merged_into_.size()); }
  /// The caller's coordinates in the normalised ones of position().
  void normalise(const double* world, double* out) const {
    for (int i = 0; i < 3; ++i) out[i] = (world[i] - s_.center[i]) * (1.0 / s_.extent);
  }

 private:
  bool free_pair(int32_t from, int32_t to) const {
    return s_.optimal_placement && is_free(from) && is_free(to);
  }
  bool placement(int32_t from, int32_t to, const Quadric& q, double x[3]) const;
  double cost(int32_t from, int32_t to) const;
  void set_up_spans();
  void span_of(int32_t k, double to[2]) const;
  void refresh_span(int32_t k);
  void unlink_span(int32_t u);
  void span_moved(int32_t v);
  // Per-thread scratch: a stamp per vertex marks sets without clearing.
  struct Scratch {
    std::vector<uint32_t> mark;
    uint32_t stamp = 0;
    std::vector<int32_t> list;
    std::vector<std::pair<double, int32_t>> costs;
    std::vector<double> fan;  // keeps_fan's triangles
  };
  struct Best {
    int32_t target = -1;
    double cost = 0.0;
  };
  Best evaluate(int32_t u, bool checked, Scratch& scratch) const;
  template <class Fn>
  void for_each_cost(int32_t u, const std::vector<int32_t>& around, const Fn& fn) const;
  void changed(int32_t v);
  void update(int32_t u, bool checked = false);
  void settle(int32_t u, Best best);
  void offer(int32_t x, int32_t v, int32_t removed, double c);
  void refresh(int32_t u, int32_t v);
  bool mark_ring(int32_t u, int32_t v, uint32_t ring);
  static constexpr int32_t kMaxBatch = 128;
  int32_t batch_size(int32_t excess) const;
  // One batch of run(): the cheapest queued collapses, their status, and what they leave to
  // evaluate and to cost again. Kept across batches so that its lists keep their memory.
  enum BatchStatus : uint8_t { kReady, kEvaluate, kEvaluateChecked, kWait };
  struct Batch {
    std::vector<int32_t> vertices, reserved, pending, survivors, pair_from, pair_to;
    std::vector<double> key, pair_cost_from, pair_cost_to;
    std::vector<uint8_t> status, pending_checked;
    std::vector<Best> pending_best;
  };
  void take_batch(Batch& batch, int32_t size);
  static int32_t next_batch_cap(const Batch& batch, int32_t cap);
  void reserve_batch(Batch& batch, uint32_t ring);
  uint8_t refused_at_fan(int32_t u, int32_t v, double key);
  bool at_fan(int32_t u, int32_t v) const { return size_[u] > kWideFan || size_[v] > kWideFan; }
  void check_reserved(Batch& batch);
  int32_t apply_batch(Batch& batch, Stop target);
  void cost_after_batch(Batch& batch, uint32_t ring);
  void settle_survivors(const Batch& batch, uint32_t ring);
  void queue(int32_t u, int32_t v, double c);
  bool at_quota(int32_t u) const { return use_quota_ && count_[s_.bin[u]] <= s_.quota[s_.bin[u]]; }
  bool reached(Stop stop) const {
    return stop.faces > 0 ? alive_faces_ <= stop.faces : alive_vertices_ <= stop.vertices;
  }
  bool queues(int32_t u) const { return !s_.locked[u] && !lone(u) && !at_quota(u); }
  bool lone(int32_t u) const { return !lone_.empty() && lone_[u]; }
  bool allowed(int32_t u, int32_t v, Scratch& scratch) const;
  static constexpr size_t kWideTries = 16;  // collapses a wide vertex's evaluation checks (evaluate)
  // Vertices whose collapse offers the constructor gathers before merging them (see there).
  static constexpr int32_t kSetupBlock = 1 << 15;
  bool allowed_wide(int32_t u, int32_t v, Scratch& scratch) const;
  int32_t common_neighbours(int32_t a, int32_t b, Scratch& scratch) const;
  int32_t count_neighbours(int32_t v, int32_t enough, Scratch& scratch) const;
  int32_t faces_holding(int32_t a, int32_t b, int32_t enough) const;
  int shaped_placement(int32_t u, int32_t v, double x[3]) const;
  bool keeps_fan(int32_t u, int32_t v, const double* x, Scratch& scratch) const;
  bool is_dead_end(int32_t v) const { return !s_.dead_end.empty() && s_.dead_end[v]; }
  bool curve_fans(int32_t u, int32_t nu, int32_t faces_u, const int32_t* on_edge, int32_t count) const;
  bool along_curve(int32_t u, int32_t v) const;
  bool curve_keeps_an_edge(int32_t curve) const;
  void merge_sides(int32_t v, const int32_t* from, const int32_t* to, int32_t count);
  bool duplicates_a_face(int32_t u, int32_t v, const int32_t* on_edge, int32_t count) const;
  bool merges_unlike_edges(int32_t u, int32_t v, const int32_t* on_edge, int32_t count) const;
  // The shape floor of one move or collapse (shape_floor2 of its ends), found when a triangle
  // first ends below kMinShape: most moves leave none there.
  struct ShapeFloor {
    int32_t a, b;                // the ends (b = -1: a move)
    double a2 = -1.0, b2 = -1.0;  // their shape_floor2 (-1: not read yet)
    int8_t flat = -1;             // the moved vertex's triangles lie in one plane (flat_star; -1: not read yet)
  };
  bool flat_star(int32_t v) const;
  bool walk_flat_star(int32_t v, int32_t* reference = nullptr) const;
  double face_normal2(int32_t t, double n[3]) const;
  void star_face_changed(int32_t v, int32_t t);
  bool below_floor(double twice_area2, double edges, bool flat, ShapeFloor& floor) const;
  bool keeps_shape(int32_t moved, int32_t other, const double* x, ShapeFloor& floor) const;
  bool beside_edge_keep_shape(int32_t moved, int32_t other, const double* x, ShapeFloor& floor) const;
  bool keeps_face_shape(int32_t t, int32_t moved, const double* x, ShapeFloor& floor) const;
  double shape_floor2(int32_t v) const;
  double shape2(int32_t t) const;
  bool below_end_floor(double twice_area2, double edges, bool flat, int32_t v, double& floor2) const;
  void lower_floor_bounds(int32_t t);
  void moved_floor_bounds(int32_t v);
  double shape(const int32_t* c, int32_t replace, const double* at, double twice_area) const;
  double squared_edges(const int32_t* c, int32_t replace, const double* at) const;
  void normal(const int32_t* c, int32_t replace, const double* at, double n[3]) const;
  bool thin(int32_t t, double min_shape) const;
  void collapse(int32_t u, int32_t v);
  void move_to(int32_t v, const double* x);
  void neighbours(int32_t v, Scratch& scratch, std::vector<int32_t>& out) const;
  int32_t sector_at(int32_t t, int32_t v) const;
  bool has(int32_t t, int32_t v) const {
    const int32_t* c = &(*tri_)[3 * size_t(t)];
    return c[0] == v || c[1] == v || c[2] == v;
  }
  // The live faces of v.
  const int32_t* faces_begin(int32_t v) const { return &pool_[begin_[v]]; }
  const int32_t* faces_end(int32_t v) const { return &pool_[begin_[v]] + size_[v]; }
  void remove_face(int32_t v, int32_t t);
  void append_faces(int32_t v, const int32_t* faces, int32_t count);

  std::vector<int32_t>* tri_;            // updated in place (the caller's arrays)
  std::vector<int32_t>* corner_source_;
  CollapseSetup s_;
  std::vector<int32_t> count_;  // per bin: vertices alive
  std::vector<uint8_t> held_;  // per vertex: refused by the caller (hold); empty: none
  // per vertex: a corner of a triangle that is a whole component (no collapse can keep it: a
  // scene of leaf cards at its floor had every vertex evaluated in every pass); empty: none
  std::vector<uint8_t> lone_;
  int32_t last_removed_ = -1;  // the vertex the last collapse removed
  FanCheck fan_check_;         // set_fan_check's
  bool use_quota_ = true;
  bool rescue_ = false;  // every collapse left failed its checks: see shaped_placement
  bool shape_checks_ = true;  // keeps_shape checks the triangles a move leaves (drop_shape_checks)
  double min_shape_ = kMinShape;              // a triangle may end no thinner (keeps_shape)
  double fold2_ = kMinTurnCos * kMinTurnCos;  // squared cosine of the largest turn of a normal
  int32_t alive_vertices_ = 0, alive_faces_ = 0;
  std::vector<int32_t> pool_, begin_, size_, capacity_;  // vertex -> faces
  // A value the checks on the team's threads read and write (a const read of the state caches
  // it): a relaxed atomic, the same value by whichever thread.
  template <class T>
  struct Shared {
    mutable std::atomic<T> value;
    explicit Shared(T unset = T(-1)) : value(unset) {}
    Shared(const Shared& other) : value(other.get()) {}
    Shared& operator=(const Shared& other) { return set(other.get()), *this; }
    T get() const { return value.load(std::memory_order_relaxed); }
    void set(T x) const { value.store(x, std::memory_order_relaxed); }
  };
  // Per vertex of more than kWideFan faces whose floor was read: a bound at or below the least
  // squared shape of its triangles (shape_floor2 before the cap), lowered as they change, so that
  // a triangle far thinner than a fan's floor is refused without the walk of the fan (-1: none).
  std::vector<Shared<double>> floor_bound_;  // empty: no vertex is wide
  // Per such vertex: its thinnest triangle at the last walk (-1: none). While it is alive and
  // still the vertex's, its shape bounds the floor from above: a triangle no thinner than it is
  // not below the floor, without the walk of the fan.
  std::vector<Shared<int32_t>> floor_witness_;  // empty: no vertex is wide
  // Per vertex of more than kWideFan faces: flat_star's answer once read (-1: not known), kept as
  // its triangles change where the changed one alone decides it (star_face_changed), so that a
  // fan's centre is walked again only when its first triangle changes or it was not flat.
  std::vector<Shared<int8_t>> flat_star_;  // empty: no vertex is wide
  // Per such vertex with flat_star_ known: the triangle its walk compared the others with (the
  // first with area; -1: none).
  std::vector<Shared<int32_t>> flat_reference_;
  bool tracking_floors_ = false;
  // Where some vertex is wide: per vertex, the clock at its last change of quadric or position
  // (changed); per vertex wide at the start, the index of its kept costs in kept_costs_ (-1:
  // none). for_each_cost reads and fills them: a kept cost stands while neither end changed since.
  std::vector<uint32_t> changed_at_;
  uint32_t clock_ = 0;
  std::vector<int32_t> kept_costs_of_;
  // Per curve slot (CollapseSetup::curve_order): the slots of its live neighbours along the
  // curve (-1 past an open curve's end whose vertex is gone) and, for a curve vertex, its span
  // costs onto the next and onto the previous (span_of); empty without spans.
  std::vector<int32_t> span_prev_, span_next_;
  std::vector<double> span_;
  mutable std::vector<CostCache> kept_costs_;
  int32_t kept_slot(int32_t v) const { return kept_costs_of_.empty() ? -1 : kept_costs_of_[v]; }
  std::vector<uint8_t> alive_face_, dirty_, placed_;
  std::vector<int32_t> merged_into_, target_;
  IndexedHeap heap_;
  std::vector<int32_t> merged_from_;  // per survivor: the vertex its last collapse removed
  std::vector<uint32_t> waiting_;      // per vertex: the batch whose collapses touched it
  std::vector<uint32_t> beside_;       // per slot of kept_costs_: the batch whose collapses passed beside it
  std::vector<uint32_t> settled_;      // per vertex: the batch that evaluated it anew
  uint32_t ring_stamp_ = 0;  // one per batch run() took
  int64_t taken_ = 0, ring_faces_ = 0;  // see taken(), ring_faces()
  // The next batch's largest size (next_batch_cap): part of the state, so that a run resumed
  // from a kept copy takes the batches the uninterrupted run takes.
  int32_t batch_cap_ = kMaxBatch;
  PerThread<Scratch> scratch_{0};  // one per thread, each on its own cache lines
  std::vector<int32_t> options_, star_, moved_faces_;
};

}  // namespace topstoc
