#include "topstoc/decimate/decimate.hpp"
#include "topstoc/core/buffer.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/core/progress.hpp"


#include <algorithm>
#include <unordered_set>
#include <chrono>
#include <exception>
#include <memory>
#include <cmath>
#include <stdexcept>
#include <string>

#include "topstoc/decimate/clustering.hpp"
#include "topstoc/decimate/flood_cache.hpp"
#include "decimate/collapser.hpp"
#include "decimate/placement.hpp"
#include "decimate/refine.hpp"
#include "../core/per_thread.hpp"

namespace topstoc {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Rounds in which zero-area triangles are still repaired; after that they are only counted
// (an input with collinear vertices may not allow removing them all).
constexpr int32_t kSliverRounds = 8;
// Rounds of splitting the widest clusters to make up for absorbed ones (see cluster_and_emit).
constexpr int32_t kMaxTopUpRounds = 12;
constexpr int32_t kSmallTopUp = 3;       // top-ups this small may be undone and retried
constexpr size_t kMaxTopUpRetries = 12;  // clusters tried for them

void accumulate(PartitionIssues& into, const PartitionIssues& add) {
  into.unreached += add.unreached;
  into.non_disk += add.non_disk;
  into.bad_edge += add.bad_edge;
  into.duplicate += add.duplicate;
  into.bad_link += add.bad_link;
  into.short_loop += add.short_loop;
  into.isolated += add.isolated;
  into.sliver += add.sliver;
  into.bad_component += add.bad_component;
  into.pillows += add.pillows;
  into.absorbed += add.absorbed;
}

// New samples that split the given clusters: the vertex farthest from the cluster's sample,
// avoiding vertices the user excluded (u = -1) while others exist; lowest id on ties. A cluster
// of one vertex cannot split, so its neighbouring clusters split instead.
std::vector<int32_t> splitting_vertices(const Mesh& mesh, const Clustering& c, const std::vector<int32_t>& samples,
                                        const std::vector<int32_t>& clusters, const std::vector<uint8_t>& avoid) {
  const int32_t n = mesh.num_vertices();
  const int32_t num_samples = static_cast<int32_t>(samples.size());
  std::vector<int32_t> result;
  std::vector<uint8_t> wanted(num_samples, 0);
  for (int32_t s : clusters) wanted[s] = 1;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int32_t> best(num_samples, -1);
    auto better = [&](int32_t v, int32_t w) {  // is v a better split vertex than w?
      if (w < 0) return true;
      const bool av = !avoid.empty() && avoid[v], aw = !avoid.empty() && avoid[w];
      if (av != aw) return aw;
      return c.dist(v) > c.dist(w);
    };
    for (int32_t v = 0; v < n; ++v) {
      const int32_t s = c.label(v);
      if (s < 0 || !wanted[s] || c.dist(v) == 0) continue;
      if (better(v, best[s])) best[s] = v;
    }
    std::vector<uint8_t> neighbours(num_samples, 0);
    bool any_singleton = false;
    for (int32_t s = 0; s < num_samples; ++s) {
      if (!wanted[s]) continue;
      if (best[s] >= 0) {
        result.push_back(best[s]);
        continue;
      }
      // Singleton: split the clusters around it instead (second pass only).
      any_singleton = true;
      const auto& ao = mesh.adjacency_offsets();
      const int32_t sample_vertex = samples[s];
      for (int32_t i = ao[sample_vertex]; i < ao[sample_vertex + 1]; ++i) {
        const int32_t t = c.label(mesh.adjacency()[i]);
        if (t >= 0 && t != s) neighbours[t] = 1;
      }
    }
    if (!any_singleton || pass == 1) break;
    wanted = neighbours;
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

// A corner of `sample_vertex` in a face reached from `face` across edges that are no feature
// edge, over faces with a corner in the sample's cluster (the same side of every border); a
// corner of any of its faces where none is. For attribute_corner's flood walk where it fails.
int32_t corner_across_faces(const Mesh& mesh, const FeatureLayout& layout, const Clustering& c, int32_t face,
                            int32_t sample_vertex) {
  const auto& faces = mesh.faces();
  const int32_t cluster = c.label(sample_vertex);
  std::vector<int32_t> queue{face};
  std::unordered_set<int32_t> seen{face};
  for (size_t next = 0; next < queue.size(); ++next) {
    const int32_t g = queue[next];
    for (int j = 0; j < 3; ++j)
      if (faces[3 * size_t(g) + j] == sample_vertex) return 3 * mesh.face_source()[g] + j;
    for (int j = 0; j < 3; ++j) {
      const int32_t e = mesh.face_edges()[3 * size_t(g) + j];
      if (layout.is_feature_edge(e)) continue;
      mesh.for_each_edge_face(e, [&](int32_t h) {
        bool in_cluster = false;
        for (int i = 0; i < 3; ++i) in_cluster |= c.label(faces[3 * size_t(h) + i]) == cluster;
        if (in_cluster && seen.insert(h).second) queue.push_back(h);
      });
    }
  }
  return mesh.first_corner(sample_vertex);
}

// Corner of the caller's mesh that carries the attributes (UV, colour) an output corner needs:
// a corner of the sample vertex on the same side of every border as the input face the output
// triangle came from. Walks the flood's steps back from the face's corner to the sample,
// carrying the current face across edges so the side is kept; where no step leads on (a
// repaired cluster's hop counts), across the cluster's faces instead (a corner of -1 had the
// caller's arrays read from their end: duck_via_assimp at 20 % in fast mode).
int32_t attribute_corner(const Mesh& mesh, const FeatureLayout& layout, const Clustering& c, int32_t face,
                         int32_t slot, int32_t sample_vertex) {
  const auto& faces = mesh.faces();
  auto corner_of = [&](int32_t f, int32_t v) {
    for (int j = 0; j < 3; ++j)
      if (faces[3 * size_t(f) + j] == v) return 3 * mesh.face_source()[f] + j;
    return -1;
  };
  if (layout.sectors_of(mesh, sample_vertex) <= 1) return mesh.first_corner(sample_vertex);  // one side: any face will do
  int32_t current = face;
  int32_t x = faces[3 * size_t(face) + slot];
  for (int32_t guard = 0; x != sample_vertex && guard <= mesh.num_vertices(); ++guard) {
    const int32_t p = step_towards_sample(mesh, layout, c, x);
    if (p < 0) break;
    const int32_t e = mesh.find_edge(x, p);
    const int32_t side = layout.sector_of(mesh, x, current);
    // The edge's first face on the same side, else its first face.
    int32_t next = -1;
    bool same_side = false;
    mesh.for_each_edge_face(e, [&](int32_t g) {
      if (next < 0) next = g;
      if (!same_side && layout.sector_of(mesh, x, g) == side) next = g, same_side = true;
    });
    current = next;
    x = p;
  }
  const int32_t corner = corner_of(current, sample_vertex);
  return corner >= 0 ? corner : corner_across_faces(mesh, layout, c, face, sample_vertex);
}

// The output from the final clustering; relabelled (if given) receives each vertex whose
// cluster was absorbed, with its key before it joined a neighbouring one.
DecimateResult finish(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> samples,
                      Clustering& clustering, const Partition& partition, Placement placement, bool draft,
                      DecimateResult result, std::vector<std::pair<int32_t, uint64_t>>* relabelled) {
  const auto start = Clock::now();
  const int32_t k = static_cast<int32_t>(samples.size());
  // Output vertices: the samples that carry triangles, in sample order.
  std::vector<int32_t> output_index(k, -1);
  for (int32_t s = 0; s < k; ++s)
    if (!partition.absorbed[s]) {
      output_index[s] = static_cast<int32_t>(result.kept.size());
      result.kept.push_back(samples[s]);
    }
  // Vertices of absorbed clusters join a neighbouring cluster that survives (lowest rank,
  // repeated outwards), so every input vertex maps to an output vertex.
  // Only vertices of clusters absorbed at the start ever change, so the passes visit just them,
  // in vertex order as passes over every vertex did (found by one parallel scan; usually none).
  auto label = [&clustering](int32_t v) { return clustering.label(v); };
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  // (A draft keeping input positions reads neither labels nor the clusters: it skips this.)
  std::vector<int32_t> orphans;
  const bool relabel = !draft || placement == Placement::Filtered;
  if (relabel && std::find(partition.absorbed.begin(), partition.absorbed.end(), 1) != partition.absorbed.end()) {
    const int32_t n = mesh.num_vertices();
    PerThread<std::vector<int32_t>> found(max_threads());
    parallel_region(team_for(n, kParallelMin), [&](Team& team) {
      auto& mine = found.mine();
      team.for_static(0, n, [&](int32_t v) {
        if (label(v) >= 0 && partition.absorbed[label(v)]) mine.push_back(v);
      });
    });
    append_and_clear(found, orphans);
  }
  for (bool changed = !orphans.empty(); changed;) {
    changed = false;
    for (int32_t v : orphans) {
      if (!partition.absorbed[label(v)]) continue;
      int32_t best = -1;
      for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
        const int32_t l = label(adj[i]);
        if (l >= 0 && !partition.absorbed[l] && (best < 0 || l < best)) best = l;
      }
      if (best >= 0) {
        if (relabelled) relabelled->push_back({v, clustering.key[v]});
        clustering.relabel(v, best);
        changed = true;
      }
    }
  }
  const std::vector<double> filtered =
      placement == Placement::Filtered ? filtered_positions(mesh, layout, samples, clustering) : std::vector<double>();
  result.vertices.resize(3 * result.kept.size());
  parallel_for(0, k, kParallelMinCostly, [&](int32_t s) {
    if (output_index[s] < 0) return;
    for (int j = 0; j < 3; ++j)
      result.vertices[3 * size_t(output_index[s]) + j] =
          filtered.empty() ? mesh.position(samples[s])[j] : filtered[3 * size_t(s) + j];
    // A filtered point that is not finite (should not happen: placement works in normalised
    // coordinates) falls back to the sample itself rather than reaching the output.
    const double* p = &result.vertices[3 * size_t(output_index[s])];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      for (int j = 0; j < 3; ++j) result.vertices[3 * size_t(output_index[s]) + j] = mesh.position(samples[s])[j];
  });
  const size_t t = partition.source_face.size();
  result.triangles.resize(3 * t);
  auto publish_ids = [&]() {  // public ids are the caller's
    const auto& source = mesh.vertex_source();
    for (auto& v : result.kept) v = source[v];
    for (auto& v : samples) v = source[v];
    result.samples = std::move(samples);
    result.seconds_output = seconds_since(start);
  };
  if (draft) {  // geometry only (DecimateParams::draft)
    parallel_for(0, 3 * t, parallel_if(t >= kParallelMin), [&](size_t i) { result.triangles[i] = output_index[partition.triangles[i]]; });
    if (!mesh.winding_flips().empty()) {  // the input's winding back, as restore_winding gives a full result
      result.face_source.resize(t);
      for (size_t i = 0; i < t; ++i) result.face_source[i] = mesh.face_source()[partition.source_face[i]];
      restore_winding(mesh, result);
      std::vector<int32_t>().swap(result.face_source);  // a draft has none
    }
    publish_ids();
    return result;
  }
  // A sample with one sector has one corner to copy attributes from, whatever the triangle:
  // the mesh's first corner of it (others walk per output corner, see attribute_corner),
  // looked up once per sample here rather than per output corner (four reads far apart).
  std::vector<int32_t> single_corner(k, -1);
  parallel_for(0, k, kParallelMinCostly, [&](int32_t s) {
    if (output_index[s] >= 0 && layout.sectors_of(mesh, samples[s]) <= 1) single_corner[s] = mesh.first_corner(samples[s]);
  });
  result.face_source.resize(t);
  result.corner_source.resize(3 * t);
  const std::vector<uint8_t>& flips = mesh.winding_flips();
  parallel_for(0, t, kParallelMin, [&](size_t i) {
    const int32_t f = partition.source_face[i];
    result.face_source[i] = mesh.face_source()[f];
    for (int j = 0; j < 3; ++j) {
      const int32_t rank = partition.triangles[3 * i + j];
      result.triangles[3 * i + j] = output_index[rank];
      result.corner_source[3 * i + j] = single_corner[rank] >= 0
                                            ? single_corner[rank]
                                            : attribute_corner(mesh, layout, clustering, f,
                                                               winding_slot(flips, f, j), samples[rank]);
    }
  });
  const auto& source = mesh.vertex_source();
  result.labels.resize(clustering.key.size());
  const int64_t n = int64_t(clustering.key.size());
  const bool in_mesh_order = result.labels_in_mesh_order;
  parallel_for(0, n, kParallelMin, [&](int64_t v) {
    result.labels[in_mesh_order ? v : source[v]] = label(v) >= 0 ? output_index[label(v)] : -1;
  });
  publish_ids();
  return result;
}

// Floods, checks and repairs until the partition passes (see partition.hpp).
// How far a result may miss an unguided target: 0.5 % (within the promised 1 %), so that the
// usual handful of absorbed clusters costs no extra round; below 200 vertices, nothing.
int32_t budget_tolerance(int32_t target) { return int32_t(0.005 * target); }

// The `count` widest clusters (largest flood distance, then lowest rank) that can split.
std::vector<int32_t> widest_clusters(const Clustering& c, const std::vector<uint8_t>& absorbed, int32_t count,
                                     const std::vector<int32_t>& excluded) {
  std::vector<int32_t> radius(absorbed.size(), 0);
  for (int32_t v = 0; v < c.num_vertices(); ++v)
    if (c.label(v) >= 0) radius[c.label(v)] = std::max(radius[c.label(v)], c.dist(v));
  for (int32_t s : excluded) radius[s] = 0;
  std::vector<int32_t> ranks;
  for (int32_t s = 0; s < int32_t(absorbed.size()); ++s)
    if (!absorbed[s] && radius[s] > 0) ranks.push_back(s);
  const size_t take = std::min<size_t>(ranks.size(), size_t(std::max(0, count)));
  std::partial_sort(ranks.begin(), ranks.begin() + take, ranks.end(), [&](int32_t a, int32_t b) {
    return radius[a] > radius[b] || (radius[a] == radius[b] && a < b);
  });
  ranks.resize(take);
  return ranks;
}

// One clustering of a decimation: the flood (fresh, or updated from the cache), then rounds of
// checks, each followed by repairs (samples added where the check names a problem) or, once
// clean, by top-ups towards the target. The stages run in the order of run().
class ClusterRun {
 public:
  ClusterRun(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> samples, int32_t max_rounds,
             bool repair_slivers, bool fast_path, const std::vector<uint8_t>& avoid, const std::vector<uint8_t>& required,
             int32_t top_up_to, FloodCache* cache, bool one_off, DecimateResult result)
      : mesh(mesh), layout(layout), max_rounds(max_rounds), repair_slivers(repair_slivers), fast_path(fast_path),
        one_off(one_off), avoid(avoid), required(required), top_up_to(top_up_to), cache(cache),
        samples(std::move(samples)), result(std::move(result)) {}

  DecimateResult run(Placement placement, bool draft) {
    auto start = Clock::now();
    if (cache && cache->holds(mesh, layout) && cache->worth_updating(samples)) update_cached_flood();
    else flood_afresh();
    result.seconds_clustering = seconds_since(start);
    result.fast_path = fast_path;
    start = Clock::now();
    for (int32_t round = 0;; ++round) {
      check_cancelled("checking");  // (a cached flood left half-updated is emptied: BorrowedCache)
      const bool slivers = repair_slivers && round < kSliverRounds;
      check(round, slivers);
      accumulate(result.issues_found, partition.issues);
      const bool clean = partition.issues.topological() == 0 && (!slivers || partition.issues.sliver == 0);
      std::vector<int32_t> to_split = partition.split_clusters;
      if (clean && !plan_top_up(to_split)) break;
      std::vector<int32_t> added = samples_to_add(clean, to_split);
      // Components no sample reached get one before anything else can be checked; that is not
      // a repair round (without it max_repair_rounds = 0 returned an empty mesh).
      const bool seeding = partition.issues.unreached > 0;
      if (added.empty() || (round >= max_rounds && !seeding)) {
        result.issues_remaining = partition.issues;
        if (!slivers) result.issues_remaining.sliver = 0;
        break;
      }
      add_samples(added, clean, seeding);
      if (seeding && !clean) --round;  // does not use up a repair round
    }
    // Zero-area triangles left after the repair rounds are reported, not hidden.
    if (partition.issues.sliver > 0 && partition.issues.topological() == 0)
      result.issues_remaining.sliver = partition.issues.sliver;
    result.seconds_checking = seconds_since(start);
    check_cancelled("output");
    // The output needs the clustering and the last partition only: the check's state (a byte a
    // face) and the top-ups' snapshot go before it (the cache holds its own first check).
    checked = CheckState();
    snapshot = Snapshot();
    release_heap();
    std::vector<std::pair<int32_t, uint64_t>> relabelled;
    const int32_t drawn = keeper ? int32_t(keeper->samples.size()) : 0, count = int32_t(samples.size());
    DecimateResult out = finish(mesh, layout, std::move(samples), clustering, partition, placement, draft,
                                std::move(result), keeper ? &relabelled : nullptr);
    if (keeper) hand_flood_to_cache(relabelled, drawn, count);
    clustering = Clustering();
    partition = Partition();
    release_heap();  // the flood, under the refinement otherwise
    return out;
  }

 private:
  const Mesh& mesh;
  const FeatureLayout& layout;
  const int32_t max_rounds;
  const bool repair_slivers, fast_path;
  const bool one_off;  // no flood is kept: freed heap goes back between stages (release_heap)
  const std::vector<uint8_t>& avoid;
  const std::vector<uint8_t>& required;
  const int32_t top_up_to;
  FloodCache* cache;  // until the first check is handed to it
  FloodCache* keeper = nullptr;  // the cache that takes the flood of the draw once the output is made
  std::vector<int32_t> samples;
  DecimateResult result;
  Clustering clustering;
  std::vector<int32_t> cross_edges;
  CheckState checked;  // later rounds re-test only what the relabelled vertices changed
  Partition partition;
  // The last few top-up samples can overshoot (a split may revive an absorbed neighbour): then
  // the state before them is restored and the next widest clusters are tried instead.
  struct Snapshot {
    size_t samples = 0;
    Clustering clustering;
    int32_t repair_rounds = 0, repairs = 0, top_up = 0;
    std::vector<int32_t> tried;
    bool active = false;
  } snapshot;

  // The cached flood becomes this one (the same keys a fresh flood gives); the first check
  // then re-tests only the faces around the vertices that changed. The cache keeps the flood
  // without the repairs below.
  // The first check of the cached flood, given back after this one's, updated. In the new
  // ranks, its triangles are taken over except around the vertices that changed (whose old
  // ranks may be gone; zero-area flags: the same vertices, same areas), and its per-sample
  // findings except for the samples whose triangles changed.
  void update_cached_flood() {
    checked = std::move(cache->first_check);
    cache->first_check = CheckState();
    checked.changed.clear();
    std::vector<int32_t> new_rank;
    flood_update(mesh, layout, cache->samples, samples, cache->clustering, &checked.changed, &new_rank);
    cache->samples = samples;
    clustering = std::move(cache->clustering);  // given back at the end (hand_flood_to_cache)
    keeper = cache;
    checked.renumber(new_rank, int32_t(samples.size()));
    if (!checked.valid) checked.changed.clear();  // every face is tested
    result.flood_updated = true;
  }

  void flood_afresh() {
    flood(mesh, layout, samples, clustering, fast_path ? &cross_edges : nullptr);
    if (!cache) return;
    cache->mesh = mesh.serial();
    cache->layout = layout.serial;
    cache->samples = samples;
    cache->clustering = Clustering();  // the flood of the draw is handed over at the end
    cache->first_check = CheckState();
    keeper = cache;
  }

  // The cache keeps the flood of the draw: the output made, the working state goes, the absorbed
  // clusters' vertices take back their keys and the samples the repairs and top-ups appended are
  // dropped (flood_drop_tail), which gives exactly the flood of the draw without a copy of it
  // alongside the decimation's working set (4 bytes a triangle of its peak).
  void hand_flood_to_cache(const std::vector<std::pair<int32_t, uint64_t>>& relabelled, int32_t drawn,
                           int32_t count) {
    partition = Partition();
    for (auto it = relabelled.rbegin(); it != relabelled.rend(); ++it) clustering.key[it->first] = it->second;
    flood_drop_tail(mesh, layout, drawn, count, clustering);
    keeper->clustering = std::move(clustering);
  }

  // A one-off decimation's freed heap goes back to the system between stages, so that the next
  // stage's working set does not sit above it (a slider's decimations skip it: they run again).
  void release_heap() const {
    if (one_off) release_freed_heap(8 * size_t(mesh.num_vertices()));
  }

  // One round's partition check; the first check goes to the cache too.
  void check(int32_t round, bool slivers) {
    if (round == 0 && fast_path) {
      const auto candidates = faces_near_borders();
      partition = check_partition(mesh, layout, samples, clustering, required, slivers, &candidates, &checked);
    } else {
      partition = check_partition(mesh, layout, samples, clustering, required, slivers, nullptr, &checked);
    }
    if (cache) {
      // What the first check found, for the cached flood (repairs change the clustering from
      // here on, and seeding rounds repeat round 0).
      cache->first_check = checked;
      cache->first_check.keep_complete();
      cache = nullptr;
    }
  }

  // Only faces around cluster borders can hold three clusters; in face order.
  std::vector<int32_t> faces_near_borders() const {
    std::vector<uint8_t> near_border(mesh.num_faces(), 0);
    auto mark = [&](int32_t f) { near_border[f] = 1; };
    for (int32_t e : cross_edges) mesh.for_each_edge_face(e, mark);
    // The flood does not step between two samples along a feature edge, so such an edge is
    // not among the crossings: a triangle bounded by features (a crease corner on a small
    // mesh) could be missed and its output triangle lost. Feature faces are few.
    for (int32_t e : layout.feature_edges) mesh.for_each_edge_face(e, mark);
    std::vector<int32_t> candidates;
    for (int32_t f = 0; f < mesh.num_faces(); ++f)
      if (near_border[f]) candidates.push_back(f);
    return candidates;
  }

  // Exact budget: absorbed clusters leave the output, so a clean result can fall short of the
  // target. Names in `to_split` the widest clusters to split at their farthest vertex; false
  // when the result is final.
  bool plan_top_up(std::vector<int32_t>& to_split) {
    const int32_t kept = int32_t(samples.size()) - partition.issues.absorbed;
    if (snapshot.active && kept > top_up_to && snapshot.tried.size() < kMaxTopUpRetries) {
      samples.resize(snapshot.samples);
      clustering = snapshot.clustering;
      checked = CheckState();
      result.repair_rounds = snapshot.repair_rounds;
      result.repairs = snapshot.repairs;
      result.top_up = snapshot.top_up;
      partition = check_partition(mesh, layout, samples, clustering, required, false, nullptr, &checked);
    } else if (top_up_to <= 0 || kept >= top_up_to - budget_tolerance(top_up_to) ||
               result.top_up_rounds >= kMaxTopUpRounds) {
      return false;
    } else {
      snapshot = Snapshot();
    }
    int32_t need = top_up_to - (int32_t(samples.size()) - partition.issues.absorbed);
    // Some new samples get absorbed in turn: ask for that many more, so that one round
    // usually lands on the target (a small overshoot stays within the budget tolerance).
    if (need > kSmallTopUp)
      need += int32_t(std::ceil(1.5 * need * double(partition.issues.absorbed) / double(samples.size())));
    if (need <= kSmallTopUp && !snapshot.active) {
      snapshot.active = true;
      snapshot.samples = samples.size();
      snapshot.clustering = clustering;
      snapshot.repair_rounds = result.repair_rounds;
      snapshot.repairs = result.repairs;
      snapshot.top_up = result.top_up;
    }
    to_split = widest_clusters(clustering, partition.absorbed, need, snapshot.tried);
    if (snapshot.active) snapshot.tried.insert(snapshot.tried.end(), to_split.begin(), to_split.end());
    if (to_split.empty()) return false;
    ++result.top_up_rounds;
    return true;
  }

  // The vertices to add as samples: those the check named, and a splitting vertex of each
  // cluster to split; each once, none already a sample.
  std::vector<int32_t> samples_to_add(bool clean, const std::vector<int32_t>& to_split) const {
    std::vector<int32_t> added = clean ? std::vector<int32_t>() : partition.new_samples;
    const auto split = splitting_vertices(mesh, clustering, samples, to_split, avoid);
    added.insert(added.end(), split.begin(), split.end());
    std::sort(added.begin(), added.end());
    added.erase(std::unique(added.begin(), added.end()), added.end());
    added.erase(std::remove_if(added.begin(), added.end(), [&](int32_t v) { return clustering.dist(v) == 0; }),
                added.end());
    if (added.empty() && !clean) added = samples_next_to_named();
    if (added.empty() && !clean) added = samples_in_lost_components();
    return added;
  }

  // The repairs stalled (an issue they cannot fix, e.g. triangles of a component facing both
  // ways, named nothing new) and a component has no triangle left: only the Euler check saw
  // it, and it names clusters only when it is the sole finding. Split each such component's
  // widest cluster, so that no component is lost while repair rounds remain.
  std::vector<int32_t> samples_in_lost_components() const {
    std::vector<uint8_t> has_triangle(mesh.num_components(), 0);
    for (size_t i = 0; i < partition.triangles.size(); i += 3)
      has_triangle[mesh.component()[samples[partition.triangles[i]]]] = 1;
    std::vector<int32_t> widest(mesh.num_components(), -1);
    for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
      const int32_t comp = mesh.component()[v];
      if (clustering.label(v) < 0 || clustering.dist(v) == 0 || has_triangle[comp]) continue;
      if (widest[comp] < 0 || clustering.dist(v) > clustering.dist(widest[comp])) widest[comp] = v;
    }
    std::vector<int32_t> added;
    for (int32_t v : widest)
      if (v >= 0) added.push_back(v);
    return added;
  }

  // Every cluster named is a single vertex and so are its neighbours (seen with creases
  // cutting a small mesh into short curves): the round would end with the issue reported.
  // Sample the vertices next to the named clusters instead, or failing that the widest
  // clusters anywhere; more samples always converge (all of them give the input back).
  // Not in components with a non-manifold edge: an issue there (a fin) is in the input
  // itself, and chasing it would sample the whole mesh. (Pinched vertices are repairable:
  // each fan gets its own clusters.)
  std::vector<int32_t> samples_next_to_named() const {
    std::vector<int32_t> added;
    std::vector<uint8_t> manifold_component(mesh.num_components(), 1);
    for (int32_t e = 0; e < int32_t(mesh.edge_vertices().size() / 2); ++e)
      if (mesh.edge_face_count(e) > 2) manifold_component[mesh.component()[mesh.edge_vertices()[2 * size_t(e)]]] = 0;
    std::vector<uint8_t> named(samples.size(), 0);
    bool any_named = false;
    for (int32_t s : partition.split_clusters)
      if (manifold_component[mesh.component()[samples[s]]]) named[s] = 1, any_named = true;
    const auto& ao = mesh.adjacency_offsets();
    const auto& adj = mesh.adjacency();
    for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
      if (clustering.label(v) < 0 || clustering.dist(v) == 0) continue;
      for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
        const int32_t l = clustering.label(adj[i]);
        if (l >= 0 && named[l]) {
          added.push_back(v);
          break;
        }
      }
    }
    if (added.empty() && any_named) {
      const auto widest = widest_clusters(clustering, partition.absorbed,
                                          std::max<int32_t>(4, int32_t(samples.size()) / 8), {});
      added = splitting_vertices(mesh, clustering, samples, widest, avoid);
    }
    return added;
  }

  // Floods from the added samples and counts them as a top-up, a seeding or a repair round.
  void add_samples(const std::vector<int32_t>& added, bool clean, bool seeding) {
    const int32_t first_new = static_cast<int32_t>(samples.size());
    samples.insert(samples.end(), added.begin(), added.end());
    flood_add(mesh, layout, samples, first_new, clustering, &checked.changed);
    if (clean) {
      result.top_up += static_cast<int32_t>(added.size());
    } else if (seeding) {
      result.repairs += static_cast<int32_t>(added.size());
    } else {
      result.repair_rounds += 1;
      result.repairs += static_cast<int32_t>(added.size());
    }
  }
};

DecimateResult cluster_and_emit(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> samples,
                                Placement placement, int32_t max_rounds, bool repair_slivers, bool fast_path,
                                const std::vector<uint8_t>& avoid, const std::vector<uint8_t>& required,
                                int32_t top_up_to, FloodCache* cache, bool one_off, bool draft,
                                DecimateResult result) {
  return ClusterRun(mesh, layout, std::move(samples), max_rounds, repair_slivers, fast_path, avoid, required, top_up_to,
                    cache, one_off, std::move(result))
      .run(placement, draft);
}

// The final check (verify.hpp): a result whose repairs left no issue must pass it; otherwise
// something the partition checks missed would be returned as success, so it is an error.
void check_result(const Mesh& mesh, const FeatureLayout& layout, DecimateResult& result) {
  const auto start = Clock::now();
  const std::vector<int32_t> kept = mesh.internal_ids(result.kept);
  result.output_check = check_output(mesh, layout, kept, result.vertices, result.triangles);
  result.output_checked = true;
  result.seconds_verify = seconds_since(start);
}

bool topology_kept(const DecimateResult& result) {
  return result.issues_remaining.topological() == 0 && result.output_check.violations() == 0;
}

// A checked result, unless its check found a violation the repairs did not report.
DecimateResult reported(DecimateResult result) {
  if (result.output_check.violations() > 0 && result.issues_remaining.topological() == 0)
    throw std::runtime_error("decimation output failed its final check (" + result.output_check.describe() +
                             "); please report this mesh and the parameters");
  return result;
}

DecimateResult verified(const Mesh& mesh, const FeatureLayout& layout, DecimateResult result) {
  check_result(mesh, layout, result);
  return reported(std::move(result));
}

// The guidance multipliers, empty when every one would be 1 (no painted guidance, no boxes):
// the refinement treats no multipliers as all ones, and n doubles of ones were a twentieth of a
// large decimation's peak memory.
std::vector<double> multipliers_if_guided(const Mesh& mesh, const SamplingParams& sampling) {
  if (!has_multipliers(sampling)) return {};
  return guidance_multipliers(mesh, sampling);
}

const std::vector<double>* or_null(const std::vector<double>& multipliers) {
  return multipliers.empty() ? nullptr : &multipliers;
}

int32_t active_vertices(const Mesh& mesh) {
  return mesh.num_vertices() - mesh.report().isolated_vertices;
}

// Every triangle a piece of its own (an unwelded mesh): each piece keeps its three corners, so
// the draw forces every vertex and no collapse is possible. The result is the input.
bool only_loose_triangles(const Mesh& mesh, const FeatureLayout& layout) {
  return int64_t(layout.loose_vertices.size()) == active_vertices(mesh);
}

// Every triangle of a pass a piece of its own (leaf cards, each at its floor of one triangle):
// no collapse is possible, so the collapses would only build their tables over it.
bool only_lone_triangles(const DecimateResult& result) {
  const std::vector<uint8_t> lone = lone_corners(result.triangles, result.vertices.size() / 3);
  return std::all_of(result.triangles.begin(), result.triangles.end(), [&](int32_t v) { return !lone.empty() && lone[v]; });
}

}  // namespace

namespace {

// A cache of the pool for one decimation: none without a pool or when all are in use. One left
// half-updated by an exception is emptied.
class BorrowedCache {
 public:
  explicit BorrowedCache(FloodCachePool* pool) : pool_(pool), cache_(pool ? pool->take() : nullptr) {}
  ~BorrowedCache() {
    if (!pool_ || !cache_) return;
    if (std::uncaught_exceptions() > exceptions_) cache_->clear();
    pool_->give_back(std::move(cache_));
  }
  BorrowedCache(const BorrowedCache&) = delete;
  BorrowedCache& operator=(const BorrowedCache&) = delete;
  FloodCache* get() const { return cache_.get(); }

 private:
  FloodCachePool* pool_;
  std::unique_ptr<FloodCache> cache_;
  int exceptions_ = std::uncaught_exceptions();  // in flight when borrowed (a handler may borrow)
};

// A caller that keeps no floods decimates once: the draw's per-vertex tables (the importance
// table, a seed's uniforms and candidate order, up to 16 bytes a triangle) are not kept on the
// layout beside the flood and the refinement either (rebuilt by a later draw, the same bits).
void forget_draw_tables(const FeatureLayout& layout) {
  layout.sampling_table.set(nullptr);
  layout.selection_uniforms.set(nullptr);
  layout.candidate_order.set(nullptr);
}

// One pass: draw samples for `target`, then flood, check, repair, emit.
DecimateResult decimate_once(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params,
                             int32_t target, int32_t top_up_to, FloodCache* cache) {
  check_cancelled("sampling");
  const int32_t active = active_vertices(mesh);
  const auto start = Clock::now();
  SampleSet set = select_samples(mesh, layout, params.sampling, target);
  DecimateResult result;
  result.labels_in_mesh_order = params.labels_in_mesh_order;
  result.target_vertices = params.target_vertices;
  result.selected = static_cast<int32_t>(set.samples.size());
  result.forced = set.forced;
  result.loop_forced = set.loop_forced;
  result.density_rejected = set.density_rejected;
  result.guided = set.guided;
  result.expected_vertices = set.expected;
  result.rate = set.rate;
  result.seconds_sampling = seconds_since(start);
  // Vertices the user excluded (u = -1) are the last choice when a repair needs a new sample;
  // control points (u = 1) must stay in the output. Without guidance both stay empty (none).
  std::vector<uint8_t> avoid, required;
  if (has_multipliers(params.sampling)) {
    const auto p = sampling_probabilities(mesh, layout, params.sampling, set.rate);
    avoid.resize(p.size());
    required.resize(p.size());
    for (size_t v = 0; v < p.size(); ++v) {
      avoid[v] = p[v] <= 0.0;
      required[v] = p[v] >= 1.0;
    }
  }
  const bool one_off = !params.flood_caches;
  if (one_off) {
    forget_draw_tables(layout);
    release_freed_heap(8 * size_t(mesh.num_vertices()));  // the draw's sort, under the flood otherwise
  }
  const bool fast = params.fast_path == 1 || (params.fast_path < 0 && target < 0.05 * active);
  // The fast path finds emitting faces from the flood's crossings, which can miss one that
  // a full scan (and so an updated flood) finds: its results are its own, never updated.
  return cluster_and_emit(mesh, layout, std::move(set.samples), params.placement, params.max_repair_rounds, true,
                          fast, avoid, required, top_up_to, fast ? nullptr : cache, one_off, params.draft,
                          std::move(result));
}

}  // namespace

namespace {

// A first pass above its target (stalled repairs, or a topology that needs more vertices than
// drawn), taken the rest of the way by quality
// mode's collapses (refine.hpp: the topology of every component, its non-manifold curves and
// its borders kept), keeping input positions (half-edge collapses) as fast mode promises.
void collapse_rest(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params,
                   DecimateResult& result) {
  const std::vector<double> multipliers = multipliers_if_guided(mesh, params.sampling);
  RefineParams rest;
  rest.target_vertices = params.target_vertices;
  rest.target_triangles = params.target_triangles;
  rest.multipliers = or_null(multipliers);
  rest.keep_positions = true;
  rest.attributes = params.attributes;
  check_cancelled("refinement");
  refine_by_collapses(mesh, layout, rest, result);
}

// One edge of each zero-area triangle collapsed (never an output with a zero-area triangle).
void collapse_zero_area(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params,
                        DecimateResult& result) {
  const std::vector<double> multipliers = multipliers_if_guided(mesh, params.sampling);
  RefineParams cleanup;
  cleanup.multipliers = or_null(multipliers);
  cleanup.zero_area_only = true;
  refine_by_collapses(mesh, layout, cleanup, result);
}

// What must stay whatever the target, as result.forced: border corners and control points (a
// first pass may have drawn every vertex, which says nothing about the budget).
void count_forced(const Mesh& mesh, const FeatureLayout& layout, const std::vector<double>& multipliers,
                  DecimateResult& result) {
  result.forced = 0;
  result.loop_forced = 0;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    result.forced += layout.is_corner(v) || (!multipliers.empty() && multipliers[v] == kForcedMultiplier);
}

// Every vertex a sample (the input itself, which passes every check), collapsed to the target
// keeping input positions: what a plain pass falls back to when its repairs left it broken.
DecimateResult collapsed_from_whole_mesh(const Mesh& mesh, const FeatureLayout& layout,
                                         const DecimateParams& params) {
  const int32_t active = active_vertices(mesh);
  DecimateResult whole = decimate_once(mesh, layout, params, active, active, nullptr);
  collapse_rest(mesh, layout, params, whole);
  if (has_zero_area(whole)) collapse_zero_area(mesh, layout, params, whole);
  count_forced(mesh, layout, multipliers_if_guided(mesh, params.sampling), whole);
  return verified(mesh, layout, std::move(whole));
}

// The engine's door for a plain decimation: the target, the repair rounds and every caller's
// sampling parameters checked here.
void check_plain_params(const Mesh& mesh, const DecimateParams& params, int32_t active) {
  if (params.target_vertices < 1)
    throw std::invalid_argument("target must be at least 1 vertex, got " + std::to_string(params.target_vertices));
  if (params.target_vertices > active)
    throw std::invalid_argument("target of " + std::to_string(params.target_vertices) +
                                " vertices exceeds the mesh's " + std::to_string(active) + " vertices in triangles");
  if (params.max_repair_rounds < 0) throw std::invalid_argument("max_repair_rounds must be >= 0");
  validate_sampling_params(mesh, params.sampling);
}

// TopStoc to params.target_vertices. `refined`: a first pass the refinement thins next, which
// removes zero-area triangles and whose output is checked after it, so neither happens here
// (except the check that decides whether a fast-path miss must be redone).
DecimateResult stochastic_pass(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params,
                               bool refined) {
  const int32_t active = active_vertices(mesh);
  check_plain_params(mesh, params, active);
  const int32_t target = params.target_vertices;
  // Without guidance the budget is exact. Repairs add samples and absorbed clusters remove
  // some; a shortfall is topped up inside the pass (widest clusters split), an excess (the
  // topology needed more than drawn) is drawn again lower and topped up. Guided decimations
  // too: the guidance redistributes the budget, it does not change it.
  // The kept flood serves the draw for the target: the next decimation's draw is near that
  // one, not near the lower draws below (on a mesh whose topology needs many repairs, 1 sample).
  DecimateResult best;
  {
    BorrowedCache cache(params.flood_caches);
    best = decimate_once(mesh, layout, params, target, target, cache.get());
  }
  const auto excess = [&](const DecimateResult& r) { return int32_t(r.kept.size()) - target; };
  const int32_t tolerance = budget_tolerance(target);
  // Issues the repairs could not fix (what the partition check cannot judge: non-manifold
  // edges, a component whose triangles face both ways) come back at every lower draw: a plain
  // pass skips those draws and collapses to the target instead (below).
  const bool stalled = best.issues_remaining.topological() > 0;
  const int passes = stalled && !refined ? 0 : params.budget_passes;
  int32_t drawn = target;
  for (int pass = 0; pass < passes && excess(best) > tolerance && best.forced < target; ++pass) {
    const int32_t lower = std::max(1, drawn - excess(best) - tolerance);
    if (lower == drawn) break;  // the same draw again: the same pass (a sheet with thousands of holes, at 1)
    drawn = lower;
    DecimateResult r = decimate_once(mesh, layout, params, drawn, target, nullptr);
    if (std::abs(excess(r)) < std::abs(excess(best))) {
      r.flood_updated = best.flood_updated;  // (it tells of the draw for the target)
      best = std::move(r);
    }
  }
  // A pass above its target (a stalled one, or one whose topology needed more vertices than
  // drawn) is collapsed the rest of the way. A draft that did not stall stays the plain pass
  // (a drag stays fast on high-genus meshes at tiny targets); the rest's full result does not.
  // (The pass kept may be a lower draw that stalled where the draw for the target did not.)
  if (!refined && excess(best) > tolerance && !only_loose_triangles(mesh, layout) && !only_lone_triangles(best)) {
    if (params.draft && best.issues_remaining.topological() == 0) {
      best.collapses_skipped = true;
    } else if (params.draft) {
      // The collapses follow the result's labels and corners, which a draft leaves out.
      DecimateParams full = params;
      full.draft = false;
      return stochastic_pass(mesh, layout, full, refined);
    } else {
      collapse_rest(mesh, layout, params, best);
    }
  }
  // An input with collinear vertices can leave zero-area triangles the repairs could not
  // remove: collapse one edge of each (never an output with a zero-area triangle).
  // A draft keeps them (they show nothing) and says the full result collapses further: the
  // cleanup follows the labels and corners a draft leaves out, and making such frames in full
  // (every frame of a scan with collinear points: Stanford's dragon, 5 a second) stalled a drag.
  if (!refined && has_zero_area(best)) {
    if (params.draft)
      best.collapses_skipped = true;
    else
      collapse_zero_area(mesh, layout, params, best);
    // Some the clean-up cannot remove keeping input positions (a piece of coincident vertices
    // reduced to a flat tetrahedron: the spider of tests/data, 8 at 20 %): collapsing the whole
    // mesh keeps other vertices there, where the mesh is small enough for it.
    if (!params.draft && has_zero_area(best) && active <= kMaxAwareVertices)
      return collapsed_from_whole_mesh(mesh, layout, params);
  }
  // A draft's output is not re-checked; a fast-path result is, since the check decides
  // whether it must be redone.
  if ((refined || params.draft) && !best.fast_path) return best;
  check_result(mesh, layout, best);
  if (best.fast_path && !topology_kept(best)) {
    // The fast path's candidate faces can miss an emitting face (seen once in 55,000 random
    // decimations with creases: one triangle lost, so the repairs chased an issue they could
    // not see). Scanning every face instead is the repair.
    DecimateParams every_face = params;
    every_face.fast_path = 0;
    return stochastic_pass(mesh, layout, every_face, refined);
  }
  // Repairs that ran out of rounds can leave a surface the final check rejects: on a double cone
  // a sampled apex, one hop from every rim vertex and first on ties, keeps rim pieces in its
  // cluster, and a round frees one. Collapsing that kept it wrong: start from the whole mesh.
  if (!refined && best.issues_remaining.topological() > 0 && best.output_check.violations() > 0)
    return collapsed_from_whole_mesh(mesh, layout, params);
  return reported(std::move(best));  // checked above
}

}  // namespace

namespace {

// A refined decimation starts from the whole mesh up to this many times refine_collapses
// vertices: below that the collapses' time is small, and the stochastic first pass's choices
// cost quality (3.8 times the mean error on a 62k-vertex character; docs/benchmarks.md).
constexpr double kWholeMeshCollapses = 8.0;

// ... and, whatever refine_collapses, up to this many vertices, where the max-aware reruns run
// (refine.hpp): from the stochastic pass a box-cut gyroid of 172,706 vertices at 10 % had 4.6
// times the best peer's max error and a field of 600 spheres 2.1 times (the first pass's
// random gaps, which the collapses cannot fill), in 0.2-0.4 s; collapsed whole 0.89 and 0.99
// times, in 2.6-4.7 s, about Blender's Decimate's time (docs/bench_notes/large-first-pass.md).
constexpr int32_t kWholeMeshVertices = kMaxAwareVertices;

// Above it the first pass keeps kFirstPassTimes times the target, at most kWholeMeshVertices
// vertices, and up to kFloorVertices at least kFirstPassFloor: on Stanford's dragon scan
// (437,645 vertices) a first pass of the target and 10,000 more had 2.3 times Blender's mean
// error at 10 % and 1.7 times at 2 %; 8 times the target up to 125,000 left 1.4 times at 10 %
// (first pass 125,000; 250,000 gives 1.04) and a max 1.34 times the best peer's at 2 % (first
// pass 70,000; 125,000 gives 0.96), in 1-2.5 s where Blender's Decimate takes 15
// (docs/bench_notes/large-first-pass.md). On the horse (775,000 vertices) the target and a
// quarter more had 3.0 times Blender's mean error at 10 % and 1.7 times at 1 %; 8 times the
// target, 1.35 and 1.07 times (docs/bench_notes/large-first-pass.md, third section). The
// collapser's state costs about 450 bytes a first-pass vertex: a 2M-triangle torus at 1 % peaks
// at 93 bytes a triangle instead of 81.
constexpr int32_t kFirstPassFloor = kWholeMeshVertices / 2;
constexpr double kFirstPassTimes = 8.0;
constexpr int32_t kFloorVertices = 2 * kWholeMeshVertices;

// A sliver-heavy mesh (sliver_heavy, refine.hpp) starts from the whole mesh up to this many
// vertices: on it the stochastic pass's clusters, grown by hop count, stretch along the long
// edges and its triangles cut across the surface (a UV sphere of 2,000 segments kept 1.8 % of the
// diagonal as max error from that first pass, 0.002 % collapsed whole). Above it (a UV sphere
// of 990,002 vertices: 20 s and 0.64 GB collapsed whole, 1.2 s from the stochastic pass) the
// stochastic pass's result is the start.
constexpr int32_t kSliverWholeVertices = 2000000;

// Vertices the first pass of a refined decimation keeps (see DecimateParams::refine_collapses).
int32_t first_pass_vertices(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params,
                            int32_t active) {
  const double target = params.target_vertices, collapses = std::max(0, params.refine_collapses);
  if (collapses > 0 && active <= std::max<double>(kWholeMeshCollapses * collapses, kWholeMeshVertices)) return active;
  if (collapses > 0 && active <= kSliverWholeVertices && sliver_heavy(mesh, layout)) return active;
  const double extra = collapses > 0 ? std::max(collapses, 0.25 * target) : 0.0;
  double floor = 0.0;
  if (collapses > 0) floor = std::min<double>(kFirstPassTimes * target, kWholeMeshVertices);
  if (collapses > 0 && active <= kFloorVertices) floor = std::max<double>(floor, kFirstPassFloor);
  return int32_t(std::min<double>(active, std::max({std::ceil(params.refine * target), target + extra, floor})));
}

// Whether the collapses start the same way for every target from kWarmUpReach of this one up,
// so that a collapse state kept from it serves them: a decimation toward kWarmUpReach of the
// target draws as many first-pass vertices (the whole mesh, or the cap or floor above; the
// count grows with the target, so every target in between does too), and no feature edge's
// planes are weighed by the target (refine.hpp's start_depends_on_target). A live preview warms
// up toward 1.15 times the highest ratio asked, and the rests that follow lie a little under it.
constexpr double kWarmUpReach = 0.75;
bool start_fixed(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params, int32_t active,
                 int32_t first_vertices) {
  DecimateParams lower = params;
  lower.target_vertices = std::max(1, int32_t(kWarmUpReach * params.target_vertices));
  return first_pass_vertices(mesh, layout, lower, active) == first_vertices &&
         !start_depends_on_target(layout, first_vertices == active);
}

// TopStoc to a few times the target, then collapses down to it (refine.hpp). Painted regions
// keep the share of the budget the guidance gives them. target_triangles > 0: the collapses
// stop there instead (the vertex target then sets the first pass and the guidance quotas).
DecimateResult refined(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params,
                       int32_t target_triangles) {
  if (params.draft) throw std::invalid_argument("a draft is plain TopStoc: refine must be 0");
  const int32_t active = active_vertices(mesh);
  DecimateParams first = params;
  first.refine = 0.0;
  first.placement = Placement::Subsample;  // the refinement places the vertices it keeps
  first.labels_in_mesh_order = true;        // what the refinement reads (no copy in its order)
  first.target_vertices = first_pass_vertices(mesh, layout, params, active);
  first.sampling.keep_curves = true;  // the collapses thin the borders (sampling.cpp force_curves)
  first.warm_up = false;
  // A start that depends on the target (start_fixed), or guidance (its quotas do from the
  // start): no state a later decimation toward another target could resume from. Said before
  // any pass, so asking costs nothing.
  if (params.warm_up && (!start_fixed(mesh, layout, params, active, first.target_vertices) ||
                         !params.collapse_snapshots || target_triangles > 0 || has_multipliers(params.sampling)))
    return {};
  DecimateResult result = stochastic_pass(mesh, layout, first, true);
  // A first pass whose repairs left issues may be broken (the double cone of n = 80,000): the
  // collapses would keep it so. If its check rejects it, the first pass is the whole mesh.
  if (result.issues_remaining.topological() > 0 && first.target_vertices != active) {
    check_result(mesh, layout, result);
    if (result.output_check.violations() > 0) {
      first.target_vertices = active;
      result = stochastic_pass(mesh, layout, first, true);
    }
  }
  // A first pass far below its budget leaves the collapses little or nothing to choose: its
  // lower draws, taken for a draw far over budget, can land there (a UV sphere of 2,000
  // segments kept 2,104 vertices for a budget of 19,800 and a target of 9,800; from 1 sample
  // and the repairs). The first pass is then the whole mesh.
  const int32_t first_kept = int32_t(result.kept.size());
  if ((first_kept < params.target_vertices || first_kept < first.target_vertices / 2) && first.target_vertices != active) {
    first.target_vertices = active;
    result = stochastic_pass(mesh, layout, first, true);
  }
  const std::vector<double> multipliers = multipliers_if_guided(mesh, params.sampling);
  RefineParams refine;
  refine.target_vertices = params.target_vertices;
  refine.target_triangles = target_triangles;
  refine.multipliers = or_null(multipliers);
  refine.refit = params.placement == Placement::Filtered;
  refine.max_aware = refine.refit;
  refine.large_fit = params.large_fit;
  refine.attributes = params.attributes;
  refine.snapshots = params.collapse_snapshots;
  refine.warm_up = params.warm_up;
  check_cancelled("refinement");
  refine_by_collapses(mesh, layout, refine, result);
  if (params.warm_up) {  // the kept state is the point: the result is unfinished
    DecimateResult warmed;
    warmed.refine_vertices = result.refine_vertices;  // set where a state was kept
    return warmed;
  }
  result.target_vertices = params.target_vertices;
  count_forced(mesh, layout, multipliers, result);
  return verified(mesh, layout, std::move(result));
}

}  // namespace

DecimateResult decimate(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params) {
  const int32_t active = active_vertices(mesh);
  if (!(params.refine == 0.0 || params.refine >= 1.0))
    throw std::invalid_argument("refine must be 0 (off) or at least 1, got " + std::to_string(params.refine));
  if ((params.warm_up || params.refine >= 1.0) && only_loose_triangles(mesh, layout)) {
    // Nothing to refine, place or keep: the plain pass gives the input, without the collapser's set-up.
    if (params.warm_up) return {};
    DecimateParams plain = params;
    plain.refine = 0.0;
    plain.placement = Placement::Subsample;
    return stochastic_pass(mesh, layout, plain, false);
  }
  if (params.refine >= 1.0 && params.target_vertices >= 1 && params.target_vertices <= active)
    return refined(mesh, layout, params, 0);
  if (params.warm_up) return {};  // plain TopStoc keeps no collapse state
  // On a sliver-heavy mesh TopStoc's clusters, grown by hops, cut across the surface (a capped
  // cylinder of 5,000 segments 16.7 % of the diagonal at 10 %): a fast decimation collapses the
  // whole mesh instead, keeping input positions, up to kMaxAwareVertices (about 1-2 s at
  // 100,000). A draft is that frame made in full (the collapses follow the labels a draft leaves out).
  if (active <= kMaxAwareVertices && sliver_heavy(mesh, layout)) {
    check_plain_params(mesh, params, active);
    DecimateParams full = params;
    full.draft = false;
    return collapsed_from_whole_mesh(mesh, layout, full);
  }
  return stochastic_pass(mesh, layout, params, false);
}

DecimateResult decimate_with_samples(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> samples,
                                     Placement placement, int32_t max_repair_rounds, int32_t refine_vertices,
                                     const double* guidance, const CornerAttributes& attributes,
                                     int32_t refine_triangles, bool refine_keeps_positions, bool large_fit) {
  if (samples.empty()) throw std::invalid_argument("the sample list is empty");
  for (size_t i = 0; i < samples.size(); ++i) {
    const int32_t v = samples[i];
    if (v < 0 || v >= mesh.num_vertices())
      throw std::invalid_argument("sample " + std::to_string(i) + " is vertex " + std::to_string(v) +
                                  ", outside [0, " + std::to_string(mesh.num_vertices()) + ")");
    samples[i] = mesh.vertex_index()[v];
    if (!mesh.in_faces(samples[i]))
      throw std::invalid_argument("sample " + std::to_string(i) + " is vertex " + std::to_string(v) +
                                  ", which lies in no triangle");
  }
  // Corners (feature corners, pinched vertices) are always kept, as decimate() keeps them: a
  // list from a finished decimation holds them all, and a list without a bowtie's centre lost
  // a whole wing (the wing's clusters were absorbed and every count stayed the same). Missing
  // ones are appended, so the given samples keep their ranks.
  std::vector<uint8_t> listed(mesh.num_vertices(), 0);
  for (int32_t v : samples) listed[v] = 1;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    if (layout.is_corner(v) && !listed[v]) samples.push_back(v);
  DecimateResult result;
  result.target_vertices = static_cast<int32_t>(samples.size());
  result.selected = result.target_vertices;
  // Saved lists come from a finished decimation; only topology is re-checked, so the same
  // list always gives the same mesh.
  // A refined result's first pass keeps input positions: the refinement places what it keeps.
  result = cluster_and_emit(mesh, layout, std::move(samples), refine_vertices > 0 ? Placement::Subsample : placement,
                            max_repair_rounds, false, false, {},
                            {}, 0, nullptr, false, false, std::move(result));
  // A refined result is thinned again; an unrefined one loses its zero-area triangles, as
  // decimate() does.
  if (refine_vertices > 0 || has_zero_area(result)) {
    std::vector<double> multipliers;
    if (guidance) {
      SamplingParams sampling;
      sampling.guidance = guidance;
      multipliers = guidance_multipliers(mesh, sampling);
    }
    RefineParams refine;
    refine.multipliers = guidance ? &multipliers : nullptr;
    refine.target_vertices = refine_vertices;
    refine.target_triangles = refine_vertices > 0 ? refine_triangles : 0;
    refine.zero_area_only = refine_vertices == 0;
    refine.refit = refine_vertices > 0 && placement == Placement::Filtered;
    refine.max_aware = refine.refit;
    refine.keep_positions = refine_keeps_positions;
    refine.large_fit = large_fit;
    refine.attributes = attributes;
    refine_by_collapses(mesh, layout, refine, result);
  }
  return verified(mesh, layout, std::move(result));
}

void restore_winding(const Mesh& mesh, DecimateResult& result) {
  const std::vector<uint8_t>& flips = mesh.winding_flips();
  const size_t t = result.face_source.size();
  if (flips.empty() || 3 * t != result.triangles.size()) return;
  // Per caller triangle its flip and component; per component the flips its input and its
  // output triangles have (bit 1: unflipped, bit 2: flipped), and its first output triangle.
  const size_t components = size_t(mesh.report().components) + 1;
  std::vector<uint8_t> flipped(size_t(mesh.report().input_triangles), 0), input(components, 0), output(components, 0);
  std::vector<int32_t> component(flipped.size(), 0), first(components, -1);
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t c = std::max(0, int32_t(mesh.component()[mesh.faces()[3 * size_t(f)]]));
    flipped[size_t(mesh.face_source()[f])] = flips[f];
    component[size_t(mesh.face_source()[f])] = c;
    input[size_t(c)] |= uint8_t(1 << flips[f]);
  }
  const bool corners = result.corner_source.size() == 3 * t;
  auto turn = [&](size_t i) {
    std::swap(result.triangles[3 * i + 1], result.triangles[3 * i + 2]);
    if (corners) std::swap(result.corner_source[3 * i + 1], result.corner_source[3 * i + 2]);
  };
  for (size_t i = 0; i < t; ++i) {
    const size_t source = size_t(result.face_source[i]), c = size_t(component[source]);
    output[c] |= uint8_t(1 << flipped[source]);
    if (first[c] < 0) first[c] = int32_t(i);
    if (flipped[source]) turn(i);
  }
  // A component whose seam went all the same (a result of a few triangles, whose emission or
  // collapses kept other sources): its first triangle is turned, so that it stays inconsistently
  // oriented as its input is (a component's orientation is part of the topology kept).
  for (size_t c = 0; c < components; ++c)
    if (input[c] == 3 && output[c] != 3 && first[c] >= 0) turn(size_t(first[c]));
}

// Results above this many triangles stop the search for a triangle target at a floor (below).
constexpr int32_t kFloorSearchFaces = 1000;

DecimateResult decimate_to_triangles(const Mesh& mesh, const FeatureLayout& layout, DecimateParams params,
                                     int32_t target_triangles, int max_iterations) {
  const int32_t active = active_vertices(mesh);
  if (target_triangles < 1) throw std::invalid_argument("target must be at least 1 triangle");
  if (target_triangles > mesh.num_faces())
    throw std::invalid_argument("target of " + std::to_string(target_triangles) + " triangles exceeds the mesh's " +
                                std::to_string(mesh.num_faces()) + " triangles");
  // First guess from the input's triangle-to-vertex ratio, then correct by what came out.
  double vertices = double(target_triangles) * active / mesh.num_faces();
  if (params.refine >= 1.0 && !only_loose_triangles(mesh, layout)) {
    // The collapses stop at the triangle count itself: one pass.
    params.target_vertices = std::clamp(int32_t(std::lround(vertices)), 1, active);
    return refined(mesh, layout, params, target_triangles);
  }
  DecimateResult best;
  int32_t best_error = INT32_MAX, last_got = -1, last_drawn = -1;
  params.target_triangles = target_triangles;
  for (int it = 0; it < std::max(1, max_iterations); ++it) {
    params.target_vertices = std::clamp(int32_t(std::lround(vertices)), 1, active);
    DecimateResult r = decimate(mesh, layout, params);
    // The full decimation collapses this pass to the triangle target and stops: so does its draft.
    if (r.collapses_skipped) return r;
    const int32_t got = static_cast<int32_t>(r.triangles.size() / 3);
    const int32_t error = std::abs(got - target_triangles);
    const int32_t drawn = r.selected;
    if (error < best_error) {
      best_error = error;
      best = std::move(r);
    }
    if (error <= 0.01 * target_triangles || got == 0) break;
    // Fewer vertices asked and the same result, or within 1 % of it, from as many samples drawn
    // (the whole mesh where repairs left issues, or the lowest draw): the topology's floor. A
    // genus-2,000 slab at 1 % tried six ever lower targets for it, 0.5 s each. Small results go
    // on (their probes are cheap, and a lower draw still lands nearer: fertility at 50 triangles
    // after two of 56), as do results from a draw of the target's size.
    if (got > std::max(target_triangles, kFloorSearchFaces) && drawn == last_drawn &&
        std::abs(got - last_got) <= 0.01 * got)
      break;
    last_got = got, last_drawn = drawn;
    vertices = std::max(1.0, vertices * double(target_triangles) / got);
  }
  return best;
}

}  // namespace topstoc
