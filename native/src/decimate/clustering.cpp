#include "topstoc/decimate/clustering.hpp"
#include "topstoc/core/parallel.hpp"
#include "../core/byte_flags.hpp"
#include "../core/counting_sort.hpp"
#include "../core/per_thread.hpp"
#include "../core/portable.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace topstoc {

namespace {

inline int32_t dist_of(uint64_t key) { return int32_t(key >> 32); }
inline int32_t rank_of(uint64_t key) { return int32_t(key & 0xffffffffu); }
constexpr uint64_t kUnreached = kUnreachedKey;

// A key one thread found for a vertex another thread owns (relax_levels).
struct Lowering {
  int32_t vertex;
  uint64_t key;
};

// Level-synchronous relaxation from `frontier` (all at distance `level`): a neighbour improves
// when (level + 1, rank) beats what it holds. Each key ends a level at the smallest offer made
// to it, whichever thread made it and in whatever order, so the result is the same for any
// thread count. Threads own ranges of vertex ids and lower only their own keys, with plain
// stores; offers to another range are handed to its owner after the level (an atomic minimum
// on every key, the earlier scheme, was slower).
// Serves the full fill and incremental additions alike (only improvements propagate). With
// cross_edges, every edge between two clusters is recorded once, from its farther end, when
// both ends are final (only for a full fill).
// The loop is bound by memory latency: each level's frontier is a thin ring around every
// sample, spread over the whole mesh. So each frontier is walked in vertex order (vertices are
// numbered along a space-filling curve) and the rows and keys a few vertices ahead are
// prefetched, which cut the flood by about a third; discovery order, or cache-sized pieces
// flooded one at a time, measured no better. Fetching the neighbours' keys ahead as well costs
// more instructions than it saves.
// Seeds (flood_update: kept vertices around emptied clusters, as (distance << 32 | vertex),
// ordered by distance) join the frontier at the level of their distance.
void relax_levels(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> frontier, int32_t level,
                  std::vector<uint64_t>& key, std::vector<int32_t>* cross_edges, std::vector<int32_t>* changed,
                  const std::vector<uint64_t>& seeds = {}) {
  const int32_t n = mesh.num_vertices();
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  // Edge ids are read only at feature vertices and for cross edges: without either the mesh
  // need not build its edge tables.
  const int32_t* ae = cross_edges || layout.has_feature_vertices ? mesh.adjacency_edge().data() : nullptr;
  const auto& vertex_feature = layout.vertex_feature;
  const bool has_features = layout.has_feature_vertices;  // else vertex_feature is all zero (or empty)
  std::vector<uint8_t> queued(n, 0);
  const int threads = max_threads();
  PerThread<std::vector<int32_t>> next(threads), cross(threads);
  PerThread<std::vector<Lowering>> outboxes(threads);
  uint64_t* keys = key.data();
  uint8_t* in_next = queued.data();
  if (!std::is_sorted(frontier.begin(), frontier.end())) std::sort(frontier.begin(), frontier.end());
  size_t next_seed = 0;
  while (!frontier.empty() || next_seed < seeds.size()) {
    // Every vertex is lowered at one level at most, so the frontiers list each change once.
    if (changed) changed->insert(changed->end(), frontier.begin(), frontier.end());
    if (next_seed < seeds.size()) {
      if (frontier.empty()) level = std::max(level, int32_t(seeds[next_seed] >> 32));
      // A seed lowered by a new sample meanwhile relaxes from its new level (or is here already).
      for (; next_seed < seeds.size() && int32_t(seeds[next_seed] >> 32) <= level; ++next_seed) {
        const int32_t v = int32_t(uint32_t(seeds[next_seed]));
        if (dist_of(keys[v]) == level) frontier.push_back(v);
      }
      // (A seed lowered at this very level is listed twice: relaxing it again changes
      // nothing, and the frontier's order only matters for memory locality.)
      if (frontier.empty()) continue;
    }
    const uint64_t d = uint64_t(level) + 1;
    const int64_t count = int64_t(frontier.size());
    const int32_t* front = frontier.data();
    // Relaxes the neighbours of front[i] for the thread owning vertex ids [lo, hi): it alone
    // lowers their keys and queues them, with plain stores (locked instructions would stall
    // this latency-bound loop); a lowering outside goes to its outbox for the owner. Keys are
    // read with relaxed loads, as another thread may be lowering them. Cross: record the edges
    // between clusters (known at compile time, so the full fill's test costs nothing elsewhere).
    auto relax = [&](int64_t i, int32_t lo, int32_t hi, std::vector<int32_t>& mine, std::vector<int32_t>& my_cross,
                     std::vector<Lowering>& outbox, auto cross) {
      // The frontier is known ahead: fetch the rows and keys the next iterations will read.
      if (i + 16 < count) prefetch(&ao[front[i + 16]]);
      if (i + 8 < count) {
        const int32_t ahead = front[i + 8];
        prefetch(&adj[ao[ahead]]);
        prefetch(&keys[ahead]);
      }
      const int32_t v = front[i];
      const int32_t rank = rank_of(keys[v]);  // v's key is final
      const uint64_t candidate = (d << 32) | uint32_t(rank);
      const int32_t end = ao[v + 1];
      for (int32_t j = ao[v]; j < end; ++j) {
        const int32_t u = adj[j];
        const uint64_t held = __atomic_load_n(&keys[u], __ATOMIC_RELAXED);
        if constexpr (decltype(cross)::value) {
          // Keys at distance <= level are final during this pass.
          if (held != kUnreached && dist_of(held) <= level && rank_of(held) != rank && (dist_of(held) < level || u > v))
            my_cross.push_back(ae[j]);
        }
        if (candidate >= held) continue;
        // Feature vertices are entered only along feature edges.
        if (has_features && vertex_feature[u] && !layout.is_feature_edge(ae[j])) continue;
        if (u < lo || u >= hi) {
          outbox.push_back({u, candidate});
        } else {
          __atomic_store_n(&keys[u], candidate, __ATOMIC_RELAXED);
          if (!in_next[u]) {
            in_next[u] = 1;
            mine.push_back(u);
          }
        }
      }
    };
    auto relax_run = [&](int64_t begin, int64_t end, int32_t lo, int32_t hi, std::vector<int32_t>& mine,
                         std::vector<int32_t>& my_cross, std::vector<Lowering>& outbox) {
      if (cross_edges)
        for (int64_t i = begin; i < end; ++i) relax(i, lo, hi, mine, my_cross, outbox, std::true_type());
      else
        for (int64_t i = begin; i < end; ++i) relax(i, lo, hi, mine, my_cross, outbox, std::false_type());
    };
    const int team = count >= kParallelMin / 16 ? threads : 1;
    if (team == 1) {
      relax_run(0, count, 0, n, next[0], cross[0], outboxes[0]);
    } else {
      parallel_region(team, [&](Team& running) {
        // Each thread owns an equal range of vertex ids, near a region of the mesh (ids follow
        // a space-filling curve), and relaxes the run of the sorted frontier inside it. Few
        // edges join two ranges, so the outboxes stay short. The team may come out smaller
        // than asked: the ranges follow the team actually running.
        const int me = running.index(), size = running.size();
        const int32_t lo = int32_t(int64_t(n) * me / size), hi = int32_t(int64_t(n) * (me + 1) / size);
        const int64_t begin = std::lower_bound(front, front + count, lo) - front;
        const int64_t end = std::lower_bound(front, front + count, hi) - front;
        auto& mine = next[me];
        relax_run(begin, end, lo, hi, mine, cross[me], outboxes[me]);
        running.barrier();
        // The lowerings of this range found by the other threads; the smallest wins, as it
        // would in one pass, whatever the order.
        for (int t = 0; t < size; ++t) {
          if (t == me) continue;
          for (const Lowering& offer : outboxes[t]) {
            const int32_t u = offer.vertex;
            if (u < lo || u >= hi || offer.key >= keys[u]) continue;
            keys[u] = offer.key;
            if (!in_next[u]) {
              in_next[u] = 1;
              mine.push_back(u);
            }
          }
        }
      });
      for (int t = 0; t < team; ++t) outboxes[t].clear();
    }
    // Next frontier in vertex order: a short one sorted, a longer one read off the flags, eight
    // at a time (sorting a few ten thousand vertices per level was a third of the flood at 1 %).
    size_t total = 0;
    for (int t = 0; t < threads; ++t) total += next[t].size();
    frontier.clear();
    if (total * 256 < size_t(n)) {
      for (int t = 0; t < threads; ++t)
        for (int32_t u : next[t]) in_next[u] = 0;
      append_and_clear(next, frontier);
      std::sort(frontier.begin(), frontier.end());
    } else {
      for (int t = 0; t < threads; ++t) next[t].clear();
      const int64_t words = int64_t(n) / 8;
      parallel_region(team_for(n, kParallelMin), [&](Team& team) {  // the scan reads every flag, however few are set
        auto& mine = next.mine();
        team.for_static(0, words, [&](int64_t w) {
          const uint64_t word = flag_word(in_next + 8 * w);
          if (!word) return;
          std::memset(in_next + 8 * w, 0, 8);
          for (uint32_t bits = flag_bits(word); bits; bits &= bits - 1)
            mine.push_back(int32_t(8 * w + lowest_bit(bits)));
        });
      });
      for (int32_t v = int32_t(8 * words); v < n; ++v)  // the last few, past the whole words
        if (in_next[v]) {
          in_next[v] = 0;
          next[threads - 1].push_back(v);
        }
      append_and_clear(next, frontier);
    }
    if (cross_edges) append_and_clear(cross, *cross_edges);
    ++level;
  }
}

// Sets the samples from first_new on (distance 0) and relaxes from them. The keys of a full
// fill are set to unreached first; flood_add starts from the clustering it is given.
void seed_and_relax(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                    int32_t first_new, Clustering& c, std::vector<int32_t>* cross_edges,
                    std::vector<int32_t>* changed) {
  const int32_t n = mesh.num_vertices();
  std::vector<uint64_t>& key = c.key;
  if (first_new == 0) {  // a full fill: nothing reached yet (the clustering is not read)
    key.resize(n);
    parallel_for(0, n, kParallelMin, [&](int32_t v) { key[v] = kUnreached; });
  } else if (int32_t(key.size()) != n) {
    throw std::invalid_argument("flood_add: the clustering is not one of this mesh");
  }
  std::vector<int32_t> frontier;
  for (size_t r = size_t(first_new); r < samples.size(); ++r) {
    const int32_t s = samples[r];
    if (s < 0 || s >= n)
      throw std::invalid_argument("sample " + std::to_string(r) + " is vertex " + std::to_string(s) + ", outside [0, " +
                                  std::to_string(n) + ")");
    if (key[s] != kUnreached && dist_of(key[s]) == 0)
      throw std::invalid_argument("vertex " + std::to_string(s) + " is sampled twice");
    key[s] = cluster_key(0, static_cast<int32_t>(r));
    frontier.push_back(s);
  }
  relax_levels(mesh, layout, std::move(frontier), 0, key, cross_edges, changed);
}

// Kept clusters take their new ranks (new_rank[old rank], -1: removed); the vertices of removed
// ones are emptied and refilled from around them, with the added samples `frontier` (ranks
// added_rank) relaxing outwards: what flood() gives for the new list.
void rerank_and_refill(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& new_rank,
                       std::vector<int32_t> frontier, const std::vector<int32_t>& added_rank, Clustering& c,
                       std::vector<int32_t>* changed) {
  const int32_t n = mesh.num_vertices();
  std::vector<uint64_t>& key = c.key;
  const int threads = max_threads();
  PerThread<std::vector<int32_t>> emptied_by_thread(threads);
  parallel_region(team_for(n, kParallelMin), [&](Team& team) {
    auto& mine = emptied_by_thread.mine();
    team.for_static(0, n, [&](int32_t v) {
      const uint64_t k = key[v];
      if (k == kUnreached) return;
      const int32_t rank = new_rank[rank_of(k)];
      if (rank < 0) {
        key[v] = kUnreached;
        mine.push_back(v);
      } else {
        key[v] = cluster_key(dist_of(k), rank);
      }
    });
  });
  // Emptied vertices are refilled from the kept vertices around them, each entering the fill
  // at its own distance, and from the added samples (a multi-source search, as in flood()).
  // Seeds are listed once each (a flag per vertex) and ordered by distance with a stable
  // counting sort; within a distance they stay in the order found, near vertex order (sorting
  // them fully cost more than a fresh flood when a tenth of the samples went).
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  std::vector<uint64_t> found;
  std::vector<uint8_t> listed(n, 0);
  int32_t farthest = 0;
  for (int t = 0; t < threads; ++t) {
    const auto& emptied = emptied_by_thread[t];
    for (int32_t v : emptied)
      for (int32_t j = ao[v]; j < ao[v + 1]; ++j) {
        const int32_t u = adj[j];
        if (key[u] == kUnreached || listed[u]) continue;
        listed[u] = 1;
        found.push_back((uint64_t(dist_of(key[u])) << 32) | uint32_t(u));
        farthest = std::max(farthest, dist_of(key[u]));
      }
    if (changed) changed->insert(changed->end(), emptied.begin(), emptied.end());
  }
  std::vector<uint64_t> seeds(found.size());
  std::vector<int32_t> level_start;
  stable_counting_sort(
      int64_t(found.size()), farthest + 1, [&](int64_t i) { return int32_t(found[i] >> 32); },
      [&](int64_t i, int32_t at) { seeds[at] = found[i]; }, level_start);
  for (size_t i = 0; i < frontier.size(); ++i) key[frontier[i]] = cluster_key(0, added_rank[i]);
  relax_levels(mesh, layout, std::move(frontier), 0, key, nullptr, changed, seeds);
}

}  // namespace

void flood_update(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& old_samples,
                  const std::vector<int32_t>& samples, Clustering& c, std::vector<int32_t>* changed,
                  std::vector<int32_t>* new_rank_out) {
  const int32_t n = mesh.num_vertices();
  std::vector<uint64_t>& key = c.key;
  if (int32_t(key.size()) != n) throw std::invalid_argument("flood_update: the clustering is not one of this mesh");
  for (const auto* list : {&old_samples, &samples})
    for (size_t i = 0; i < list->size(); ++i)
      if ((*list)[i] < 0 || (*list)[i] >= n || (i > 0 && (*list)[i] <= (*list)[i - 1]))
        throw std::invalid_argument("flood_update: sample lists must be increasing vertex ids of the mesh");
  // Both lists are sorted, so the samples in both keep their order: their new ranks compare as
  // the old ones did, and every key of a kept cluster stays what flood() would give it.
  std::vector<int32_t> new_rank(old_samples.size(), -1), frontier, added_rank;
  for (size_t i = 0, j = 0; i < old_samples.size() || j < samples.size();) {
    if (j == samples.size() || (i < old_samples.size() && old_samples[i] < samples[j])) {
      ++i;  // removed
    } else if (i == old_samples.size() || samples[j] < old_samples[i]) {
      frontier.push_back(samples[j]);  // added
      added_rank.push_back(int32_t(j++));
    } else {
      new_rank[i++] = int32_t(j++);
    }
  }
  rerank_and_refill(mesh, layout, new_rank, std::move(frontier), added_rank, c, changed);
  if (new_rank_out) *new_rank_out = std::move(new_rank);
}

void flood_drop_tail(const Mesh& mesh, const FeatureLayout& layout, int32_t keep, int32_t count, Clustering& c) {
  if (int32_t(c.key.size()) != mesh.num_vertices() || keep < 0 || keep > count)
    throw std::invalid_argument("flood_drop_tail: the clustering is not one of this mesh");
  if (keep == count) return;
  std::vector<int32_t> new_rank(count, -1);
  std::iota(new_rank.begin(), new_rank.begin() + keep, 0);
  rerank_and_refill(mesh, layout, new_rank, {}, {}, c, nullptr);
}

void flood(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples, Clustering& out,
           std::vector<int32_t>* cross_edges) {
  if (cross_edges) cross_edges->clear();
  seed_and_relax(mesh, layout, samples, 0, out, cross_edges, nullptr);
}

void flood_add(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
               int32_t first_new, Clustering& c, std::vector<int32_t>* changed) {
  seed_and_relax(mesh, layout, samples, first_new, c, nullptr, changed);
}

int32_t step_towards_sample(const Mesh& mesh, const FeatureLayout& layout, const Clustering& c, int32_t x) {
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  int32_t best = -1;
  for (int32_t j = ao[x]; j < ao[x + 1]; ++j) {
    const int32_t p = adj[j];
    if (c.label(p) != c.label(x) || c.dist(p) != c.dist(x) - 1) continue;
    // The fill could not come this way (edge ids are read at feature vertices only).
    if (layout.is_feature_vertex(x) && !layout.is_feature_edge(mesh.adjacency_edge()[j])) continue;
    if (best < 0 || p < best) best = p;
  }
  return best;
}

}  // namespace topstoc
