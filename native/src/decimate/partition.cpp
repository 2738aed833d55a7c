#include "topstoc/decimate/partition.hpp"
#include "topstoc/core/parallel.hpp"
#include "../core/fans.hpp"
#include "link_arcs.hpp"
#include "../core/byte_flags.hpp"
#include "../core/counting_sort.hpp"
#include "../core/id_bits.hpp"
#include "../core/per_thread.hpp"
#include "../core/portable.hpp"
#include "pinched_fans.hpp"


#include <algorithm>
#include <atomic>
#include <array>
#include <climits>
#include <cmath>
#include <memory>

namespace topstoc {

namespace {

inline uint64_t pair_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

// Adds one sample per group of unreached vertices (the lowest id of each group).
void seed_unreached(const Mesh& mesh, const Clustering& c, Partition& out) {
  const int32_t n = mesh.num_vertices();
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  std::vector<uint8_t> seen(n, 0);
  std::vector<int32_t> stack;
  for (int32_t v = 0; v < n; ++v) {
    if (c.label(v) >= 0 || !mesh.in_faces(v) || seen[v]) continue;
    out.new_samples.push_back(v);
    seen[v] = 1;
    stack.push_back(v);
    while (!stack.empty()) {
      const int32_t x = stack.back();
      stack.pop_back();
      ++out.issues.unreached;
      for (int32_t i = ao[x]; i < ao[x + 1]; ++i) {
        const int32_t u = adj[i];
        if (!seen[u] && c.label(u) < 0) {
          seen[u] = 1;
          stack.push_back(u);
        }
      }
    }
  }
}

// Triangle i as seen from its lowest rank s: (b, c) such that (s, b, c) is a rotation of it.
inline std::array<int32_t, 2> rotated_from_lowest(const int32_t* t) {
  const int j = (t[0] < t[1] && t[0] < t[2]) ? 0 : (t[1] < t[2] ? 1 : 2);
  return {t[(j + 1) % 3], t[(j + 2) % 3]};
}

// Collects per-thread lists of marked clusters into one sorted, unique list.
struct Marks {
  PerThread<std::vector<int32_t>> per_thread;
  explicit Marks(int threads) : per_thread(threads) {}
  void add(int32_t s) { per_thread.mine().push_back(s); }
  void merge_into(std::vector<int32_t>& out) {
    append_and_clear(per_thread, out);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
};

// The faces around the given vertices, each once, in increasing order. The vertices (a flood's
// frontiers, scattered over the mesh) are put in vertex order first, and the faces are read back
// in face order: both walk the mesh's arrays in order instead of at random.
std::vector<int32_t> faces_around(const Mesh& mesh, const std::vector<int32_t>& vertices) {
  IdBits vertex_set(mesh.num_vertices()), face_set(mesh.num_faces());
  for (int32_t v : vertices) vertex_set.insert(v);
  vertex_set.for_each([&](int32_t v) { mesh.for_each_face(v, [&](int32_t f) { face_set.insert(f); }); });
  std::vector<int32_t> faces;
  face_set.for_each([&](int32_t f) { faces.push_back(f); });
  return faces;
}

constexpr uint8_t kUntested = 2;  // a triangle's zero-area flag before it is tested

// Samples whose link may differ from the last check's (1 per rank): the corners of every
// triangle emitted then or now but not both (both lists are in face order, so one walk
// compares them), the new samples, both samples of every feature pair whose expected copies
// changed, and those the last check named. Every other sample's link is the same triangles
// as then. Triangles emitted both times keep their zero-area flags when `sliver` is given.
std::vector<uint8_t> changed_links(const CheckState& last, const Partition& out, int32_t k,
                                   const std::vector<std::pair<uint64_t, int32_t>>& feature_pairs,
                                   std::vector<uint8_t>* sliver) {
  std::vector<uint8_t> affected(k, 0);
  std::fill(affected.begin() + last.links.samples, affected.end(), 1);
  const auto& was = last.emitted.faces;
  const auto& now = out.source_face;
  auto mark = [&](const std::vector<int32_t>& triangles, size_t i) {
    for (int j = 0; j < 3; ++j)
      if (triangles[3 * i + j] >= 0) affected[triangles[3 * i + j]] = 1;  // (-1: a sample removed since)
  };
  size_t i = 0, j = 0;
  while (i < was.size() || j < now.size()) {
    if (j == now.size() || (i < was.size() && was[i] < now[j])) {
      mark(last.emitted.triangles, i++);  // no longer emitted
    } else if (i == was.size() || now[j] < was[i]) {
      mark(out.triangles, j++);  // emitted now
    } else {
      if (std::equal(&out.triangles[3 * j], &out.triangles[3 * j] + 3, &last.emitted.triangles[3 * i])) {
        if (sliver) (*sliver)[j] = last.emitted.sliver[i];
      } else {
        mark(last.emitted.triangles, i), mark(out.triangles, j);
      }
      ++i, ++j;
    }
  }
  auto mark_pair = [&](uint64_t key) { affected[int32_t(key >> 32)] = affected[int32_t(key & 0xffffffffu)] = 1; };
  size_t a = 0, b = 0;
  const auto& then = last.links.feature_pairs;
  while (a < then.size() || b < feature_pairs.size()) {
    if (b == feature_pairs.size() || (a < then.size() && then[a].first < feature_pairs[b].first)) {
      mark_pair(then[a++].first);
    } else if (a == then.size() || feature_pairs[b].first < then[a].first) {
      mark_pair(feature_pairs[b++].first);
    } else {
      if (then[a].second != feature_pairs[b].second) mark_pair(then[a].first);
      ++a, ++b;
    }
  }
  for (int32_t s : last.links.revisit) affected[s] = 1;
  return affected;
}

// Sets sliver[i] for the triangles listed: 1 when triangle i (sample ranks) has zero area
// relative to its longest edge, else 0.
void test_slivers(const Mesh& mesh, const std::vector<int32_t>& samples, const std::vector<int32_t>& triangles,
                  const std::vector<int32_t>& listed, std::vector<uint8_t>& sliver) {
  const int64_t count = int64_t(listed.size());
  const int32_t k = int32_t(samples.size());
  // Testing many triangles, the samples' positions are gathered first, in rank order: the
  // triangles then read a compact array instead of the whole mesh's.
  std::vector<double> at;
  if (3 * count > k) {
    at.resize(3 * size_t(k));
    parallel_for(0, k, kParallelMinCostly, [&](int32_t s) {
      for (int j = 0; j < 3; ++j) at[3 * size_t(s) + j] = mesh.position(samples[s])[j];
    });
  }
  auto position = [&](int32_t s) { return at.empty() ? mesh.position(samples[s]) : &at[3 * size_t(s)]; };
  parallel_for(0, count, kParallelMin, [&](int64_t l) {
    const int32_t i = listed[l];
    const double* p[3];
    for (int j = 0; j < 3; ++j) p[j] = position(triangles[3 * size_t(i) + j]);
    double u[3], w[3], longest = 0;
    for (int a = 0; a < 3; ++a) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
    for (int j = 0; j < 3; ++j) {
      const double* q0 = p[j];
      const double* q1 = p[(j + 1) % 3];
      longest = std::max(longest, (q1[0] - q0[0]) * (q1[0] - q0[0]) + (q1[1] - q0[1]) * (q1[1] - q0[1]) +
                                      (q1[2] - q0[2]) * (q1[2] - q0[2]));
    }
    const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2], cz = u[0] * w[1] - u[1] * w[0];
    const double c2 = cx * cx + cy * cy + cz * cz;
    // Far above the bound (squared, with a margin of 2 for rounding; only where the squares
    // stay normal numbers) the square root is not needed: nearly every triangle is.
    const bool clearly_not = longest > 1e-140 && c2 > 2e-18 * longest * longest;
    sliver[i] = !clearly_not && std::sqrt(c2) <= 1e-9 * longest;
  });
}

}  // namespace

void SampleLinks::renumber(const std::vector<int32_t>& new_rank, int32_t count) {
  std::vector<int64_t> new_chi6(count, 0);
  std::vector<uint8_t> new_absorbed(count, 0), taken(count, 0);
  std::vector<int32_t> new_revisit;
  for (size_t s = 0; s < new_rank.size(); ++s) {
    const int32_t r = new_rank[s];
    if (r < 0) continue;
    new_chi6[r] = chi6[s];
    new_absorbed[r] = absorbed[s];
    taken[r] = 1;
    if (absorbed[s]) new_revisit.push_back(r);
  }
  for (int32_t r = 0; r < count; ++r)
    if (!taken[r]) new_revisit.push_back(r);
  for (int32_t s : revisit)
    if (new_rank[s] >= 0) new_revisit.push_back(new_rank[s]);
  // Ranks keep their order, so the renumbered keys stay sorted. A pair with a removed sample
  // is dropped: the other sample's link had a triangle with it, so it changed, or had none
  // (an issue the check finds from the pairs, not the links).
  auto renumbered = [&](uint64_t key) {
    const int32_t a = new_rank[int32_t(key >> 32)], b = new_rank[int32_t(key & 0xffffffffu)];
    return a < 0 || b < 0 ? uint64_t(-1) : pair_key(a, b);
  };
  size_t kept = 0;
  for (uint64_t key : seen_pairs)
    if (const uint64_t k = renumbered(key); k != uint64_t(-1)) seen_pairs[kept++] = k;
  seen_pairs.resize(kept);
  kept = 0;
  for (const auto& [key, copies] : feature_pairs)
    if (const uint64_t k = renumbered(key); k != uint64_t(-1)) feature_pairs[kept++] = {k, copies};
  feature_pairs.resize(kept);
  samples = count;
  chi6 = std::move(new_chi6);
  absorbed = std::move(new_absorbed);
  revisit = std::move(new_revisit);
}

std::vector<int64_t> cluster_euler6(const Mesh& mesh, const FeatureLayout& layout, int32_t num_samples,
                                    const Clustering& c) {
  // 6 chi = sum over the cluster's vertices of the layout's per-vertex constant, corrected by
  // the edges and faces the cluster shares with others (see FeatureLayout::chi_constant, chi_of).
  // chi_of's face term (2 per face around the vertex) less the correction of the faces shared
  // leaves 6 per face all of whose corners lie in the cluster: counted so, no vertex's faces
  // are walked.
  std::vector<int64_t> chi6(num_samples, 0);
  auto label = [&c](int32_t v) { return c.label(v); };
  const auto& ao = mesh.adjacency_offsets();
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    if (label(v) < 0) continue;
    chi6[label(v)] += layout.chi_constant.empty() ? 6 * layout.sectors_of(mesh, v) - 3 * (ao[v + 1] - ao[v])
                                                  : layout.chi_constant[v] - 2 * mesh.face_count(v);
  }
  const auto& faces = mesh.faces();
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t la = label(faces[3 * size_t(f)]), lb = label(faces[3 * size_t(f) + 1]),
                  lc = label(faces[3 * size_t(f) + 2]);
    if (la >= 0 && la == lb && lb == lc) chi6[la] += 6;
  }
  // Each edge between two clusters once, from its lower end (from the adjacency: the faces of
  // each edge are a table of their own, not built for this).
  const auto& adj = mesh.adjacency();
  const int32_t* ae = layout.feature_edges.empty() ? nullptr : mesh.adjacency_edge().data();
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
      const int32_t u = adj[i];
      if (u < v || label(u) == label(v)) continue;
      const int32_t copies = ae ? layout.edge_copies(mesh, ae[i]) : 1;
      chi6[label(v)] += 3 * copies, chi6[label(u)] += 3 * copies;
    }
  return chi6;
}

namespace {

// One arc of a sample's link: triangle (s, from, to) around sample s.
struct Arc {
  int32_t from, to, triangle;
};

// One run of check_partition: its inputs, what the last check carried, and what each stage
// leaves for the next. The stages run in the order of run().
class PartitionCheck {
 public:
  PartitionCheck(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                 const Clustering& c, const std::vector<uint8_t>& required, bool check_slivers,
                 const std::vector<int32_t>* candidate_faces, CheckState* state)
      : mesh(mesh), layout(layout), samples(samples), c(c), required(required), check_slivers(check_slivers),
        candidate_faces(candidate_faces), state(state), carried(state ? *state : local), n(mesh.num_vertices()),
        k(static_cast<int32_t>(samples.size())), m(mesh.num_faces()), threads(max_threads()),
        faces(mesh.faces()), flips(mesh.winding_flips()), marks(threads) {}

  Partition run() {
    choose_faces_to_test();
    if (!all_reached()) {
      seed_unreached(mesh, c, out);
      carried.emitted_valid = carried.links_valid = false;
      return std::move(out);
    }
    retest_faces();
    if (patch) patch_triangles();
    else write_emitting_faces();
    emitted = static_cast<int32_t>(out.source_face.size());
    collect_feature_pairs();
    choose_samples_to_evaluate();
    build_arcs();
    evaluate_links();
    settle_repeated_triangles();
    count_link_issues();
    if (check_slivers) find_slivers();
    if (state) carry_links();
    if (any_dropped) drop_pillows();
    check_euler();
    check_closed_curves();
    check_boundary_loops();
    std::sort(out.split_clusters.begin(), out.split_clusters.end());
    out.split_clusters.erase(std::unique(out.split_clusters.begin(), out.split_clusters.end()),
                             out.split_clusters.end());
    return std::move(out);
  }

 private:
  const Mesh& mesh;
  const FeatureLayout& layout;
  const std::vector<int32_t>& samples;
  const Clustering& c;
  const std::vector<uint8_t>& required;
  const bool check_slivers;
  const std::vector<int32_t>* candidate_faces;
  CheckState* state;
  CheckState local;
  CheckState& carried;  // what the last check left, and what this one leaves
  const int32_t n, k, m;
  const int threads;
  const Buffer<int32_t>& faces;
  const std::vector<uint8_t>& flips;  // Mesh::winding_flips()
  Partition out;
  Marks marks;

  // Which faces are tested (choose_faces_to_test).
  bool test_all = false, patch = false;
  int team = 1;
  // The faces re-tested around the changed vertices (increasing), and those that emit now.
  std::vector<int32_t> retested, fresh_faces, fresh_triangles;
  // Zero-area flags of the triangles taken over (a triangle is the same three vertices), when
  // the last check tested them; the re-tested faces' triangles are tested below.
  std::vector<uint8_t> kept_sliver;
  bool keep_slivers = false;
  int32_t emitted = 0;
  // Clusters adjacent along a feature curve, with the copies of their edge, sorted by key; a
  // sample's pairs with higher samples start at pair_rows[sample].
  std::vector<std::pair<uint64_t, int32_t>> feature_pairs;
  std::vector<int32_t> pair_rows;
  // The samples to evaluate.
  bool incremental = false;
  std::vector<uint8_t> sliver;  // per emitted triangle: 0, 1 or kUntested
  std::vector<uint8_t> affected;
  std::vector<int32_t> todo;
  // The arcs of the evaluated samples' links, per sample.
  std::vector<int32_t> arc_offsets;
  std::unique_ptr<Arc[]> arcs;
  // What the links gave.
  std::vector<int64_t> chi6_out;
  std::vector<uint8_t> drop;
  bool any_dropped = false;  // drop is read only once pillows are dropped
  PerThread<std::vector<uint64_t>> seen_pairs{threads};
  PerThread<std::vector<int32_t>> repeated_lists{threads}, named_lists{threads};
  int32_t bad_link = 0, bad_edge = 0, isolated = 0;
  std::vector<uint64_t> seen;

  int32_t label(int32_t v) const { return c.label(v); }
  // A face's corners' labels in its component's consistent winding: the emitted triangle.
  std::array<int32_t, 3> corner_labels(int32_t f) const {
    return {label(faces[3 * size_t(f)]), label(faces[3 * size_t(f) + winding_slot(flips, f, 1)]),
            label(faces[3 * size_t(f) + winding_slot(flips, f, 2)])};
  }
  static uint8_t distinct(const std::array<int32_t, 3>& l) {
    return uint8_t(l[0] != l[1] && l[1] != l[2] && l[2] != l[0]);
  }
  uint8_t three_clusters(int32_t f) const { return distinct(corner_labels(f)); }
  int32_t incident(int32_t s) const { return arc_offsets[s + 1] - arc_offsets[s]; }

  // --- emit: faces whose corners lie in three clusters ------------------------------------------

  // Every face is tested (a first check), or only those around relabelled vertices (later
  // rounds) or the candidates (fast path). Then the emitting faces are written in face order.
  // Re-testing the faces around many changed vertices, scattered over the mesh, costs more
  // than testing every face in order: beyond a sixteenth of the vertices, every face is tested.
  void choose_faces_to_test() {
    if (carried.valid && int64_t(carried.changed.size()) > n / 16) carried.valid = false;
    test_all = !carried.valid && !candidate_faces;
    // Re-testing around changed vertices with the last check's triangles known: every other
    // face keeps its corners' labels, so only the re-tested faces' triangles are written anew.
    patch = !test_all && carried.valid && carried.emitted_valid;
    team = m >= kParallelMin ? threads : 1;
  }

  // Vertices in a face but in no cluster stop the check here: the other checks need every
  // vertex in a cluster. Testing every face reads every such vertex's label and notes them on
  // the way (the emits then hold for this clustering, as after any test); otherwise the
  // vertices are scanned: only the changed ones when the last check got past this test (its
  // triangles are known only then).
  bool all_reached() {
    int unreached = 0;
    if (patch) {
      for (int32_t v : carried.changed)
        if (label(v) < 0 && mesh.in_faces(v)) unreached = 1;
    } else if (test_all) {
      carried.emits.resize(m);
      uint8_t* emits = carried.emits.data();
      unreached = parallel_reduce(
          0, m, parallel_if(team > 1), 0,
          [&](int& any, int32_t f) {
            const auto l = corner_labels(f);
            emits[f] = distinct(l);
            any |= (l[0] | l[1] | l[2]) < 0;
          },
          [](int& any, int part) { any |= part; });
      carried.valid = true;
      carried.changed.clear();
    } else {
      unreached = parallel_reduce(
          0, n, kParallelMin, 0,
          [&](int& any, int32_t v) {
            if (label(v) < 0 && mesh.in_faces(v)) any = 1;
          },
          [](int& any, int part) { any |= part; });
    }
    return !unreached;
  }

  // Tests the faces around the changed vertices, or the candidates; notes the re-tested faces
  // that emit now when the last check's triangles are patched.
  void retest_faces() {
    keep_slivers = patch && check_slivers && carried.emitted.slivers_checked &&
                   carried.emitted.sliver.size() == carried.emitted.faces.size();
    if (!test_all && carried.valid) {
      retested = faces_around(mesh, carried.changed);
      for (int32_t f : retested) {
        const auto l = corner_labels(f);
        carried.emits[f] = distinct(l);
        if (!patch || !carried.emits[f]) continue;
        fresh_faces.push_back(f);
        fresh_triangles.insert(fresh_triangles.end(), l.begin(), l.end());
      }
    } else if (candidate_faces) {
      carried.emits.assign(m, 0);
      const int64_t count = int64_t(candidate_faces->size());
      parallel_for(0, count, kParallelMin, [&](int64_t i) {
        carried.emits[(*candidate_faces)[i]] = three_clusters((*candidate_faces)[i]);
      });
    }
    carried.valid = true;
    carried.changed.clear();
  }

  // The last check's triangles without the re-tested faces, merged with the re-tested faces
  // that emit now (all three lists increasing).
  void patch_triangles() {
    const auto& was_faces = carried.emitted.faces;
    const auto& was_triangles = carried.emitted.triangles;
    const size_t was = was_faces.size(), fresh = fresh_faces.size(), count = retested.size();
    out.source_face.resize(was + fresh);
    out.triangles.resize(3 * (was + fresh));
    if (keep_slivers) kept_sliver.resize(was + fresh);
    size_t i = 0, e = 0, r = 0, at = 0;
    auto put = [&](int32_t f, const int32_t* t, uint8_t flag) {
      out.source_face[at] = f;
      if (keep_slivers) kept_sliver[at] = flag;
      std::copy(t, t + 3, &out.triangles[3 * at++]);
    };
    while (i < was || e < fresh) {
      if (e == fresh || (i < was && was_faces[i] < fresh_faces[e])) {
        const int32_t f = was_faces[i];
        while (r < count && retested[r] < f) ++r;
        if (r == count || retested[r] != f)  // not re-tested: unchanged
          put(f, &was_triangles[3 * i], keep_slivers ? carried.emitted.sliver[i] : kUntested);
        ++i;
      } else {
        if (i < was && was_faces[i] == fresh_faces[e]) ++i;  // emitted then and now: the new labels
        put(fresh_faces[e], &fresh_triangles[3 * e], kUntested);
        ++e;
      }
    }
    out.source_face.resize(at);
    out.triangles.resize(3 * at);
    if (keep_slivers) kept_sliver.resize(at);
  }

  // Every emitting face, in face order: each thread counts those of its run of faces (static
  // schedule, the same runs in both loops) and writes them from where the runs before it end.
  // Eight faces at a time (a tenth of them emit at most); the last few faces after the whole
  // words are appended at the end.
  void write_emitting_faces() {
    const uint8_t* emits = carried.emits.data();
    const int64_t words = m / 8;
    auto write = [&](int64_t at, int32_t f) {
      out.source_face[at] = f;
      for (int j = 0; j < 3; ++j) out.triangles[3 * at + j] = label(faces[3 * size_t(f) + winding_slot(flips, f, j)]);
    };
    int64_t tail = 0;
    for (int32_t f = int32_t(8 * words); f < m; ++f) tail += emits[f];
    std::vector<int64_t> run_start(team + 1, 0);
    parallel_region(team, [&](Team& running) {
      const int me = running.index();
      int64_t mine = 0;
      running.for_static(0, words, [&](int64_t w) { mine += flag_count(flag_word(emits + 8 * w)); });
      run_start[me + 1] = mine;
      running.barrier();
      running.single([&] {
        for (int r = 0; r < running.size(); ++r) run_start[r + 1] += run_start[r];
        out.source_face.resize(run_start[running.size()] + tail);
        out.triangles.resize(3 * out.source_face.size());
      });
      int64_t at = run_start[me];
      running.for_static(0, words, [&](int64_t w) {
        const uint64_t word = flag_word(emits + 8 * w);
        if (!word) return;
        for (uint32_t bits = flag_bits(word); bits; bits &= bits - 1) write(at++, int32_t(8 * w + lowest_bit(bits)));
      });
    });
    for (int64_t f = 8 * words, at = int64_t(out.source_face.size()) - tail; f < m; ++f)
      if (emits[f]) write(at++, int32_t(f));
  }

  // --- feature pairs: clusters adjacent along a feature curve, with the copies of their edge ---
  // Grouped by the lower sample (a counting sort), each group put in order and its repeats
  // summed: the same sorted list a map would give, without a node per pair.
  void collect_feature_pairs() {
    if (layout.feature_edges.empty()) return;  // (the edge table is built on first use: not for this)
    const auto& ev = mesh.edge_vertices();
    struct Crossing {
      int32_t lower, higher, copies;
    };
    std::vector<Crossing> crossing;
    for (int32_t e : layout.feature_edges) {
      const int32_t lx = label(ev[2 * size_t(e)]), ly = label(ev[2 * size_t(e) + 1]);
      if (lx != ly) crossing.push_back({std::min(lx, ly), std::max(lx, ly), layout.edge_copies(mesh, e)});
    }
    if (crossing.empty()) return;
    std::vector<std::pair<int32_t, int32_t>> higher(crossing.size());  // per pair: higher sample, copies
    std::vector<int32_t> start;
    stable_counting_sort(
        int64_t(crossing.size()), k, [&](int64_t i) { return crossing[i].lower; },
        [&](int64_t i, int32_t at) { higher[at] = {crossing[i].higher, crossing[i].copies}; }, start);
    pair_rows.assign(size_t(k) + 1, 0);
    feature_pairs.reserve(higher.size());
    for (int32_t s = 0; s < k; ++s) {
      pair_rows[s] = int32_t(feature_pairs.size());
      std::sort(higher.begin() + start[s], higher.begin() + start[s + 1]);
      for (int32_t i = start[s]; i < start[s + 1]; ++i) {
        const uint64_t key = pair_key(s, higher[i].first);
        if (!feature_pairs.empty() && feature_pairs.back().first == key) feature_pairs.back().second += higher[i].second;
        else feature_pairs.push_back({key, higher[i].second});
      }
    }
    pair_rows[k] = int32_t(feature_pairs.size());
  }

  // The copies expected along the feature pair (s, nb), or nullptr when they are no pair.
  const std::pair<uint64_t, int32_t>* feature_pair(int32_t s, int32_t nb) const {
    if (feature_pairs.empty()) return nullptr;
    const uint64_t key = pair_key(s, nb);
    const auto first = feature_pairs.begin() + pair_rows[std::min(s, nb)];
    const auto last = feature_pairs.begin() + pair_rows[std::min(s, nb) + 1];
    const auto it = std::lower_bound(first, last, key, [](const auto& p, uint64_t x) { return p.first < x; });
    return it != last && it->first == key ? &*it : nullptr;
  }

  // --- the samples to evaluate ------------------------------------------------------------------
  // All of them, or after a repair round or a flood update (a slider frame) only those whose
  // link may have changed; the others keep what the last check found. Unchanged triangles keep
  // their zero-area flags too.
  void choose_samples_to_evaluate() {
    incremental = carried.links_valid && carried.emitted_valid && carried.links.samples <= k;
    if (keep_slivers) sliver = std::move(kept_sliver);
    else if (check_slivers) sliver.assign(emitted, kUntested);
    affected = incremental ? changed_links(carried, out, k, feature_pairs,
                                           check_slivers && carried.emitted.slivers_checked ? &sliver : nullptr)
                           : std::vector<uint8_t>(k, 1);
    for (int32_t s = 0; s < k; ++s)
      if (affected[s]) todo.push_back(s);
  }

  // --- the arcs of each sample's link ---------------------------------------------------------
  // Triangle (a, b, c) gives a the arc b -> c, b the arc c -> a and c the arc a -> b. Stored per
  // sample in one array, so that evaluating a sample reads one short contiguous run. Only the
  // samples to evaluate get their arcs. Serial: a parallel counting sort cost more per thread
  // than this whole loop (each sample has few arcs).
  void build_arcs() {
    arc_offsets.assign(k + 1, 0);
    for (int32_t x : out.triangles) arc_offsets[x + 1] += affected[x];
    for (int32_t s = 0; s < k; ++s) arc_offsets[s + 1] += arc_offsets[s];
    // Not value-initialised: the loop below writes every arc, and zeroing them first is a
    // serial pass over the whole array.
    arcs.reset(new Arc[size_t(arc_offsets[k])]);
    std::vector<int32_t> fill(arc_offsets.begin(), arc_offsets.end() - 1);
    for (int32_t i = 0; i < emitted; ++i) {
      const int32_t* t = &out.triangles[3 * size_t(i)];
      if (affected[t[0]]) arcs[fill[t[0]]++] = {t[1], t[2], i};
      if (affected[t[1]]) arcs[fill[t[1]]++] = {t[2], t[0], i};
      if (affected[t[2]]) arcs[fill[t[2]]++] = {t[0], t[1], i};
    }
  }

  // --- per sample: one oriented fan, expected edge multiplicities, Euler contributions ----------
  // Each triangle (s, a, b) around sample s is an arc a -> b of s's link. Six times a component's
  // Euler characteristic is the sum over its samples of 6 - 3 (neighbours) + 2 (triangles),
  // counting only samples that keep a triangle. A triangle emitted twice shows up as a repeated
  // or reversed arc; such samples are set aside and settled after the pass (see below).
  void evaluate_links() {
    // The last check's values are taken over (new samples start at 0) and handed back below.
    if (incremental) chi6_out = std::move(carried.links.chi6);
    chi6_out.resize(k, 0);
    out.absorbed.assign(k, 0);
    if (incremental) {
      std::copy(carried.links.absorbed.begin(), carried.links.absorbed.end(), out.absorbed.begin());
      for (int32_t s : todo) chi6_out[s] = 0, out.absorbed[s] = 0;
    }
    drop.assign(emitted, 0);
    if (incremental)  // the pairs seen by samples not evaluated again (a pair is seen from its lower rank)
      for (uint64_t key : carried.links.seen_pairs)
        if (!affected[int32_t(key >> 32)]) seen_pairs[0].push_back(key);
    int32_t links = 0, edges = 0, lonely = 0;
    const int64_t evaluated = int64_t(todo.size());
    std::atomic<int64_t> next_sample{0};
    parallel_region(team_for(evaluated, kParallelMinCostly), [&](Team& running) {
      LinkArcs link;
      auto& seen_here = seen_pairs.mine();
      auto& repeated = repeated_lists.mine();
      auto& named = named_lists.mine();
      int32_t my_links = 0, my_edges = 0, my_lonely = 0;
      running.for_dynamic(next_sample, evaluated, 256, [&](int64_t i) {
        const int32_t s = todo[i], issues_before = my_links + my_edges + my_lonely;
        if (!evaluate(s, link, seen_here, my_links, my_edges, my_lonely))
          repeated.push_back(s);
        else if (my_links + my_edges + my_lonely != issues_before)
          named.push_back(s);
      });
      running.critical([&] { links += my_links, edges += my_edges, lonely += my_lonely; });
    });
    bad_link = links, bad_edge = edges, isolated = lonely;
  }

  // Evaluates sample s's link; returns false (and changes nothing) when it repeats a triangle.
  bool evaluate(int32_t s, LinkArcs& link, std::vector<uint64_t>& seen_here, int32_t& links, int32_t& edges,
                int32_t& lonely) {
    // Most samples: inside a surface, one closed fan, no pillow. Then every neighbour's edge
    // has two triangles, and only feature pairs expect something else.
    const Arc* around = arcs.get() + arc_offsets[s];
    if (!any_dropped && mesh.manifold_vertex()[samples[s]] && one_cycle(around, incident(s))) {
      chi6_out[s] = 6 - incident(s);  // 6 - 3 neighbours + 2 triangles, as many of each
      if (!feature_pairs.empty())
        for (int32_t i = 0; i < incident(s); ++i) check_edge(s, around[i].from, 2, seen_here, edges);
      return true;
    }
    link.clear();
    for (int32_t i = arc_offsets[s]; i < arc_offsets[s + 1]; ++i)
      if (!any_dropped || !drop[arcs[i].triangle]) link.add(arcs[i].from, arcs[i].to);
    if (link.repeated()) return false;
    if (link.arcs == 0) {
      // No triangle: the neighbours absorbed this cluster (the pillow case) unless the sample
      // must stay. The Euler characteristic check confirms the topology either way.
      if ((!required.empty() && required[samples[s]]) || layout.is_corner(samples[s])) {
        ++lonely;
        marks.add(s);
      } else {
        out.absorbed[s] = 1;
      }
      return true;
    }
    chi6_out[s] = 6 - 3 * int64_t(link.neighbours.size()) + 2 * int64_t(link.arcs);
    for (const auto& nb : link.neighbours) check_edge(s, nb.id, nb.in + nb.out, seen_here, edges);
    if (mesh.manifold_vertex()[samples[s]] && !link.single_fan()) {
      ++links;
      marks.add(s);
    } else if (!mesh.manifold_vertex()[samples[s]] && !pinched_link_kept(s, link)) {
      // A pinched vertex (a bowtie's centre) keeps one fan per fan of the input; with one
      // lost, a whole wing is gone although the Euler characteristic may not show it.
      ++links;
      marks.add(s);
      for (const auto& nb : link.neighbours) marks.add(nb.id);
    }
    return true;
  }

  // The edge between sample s and its neighbour nb (each pair once, from its lower rank) has
  // `triangles` triangles: two inside a surface, a feature pair's copies along a curve.
  void check_edge(int32_t s, int32_t nb, int32_t triangles, std::vector<uint64_t>& seen_here, int32_t& edges) {
    if (nb < s) return;
    int32_t expected = 2;
    if (const auto* it = feature_pair(s, nb)) {
      expected = it->second;
      seen_here.push_back(it->first);
    }
    if (triangles != expected) {
      ++edges;
      marks.add(s), marks.add(nb);
    }
  }

  // Fans of the input around v, nothing blocked.
  int32_t input_fan_count(int32_t v) const {
    std::vector<int32_t> fan_of_slot;
    return vertex_fans(mesh, v, [](int32_t) { return false; }, fan_of_slot);
  }

  // At a pinched sample each input fan must come out as a fan of its own sheet: the arcs from
  // one sheet's faces form that sheet's fans (as many open and closed), and no fan mixes
  // sheets. Counting the fans alone let a small wing vanish while another wing, split at the
  // pinch, made up the count.
  bool pinched_link_kept(int32_t s, const LinkArcs& link) const {
    const int32_t v = samples[s];
    if (layout.vertex_pinched.empty() || !layout.vertex_pinched[v]) return link.fans() == input_fan_count(v);
    const auto fans = input_fans(mesh, layout.face_sheet, v);
    if (link.fans() != int32_t(fans.size())) return false;
    std::vector<int32_t> sheets;
    for (const Fan& f : fans) sheets.push_back(f.sheet);
    std::sort(sheets.begin(), sheets.end());
    sheets.erase(std::unique(sheets.begin(), sheets.end()), sheets.end());
    LinkArcs part;
    int32_t arcs_on_sheets = 0;
    for (int32_t sheet : sheets) {
      part.clear();
      for (int32_t i = arc_offsets[s]; i < arc_offsets[s + 1]; ++i)
        if ((!any_dropped || !drop[arcs[i].triangle]) && layout.face_sheet[out.source_face[arcs[i].triangle]] == sheet)
          part.add(arcs[i].from, arcs[i].to);
      arcs_on_sheets += part.arcs;
      if (part.repeated()) return false;
      int32_t open = 0, closed = 0, paths = 0;
      for (const Fan& f : fans)
        if (f.sheet == sheet) ++(f.closed ? closed : open);
      for (const auto& nb : part.neighbours) paths += nb.in == 0;
      if (paths != open || part.fans() - paths != closed) return false;
    }
    return arcs_on_sheets == link.arcs;
  }

  // --- repeated triangles: pillows and duplicates ------------------------------------------------
  // A small cluster can sit between two others that wrap around it, touching it along its whole
  // border: their triangle is emitted twice, facing opposite ways, and the small cluster has no
  // other triangle. Dropping both copies gives the nerve of the partition in which the small
  // cluster joined its neighbours, so no sample is needed. Any other repeat is an issue. Every
  // sample of a repeated triangle sees the repeat in its link, so the set-aside samples hold
  // all of them; they are evaluated again once the pillows are gone.
  void settle_repeated_triangles() {
    std::vector<int32_t> repeated;
    for (int t = 0; t < threads; ++t) repeated.insert(repeated.end(), repeated_lists[t].begin(), repeated_lists[t].end());
    std::sort(repeated.begin(), repeated.end());
    if (repeated.empty()) return;
    drop_opposite_pairs(repeated);
    // A sample whose link still repeats an arc is not a manifold vertex of the output: an
    // edge with four triangles (two tetrahedra sharing an edge) or a triangle left twice. It
    // must count as an issue: its Euler contribution was never added, and leaving both out
    // can make the characteristic come out right by accident (a torus as a ring of
    // tetrahedra), so without the count such an output passed every check.
    LinkArcs link;
    for (int32_t s : repeated)
      if (!evaluate(s, link, seen_pairs[0], bad_link, bad_edge, isolated)) {
        marks.add(s);
        // A non-manifold input edge kept as a feature legitimately has more than two triangles.
        bool expected = false;
        for (const auto& nb : link.neighbours)
          if (nb.in > 1 || nb.out > 1) {
            const auto* it = feature_pair(s, nb.id);
            if (it && it->second > 2) expected = true;
          }
        if (expected) continue;
        ++bad_link;
        for (const auto& nb : link.neighbours)
          if (nb.in > 1 || nb.out > 1) marks.add(nb.id);  // the other end of the crowded edge
      }
  }

  // The triangles the repeating samples emit, grouped by their corners: opposite pairs around
  // an absorbed cluster are dropped (pillows), any other group is a duplicate.
  void drop_opposite_pairs(const std::vector<int32_t>& repeated) {
    std::vector<std::pair<std::array<int32_t, 3>, int32_t>> keyed;  // sorted triple, triangle
    for (int32_t s : repeated)
      for (int32_t i = arc_offsets[s]; i < arc_offsets[s + 1]; ++i) {
        const int32_t* t = &out.triangles[3 * size_t(arcs[i].triangle)];
        if (std::min({t[0], t[1], t[2]}) != s) continue;  // each triangle from its lowest sample
        std::array<int32_t, 3> key = {t[0], t[1], t[2]};
        std::sort(key.begin(), key.end());
        keyed.push_back({key, arcs[i].triangle});
      }
    std::sort(keyed.begin(), keyed.end());
    for (size_t a = 0; a < keyed.size();) {
      size_t b = a;
      while (b < keyed.size() && keyed[b].first == keyed[a].first) ++b;
      if (b - a >= 2) {
        const int32_t* t0 = &out.triangles[3 * size_t(keyed[a].second)];
        const int32_t* t1 = &out.triangles[3 * size_t(keyed[a + 1].second)];
        const bool opposite = b - a == 2 && rotated_from_lowest(t0)[0] == rotated_from_lowest(t1)[1];
        const bool absorbs = incident(t0[0]) == 2 || incident(t0[1]) == 2 || incident(t0[2]) == 2;
        if (opposite && absorbs) {
          ++out.issues.pillows;
          drop[keyed[a].second] = drop[keyed[a + 1].second] = 1;
          any_dropped = true;
        } else {
          ++out.issues.duplicate;
          for (int j = 0; j < 3; ++j) marks.add(t0[j]);
        }
      }
      a = b;
    }
  }

  // The links' issue counts, and feature pairs without a triangle between them: the border
  // between them collapsed.
  void count_link_issues() {
    out.issues.bad_link = bad_link;
    out.issues.bad_edge = bad_edge;
    out.issues.isolated = isolated;
    // Counted over every sample: those not evaluated again keep theirs.
    out.issues.absorbed = int32_t(std::count(out.absorbed.begin(), out.absorbed.end(), uint8_t(1)));
    append_and_clear(seen_pairs, seen);
    std::sort(seen.begin(), seen.end());
    for (const auto& [key, copies] : feature_pairs)
      if (!std::binary_search(seen.begin(), seen.end(), key)) {
        ++out.issues.bad_edge;
        marks.add(int32_t(key >> 32)), marks.add(int32_t(key & 0xffffffffu));
      }
  }

  // --- triangles of zero area (collinear samples) ------------------------------------------------
  void find_slivers() {
    std::vector<int32_t> untested;
    for (int32_t i = 0; i < emitted; ++i)
      if (sliver[i] == kUntested) untested.push_back(i);
    test_slivers(mesh, samples, out.triangles, untested, sliver);
    for (int32_t i = 0; i < emitted; ++i)
      if (sliver[i] && !(any_dropped && drop[i])) {
        ++out.issues.sliver;
        for (int j = 0; j < 3; ++j) out.split_clusters.push_back(out.triangles[3 * size_t(i) + j]);
      }
  }

  // What the next round's check starts from: the triangles before pillows are dropped (a
  // pillow's samples are evaluated again anyway), and what each sample's link gave.
  void carry_links() {
    carried.emitted_valid = carried.links_valid = true;
    carried.links.samples = k;
    carried.emitted.faces = out.source_face;
    carried.emitted.triangles = out.triangles;
    carried.emitted.sliver = std::move(sliver);
    carried.emitted.slivers_checked = check_slivers;
    carried.links.absorbed = out.absorbed;
    carried.links.revisit.clear();
    append_and_clear(repeated_lists, carried.links.revisit);
    append_and_clear(named_lists, carried.links.revisit);
    carried.links.seen_pairs = std::move(seen);
    carried.links.feature_pairs = std::move(feature_pairs);
  }

  // Dropped pillows leave the output.
  void drop_pillows() {
    int32_t kept = 0;
    for (int32_t i = 0; i < emitted; ++i) {
      if (drop[i]) continue;
      for (int j = 0; j < 3; ++j) out.triangles[3 * size_t(kept) + j] = out.triangles[3 * size_t(i) + j];
      out.source_face[kept++] = out.source_face[i];
    }
    out.triangles.resize(3 * size_t(kept));
    out.source_face.resize(kept);
  }

  // --- Euler characteristic per component -------------------------------------------------------
  // A component that lost all its triangles fails too (a torus has chi = 0 with or without).
  // (Triangles are counted by their first corner's sample: its component is the face's, and
  // the samples' components are k reads instead of a face and a vertex far apart per triangle.)
  void check_euler() {
    const int32_t num_components = mesh.num_components();
    std::vector<int64_t> component_chi6(num_components, 0);
    std::vector<int32_t> component_triangles(num_components, 0), sample_component(k);
    for (int32_t s = 0; s < k; ++s) {
      sample_component[s] = mesh.component()[samples[s]];
      component_chi6[sample_component[s]] += chi6_out[s];
    }
    if (state) carried.links.chi6 = std::move(chi6_out);  // for the next round's check
    for (size_t i = 0; i < out.source_face.size(); ++i) ++component_triangles[sample_component[out.triangles[3 * i]]];
    std::vector<uint8_t> failing(num_components, 0);
    for (int32_t comp = 0; comp < num_components; ++comp)
      if (component_chi6[comp] != 6 * mesh.component_euler()[comp] || component_triangles[comp] == 0) {
        failing[comp] = 1;
        ++out.issues.bad_component;
      }
    marks.merge_into(out.split_clusters);
    if (out.issues.bad_component > 0 && out.issues.topological() == out.issues.bad_component)
      blame_non_disks(failing);
  }

  // Only the Euler characteristic names a problem: find the clusters that are not disks.
  void blame_non_disks(const std::vector<uint8_t>& failing) {
    const auto chi6 = cluster_euler6(mesh, layout, k, c);
    for (int32_t s = 0; s < k; ++s)
      if (failing[mesh.component()[samples[s]]] && chi6[s] != 6 * int64_t(layout.sectors_of(mesh, samples[s]))) {
        ++out.issues.non_disk;
        out.split_clusters.push_back(s);
      }
    if (out.issues.non_disk > 0) return;
    // Nothing local to blame: split the widest cluster of each failing component.
    std::vector<int32_t> widest(mesh.num_components(), -1);
    for (int32_t v = 0; v < n; ++v) {
      const int32_t comp = mesh.component()[v];
      if (label(v) < 0 || !failing[comp]) continue;
      if (widest[comp] < 0 || c.dist(v) > c.dist(widest[comp])) widest[comp] = v;
    }
    for (int32_t v : widest)
      if (v >= 0) out.new_samples.push_back(v);
  }

  // --- closed feature curves need three clusters to stay loops ---------------------------------
  void check_closed_curves() {
    for (int32_t curve = 0; curve < layout.num_curves(); ++curve) {
      if (!layout.curve_closed[curve]) continue;
      const int32_t b = layout.curve_offsets[curve], e = layout.curve_offsets[curve + 1];
      int32_t changes = 0, farthest = -1;
      for (int32_t i = b; i < e; ++i) {
        const int32_t v = layout.curve_vertices[i];
        const int32_t w = layout.curve_vertices[i + 1 < e ? i + 1 : b];
        changes += label(v) != label(w);
        if (c.dist(v) > 0 && (farthest < 0 || c.dist(v) > c.dist(farthest))) farthest = v;
      }
      if (changes < 3) {
        ++out.issues.short_loop;
        if (farthest >= 0) out.new_samples.push_back(farthest);
      }
    }
  }

  // --- boundary loops need three clusters too ---------------------------------------------------
  // Corners (e.g. where creases meet a hole) split a boundary loop into open curves, which the
  // closed-curve check above does not see: a hole met by only two clusters closes up (two
  // boundary curves become one interior edge), and only the Euler characteristic noticed it,
  // with nothing local to split.
  void check_boundary_loops() {
    const int32_t boundary_loops = int32_t(layout.boundary_loop_offsets.size()) - 1;
    for (int32_t loop = 0; loop < boundary_loops; ++loop) {
      const int32_t b = layout.boundary_loop_offsets[loop], e = layout.boundary_loop_offsets[loop + 1];
      int32_t met[3] = {-1, -1, -1}, count = 0, farthest = -1;
      for (int32_t i = b; i < e; ++i) {
        const int32_t v = layout.boundary_loop_vertices[i];
        const int32_t l = label(v);
        if (count < 3 && l != met[0] && l != met[1] && l != met[2]) met[count++] = l;
        if (c.dist(v) > 0 && (farthest < 0 || c.dist(v) > c.dist(farthest))) farthest = v;
      }
      if (count < 3 && e - b >= 3) {
        ++out.issues.short_loop;
        if (farthest >= 0) out.new_samples.push_back(farthest);
      }
    }
  }
};

}  // namespace

Partition check_partition(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                          const Clustering& c, const std::vector<uint8_t>& required, bool check_slivers,
                          const std::vector<int32_t>* candidate_faces, CheckState* state) {
  return PartitionCheck(mesh, layout, samples, c, required, check_slivers, candidate_faces, state).run();
}

}  // namespace topstoc
