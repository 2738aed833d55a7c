#include "decimate/refine.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>
#include <cmath>
#include <stdexcept>
#include <string>


#include "decimate/attribute_wedges.hpp"
#include "decimate/collapse_snapshots.hpp"
#include "decimate/collapser.hpp"
#include "decimate/curve_bends.hpp"
#include "decimate/deviation.hpp"
#include "decimate/tiny_fit.hpp"
#include "topstoc/decimate/verify.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

// Slivers (shape quality below this, see Collapser) the stochastic pass left are collapsed first.
constexpr double kSliverShape = 0.1;
// A mesh with more than this share of its triangles slivers is sliver-heavy (sliver_heavy): a UV
// sphere of 1,000 segments has 0.37, the 54 meshes of bench_quality.py at most 0.18.
constexpr double kSliverHeavyShare = 0.25;
// On such an input a collapse may leave a triangle as thin as the thinnest input triangle its
// vertices stand for, less this share (rounding: congruent needles computed from other corners).
constexpr double kInputFloorSlack = 1e-6;
// On such an input, a boundary's sharp turn stays where one of its edges is this many times as
// long as the other (lock_sharp_turns).
constexpr double kSharpTurnEdgeRatio = 4.0;
// A collapse along a feature curve costs at least this times the new edge's squared length
// times the squared distance of the farthest input curve point it stands for (CollapseSetup::
// curve_order): the quadric of a border's planes measured the moved vertex against the input
// edges' lines, so a spike's tip went cheaply. On the 198 results of bench_quality's 33 meshes
// with borders, 0.5, 1, 2 gave geometric means of mean / max error 0.999 / 0.945, 0.978 / 0.943,
// 1.000 / 0.957 of the quadric alone's; the output spacing squared instead of the edge's length
// squared 1.021 / 0.969 (docs/bench_notes/outline-spans.md).
constexpr double kSpanWeight = 1.0;
// The max-aware reruns start from the first run's state at this many times the target (the
// last collapses decide where the largest deviations end up), and there are kRounds of them,
// each weighing where any run before it ended farthest.
constexpr double kRestart = 2.0;
constexpr int kRounds = 3;
// Rerun k's cost weight of a vertex is 1 + kDeviationWeights[k] times its largest deviation over
// the largest (squared distances): the worst region's collapses cost up to a hundred times more
// in the first and last, thirty in the second (a milder shift of the budget: where a hundred
// moved the max elsewhere, beast at 10 %, Ogre, polygon_mesh; docs/bench_notes/worst-cases.md).
constexpr double kDeviationWeights[kRounds] = {100.0, 30.0, 100.0};
// A rerun wins on its max only while its mean distance from the input stays within this
// fraction of the first run's: the reruns trade mean for max. (At 5 % the reruns that took the
// max off a bore's mouth or a thin rim were refused: rocker-arm at 402 triangles, mushroom,
// beast at 10 % paid 6-8 % of mean for 20-40 % of max; docs/bench_notes/worst-cases.md.)
constexpr double kMeanSlack = 0.10;
// The same for a result the fit then takes four rounds over (at most kTinyFitFaces triangles;
// Refinement::wins): at 10 % fandisk at 25 triangles took a rerun whose mean after the fit was
// 22 % higher for a max 7 % lower.
constexpr double kTinyMeanSlack = 0.05;

// Runs that all stop above the target (the topology or the borders hold them) end a few
// triangles apart; within this share of their size the smaller max is chosen over the count.
constexpr double kFloorSlack = 0.02;
// The run under the far guard (kFarGuard) is chosen only where its max is at most kGuardedMax of
// the best run's by the runs' own measure, before the fit: a gain of 11 % there (a double torus
// at 100 triangles) came out as the same max and a mean 16 % higher after it. Below the floor it
// stops a few more triangles above it (a CAD housing: 116 against 110) and is chosen within
// kGuardedFloorSlack of the best run's size where its mean is at most kGuardedMean of the best's
// (there its max 0.66 of the best run's; after the fit 8.4 % of the diagonal against 17.6 %).
constexpr double kGuardedFloorSlack = 0.12, kGuardedMax = 0.75, kGuardedMean = 0.9;

// Reruns of a result the topology or the borders stop above its target stop where the first run
// did, under looser checks (Collapser::set_shape_limits): a triangle may end as thin as shape
// quality kFloorShape[round] (0.1 elsewhere) and turn by up to a right angle (80 degrees
// elsewhere). There the last collapses are forced, and the usual checks left only the ones that
// fold a region flat or bridge a gap (figures: docs/bench_notes/worst-cases.md, fifth pass).
constexpr double kFloorShape[kRounds] = {0.05, 0.03, 0.05};
constexpr double kFloorTurnCos = 0.0;

// Past the floor: the chosen run is continued toward the target one collapse at a time under the
// loosest of those shape limits. A collapse is kept only when it removes a mesh boundary's vertex
// (a scan's ragged rim; elsewhere the fit after undid the gain: ogre at 50 triangles), no point
// of the triangles around it (a grid of kExtensionGrid steps a side: the usual few points per
// triangle missed a bridged notch, beetle 4.65 -> 8.67 %) is farther than the chosen run's max,
// the max stays no larger and the mean times the count no larger (a surface's mean error falls
// about as one over the count: a collapse may not cost more than the triangle it saves). At most
// kExtensionTries collapses are tried, on results of at most kExtensionFaces triangles: each try
// copies the run and measures the whole surface again, and above that size the 64 collapses save
// under 1 % of the result (a sphere with 4,000 random holes, 17,900 triangles: 2.4 s for 40).
constexpr int kExtensionTries = 64;
constexpr int32_t kExtensionFaces = 100 * 2 * kExtensionTries;
constexpr int kExtensionGrid = 8;

// The far guard: toward at most kTinyFitFaces triangles, one more run from the reruns' start may
// not leave a triangle with a point (on a grid of kGuardGrid steps a side) farther from the
// input than kFarGuard times the farthest point where it starts, or kFarGuardFloor of the
// input's diagonal if more. The quadric cost does not see a collapse that slides a vertex along
// a plane across an opening (a CAD housing's window covered by a triangle 15 % of the diagonal
// off it), and the max-aware reruns, which multiply that cost, cannot undo it. The floor keeps a
// flat part's last collapses free (at 1.5 % a generated housing asked for 60 stopped at 104).
constexpr double kFarGuard = 2.0, kFarGuardFloor = 0.03;
constexpr int kGuardGrid = 4;

// Fast mode's collapses to a target of at most kTinyFitFaces triangles run their tail twice
// from this many triangles (half as many vertices), the second under looser shape limits
// (Refinement::tail_choice). From twice the target, a CAD link at 100 had lost most of its
// volume before the tail began.
constexpr int32_t kTailFaces = 2 * kTinyFitFaces;

// Guidance bins: 0 for m = 0 (never sampled), 1 for control points, then m on a quarter-octave
// scale.
constexpr int32_t kBins = 2 + 81;
int32_t guidance_bin(double m) {
  if (m == kForcedMultiplier) return 1;
  if (m <= 0.0) return 0;
  return 2 + 40 + std::clamp(int32_t(std::lround(4.0 * std::log2(m))), -40, 40);
}

// Vertex quota per bin (see RefineParams): sum over the bin's vertices of min(1, k m), k solved
// so the quotas sum to `target`, rounded by largest remainder.
std::vector<int32_t> bin_quotas(const std::vector<double>& vertices, const std::vector<double>& multiplier_sum,
                                int32_t target) {
  const int32_t bins = int32_t(vertices.size());
  std::vector<double> mean(bins, 0.0);
  for (int32_t b = 2; b < bins; ++b) mean[b] = vertices[b] > 0 ? multiplier_sum[b] / vertices[b] : 0.0;
  auto total = [&](double k) {
    double sum = vertices[1];
    for (int32_t b = 2; b < bins; ++b) sum += vertices[b] * std::min(1.0, k * mean[b]);
    return sum;
  };
  std::vector<double> exact(bins, 0.0);
  exact[1] = std::min<double>(vertices[1], target);
  if (vertices[1] < target) {
    double lo = 0.0, hi = 1.0;
    while (total(hi) < target && hi < 1e30) hi *= 2.0;
    for (int it = 0; it < 200; ++it) {
      const double k = 0.5 * (lo + hi);
      (total(k) < target ? lo : hi) = k;
    }
    for (int32_t b = 2; b < bins; ++b) exact[b] = vertices[b] * std::min(1.0, hi * mean[b]);
  }
  std::vector<int32_t> quota(bins);
  int32_t assigned = 0;
  std::vector<std::pair<double, int32_t>> remainder;
  for (int32_t b = 0; b < bins; ++b) {
    quota[b] = int32_t(std::floor(exact[b]));
    assigned += quota[b];
    remainder.push_back({-(exact[b] - quota[b]), b});
  }
  std::sort(remainder.begin(), remainder.end());
  for (size_t i = 0; assigned < target && i < remainder.size(); ++i)
    if (quota[remainder[i].second] < vertices[remainder[i].second]) ++quota[remainder[i].second], ++assigned;
  return quota;
}

// Centre and half extent of the bounding box (halves taken first so that neither overflows):
// quadrics hold squared areas, which overflow at coordinates of 1e80 and underflow at 1e-80.
void bounding_box(const Mesh& mesh, double center[3], double& extent, double& diagonal) {
  double low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    for (int i = 0; i < 3; ++i) low[i] = std::min(low[i], mesh.position(v)[i]), high[i] = std::max(high[i], mesh.position(v)[i]);
  extent = 0;
  double half[3] = {0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    center[i] = mesh.num_vertices() > 0 ? 0.5 * low[i] + 0.5 * high[i] : 0.0;
    half[i] = mesh.num_vertices() > 0 ? 0.5 * high[i] - 0.5 * low[i] : 0.0;
    extent = std::max(extent, half[i]);
  }
  if (!(extent > 0) || !std::isfinite(extent) || !std::isfinite(1.0 / extent)) extent = 1.0;
  // The diagonal in normalised units (half extents divided by the largest: no overflow).
  diagonal = 2.0 * std::sqrt((half[0] / extent) * (half[0] / extent) + (half[1] / extent) * (half[1] / extent) +
                             (half[2] / extent) * (half[2] / extent));
  if (!(diagonal > 0) || !std::isfinite(diagonal)) diagonal = 1.0;
}

// The mean edge length (each side of each face) over the half extent `extent`.
double mean_edge(const Mesh& mesh, double extent) {
  const auto& faces = mesh.faces();
  double sum = 0.0;
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    for (int j = 0; j < 3; ++j) {
      const double* a = mesh.position(faces[3 * size_t(f) + j]);
      const double* b = mesh.position(faces[3 * size_t(f) + (j + 1) % 3]);
      sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
  return mesh.num_faces() > 0 ? sum / (3.0 * mesh.num_faces() * extent) : 0.0;
}

// The frame quadrics are computed in: the bounding box's centre and half extent, its diagonal
// and the mean edge length in those units. It depends on the mesh only: kept with the layout, so
// that a decimation's border terms (output_spacing) do not pass over every face again. The mean
// edge is summed on first use: only border terms read it (a pass over every face, serial so that
// its bits do not follow the team size).
struct QuadricFrame {
  double center[3] = {0, 0, 0}, extent = 1.0;
  double diagonal = 1.0;  // of the bounding box, normalised
  double mean_edge(const Mesh& mesh) const {
    std::call_once(edge_once_, [&] { edge_ = topstoc::mean_edge(mesh, extent); });
    return edge_;
  }

 private:
  mutable std::once_flag edge_once_;
  mutable double edge_ = 0.0;  // normalised
};

std::shared_ptr<const QuadricFrame> quadric_frame(const Mesh& mesh, const FeatureLayout& layout) {
  auto cached = std::static_pointer_cast<const QuadricFrame>(layout.quadric_frame.get());
  if (cached) return cached;
  auto frame = std::make_shared<QuadricFrame>();
  bounding_box(mesh, frame->center, frame->extent, frame->diagonal);
  layout.quadric_frame.set(frame);
  return frame;
}

// Input vertex v in the frame's normalised coordinates.
void normalised(const Mesh& mesh, const QuadricFrame& frame, int32_t v, double p[3]) {
  const double scale = 1.0 / frame.extent;
  for (int i = 0; i < 3; ++i) p[i] = (mesh.position(v)[i] - frame.center[i]) * scale;
}

// A third of the quadric of each triangle around each input vertex of [a, b) (in normalised
// coordinates), summed into sums (10 a vertex) in increasing face order, so that a cluster's sum
// weighs each triangle by the share of its corners in the cluster: Mesh::for_block_faces, each
// face's plane computed once for all its corners in the block. The same sums, to the bit, as
// adding each vertex's faces in for_each_face's order; a table of them was 80 bytes a vertex.
void block_vertex_quadrics(const Mesh& mesh, const QuadricFrame& frame, int32_t a, int32_t b,
                           std::vector<double>& sums) {
  sums.assign(10 * size_t(b - a), 0.0);
  const auto& faces = mesh.faces();
  auto add_face = [&](int32_t f, int32_t only) {  // to `only`, or to every corner in the block (-1)
    const int32_t* t = &faces[3 * size_t(f)];
    double p[3][3], face[10], area;
    for (int j = 0; j < 3; ++j) normalised(mesh, frame, t[j], p[j]);
    if (!VertexQuadrics::plane(p[0], p[1], p[2], face, &area)) return;
    for (int j = 0; j < 3; ++j) {
      if (only >= 0 ? t[j] != only : (t[j] < a || t[j] >= b)) continue;
      double* sum = &sums[10 * size_t(t[j] - a)];
      for (int i = 0; i < 10; ++i) sum[i] += face[i] * (1.0 / 3.0);
    }
  };
  mesh.for_block_faces(a, b, add_face, [&](int32_t f) { add_face(f, -1); });
}

// The spacing of the output's vertices, in normalised units: the mean edge length times the
// square root of input vertices per target vertex.
double output_spacing(const Mesh& mesh, const QuadricFrame& frame, int32_t target_vertices) {
  return frame.mean_edge(mesh) * std::sqrt(double(mesh.num_vertices()) / std::max(1, target_vertices));
}

// A sharp bend of a mesh boundary (curve_bends.hpp) holds its place by a point quadric: three
// orthogonal planes through it weighted by the squared output spacing, what a patch of one output
// triangle costs moved as far. The border planes are weighted by their own edges' squared
// lengths, so a bend on a rim of tiny edges (a marching-cubes surface meeting a box edge, a scan's
// tiny hole) held almost nothing and was cut. Only after a stochastic first pass (see
// add_border_planes).
void add_bend_anchors(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& label,
                      const QuadricFrame& frame, double spacing, VertexQuadrics& quadrics) {
  const double weight = spacing * spacing;
  if (!(weight > 0)) return;
  for (int32_t v : layout.curve_bends) {
    if (label[v] < 0) continue;
    double p[3];
    normalised(mesh, frame, v, p);
    for (int axis = 0; axis < 3; ++axis) {
      double u[3] = {0, 0, 0};
      u[axis] = 1.0;
      VertexQuadrics::add_plane(quadrics.at(label[v]), u, -p[axis], weight);
    }
  }
}

// Planes through each border edge (boundary, seam, material edge), perpendicular to each of its
// triangles and weighted by the edge's squared length, keep collapses from pulling the border off
// its course. With spacing > 0 (after a stochastic first pass) each edge also holds its triangle's
// own plane, weighted by its length times the spacing: a border's deviation across the surface
// (a terrain's rim profile, which lies in its border planes) then costs what a patch of surface
// that far off does, where the border's half fan alone held half of that. A mesh collapsed whole
// has neither these planes nor the anchors: the max-aware reruns guard its max, and there the
// anchors cost more than they gained (beetle at 2 %: max 1.9 times;
// docs/bench_notes/large-first-pass.md).
void add_border_planes(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& label,
                       const QuadricFrame& frame, double spacing, VertexQuadrics& quadrics) {
  const auto& faces = mesh.faces();
  const auto& ev = mesh.edge_vertices();
  for (int32_t e : layout.feature_edges) {
    const int32_t* ab = &ev[2 * size_t(e)];
    const int32_t l[2] = {label[ab[0]], label[ab[1]]};
    auto add = [&](const double* normal, const double* through, double weight) {
      const double d = -(normal[0] * through[0] + normal[1] * through[1] + normal[2] * through[2]);
      for (int j = 0; j < 2; ++j)
        if (l[j] >= 0 && (j == 0 || l[j] != l[0])) VertexQuadrics::add_plane(quadrics.at(l[j]), normal, d, weight);
    };
    double a[3], b[3];
    normalised(mesh, frame, ab[0], a);
    normalised(mesh, frame, ab[1], b);
    mesh.for_each_edge_face(e, [&](int32_t f) {
      const int32_t* t = &faces[3 * size_t(f)];
      int32_t opposite = t[0];
      for (int j = 0; j < 3; ++j)
        if (t[j] != ab[0] && t[j] != ab[1]) opposite = t[j];
      double c[3], u[3], w[3], n[3];
      normalised(mesh, frame, opposite, c);
      for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], w[k] = c[k] - a[k];
      n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
      double side[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
      const double side_length = std::sqrt(side[0] * side[0] + side[1] * side[1] + side[2] * side[2]);
      if (!(side_length > 0)) return;
      for (double& x : side) x /= side_length;
      const double length2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
      add(side, a, length2);
      if (!(spacing > 0)) return;
      const double n_length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (double& x : n) x /= n_length;
      add(n, a, std::sqrt(length2) * spacing);
    });
  }
}

// Adds each labelled input vertex's share of its faces' quadrics (block_vertex_quadrics) to its
// cluster's, in vertex order. The members sum blocks of vertices at once, each block's sums
// added to the clusters once the block before it has been: every cluster's sum then takes its
// vertices in the same order whatever the team size.
void sum_vertex_quadrics(const Mesh& mesh, const QuadricFrame& frame, const std::vector<int32_t>& label,
                         VertexQuadrics& quadrics) {
  constexpr int32_t kBlock = 4096;
  const int32_t n = mesh.num_vertices(), blocks = (n + kBlock - 1) / kBlock;
  std::atomic<int32_t> next{0}, added{0};
  parallel_region(team_for(n, kParallelMin), [&](Team&) {
    std::vector<double> sums;
    for (int32_t block = next++; block < blocks; block = next++) {
      const int32_t a = block * kBlock, b = std::min(n, a + kBlock);
      block_vertex_quadrics(mesh, frame, a, b, sums);
      while (added.load(std::memory_order_acquire) != block) std::this_thread::yield();
      for (int32_t v = a; v < b; ++v)
        if (label[v] >= 0) quadrics.add(label[v], &sums[10 * size_t(v - a)]);
      added.store(block + 1, std::memory_order_release);
    }
  });
}

// Each output vertex stands for the input triangles of its cluster (each weighed by the share of
// its corners in the cluster) and for the border edges in it (add_border_planes), after a
// stochastic first pass also for the bends in it (add_bend_anchors). Each cluster's sum takes its
// terms in input order (with attributes each thread owns a range of clusters), so the sums do not
// depend on the number of threads.
VertexQuadrics cluster_quadrics(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params,
                                const std::vector<int32_t>& label, int32_t clusters, const QuadricFrame& frame,
                                bool stochastic_start) {
  const int channels = params.attributes.values ? params.attributes.channels : 0;
  // Wedges only where some cluster has two: otherwise one attribute part per vertex is the same.
  std::vector<uint8_t> wedge;
  int wedges = 0;
  if (channels > 0 && params.attributes.wedges > 1) {
    wedge = corner_wedges(mesh, params.attributes, label, clusters,
                          std::min(params.attributes.wedges, VertexQuadrics::kMaxWedges));
    for (uint8_t w : wedge) wedges = std::max(wedges, w + 1);
    if (wedges < 2) wedge.clear(), wedges = 0;
  }
  VertexQuadrics quadrics(clusters, channels, wedges);
  const auto& faces = mesh.faces();
  const auto& face_source = mesh.face_source();
  const int32_t n = mesh.num_vertices(), m = mesh.num_faces();
  if (channels == 0) {
    sum_vertex_quadrics(mesh, frame, label, quadrics);
  } else {
    parallel_region(team_for(n, kParallelMin), [&](Team& team) {
      const int32_t threads = team.size(), me = team.index();
      const int32_t low = int32_t(int64_t(clusters) * me / threads), high = int32_t(int64_t(clusters) * (me + 1) / threads);
      // Attributes: each face's generalised quadric, a third to the cluster of each corner
      // (to that corner's wedge there: attribute_wedges.hpp).
      std::vector<double> face(quadrics.face_size()), values(3 * size_t(channels));
      for (int32_t f = 0; f < m; ++f) {
        const int32_t* t = &faces[3 * size_t(f)];
        const int32_t l[3] = {label[t[0]], label[t[1]], label[t[2]]};
        if (!((l[0] >= low && l[0] < high) || (l[1] >= low && l[1] < high) || (l[2] >= low && l[2] < high)))
          continue;
        double p[3][3];
        for (int j = 0; j < 3; ++j) normalised(mesh, frame, t[j], p[j]);
        for (int j = 0; j < 3; ++j)
          for (int a = 0; a < channels; ++a)
            values[size_t(j) * channels + a] =
                params.attributes.values[(3 * size_t(face_source[f]) + j) * channels + a] *
                params.attributes.weights[a] * frame.diagonal;
        if (!quadrics.face(p[0], p[1], p[2], values.data(), face.data())) continue;
        for (double& x : face) x *= 1.0 / 3.0;
        double centroid[3];
        for (int i = 0; i < 3; ++i) centroid[i] = (p[0][i] + p[1][i] + p[2][i]) / 3.0;
        for (int j = 0; j < 3; ++j) {
          if (!(l[j] >= low && l[j] < high)) continue;
          if (wedge.empty()) quadrics.add(l[j], face.data());
          else quadrics.add_corner(l[j], wedge[3 * size_t(f) + j], face.data(), centroid);
        }
      }
    });
  }
  // The edge tables are built on first use: a mesh without feature edges never needs them here.
  if (layout.feature_edges.empty()) return quadrics;
  const bool by_target = start_depends_on_target(layout, !stochastic_start);
  const double spacing = by_target ? output_spacing(mesh, frame, params.target_vertices) : 0.0;
  add_border_planes(mesh, layout, label, frame, spacing, quadrics);
  add_bend_anchors(mesh, layout, label, frame, spacing, quadrics);
  return quadrics;
}

// Zero-area triangles no collapse may remove (collinear or coincident input vertices where the
// topology needs every vertex) lose a corner to another input vertex of its cluster: a free
// corner (off every border) takes the first member in the prepared mesh's vertex order (so the
// choice is deterministic) where the triangle gains area and none around it folds, loses area
// or becomes a sliver. The output vertex then stands for that input vertex (kept, position and
// attribute corners), so positions remain input positions in fast mode. Vertices the guidance
// excludes (u = -1) are never taken.
void relocate_zero_area(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params,
                        const std::vector<int32_t>& label, DecimateResult& result, Collapser& collapser) {
  const int32_t n = static_cast<int32_t>(result.kept.size());
  std::vector<int32_t> offsets(n + 1, 0), members(mesh.num_vertices());
  for (int32_t w = 0; w < mesh.num_vertices(); ++w)
    if (label[w] >= 0) ++offsets[collapser.survivor(label[w]) + 1];
  for (int32_t v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
  for (int32_t w = 0; w < mesh.num_vertices(); ++w)
    if (label[w] >= 0) members[fill[collapser.survivor(label[w])]++] = w;
  const auto& source = mesh.vertex_source();
  const auto& index = mesh.vertex_index();
  const auto& faces = mesh.faces();
  for (int32_t t : collapser.zero_area_face_list()) {
    if (!collapser.face_alive(t) || !collapser.zero_area(t)) continue;
    for (int j = 0; j < 3 && collapser.zero_area(t); ++j) {
      const int32_t v = result.triangles[3 * size_t(t) + j];
      if (!collapser.is_free(v)) continue;
      for (int32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
        const int32_t w = members[i];
        if (w == index[result.kept[v]] || layout.is_feature_vertex(w) || !mesh.in_faces(w)) continue;
        if (params.multipliers && (*params.multipliers)[w] == 0.0) continue;
        if (!collapser.place(v, mesh.position(w), t)) continue;
        result.kept[v] = source[w];
        // Attributes from a corner of w (one sector: any of its triangles).
        const int32_t f = mesh.first_face(w);
        int32_t slot = 0;
        while (faces[3 * size_t(f) + slot] != w) ++slot;
        const int32_t corner = 3 * mesh.face_source()[f] + slot;
        for (size_t c = 0; c < result.triangles.size(); ++c)
          if (result.triangles[c] == v) result.corner_source[c] = corner;
        break;
      }
    }
  }
}

}  // namespace

bool has_zero_area(const DecimateResult& result) {
  const auto& p = result.vertices;
  for (size_t t = 0; t < result.triangles.size(); t += 3) {
    const double* a = &p[3 * size_t(result.triangles[t])];
    const double* b = &p[3 * size_t(result.triangles[t + 1])];
    const double* c = &p[3 * size_t(result.triangles[t + 2])];
    double u[3], w[3];
    for (int i = 0; i < 3; ++i) u[i] = b[i] - a[i], w[i] = c[i] - a[i];
    if (u[1] * w[2] - u[2] * w[1] == 0.0 && u[2] * w[0] - u[0] * w[2] == 0.0 && u[0] * w[1] - u[1] * w[0] == 0.0)
      return true;
  }
  return false;
}

namespace {

// Input face f's squared twice-area (|n|², n its unnormalised normal) and its sum of squared
// edges: its shape quality is 2 sqrt(3) |n| / edges.
void face_shape_terms(const Mesh& mesh, int32_t f, double& area2, double& edges) {
  const int32_t* t = &mesh.faces()[3 * size_t(f)];
  const double *a = mesh.position(t[0]), *b = mesh.position(t[1]), *c = mesh.position(t[2]);
  double u[3], w[3];
  edges = 0;
  for (int i = 0; i < 3; ++i) {
    u[i] = b[i] - a[i], w[i] = c[i] - a[i];
    edges += u[i] * u[i] + w[i] * w[i] + (c[i] - b[i]) * (c[i] - b[i]);
  }
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  area2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
}

// Judged on at most 65,536 triangles evenly spread: a count, the same on any thread count.
bool count_slivers(const Mesh& mesh) {
  const int32_t m = mesh.num_faces();
  const int32_t step = std::max<int32_t>(1, int32_t((int64_t(m) + 65535) / 65536));
  int64_t seen = 0, thin = 0;
  for (int32_t f = 0; f < m; f += step) {
    double area2, edges;
    face_shape_terms(mesh, f, area2, edges);
    ++seen;
    thin += !(2.0 * std::sqrt(3.0) * std::sqrt(area2) >= kSliverShape * edges);
  }
  return seen > 0 && thin > kSliverHeavyShare * double(seen);
}

// Per output vertex: the squared shape of the thinnest input triangle around an input vertex it
// stands for (label), a little below it so that a triangle as thin, computed from other corners,
// still passes (CollapseSetup::input_floor2). A fan's slivers (at a vertex of more than
// Collapser::kWideFan faces) are its centre's, not the surface's: left out (a capped cylinder of 5,000
// segments at 10 %, max 0.0007 -> 0.047 % of the diagonal with them).
std::vector<double> input_shape_floors(const Mesh& mesh, const std::vector<int32_t>& label, int32_t n) {
  std::vector<double> floor2(n, std::numeric_limits<double>::infinity());
  const int32_t m = mesh.num_faces();
  // Faces per input vertex, counted here: the mesh's vertex-face table, made on first use, would
  // stay with the mesh (14 bytes a triangle).
  std::vector<int32_t> faces_at(mesh.num_vertices(), 0);
  for (int32_t corner : mesh.faces()) ++faces_at[corner];
  auto wide = [&](int32_t v) { return faces_at[v] > Collapser::kWideFan; };
  for (int32_t f = 0; f < m; ++f) {
    const int32_t* t = &mesh.faces()[3 * size_t(f)];
    if (wide(t[0]) || wide(t[1]) || wide(t[2])) continue;
    double area2, edges;
    face_shape_terms(mesh, f, area2, edges);
    if (!(area2 > 0.0) || !(edges > 0.0)) continue;  // degenerate: no floor (as shape_floor2)
    const double shape2 = (1.0 - kInputFloorSlack) * 12.0 * area2 / (edges * edges);
    for (int j = 0; j < 3; ++j)
      if (label[t[j]] >= 0 && label[t[j]] < n) floor2[label[t[j]]] = std::min(floor2[label[t[j]]], shape2);
  }
  return floor2;
}

}  // namespace

bool sliver_heavy(const Mesh& mesh, const FeatureLayout& layout) {
  auto cached = std::static_pointer_cast<const bool>(layout.sliver_heavy.get());
  if (cached) return *cached;
  const bool heavy = count_slivers(mesh);
  layout.sliver_heavy.set(std::make_shared<const bool>(heavy));
  return heavy;
}

namespace {

// One refinement of a decimation result: the collapser's setup from the result and the
// layout, the collapses, the optional re-fit, and the result compacted. The stages run in the
// order of run().
class Refinement {
 public:
  Refinement(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params, DecimateResult& result)
      : mesh(mesh), layout(layout), params(params), result(result), n(static_cast<int32_t>(result.kept.size())),
        num_input(mesh.num_vertices()), sliver_heavy_input(sliver_heavy(mesh, layout)),
        guided(params.multipliers && std::any_of(params.multipliers->begin(), params.multipliers->end(),
                                                 [](double m) { return m != 1.0; })) {}

  void run() {
    if (params.warm_up && (guided || params.target_triangles > 0 || !params.snapshots)) return;  // none kept
    const auto& source = mesh.vertex_source();
    // The labels in the mesh's order: taken as they are from a refined decimation's first pass,
    // else gathered; the caller's are published from them at the end (publish_labels).
    if (result.labels_in_mesh_order) {
      label = std::move(result.labels);
    } else {
      label.resize(num_input);
      parallel_for(0, num_input, kParallelMin, [&](int32_t v) { label[v] = result.labels[source[v]]; });
    }
    std::vector<int32_t>().swap(result.labels);
    kept_vertex = mesh.internal_ids(result.kept);
    CollapseSetup setup = collapse_setup();
    const double center[3] = {setup.center[0], setup.center[1], setup.center[2]}, extent = setup.extent;
    if (params.max_aware && whole_input() && n <= kMaxAwareVertices) {
      collapse_max_aware(std::move(setup), center, extent);
      if (params.warm_up) return;
    } else {
      const bool keep = keeps_plain_state();
      if (params.warm_up && !keep) return;  // no state is kept on this path
      collapse_plain(std::move(setup), center, extent, keep);
      if (params.warm_up) return;
    }
    publish_labels();
  }

 private:
  const Mesh& mesh;
  const FeatureLayout& layout;
  const RefineParams& params;
  DecimateResult& result;

  // The collapser's setup from the first pass's result (its arrays as that pass left them), the
  // labels and the layout.
  CollapseSetup collapse_setup() const {
    CollapseSetup setup;
    const auto frame = quadric_frame(mesh, layout);
    for (int i = 0; i < 3; ++i) setup.center[i] = frame->center[i];
    setup.extent = frame->extent;
    setup.quadrics = cluster_quadrics(mesh, layout, params, label, n, *frame, !whole_input());
    set_up_vertices(setup);
    lock_whole_triangles(setup);
    lock_sharp_turns(setup);
    // The input's own shape as a floor, in flat regions (may_loosen: on every collapse after a stall).
    if (sliver_heavy_input && !params.zero_area_only) setup.input_floor2 = input_shape_floors(mesh, label, n);
    lock_inconsistent(setup);
    count_locked_ends(setup);
    setup.quota = quotas();
    set_up_corner_sectors(setup);
    set_up_curve_spans(setup);
    // The zero-area clean-up and fast mode keep the caller's positions.
    setup.optimal_placement = !params.zero_area_only && !params.keep_positions;
    return setup;
  }

  // The curves in order for the collapses' span costs (CollapseSetup::curve_order), where every
  // curve vertex is a collapser vertex of its own and its curve is the layout's.
  void set_up_curve_spans(CollapseSetup& setup) const {
    if (layout.num_curves() == 0 || params.zero_area_only) return;
    const auto& offsets = layout.curve_offsets;
    const auto& vertices = layout.curve_vertices;
    std::vector<int32_t> order(vertices.size()), slot(n, -1);
    for (size_t k = 0; k < vertices.size(); ++k) order[k] = label[vertices[k]];
    for (int32_t c = 0; c < layout.num_curves(); ++c)
      for (int32_t k = offsets[c]; k < offsets[c + 1]; ++k) {
        const int32_t i = order[k];
        if (i < 0) return;
        if (!layout.is_feature_vertex(vertices[k]) || layout.is_corner(vertices[k])) continue;
        if (setup.curve[i] != c || slot[i] >= 0) return;  // a dead end, or clusters shared along a curve
        slot[i] = k;
      }
    setup.curve_points.resize(3 * vertices.size());
    for (size_t k = 0; k < vertices.size(); ++k)
      for (int j = 0; j < 3; ++j) setup.curve_points[3 * k + j] = setup.positions[3 * size_t(order[k]) + j];
    setup.curve_order = std::move(order);
    setup.curve_offsets = offsets;
    setup.curve_slot = std::move(slot);
    setup.span_weight = kSpanWeight;
  }

  // The first pass kept every input vertex: its triangles are the input's own.
  bool whole_input() const { return n == num_input - mesh.report().isolated_vertices; }

  // The slivers a stochastic first pass made between its clusters (needles) go before the
  // target's collapses. An input's own slivers are its design and are left to the quadric order:
  // taken first, by shape and not by error, they ate a UV sphere's polar rings (1,000 segments at
  // 10 %: max 0.54 % of the diagonal, 0.009 % now) and joined the two rims of a CAD part's holes
  // along their walls' tall thin triangles (a 84k-triangle STL at 10 %: max 1.35 % of the
  // diagonal, 0.08 % now). Toward a tiny result (kTinyFitFaces) they still go first: there they
  // let the collapses reach lower floors (a printed part's 140 -> 114 triangles), and left to the
  // quadric order the results were no better on the whole. Fans of slivers (a cap's centre, a
  // pole) always go first: left to the collapses, every evaluation of the centre read its
  // thousands of neighbours and faces (a cylinder of 5,000 segments: 0.8 -> 69 s).
  // A stochastic first pass draws its borders whole: their tiny edges beside the sparse surface
  // make slivers of the triangles along them, and where only a border vertex could move, the
  // first such move in corner order cut a bend (a box-cut gyroid's bend at an edge of the box, by
  // one tiny edge at 2 %: max 0.219 % of the diagonal). There the cheapest by quadric cost goes.
  int32_t slivers_first(Collapser& collapser, Collapser::Stop stop) const {
    return collapser.remove_thin(kSliverShape, stop, {fans_of_slivers_only(), !whole_input()});
  }
  bool fans_of_slivers_only() const {
    return sliver_heavy_input || (whole_input() && target_faces() > kTinyFitFaces);
  }
  // The target in triangles (a vertex target's: about twice its vertices).
  int32_t target_faces() const {
    return params.target_triangles > 0 ? params.target_triangles : 2 * params.target_vertices;
  }

  const int32_t n, num_input;
  const bool sliver_heavy_input;  // sliver_heavy(mesh, layout)
  const bool guided;
  std::vector<int32_t> label;  // per input vertex: its output vertex
  std::vector<int32_t> final_index;  // per output vertex of the first pass: its vertex in the result
  // Per output vertex of the first pass: its mesh vertex (found without the mesh's
  // caller-to-internal map, 2 bytes a triangle, which would otherwise be made under the collapser).
  std::vector<int32_t> kept_vertex;
  bool guarded_best_ = false;  // the chosen run is guarded_run's

  // The caller's labels from the mesh-order ones, once the collapser is gone (the two tables
  // then never sit beside it).
  void publish_labels() {
    const auto& source = mesh.vertex_source();
    result.labels.resize(num_input);
    parallel_for(0, num_input, kParallelMin, [&](int32_t v) {
      result.labels[source[v]] = label[v] >= 0 ? final_index[label[v]] : -1;
    });
    std::vector<int32_t>().swap(label);
    result.labels_in_mesh_order = false;
  }

  double multiplier(int32_t v) const { return guided ? (*params.multipliers)[v] : 1.0; }

  // Per output vertex: normalised position, weight, feature curve, lock and guidance bin.
  void set_up_vertices(CollapseSetup& setup) const {
    setup.world = result.vertices;
    setup.positions.resize(3 * size_t(n));
    setup.weight.assign(n, 1.0);
    setup.locked.assign(n, 0);
    setup.curve.assign(n, -1);
    setup.curve_size.assign(layout.num_curves(), 0);
    setup.curve_closed = layout.curve_closed;
    setup.on_boundary.assign(n, 0);
    setup.bin.resize(n);
    const std::vector<int32_t> end_curve = dead_end_curves();
    setup.dead_end.assign(end_curve.empty() ? 0 : n, 0);
    for (int32_t i = 0; i < n; ++i) {
      const int32_t v = kept_vertex[i];
      const double m = multiplier(v);
      if (layout.is_feature_vertex(v)) setup.curve[i] = layout.curve_of(v);
      const bool dead_end = !end_curve.empty() && end_curve[v] >= 0 && m != kForcedMultiplier;
      if (dead_end) setup.curve[i] = end_curve[v], setup.dead_end[i] = 1;
      if (setup.curve[i] >= 0) ++setup.curve_size[setup.curve[i]];
      // A curve vertex with one sector lies on a mesh boundary (a seam or crease has two).
      setup.on_boundary[i] = setup.curve[i] >= 0 && layout.sectors_of(mesh, v) == 1;
      setup.locked[i] = (layout.is_corner(v) && !dead_end) || (layout.is_feature_vertex(v) && setup.curve[i] < 0) ||
                        m == kForcedMultiplier;
      if (m == kForcedMultiplier)  // a control point stays where the user put it
        for (int k = 0; k < 3; ++k) setup.world[3 * size_t(i) + k] = mesh.position(v)[k];
      setup.weight[i] = m == kForcedMultiplier ? 1.0 : std::max(m, 1.0 / 81.0);
      setup.bin[i] = guidance_bin(m);
    }
    for (size_t i = 0; i < setup.world.size(); ++i)
      setup.positions[i] = (setup.world[i] - setup.center[i % 3]) * (1.0 / setup.extent);
  }

  // Per input vertex, the open curve it ends as a dead end the collapses may move (-1
  // elsewhere; empty without non-manifold edges): no other feature edge meets it, its one edge
  // is non-manifold and each sheet goes round it once (two sectors for an edge of four
  // triangles). There two sheets stop touching; the layout keeps it as a corner.
  std::vector<int32_t> dead_end_curves() const {
    std::vector<int32_t> end_curve;
    if (mesh.report().nonmanifold_edges == 0) return end_curve;
    end_curve.assign(num_input, -1);
    const auto& offsets = layout.curve_offsets;
    const auto& vertices = layout.curve_vertices;
    for (int32_t c = 0; c < layout.num_curves(); ++c) {
      if (layout.curve_closed[c] || offsets[c + 1] - offsets[c] < 2) continue;
      for (const auto& [end, next] : {std::pair{offsets[c], offsets[c] + 1}, std::pair{offsets[c + 1] - 1, offsets[c + 1] - 2}}) {
        const int32_t v = vertices[end], e = mesh.find_edge(v, vertices[next]);
        if (layout.feature_degree[v] != 1 || e < 0) continue;
        const int32_t k = mesh.edge_face_count(e);
        if (k >= 3 && 2 * layout.sectors_of(mesh, v) == k) end_curve[v] = c;
      }
    }
    return end_curve;
  }

  // An input triangle that is a piece of its own (an unwelded mesh is made of them) is the
  // fewest its piece may keep: its corners (FeatureLayout::loose_vertices, which the draw
  // forces) are locked, so that the collapses never queue or cost them (every collapse there was
  // refused, one by one: 2.4 s for 82,000 loose triangles). The winding seam's two triangles a
  // component (FeatureLayout::winding_seam_vertices) stay the same way, but for the zero-area
  // clean-up, which must be free to collapse next to them (coincident vertices).
  void lock_whole_triangles(CollapseSetup& setup) const {
    for (const auto* kept : {&layout.loose_vertices, &layout.winding_seam_vertices}) {
      if (kept->empty() || (kept == &layout.winding_seam_vertices && params.zero_area_only)) continue;
      for (int32_t i = 0; i < n; ++i)
        if (std::binary_search(kept->begin(), kept->end(), kept_vertex[i])) setup.locked[i] = 1;
    }
  }

  // On a sliver-heavy input a sharp turn of a boundary between a short edge and a long one
  // stays. Moving it along the long edge (a strip of needles eaten from its end: a 2,000 x 4
  // strip of 1 x 0.05 cells at 2 %, max error 25.6 % of the diagonal) was the cheapest collapse:
  // the short edge's border plane weighs its tiny squared length.
  void lock_sharp_turns(CollapseSetup& setup) const {
    if (!sliver_heavy_input) return;
    for (int32_t v : find_sharp_turns(mesh, layout, kSharpTurnEdgeRatio)) {
      const int32_t i = label[v];
      if (i >= 0 && i < n && kept_vertex[i] == v) setup.locked[i] = 1;
    }
  }

  // On a sliver-heavy input a triangle may be as thin as the input's thinnest where its vertex
  // stands (input_shape_floors), in flat regions (Collapser::flat_star): in a strip of needles
  // every triangle is as thin as its neighbours, so the shape rule refused every merge along it
  // (a 20,000 x 8 strip of 1 x 0.001 cells: 163,733 triangles for 32,000), and a CAD tray at 10 %
  // had 5.7 times the peers' mean error. Loosened, the floor holds on every collapse: only after
  // a stall, since on UV spheres (planar quads), capped cylinders and fanned discs, which reach
  // their targets, it made the max error 14-60 times larger.
  bool may_loosen(const CollapseSetup& setup) const {
    return !setup.input_floor2.empty() && setup.input_floor_flat_only;
  }
  void loosen(CollapseSetup& setup) const { setup.input_floor_flat_only = false; }

  // Whether the shape rule holds a sliver-heavy input's run above its target
  // (DecimateResult::shape_floor): a copy with no shape limit goes at least halfway from there to
  // the target. The stalled run works on result's arrays.
  bool held_by_shape(const Collapser& stalled) const {
    return goes_halfway(stalled, [](Collapser& free) { free.set_shape_limits(0.0, Collapser::kMinTurnCos); });
  }
  // Whether the shape checks hold a run at twice the target or more (DecimateResult::fold_floor):
  // a copy without them goes at least halfway from there to the target. A stall nearer the
  // target, or under twice a generous count of what the topology keeps, is left to the
  // topology's reason without the copy (it costs the whole collapser and a run).
  bool held_by_folds(const Collapser& stalled) const {
    return !params.zero_area_only && stalled_far(stalled) && stalled.live_vertices() > 2 * topology_keeps() &&
           goes_halfway(stalled, [](Collapser& free) { free.drop_shape_checks(); });
  }
  // A generous count of the vertices the topology alone keeps: per component 4, 6 a handle and
  // 3 a boundary loop (a torus stops at 7 to 9 vertices, a disc at 3).
  int64_t topology_keeps() const {
    const std::vector<int32_t> loops = component_boundary_loops(mesh, layout);
    int64_t keeps = 0;
    for (int32_t c = 0; c < mesh.num_components(); ++c) {
      const int64_t twice_genus = std::max<int64_t>(0, 2 - mesh.component_euler()[c] - loops[c]);
      keeps += 4 + 3 * twice_genus + 3 * loops[c];
    }
    return keeps;
  }
  // Whether the far guard held a run above the target: without it (its check is gone once the
  // run ends), its collapses go at least halfway from there to the target.
  bool held_by_guard(const Collapser& stalled) const {
    return goes_halfway(stalled, [](Collapser&) {});
  }
  // Whether a copy of a run stopped above the target, changed by `loosen`, gets at least halfway
  // from there to the target.
  template <class Loosen>
  bool goes_halfway(const Collapser& stalled, Loosen&& loosen) const {
    if (stalled_by(stalled) == 0 || !stalled.has_free_vertex()) return false;  // (a copy costs the whole collapser)
    std::vector<int32_t> triangles = result.triangles, corners = result.corner_source;
    Collapser free(stalled);
    free.use_arrays(triangles, corners);
    loosen(free);
    free.reopen();
    const int32_t halfway = target_count() + stalled_by(stalled) / 2;  // no further: the answer is known there
    free.run(params.target_triangles > 0 ? Collapser::Stop{params.target_vertices, halfway} : Collapser::Stop{halfway, 0});
    return 2 * stalled_by(free) <= stalled_by(stalled);
  }
  // Loosened collapses are tried where the plain ones stopped at twice the target or more, and
  // kept where they get at least halfway from there to the target. A stall nearer the target is
  // the topology's floor at a tiny budget, where CAD parts lost more than they gained: a tray of
  // 4,520 triangles at 100, 316 -> 272 triangles for a max 0.78 -> 1.22 % of the diagonal; a
  // filter housing at 100, 120 -> 106 for a mean 1.4 -> 2.2 %.
  bool stalled_far(const Collapser& plain) const { return stalled_by(plain) >= target_count(); }
  bool loosened_wins(const Collapser& loosened, const Collapser& plain) const {
    return 2 * stalled_by(loosened) <= stalled_by(plain);
  }
  // How far a collapser stands above the target (0: reached).
  int32_t stalled_by(const Collapser& collapser) const {
    return std::max(0, (params.target_triangles > 0 ? collapser.live_faces() : collapser.live_vertices()) - target_count());
  }
  int32_t target_count() const { return params.target_triangles > 0 ? params.target_triangles : params.target_vertices; }

  // The plain collapses (fast mode, the zero-area clean-up, large results), loosened after a
  // stall when that wins (may_loosen, loosened_wins). The loosened run's setup is built again
  // from the first pass's arrays, kept for it, rather than copied for every run that might stall.
  // `keep`: the plain run's state is kept for later runs (keeps_plain_state; not the loosened one's).
  void collapse_plain(CollapseSetup setup, const double* center, double extent, bool keep) {
    const bool may_retry = may_loosen(setup);
    std::vector<int32_t> start_triangles, start_corners;
    if (may_retry) start_triangles = result.triangles, start_corners = result.corner_source;
    std::unique_ptr<Collapser> collapser;
    collapse(std::move(setup), collapser, center, extent, keep);
    if (params.warm_up) return;  // the kept state is the point
    if (may_retry && stalled_far(*collapser)) {
      const int32_t collapses = result.refine_collapses;
      result.triangles.swap(start_triangles);  // the first pass's arrays, for the setup and the run
      result.corner_source.swap(start_corners);
      CollapseSetup loosened_setup = collapse_setup();
      loosen(loosened_setup);
      std::unique_ptr<Collapser> loosened;
      collapse(std::move(loosened_setup), loosened, center, extent, false);
      if (loosened_wins(*loosened, *collapser)) {
        collapser = std::move(loosened);
      } else {  // the plain run's arrays back
        result.triangles.swap(start_triangles);
        result.corner_source.swap(start_corners);
        result.refine_collapses = collapses;
      }
    }
    if (may_retry) result.shape_floor = held_by_shape(*collapser);
    if (!result.shape_floor) result.fold_floor = held_by_folds(*collapser);
    finish(*collapser);
  }

  // A dead end locked after all (lock_inconsistent) is a locked end of its curve again; every
  // other open curve end is locked.
  void count_locked_ends(CollapseSetup& setup) const {
    setup.curve_locked_ends.assign(layout.num_curves(), 0);
    for (int32_t c = 0; c < layout.num_curves(); ++c) setup.curve_locked_ends[c] = layout.curve_closed[c] ? 0 : 2;
    for (int32_t i = 0; i < int32_t(setup.dead_end.size()); ++i) {
      if (!setup.dead_end[i]) continue;
      if (setup.locked[i]) {
        --setup.curve_size[setup.curve[i]];
        setup.curve[i] = -1;
        setup.dead_end[i] = 0;
      } else {
        --setup.curve_locked_ends[setup.curve[i]];
      }
    }
  }

  // Vertices next to a pinched vertex (several fans) or on a non-manifold edge are free: the
  // collapses that would delete a wing or a sheet there are refused one by one
  // (Collapser::duplicates_a_face, merges_unlike_edges). Freezing their rings had stopped
  // scans and multi-part models far above the target. One inconsistently oriented edge per
  // component keeps its two triangles (their corners locked): collapsing every such edge away
  // would make the component consistently oriented. (Locking the rings of all of them froze
  // whole regions of scans: Stanford's dragon at its lowest resolution kept 2,528 triangles.)
  void lock_inconsistent(CollapseSetup& setup) const {
    if (mesh.report().inconsistent_edges == 0) return;
    struct Side {
      int32_t a, b, face;
      bool forward;
    };
    std::vector<Side> sides;
    sides.reserve(result.triangles.size());
    for (int32_t t = 0; t < int32_t(result.triangles.size() / 3); ++t)
      for (int j = 0; j < 3; ++j) {
        const int32_t from = result.triangles[3 * size_t(t) + j], to = result.triangles[3 * size_t(t) + (j + 1) % 3];
        sides.push_back({std::min(from, to), std::max(from, to), t, from < to});
      }
    std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
      return x.a < y.a || (x.a == y.a && (x.b < y.b || (x.b == y.b && x.face < y.face)));
    });
    std::vector<uint8_t> component_done(mesh.report().components + 1, 0);
    for (size_t i = 0; i < sides.size();) {
      size_t k = i;
      while (k < sides.size() && sides[k].a == sides[i].a && sides[k].b == sides[i].b) ++k;
      const int32_t component = mesh.component()[kept_vertex[sides[i].a]];
      if (k - i == 2 && sides[i].forward == sides[i + 1].forward && component >= 0 &&
          size_t(component) < component_done.size() && !component_done[component]) {
        component_done[component] = 1;
        for (size_t s = i; s < k; ++s)
          for (int j = 0; j < 3; ++j) setup.locked[result.triangles[3 * size_t(sides[s].face) + j]] = 1;
      }
      i = k;
    }
  }

  // One run of the max-aware collapses: its collapser, figures and arrays (every run works on
  // result's arrays: its own are copied out before the next one starts).
  struct Run {
    std::unique_ptr<Collapser> collapser;
    Deviation deviation;
    int32_t collapses = 0;
    std::vector<int32_t> triangles, corners;
  };

  // A max-aware decimation's first run to its target, before its re-fit (after_run): its state
  // at the restart, where the reruns start (the collapses before it are shared), kept too.
  struct FirstRun {
    Run run;
    std::unique_ptr<Collapser> at_restart;
    int32_t shared = 0;
    std::vector<int32_t> restart_triangles, restart_corners;
  };
  FirstRun first_run(CollapseSetup setup, Collapser::Stop stop, Collapser::Stop restart) {
    FirstRun first;
    first.shared = shared_run(std::move(setup), stop, restart, first.run.collapser);
    first.at_restart = std::make_unique<Collapser>(*first.run.collapser);
    first.restart_triangles = result.triangles, first.restart_corners = result.corner_source;
    first.run.collapses = first.shared + first.run.collapser->run(stop);
    return first;
  }

  // Max-aware collapses (RefineParams::max_aware): a first run, then kRounds more that each
  // start from the first's state at kRestart times the target (the collapses before it are
  // shared), their cost weights grown where the runs before ended farthest from the input, so
  // that they keep more vertices there (reweighting toward the smallest max error). The run
  // nearest the target, then the one `wins` prefers (a smaller max that pays for its mean, the
  // mean within kMeanSlack of the first run's), is kept.
  void collapse_max_aware(CollapseSetup setup, const double* center, double extent) {
    const std::vector<double> guidance = setup.weight;
    result.refine_vertices = params.target_vertices;
    result.refine_triangles = params.target_triangles;
    const Collapser::Stop stop = target(), restart{int32_t(kRestart * stop.vertices), int32_t(kRestart * stop.faces)};
    CollapseSetup start = setup;
    const std::vector<int32_t> start_triangles = result.triangles, start_corners = result.corner_source;
    FirstRun first = first_run(std::move(setup), stop, restart);
    first.run.collapses += after_run(*first.run.collapser, center, extent);
    const std::shared_ptr<const Surface> whole = kept_input(*first.run.collapser, 1);
    if (params.warm_up) return;  // what a later run reuses is kept
    if (first.run.collapses == 0 && std::find(start.locked.begin(), start.locked.end(), 0) == start.locked.end()) {
      // Every vertex locked (loose triangles): no run can change the input, so nothing to measure.
      result.refine_collapses = 0;
      finish(*first.run.collapser);
      return;
    }
    if (may_loosen(start) && stalled_far(*first.run.collapser)) {
      // Stalled on a sliver-heavy input: all over again, loosened, kept if it wins (loosened_wins).
      // (A far stall's reruns never start from its own state at the restart: see floor below.)
      first.at_restart.reset();
      std::vector<int32_t> triangles = std::move(result.triangles), corners = std::move(result.corner_source);
      result.triangles = start_triangles, result.corner_source = start_corners;
      CollapseSetup loosened = start;
      loosen(loosened);
      FirstRun probe = first_run(loosened, stop, restart);
      if (loosened_wins(*probe.run.collapser, *first.run.collapser)) {
        probe.run.collapses += after_run(*probe.run.collapser, center, extent);
        first = std::move(probe);
        start = std::move(loosened);
      } else {  // the plain run's arrays back
        result.triangles = std::move(triangles), result.corner_source = std::move(corners);
      }
    }
    Run best = std::move(first.run);  // the first run, then any rerun that wins over the best so far
    std::unique_ptr<Collapser> at_restart = std::move(first.at_restart);
    int32_t shared = first.shared;
    std::vector<int32_t> restart_triangles = std::move(first.restart_triangles), restart_corners = std::move(first.restart_corners);
    const Collapser::Stop floor = restart_above(*best.collapser, stop);
    // Below the floor the reruns stop where the first run did, under looser checks.
    const bool below_floor = floor.vertices > 0 || floor.faces > 0;
    const Collapser::Stop reached{best.collapser->live_vertices(), stop.faces > 0 ? best.collapser->live_faces() : 0};
    if (!at_restart || floor.vertices > at_restart->live_vertices() || floor.faces > at_restart->live_faces()) {
      // The first run stopped above the target (the topology or the borders) and made few
      // collapses after the restart: the reruns restart from kRestart times where it ended
      // instead, so that they can still choose which vertices stay.
      const std::vector<int32_t> floor_triangles = result.triangles, floor_corners = result.corner_source;
      result.triangles = start_triangles;
      result.corner_source = start_corners;
      at_restart = std::make_unique<Collapser>(result.triangles, result.corner_source, start);
      shared = slivers_first(*at_restart, stop) + at_restart->run(floor);
      restart_triangles = result.triangles, restart_corners = result.corner_source;
      result.triangles = floor_triangles;
      result.corner_source = floor_corners;
    }
    const InputSurface input(mesh, whole);
    best.deviation = surface_deviation(mesh, input, label, *best.collapser, result.triangles);
    best.triangles = result.triangles, best.corners = result.corner_source;
    const bool tiny = best.collapser->live_faces() <= kTinyFitFaces;
    const double mean_bound = (1.0 + (tiny ? kTinyMeanSlack : kMeanSlack)) * best.deviation.mean;
    Deviation last = best.deviation;
    std::vector<double> worst(n, 0.0);  // per vertex: its largest deviation over the largest, of every run so far
    // A tiny result that reached its target gets kRounds more reruns under the floor's looser
    // limits, which must lower the max by more than they add to the mean (loose_rerun).
    const int rounds = tiny && !below_floor ? 2 * kRounds : kRounds;
    for (int r = 0; r < rounds && last.top2 > 0; ++r) {
      const int round = r % kRounds;
      const bool loose_rerun = r >= kRounds;
      for (int32_t v = 0; v < n; ++v) worst[v] = std::max(worst[v], last.vertex2[v] / last.top2);
      result.triangles = restart_triangles;
      result.corner_source = restart_corners;
      auto run = std::make_unique<Collapser>(*at_restart);
      run->reweigh(deviation_weights(*run, guidance, worst, kDeviationWeights[round]));
      if (below_floor || loose_rerun) run->set_shape_limits(kFloorShape[round], kFloorTurnCos);
      const int32_t collapses = shared + collapse_rest(*run, center, extent, below_floor ? reached : stop);
      // The last run's deviation serves only the choice: measured until it loses.
      const Rival rival{best.deviation.top2, mean_bound};
      last = surface_deviation(mesh, input, label, *run, result.triangles, r + 1 == rounds ? &rival : nullptr);
      if (wins(last, best.deviation, mean_bound, tiny && !loose_rerun))
        best = Run{std::move(run), last, collapses, result.triangles, result.corner_source};
    }
    if (guards_tail(stop)) {
      result.triangles = restart_triangles, result.corner_source = restart_corners;
      guarded_run(best, *at_restart, shared, below_floor ? reached : stop, input, center, extent);
    }
    if (below_floor && best.collapser->live_faces() <= kExtensionFaces) extend_past_floor(best, input, stop);
    result.triangles = std::move(best.triangles);
    result.corner_source = std::move(best.corners);
    result.refine_collapses = best.collapses;
    if (sliver_heavy_input) result.shape_floor = held_by_shape(*best.collapser);
    if (!result.shape_floor) result.fold_floor = held_by_folds(*best.collapser);
    if (guarded_best_) result.far_guard = held_by_guard(*best.collapser);
    // The fit moves vertices under the usual limits (under the looser ones it left slivers: a
    // torus at 16 triangles, aspect ratio up to 187 against 35).
    best.collapser->set_shape_limits(Collapser::kMinShape, Collapser::kMinTurnCos);
    // The max its samples found: what a result too large for the fit's brackets is held to.
    finish(*best.collapser, whole, std::sqrt(best.deviation.top2));
  }

  // One more run, under the far guard (kFarGuard), from the reruns' start (result.triangles its
  // triangles), its bound from there. It is chosen where its max is at most kGuardedMax of the
  // best run's and it lowers the max by a larger share than it raises the mean both ways (the
  // guard keeps triangles off empty space, which the input's own distances do not see); below the
  // floor, where it stops a few triangles above the best run, within kGuardedFloorSlack of its
  // size where that mean is at most kGuardedMean of the best's.
  void guarded_run(Run& best, const Collapser& at_restart, int32_t shared, Collapser::Stop stop,
                   const InputSurface& input, const double* center, double extent) {
    auto run = std::make_unique<Collapser>(at_restart);
    const Collapser::FanCheck guard = far_guard(input, *run);
    const bool below_floor = excess(best.deviation) > 0;
    if (below_floor) run->set_shape_limits(kFloorShape[0], kFloorTurnCos);
    const int32_t collapses = shared + collapse_rest(*run, center, extent, stop, guard);
    Deviation d = surface_deviation(mesh, input, label, *run, result.triangles);
    const double mean = 0.5 * (d.mean + d.back_mean), best_mean = 0.5 * (best.deviation.mean + best.deviation.back_mean);
    const int32_t x = count_of(d), y = count_of(best.deviation);
    const double max_share = std::sqrt(d.top2 / best.deviation.top2);
    const bool chosen = max_share <= kGuardedMax &&
                        (below_floor ? mean <= kGuardedMean * best_mean && std::abs(x - y) <= kGuardedFloorSlack * y
                                     : excess(d) == 0 && 1.0 - max_share > mean / best_mean - 1.0);
    if (!chosen) return;
    best = Run{std::move(run), std::move(d), collapses, result.triangles, result.corner_source};
    guarded_best_ = true;
  }

  // Below the floor: the chosen run continued one collapse at a time toward `stop`, each kept
  // under the rules of kExtensionTries, a refused one undone and its vertex held from then on.
  void extend_past_floor(Run& best, const InputSurface& input, Collapser::Stop stop) {
    const bool faces = stop.faces > 0;
    result.triangles = best.triangles;
    result.corner_source = best.corners;
    auto run = std::make_unique<Collapser>(*best.collapser);
    run->set_shape_limits(kFloorShape[1], Collapser::kMinTurnCos);
    run->reopen();
    Deviation reached = best.deviation;
    int32_t kept = 0;
    for (int tried = 0; tried < kExtensionTries; ++tried) {
      if ((faces ? run->live_faces() : run->live_vertices()) <= (faces ? stop.faces : stop.vertices)) break;
      auto before = std::make_unique<Collapser>(*run);
      const std::vector<int32_t> triangles_before = result.triangles, corners_before = result.corner_source;
      const int32_t removed = run->collapse_one();
      if (removed < 0) break;
      if (run->on_mesh_boundary(removed) &&
          farthest_around(input, *run, result.triangles, run->survivor(removed), kExtensionGrid) <= best.deviation.top2) {
        const Rival bound = count_bound(best.deviation, faces ? run->live_faces() : run->live_vertices());
        Deviation d = surface_deviation(mesh, input, label, *run, result.triangles, &bound);
        if (d.complete && d.top2 <= bound.top2 && d.mean <= bound.mean) {
          reached = std::move(d);
          ++kept;
          continue;
        }
      }
      // Refused: back to the state before it, its vertex held.
      run = std::move(before);
      result.triangles = triangles_before, result.corner_source = corners_before;
      run->hold(removed);
    }
    if (kept == 0) return;
    const int32_t thin = run->remove_thin(0.0, {});
    best = Run{std::move(run), reached, best.collapses + kept + thin, result.triangles, result.corner_source};
  }

  // What a run continued past the floor to `count` (triangles or vertices, as the target) must
  // stay within against the chosen run: no larger max, no larger mean times the count.
  Rival count_bound(const Deviation& chosen, int32_t count) const {
    const double scale = double(params.target_triangles > 0 ? chosen.faces : chosen.vertices) / double(count);
    return Rival{chosen.top2, chosen.mean * scale};
  }

  // The first run to `restart` (slivers first), from a state kept by an earlier refinement
  // toward as many vertices or more when there is one; it keeps its own where its batches start
  // to depend on the target (unless `keep` is false). Returns the collapses from the start.
  int32_t shared_run(CollapseSetup setup, Collapser::Stop stop, Collapser::Stop restart, std::unique_ptr<Collapser>& run,
                     bool keep = true) {
    CollapseSnapshots* snapshots = params.target_triangles == 0 && !guided ? params.snapshots : nullptr;
    if (!snapshots) {
      run = std::make_unique<Collapser>(result.triangles, result.corner_source, std::move(setup));
      return slivers_first(*run, stop) + run->run(restart);
    }
    std::vector<uint64_t> start = start_key(setup, result.triangles, result.corner_source);
    start.push_back(fans_of_slivers_only());  // which slivers went first: states of either kind differ
    int32_t before = 0;
    if (const auto kept = snapshots->find(start, restart.vertices)) {
      run = resumed(*kept, result.triangles, result.corner_source, std::move(setup.quota));
      before = kept->collapses;
    } else {
      run = std::make_unique<Collapser>(result.triangles, result.corner_source, std::move(setup));
      before = slivers_first(*run, stop);
    }
    if (!keep) return before + run->run(restart);
    return before + run->run(restart, [&](const Collapser& state, int32_t made) {
      snapshots->keep(snapshot(start, restart.vertices, before + made, state));
    });
  }

  // The input's triangles, every step-th, with their search structure (normalised_input): the
  // one kept with the collapse states when there are some.
  std::shared_ptr<const Surface> kept_input(const Collapser& collapser, int64_t step) const {
    if (!params.snapshots) return normalised_input(mesh, collapser, step);
    return params.snapshots->input_surface(input_surface_key(mesh, collapser, step),
                                           [&] { return normalised_input(mesh, collapser, step); });
  }

  // Whether a rerun's result beats the best so far: nearer the target, or as near with its mean
  // within the bound and a max smaller by a larger share than its mean is larger (a max 3 %
  // lower for a mean 5 % higher is no gain), or the same max and a smaller mean (a rerun that
  // could not move the max, held where the topology needs it, keeps the run that cost less).
  // A result the fit takes four rounds over (`tiny`) needs only a max no larger: the fit moves
  // its mean and max more than the reruns do, so their own figures are a poor guide to trade.
  bool wins(const Deviation& run, const Deviation& best, double mean_bound, bool tiny) const {
    if (excess(run) != excess(best) && !near_floor(run, best)) return excess(run) < excess(best);
    if (!run.complete || run.mean > mean_bound) return false;
    if (excess(run) != excess(best)) {
      // Both stopped above the target, a few triangles apart: the smaller max wins if it pays
      // for its mean, then the one nearer the target.
      if (run.top2 != best.top2) return lowers_max_for_its_mean(run, best);
      return excess(run) < excess(best);
    }
    if (tiny) return run.top2 <= best.top2;
    if (run.top2 == best.top2) return run.mean < best.mean;
    return lowers_max_for_its_mean(run, best);
  }

  // Whether run's max is smaller than best's by a larger share than its mean is larger.
  static bool lowers_max_for_its_mean(const Deviation& run, const Deviation& best) {
    const double max_gain = 1.0 - std::sqrt(run.top2 / best.top2);
    const double mean_loss = best.mean > 0.0 ? run.mean / best.mean - 1.0 : 0.0;
    return run.top2 < best.top2 && max_gain > mean_loss;
  }

  // Where the reruns restart when a run stopped above the target: kRestart times where it
  // ended (an empty stop when it reached the target).
  Collapser::Stop restart_above(const Collapser& run, Collapser::Stop stop) const {
    if (stop.faces > 0)
      return {0, run.live_faces() > stop.faces ? int32_t(kRestart * run.live_faces()) : 0};
    return {run.live_vertices() > stop.vertices ? int32_t(kRestart * run.live_vertices()) : 0, 0};
  }

  // Whether two runs both stopped above the target (the topology or the borders) within
  // kFloorSlack of each other's size: there a few triangles more for a smaller max is a gain.
  bool near_floor(const Deviation& a, const Deviation& b) const {
    if (excess(a) == 0 || excess(b) == 0) return false;
    const bool faces = params.target_triangles > 0;
    const int32_t x = faces ? a.faces : a.vertices, y = faces ? b.faces : b.vertices;
    return std::abs(x - y) <= kFloorSlack * std::min(x, y);
  }

  // How far a run stayed above the target (0 once reached).
  int32_t excess(const Deviation& d) const { return std::max(0, count_of(d) - target_count()); }
  int32_t count_of(const Deviation& d) const { return params.target_triangles > 0 ? d.faces : d.vertices; }

  // The weight of each vertex alive in `restarted`: its guidance weight times 1 +
  // `strength` x the largest worst[] (a squared deviation over the largest) of the vertices
  // merged into it.
  std::vector<double> deviation_weights(Collapser& restarted, std::vector<double> weight,
                                        const std::vector<double>& worst, double strength) const {
    std::vector<double> merged(n, 0.0);
    for (int32_t v = 0; v < n; ++v) {
      const int32_t s = restarted.survivor(v);
      merged[s] = std::max(merged[s], worst[v]);
    }
    for (int32_t v = 0; v < n; ++v) weight[v] *= 1.0 + strength * merged[v];
    return weight;
  }

  // A tiny result fitted to the input (after the max-aware choice, which compares the
  // collapses' own results), the zero-area triangles left moved off, and the result compacted.
  // With attributes too: a vertex the fit moves takes the input's attributes where it lands
  // (attributes.moved_vertices), and seam vertices, whose sides differ, do not move. whole: the
  // whole input's surface when the caller has it (the fit's, unless the input is large).
  // known_max: a distance the symmetric max attains (a larger result is fitted only with one,
  // against the whole input).
  void finish(Collapser& collapser, std::shared_ptr<const Surface> whole = nullptr, double known_max = -1.0) {
    const int32_t faces = collapser.live_faces(), rounds = fit_rounds(faces);
    if (params.refit && rounds > 0 && (faces <= kFitFaces || (known_max > 0.0 && params.large_fit))) {
      const int64_t step = faces <= kFitFaces ? fit_input_step(mesh) : 1;
      const std::shared_ptr<const Surface> input = step == 1 && whole ? whole : kept_input(collapser, step);
      fit_tiny(mesh, collapser, rounds, faces <= kTinyFitFaces, *input, known_max);
    }
    if (collapser.zero_area_faces() > 0) relocate_zero_area(mesh, layout, params, label, result, collapser);
    result.issues_remaining.sliver = collapser.zero_area_faces();
    compact(collapser);
  }

  // The target's share of each guidance bin, from the input vertices in it.
  std::vector<int32_t> quotas() const {
    std::vector<double> bin_vertices(kBins, 0.0), bin_multipliers(kBins, 0.0);
    if (guided) {
      for (int32_t v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.in_faces(v)) {
          const int32_t b = guidance_bin(multiplier(v));
          bin_vertices[b] += 1.0;
          bin_multipliers[b] += multiplier(v);
        }
    } else {
      const int32_t b = guidance_bin(1.0);
      bin_vertices[b] = mesh.num_vertices() - mesh.report().isolated_vertices;
      bin_multipliers[b] = bin_vertices[b];
    }
    return bin_quotas(bin_vertices, bin_multipliers, params.target_vertices);
  }

  // Sector of every output corner at its vertex, from the input corner it copies.
  void set_up_corner_sectors(CollapseSetup& setup) const {
    setup.corner_sector.assign(result.corner_source.size(), 0);
    std::vector<int32_t> internal_face;
    for (size_t c = 0; c < setup.corner_sector.size(); ++c) {
      const int32_t vertex = kept_vertex[result.triangles[c]];
      if (layout.sectors_of(mesh, vertex) <= 1) continue;
      if (internal_face.empty()) {
        internal_face.assign(mesh.report().input_triangles, -1);
        for (int32_t f = 0; f < mesh.num_faces(); ++f) internal_face[mesh.face_source()[f]] = f;
      }
      setup.corner_sector[c] = layout.sector_of(mesh, vertex, internal_face[result.corner_source[c] / 3]);
    }
  }

  // The collapses from `setup`: only zero-area clean-up, or slivers first, then the target (fast
  // mode's tail at a tiny target chosen, tail_choice; else from a kept state where one serves it,
  // shared_run, its own kept where `keep`), then the optional re-fit and a
  // last clean-up. A warm-up stops before those two.
  void collapse(CollapseSetup setup, std::unique_ptr<Collapser>& collapser, const double* center, double extent,
                bool keep) {
    if (params.zero_area_only) {
      collapser = std::make_unique<Collapser>(result.triangles, result.corner_source, std::move(setup));
      result.refine_collapses += collapser->remove_thin(0.0, {});
      return;
    }
    result.refine_vertices = params.target_vertices;
    result.refine_triangles = params.target_triangles;
    result.refine_keeps_positions = params.keep_positions;
    // Slivers the stochastic pass left (near-collinear corners, needles) go first: the
    // collapses thin the result anyway, and none of them makes a triangle thinner than the
    // thinnest around it was (Collapser::keeps_shape).
    if (chooses_tail()) {
      collapser = std::make_unique<Collapser>(result.triangles, result.corner_source, std::move(setup));
      result.refine_collapses = slivers_first(*collapser, target());
      result.refine_collapses += tail_choice(collapser, center, extent);
      return;
    }
    result.refine_collapses = shared_run(std::move(setup), target(), target(), collapser, keep);
    if (!params.warm_up) result.refine_collapses += collapse_rest(*collapser, center, extent);
  }

  // Whether the plain run keeps its state (shared_run) for a later run toward a lower target,
  // which resumes from it to the same bits: unguided vertex targets, not fast mode's tail (run
  // twice: chooses_tail), and not a one-off's first run (CollapseSnapshots::keeps_plain_run).
  // A warm-up asks only where the first pass is the same for lower targets (start_fixed).
  bool keeps_plain_state() const {
    if (!params.snapshots || params.target_triangles > 0 || guided || chooses_tail()) return false;
    return params.snapshots->keeps_plain_run(params.warm_up);
  }

  // Fast mode's collapses keep input positions, so near a tiny target the shape rule leaves
  // few collapses, and only costly ones: a CAD link of 21,376 triangles lost 94 % of its volume
  // over its last 8 triangles to 214 (mean 25 % of the diagonal; meshopt_simplify, with no
  // shape rule, 2 %). There the tail runs twice from kTailFaces, the second under the floor
  // reruns' looser shape limit (kFloorShape), and the measured deviation chooses (tail_wins).
  // Inputs up to kMaxAwareVertices: the measure reads the whole input.
  bool chooses_tail() const {
    const int32_t input = num_input - mesh.report().isolated_vertices;
    return params.keep_positions && input <= kMaxAwareVertices &&
           (params.target_triangles > 0 ? params.target_triangles : 2 * params.target_vertices) <= kTinyFitFaces;
  }
  int32_t tail_choice(std::unique_ptr<Collapser>& collapser, const double* center, double extent) {
    const bool faces = params.target_triangles > 0;
    const Collapser::Stop restart{faces ? 0 : kTailFaces / 2, faces ? kTailFaces : 0};
    const int32_t shared = collapser->run(restart);
    auto loose = std::make_unique<Collapser>(*collapser);
    std::vector<int32_t> triangles = result.triangles, corners = result.corner_source;
    loose->use_arrays(triangles, corners);
    const int32_t plain_collapses = shared + collapse_rest(*collapser, center, extent);
    loose->set_shape_limits(kFloorShape[1], Collapser::kMinTurnCos);
    loose->requeue();
    const int32_t loose_collapses = shared + collapse_rest(*loose, center, extent);
    // The measure only where the loosened tail lies nearer the input's planes.
    if (loose->quadric_error() >= collapser->quadric_error()) return plain_collapses;
    const InputSurface input(mesh, kept_input(*collapser, 1));
    const Deviation plain = surface_deviation(mesh, input, label, *collapser, result.triangles);
    const Deviation loosened = surface_deviation(mesh, input, label, *loose, triangles);
    if (!tail_wins(loosened, plain)) return plain_collapses;
    result.triangles.swap(triangles);
    result.corner_source.swap(corners);
    loose->use_arrays(result.triangles, result.corner_source);
    collapser = std::move(loose);
    return loose_collapses;
  }
  // The loosened tail wins where it stops no farther from the target and its max is smaller by
  // a larger share than its mean both ways is larger, or its max is the same and that mean
  // smaller. (Both ways: a filter housing's loosened tail at 100 triangles, as near the input's
  // vertices, bulged out to twice its volume.)
  bool tail_wins(Deviation loosened, Deviation plain) const {
    if (excess(loosened) > excess(plain)) return false;
    loosened.mean = 0.5 * (loosened.mean + loosened.back_mean);
    plain.mean = 0.5 * (plain.mean + plain.back_mean);
    if (loosened.top2 == plain.top2) return loosened.mean < plain.mean;
    return lowers_max_for_its_mean(loosened, plain);
  }

  Collapser::Stop target() const { return {params.target_vertices, params.target_triangles}; }

  // From where the collapses stand: to the target, the optional re-fit and a last clean-up.
  int32_t collapse_rest(Collapser& collapser, const double* center, double extent) {
    return collapse_rest(collapser, center, extent, target());
  }
  int32_t collapse_rest(Collapser& collapser, const double* center, double extent, Collapser::Stop stop,
                        const Collapser::FanCheck& guard = {}) {
    // A guarded run is not re-fitted either: at a few dozen vertices a cluster spans half the
    // part, and the re-fit bridged the opening the guard had kept (the fit after checks its max).
    const bool guarded = bool(guard);
    if (guarded) collapser.set_fan_check(guard);
    const int32_t collapses = collapser.run(stop);
    collapser.set_fan_check({});
    return collapses + after_run(collapser, center, extent, guarded);
  }
  // After a run to the target: the optional re-fit and a last clean-up.
  int32_t after_run(Collapser& collapser, const double* center, double extent, bool guarded = false) {
    if (params.refit && !guarded) collapser.refit(cluster_radii(collapser, center, extent));
    return collapser.remove_thin(0.0, {});
  }

  // Whether a max-aware run toward `stop` gets the far guard (kFarGuard).
  bool guards_tail(Collapser::Stop stop) const {
    const int32_t faces = stop.faces > 0 ? stop.faces : 2 * stop.vertices;
    return params.refit && faces <= kTinyFitFaces;
  }

  // The far guard's check against `input`, its bound from where `start` stands (result.triangles
  // its triangles).
  Collapser::FanCheck far_guard(const InputSurface& input, Collapser& start) const {
    const Deviation deviation = surface_deviation(mesh, input, label, start, result.triangles);
    const double floor = kFarGuardFloor * input.surface->diagonal();
    const double bound2 = std::max(kFarGuard * kFarGuard * deviation.top2, floor * floor);
    const TriangleBvh* bvh = &input.surface->bvh();
    return [bvh, bound2](const double* corners, int32_t triangles) {
      constexpr int64_t kPoints = (kGuardGrid + 1) * (kGuardGrid + 2) / 2;
      int32_t hint = -1;
      for (int32_t t = 0; t < triangles; ++t) {
        const double* c = corners + 9 * size_t(t);
        for (int64_t i = 0; i < kPoints; ++i) {
          double p[3];
          triangle_grid_point(c, c + 3, c + 6, kGuardGrid, i, p);
          const ClosestHit hit = bvh->closest(p, hint, bound2);
          if (hit.distance2 > bound2) return false;
          hint = hit.slot;
        }
      }
      return true;
    };
  }

  // Each vertex may move as far as its cluster reaches (as filtered placement allows): the
  // squared radius of each surviving cluster, normalised. (Survivors found first: the lookup
  // compresses paths, so it runs on one thread; the maxima per thread are merged after, which
  // gives the same whatever the thread count.)
  std::vector<double> cluster_radii(Collapser& collapser, const double* center, double extent) const {
    std::vector<int32_t> survivor(n);
    for (int32_t v = 0; v < n; ++v) survivor[v] = collapser.survivor(v);
    std::vector<double> radius2(n, 0.0);
    parallel_region(team_for(num_input, kParallelMin), [&](Team& team) {
      std::vector<double> mine(n, 0.0);
      team.for_static(0, num_input, [&](int32_t v) {
        if (label[v] < 0) return;
        const int32_t s = survivor[label[v]];
        const double* p = collapser.position(s);
        double d2 = 0;
        for (int i = 0; i < 3; ++i) {
          const double d = (mesh.position(v)[i] - center[i]) * (1.0 / extent) - p[i];
          d2 += d * d;
        }
        mine[s] = std::max(mine[s], d2);
      });
      team.critical([&] {
        for (int32_t v = 0; v < n; ++v) radius2[v] = std::max(radius2[v], mine[v]);
      });
    });
    return radius2;
  }

  // Compact: surviving vertices and faces in their old order, labels followed along the collapses.
  void compact(Collapser& collapser) {
    std::vector<int32_t> new_index(n, -1);
    int32_t next = 0;
    for (int32_t v = 0; v < n; ++v)
      if (collapser.vertex_alive(v)) {
        new_index[v] = next;
        result.kept[next] = result.kept[v];
        for (int i = 0; i < 3; ++i) result.vertices[3 * size_t(next) + i] = collapser.world(v)[i];
        ++next;
      }
    result.kept.resize(next);
    result.vertices.resize(3 * size_t(next));
    size_t faces = 0;
    for (size_t t = 0; t < result.face_source.size(); ++t) {
      if (!collapser.face_alive(int32_t(t))) continue;
      for (int j = 0; j < 3; ++j) {
        result.triangles[3 * faces + j] = new_index[result.triangles[3 * t + j]];
        result.corner_source[3 * faces + j] = result.corner_source[3 * t + j];
      }
      result.face_source[faces] = result.face_source[t];
      ++faces;
    }
    result.triangles.resize(3 * faces);
    result.corner_source.resize(3 * faces);
    result.face_source.resize(faces);
    final_index.resize(n);
    for (int32_t v = 0; v < n; ++v) final_index[v] = new_index[collapser.survivor(v)];
  }
};

}  // namespace

void refine_by_collapses(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params,
                         DecimateResult& result) {
  const auto start = std::chrono::steady_clock::now();
  if (params.target_vertices < 1 && !params.zero_area_only)
    throw std::invalid_argument("refine target must be at least 1 vertex, got " +
                                std::to_string(params.target_vertices));
  Refinement(mesh, layout, params, result).run();
  result.seconds_refine = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace topstoc
