#include "topology/loop_basis.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <memory>
#include <functional>
#include <stdexcept>
#include <tuple>

#include "core/portable.hpp"
#include "topology/ball_cycles.hpp"
#include "topology/shortest_paths.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

std::vector<std::vector<int32_t>> simple_cycles(const ClosedSurface& s, const std::vector<int32_t>& edges) {
  // Remaining cycle edges around each vertex (small lists: a cycle has few edges per vertex).
  std::vector<std::pair<int32_t, int32_t>> incidences;  // (vertex, edge)
  for (int32_t e : edges) {
    incidences.emplace_back(s.edge_vertices[2 * size_t(e)], e);
    incidences.emplace_back(s.edge_vertices[2 * size_t(e) + 1], e);
  }
  std::sort(incidences.begin(), incidences.end());
  std::vector<uint8_t> used_edge(s.num_edges(), 0);
  auto next_edge = [&](int32_t v) {
    auto it = std::lower_bound(incidences.begin(), incidences.end(), std::make_pair(v, -1));
    for (; it != incidences.end() && it->first == v; ++it)
      if (!used_edge[it->second]) return it->second;
    return -1;
  };
  auto other = [&](int32_t e, int32_t v) {
    const int32_t a = s.edge_vertices[2 * size_t(e)];
    return a == v ? s.edge_vertices[2 * size_t(e) + 1] : a;
  };
  // Walk along unused edges; whenever the walk returns to a vertex on it, cut off that cycle.
  std::vector<std::vector<int32_t>> cycles;
  std::vector<int32_t> walk;
  std::vector<int32_t> position_on_walk(s.num_vertices(), -1);
  for (const auto& start : incidences) {
    if (used_edge[start.second]) continue;
    walk.assign(1, start.first);
    position_on_walk[start.first] = 0;
    while (!walk.empty()) {
      const int32_t v = walk.back();
      const int32_t e = next_edge(v);
      if (e < 0) {  // dead end: only happens when the edge set is not a cycle
        for (int32_t u : walk) position_on_walk[u] = -1;
        walk.clear();
        break;
      }
      used_edge[e] = 1;
      const int32_t u = other(e, v);
      if (position_on_walk[u] >= 0) {
        const int32_t from = position_on_walk[u];
        cycles.emplace_back(walk.begin() + from, walk.end());
        for (size_t i = from + 1; i < walk.size(); ++i) position_on_walk[walk[i]] = -1;
        walk.resize(from + 1);
        if (walk.size() == 1 && next_edge(u) < 0) {
          position_on_walk[u] = -1;
          walk.clear();
        }
      } else {
        position_on_walk[u] = int32_t(walk.size());
        walk.push_back(u);
      }
    }
  }
  return cycles;
}

double loop_length(const ClosedSurface& s, const std::vector<int32_t>& loop, const std::vector<double>& weight) {
  double total = 0.0;
  for (size_t i = 0; i < loop.size(); ++i) total += weight[s.find_edge(loop[i], loop[(i + 1) % loop.size()])];
  return total;
}

namespace {

enum Kind { kHandle = 0, kTunnel = 1, kNeither = 2 };

struct Candidate {
  double length;
  int32_t kind;
  int64_t order;  // tie-break: creation order (deterministic)
  std::vector<int32_t> vertices;
  Z2Vector cls;
};

// Pairs each of the k loops with one of the k cycles whose coefficient is 1 (Kuhn's matching;
// a perfect matching exists because the coefficient matrix is invertible over Z2).
std::vector<int32_t> match(const std::vector<std::vector<uint8_t>>& coefficient) {
  const int32_t k = int32_t(coefficient.size());
  std::vector<int32_t> cycle_of_loop(k, -1), loop_of_cycle(k, -1);
  for (int32_t start = 0; start < k; ++start) {
    std::vector<uint8_t> visited(k, 0);
    std::function<bool(int32_t)> augment = [&](int32_t loop) {
      for (int32_t c = 0; c < k; ++c) {
        if (!coefficient[loop][c] || visited[c]) continue;
        visited[c] = 1;
        if (loop_of_cycle[c] < 0 || augment(loop_of_cycle[c])) {
          loop_of_cycle[c] = loop;
          cycle_of_loop[loop] = c;
          return true;
        }
      }
      return false;
    };
    if (!augment(start)) throw std::logic_error("the chosen loops are not a basis of their subspace");
  }
  return cycle_of_loop;
}

// A basis in echelon form (rows by their top bit) that only answers "independent?": the global
// pick tests thousands of candidates and needs neither the combinations nor the sources that
// Z2Basis keeps. Rows keep their insertion order, so it also answers "in the span of the first
// k rows?".
class Span {
 public:
  explicit Span(int32_t dim) : words_((dim + 63) / 64), pivot_(dim, -1), x_(words_) {}
  int32_t rank() const { return int32_t(rows_.size() / std::max(words_, 1)); }
  /// Adds v when it is independent of the rows; returns whether it was.
  bool insert(const Z2Vector& v) {
    if (reduce(v, rank())) return false;
    pivot_[top_] = rank();
    rows_.insert(rows_.end(), x_.begin(), x_.end());
    return true;
  }
  /// Whether v lies in the span of the first k rows.
  bool spans(const Z2Vector& v, int32_t k) { return reduce(v, k); }

 private:
  // v reduced by the first k rows into x_ (its top bit into top_); true when that leaves zero.
  // Rows have distinct top bits, so a top bit without such a row means v is outside the span.
  bool reduce(const Z2Vector& v, int32_t k) {
    std::copy(v.words.begin(), v.words.end(), x_.begin());
    for (int32_t w = words_ - 1; w >= 0;) {
      if (!x_[w]) {
        --w;
        continue;
      }
      top_ = 64 * w + highest_bit(x_[w]);
      if (pivot_[top_] < 0 || pivot_[top_] >= k) return false;
      const uint64_t* row = &rows_[size_t(words_) * pivot_[top_]];
      for (int32_t j = 0; j <= w; ++j) x_[j] ^= row[j];
    }
    return true;
  }

  int32_t words_, top_ = -1;
  std::vector<int32_t> pivot_;
  std::vector<uint64_t> rows_, x_;
};

// Sorts the candidates shortest first and takes, per kind, those that extend the kind's basis
// (a matroid greedy: the result is a shortest basis among the candidates). Returns the picks
// per kind; both have g entries when the candidates span both subspaces.
std::array<std::vector<const Candidate*>, 2> pick_shortest(std::vector<Candidate>& candidates, int32_t dim, int32_t g) {
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.length, x.order) < std::tie(y.length, y.order);
  });
  Span chosen[2] = {Span(dim), Span(dim)};
  std::array<std::vector<const Candidate*>, 2> picked;
  for (const auto& c : candidates) {
    if (chosen[c.kind].rank() < g && chosen[c.kind].insert(c.cls)) picked[c.kind].push_back(&c);
    if (chosen[0].rank() == g && chosen[1].rank() == g) break;
  }
  return picked;
}

// A candidate loop found from a root: the fundamental cycle of non-tree edge `edge`, at most
// `bound` long (through the root), of the given kind.
struct LocalCycle {
  double bound;
  int32_t edge, kind;
};

// One run of select_loops: the homology coordinates, the candidates found so far and the
// roots grown from. The stages run in the order of run().
class LoopSelection {
 public:
  LoopSelection(const ClosedSurface& s, const SurfaceHomology& h, const std::vector<PersistentCycle>& cycles,
                const std::vector<double>& weight, int32_t max_roots, Progress* progress)
      : s(s), h(h), cycles(cycles), weight(weight), max_roots(max_roots), progress(progress), dim(h.dimension()),
        g(dim / 2), n(s.num_vertices()), words((dim + 63) / 64), split(dim) {}

  std::vector<SelectedLoop> run() {
    if (g == 0) return {};
    to_cycle_coordinates();
    convert_edge_classes();
    collect_cycle_pieces();
    seed_roots();
    lower_cutoff();  // the persistence cycles' pieces often span already: no tree grows unbounded
    grow_from_roots();
    // Shortest first, keep what extends the handle or the tunnel basis.
    const auto picked = pick_shortest(candidates, dim, g);
    if (int32_t(picked[0].size()) < g || int32_t(picked[1].size()) < g)
      throw std::logic_error("found only " + std::to_string(picked[0].size()) + " handle and " +
                             std::to_string(picked[1].size()) + " tunnel loops that are simple, of " + std::to_string(g));
    return match_to_generators(picked);
  }

 private:
  const ClosedSurface& s;
  const SurfaceHomology& h;
  const std::vector<PersistentCycle>& cycles;
  const std::vector<double>& weight;
  int32_t max_roots;
  Progress* progress;
  const int32_t dim, g, n, words;
  std::vector<const PersistentCycle*> ordered;  // handle cycles, then tunnel cycles
  Z2Basis split;
  std::vector<Z2Vector> to_cycle_basis;  // row i: generator i's unit vector in the cycle basis
  std::vector<uint64_t> edge_class;      // each edge's class in cycle coordinates, `words` words each
  std::vector<Candidate> candidates;
  int64_t order = 0;
  std::vector<int32_t> roots, root_kind;  // the kind of the cycle a root was put on (kNeither: none)
  std::vector<uint8_t> is_root;
  double cutoff = ShortestPaths::kInfinity;  // no pick is longer: the larger of the two below
  double kind_cutoff[2] = {ShortestPaths::kInfinity, ShortestPaths::kInfinity};  // per kind

  // Coordinates in the basis (handle cycles, tunnel cycles) tell the two subspaces apart: bits
  // 0..g-1 are the handle cycles' coefficients, g..2g-1 the tunnel cycles'. Every class below is
  // kept in these coordinates, so telling a handle from a tunnel reads two halves of a bit
  // vector instead of eliminating against the cycle basis once per edge and root (which made
  // the selection cubic in the genus).
  void to_cycle_coordinates() {
    for (const auto& c : cycles) if (c.handle) ordered.push_back(&c);
    for (const auto& c : cycles) if (!c.handle) ordered.push_back(&c);
    for (const auto* c : ordered)
      if (!split.insert(h.class_of_edges(c->edges)))
        throw std::logic_error("the handle and tunnel cycles are not independent in H1");
    to_cycle_basis.resize(dim);
    for (int32_t i = 0; i < dim; ++i) {
      Z2Vector unit(dim);
      unit.flip(i);
      split.reduce(unit, to_cycle_basis[i]);
    }
  }

  Z2Vector in_cycle_basis(const Z2Vector& x) const {
    Z2Vector c(dim);
    for (int32_t i = 0; i < dim; ++i)
      if (x.get(i)) c.add(to_cycle_basis[i]);
    return c;
  }

  // Each edge's coordinates, converted once.
  void convert_edge_classes() {
    edge_class.assign(size_t(words) * s.num_edges(), 0);
    for (int32_t e = 0; e < s.num_edges(); ++e) {
      uint64_t* x = &edge_class[size_t(words) * e];
      h.for_each_crossing(e, [&](int32_t j, int) {
        for (int32_t k = 0; k < words; ++k) x[k] ^= to_cycle_basis[j].words[k];
      });
    }
  }

  void add_edge(uint64_t* x, int32_t e) const {
    const uint64_t* c = &edge_class[size_t(words) * e];
    for (int32_t k = 0; k < words; ++k) x[k] ^= c[k];
  }

  int32_t kind_of(const Z2Vector& c) const {
    bool handle_part = false, tunnel_part = false;
    for (int32_t k = 0; k < words; ++k) {
      const uint64_t w = c.words[k];
      if (!w) continue;
      const int32_t lo = 64 * k;  // bits lo..lo+63 of this word; bit i is a handle when i < g
      const uint64_t handle_mask = g <= lo ? 0 : g - lo >= 64 ? ~uint64_t(0) : (uint64_t(1) << (g - lo)) - 1;
      if (w & handle_mask) handle_part = true;
      if (w & ~handle_mask) tunnel_part = true;
    }
    if (handle_part == tunnel_part) return int32_t(kNeither);  // mixed, or the zero class
    return handle_part ? int32_t(kHandle) : int32_t(kTunnel);
  }

  // The simple pieces of the persistence cycles.
  void collect_cycle_pieces() {
    for (const auto* c : ordered)
      for (auto& loop : simple_cycles(s, c->edges)) {
        Z2Vector cls = in_cycle_basis(h.class_of_loop(s, loop));
        const int32_t kind = kind_of(cls);
        if (kind == kNeither) continue;
        const double length = loop_length(s, loop, weight);
        candidates.push_back({length, kind, order++, std::move(loop), std::move(cls)});
      }
  }

  void add_root(int32_t v, int32_t kind) {
    if (!is_root[v]) {
      is_root[v] = 1;
      roots.push_back(v);
      root_kind.push_back(kind);
    }
  }

  // Roots: spread along each persistence cycle, then farthest-point samples (grow_from_roots).
  // One root on every cycle before the second on any: the short loops of every handle appear
  // early, so the cutoff falls early. A root on a cycle is there for loops of that cycle's kind.
  void seed_roots() {
    is_root.assign(n, 0);
    auto kind = [](const PersistentCycle* c) { return int32_t(c->handle ? kHandle : kTunnel); };
    // Longest cycles first: their pieces set the first cutoffs, and a root on them finds the
    // short loop that replaces them, so the cutoff falls before many trees have grown far.
    std::vector<const PersistentCycle*> by_length = ordered;
    std::stable_sort(by_length.begin(), by_length.end(),
                     [](const PersistentCycle* a, const PersistentCycle* b) { return a->edges.size() > b->edges.size(); });
    for (const auto* c : by_length) add_root(s.edge_vertices[2 * size_t(c->generator_edge)], kind(c));
    for (const auto* c : by_length) {
      const size_t k = c->edges.size();
      for (size_t i = 1; i <= 3 && k; ++i) add_root(s.edge_vertices[2 * size_t(c->edges[(i * k) / 4 % k])], kind(c));
    }
    if (max_roots <= 0) max_roots = 12 + 4 * dim;
    max_roots = std::min(max_roots, n);
  }

  // No loop of a kind longer than its cutoff can be chosen: the candidates found so far that
  // are at most that long already span the kind's subspace, and the final pick takes loops
  // shortest first. So each root only grows its tree to half the larger cutoff and looks at the
  // edges inside it, and longer candidates are dropped: once every handle has a root nearby, a
  // root costs what lies near it, not the whole surface, and the selection grows about
  // linearly with the genus.
  void lower_cutoff() {
    const auto picked = pick_shortest(candidates, dim, g);
    if (int32_t(picked[0].size()) < g || int32_t(picked[1].size()) < g) return;
    for (int32_t kind : {0, 1}) kind_cutoff[kind] = picked[kind].back()->length;
    cutoff = std::max(kind_cutoff[0], kind_cutoff[1]);
    // A candidate not picked is in the span of shorter picks, now and later: only the picks
    // stay candidates, and a new one must be independent of the picks shorter than itself.
    std::vector<uint8_t> is_pick(candidates.size(), 0);
    for (const auto& kind : picked)
      for (const Candidate* c : kind) is_pick[c - candidates.data()] = 1;
    std::vector<Candidate> kept;
    for (size_t i = 0; i < candidates.size(); ++i)
      if (is_pick[i]) kept.push_back(std::move(candidates[i]));
    candidates = std::move(kept);
    for (int32_t kind : {0, 1}) {
      shorter_picks[kind] = Span(dim);
      pick_lengths[kind].clear();
    }
    for (const auto& c : candidates) {  // shortest first
      shorter_picks[c.kind].insert(c.cls);
      pick_lengths[c.kind].push_back(c.length);
    }
  }

  // Whether a cycle of this kind, class and length is in the span of shorter picks (never picked).
  bool spanned_by_shorter(int32_t kind, const Z2Vector& cls, double length) {
    const auto& lengths = pick_lengths[kind];
    const int32_t k = int32_t(std::lower_bound(lengths.begin(), lengths.end(), length) - lengths.begin());
    return k > 0 && shorter_picks[kind].spans(cls, k);
  }
  Span shorter_picks[2] = {Span(0), Span(0)};
  std::vector<double> pick_lengths[2];

  // One member's scratch for growing trees from roots.
  struct RootWork {
    explicit RootWork(const LoopSelection& ls)
        : sp(ls.s, ls.weight), prefix(size_t(ls.words) * ls.n), nearest_root(ls.n, ShortestPaths::kInfinity),
          mark(ls.n, 0), ball(ls.s) {}
    ShortestPaths sp;
    std::vector<uint64_t> prefix;
    std::vector<double> nearest_root;  // over the roots this member grew
    std::vector<uint32_t> mark;
    uint32_t mark_stamp = 0;
    std::vector<LocalCycle> local;
    BallCycles ball;
  };

  // Whether lower_cutoff runs after root r: often enough to follow the cutoff down, rarely
  // enough that the picks cost little.
  static bool lowers_cutoff_after(size_t r) { return (r & (r + 1)) == 0 || r % 64 == 63; }

  // Per root: a shortest-path tree to the cutoff, the classes of its paths, and the
  // fundamental cycles of its non-tree edges that extend a kind's basis. Roots between two
  // lower_cutoff calls see the same cutoffs and picks, so they grow on the team; their
  // candidates join in root order (as one after the other would give).
  void grow_from_roots() {
    std::vector<std::unique_ptr<RootWork>> work(size_t(std::max(1, max_threads())));
    for (size_t r = 0; r < roots.size() && int32_t(r) < max_roots;) {
      size_t end = r + 1;
      while (!lowers_cutoff_after(end - 1) && end < roots.size() && int32_t(end) < max_roots) ++end;
      std::vector<std::vector<Candidate>> found(end - r);
      std::atomic<int64_t> next{int64_t(r)};
      parallel_region(end - r >= 2 ? int(work.size()) : 1, [&](Team& team) {
        auto& mine = work[size_t(team.index())];
        if (!mine) mine = std::make_unique<RootWork>(*this);
        team.for_dynamic(next, int64_t(end), 1, [&](int64_t i) {
          if (progress && team.index() == 0) progress->update(double(i) / max_roots);
          grow_from_root(size_t(i), *mine, found[size_t(i) - r]);
        });
      });
      for (auto& list : found)
        for (auto& c : list)
          if (!spanned_by_shorter(c.kind, c.cls, c.length)) {
            c.order = order++;
            candidates.push_back(std::move(c));
          }
      if (lowers_cutoff_after(end - 1)) lower_cutoff();
      r = end;
      // Next root: the persistence-cycle roots first, then the vertex farthest from all roots.
      if (r == roots.size() && int32_t(roots.size()) < max_roots) {
        int32_t far = -1;
        double far_distance = 0.0;
        for (int32_t v = 0; v < n; ++v) {
          double nearest = ShortestPaths::kInfinity;
          for (const auto& w : work)
            if (w) nearest = std::min(nearest, w->nearest_root[v]);
          if (!is_root[v] && (far < 0 || nearest > far_distance)) far = v, far_distance = nearest;
        }
        if (far >= 0) add_root(far, kNeither);
      }
    }
  }

  // Root r's tree and the cycles through it that extend their kind's basis at this root.
  void grow_from_root(size_t r, RootWork& w, std::vector<Candidate>& found) const {
    // A cycle through the root at most `cutoff` long stays within half of it from the root; a
    // root on a persistence cycle looks as far as its kind's loops need (about half the work
    // when one kind's loops are much the longer, as the tunnels through a thick part).
    const double reach = root_kind[r] == kNeither ? cutoff : kind_cutoff[root_kind[r]];
    w.sp.run({roots[r]}, [](int32_t) { return true; }, [](int32_t) { return true; }, -1, reach / 2);
    path_classes(w.sp, w.prefix, w.nearest_root);
    local_cycles(w.sp, w.prefix, w.local);
    take_local_cycles(w, found);
  }

  // Class of the tree path from the root to each settled vertex.
  void path_classes(const ShortestPaths& sp, std::vector<uint64_t>& prefix, std::vector<double>& nearest_root) const {
    for (int32_t v : sp.settled()) {
      uint64_t* pv = &prefix[size_t(words) * v];
      const int32_t p = sp.parent(v);
      if (p < 0) {
        std::fill(pv, pv + words, 0);
      } else {
        std::copy(&prefix[size_t(words) * p], &prefix[size_t(words) * p] + words, pv);
        add_edge(pv, sp.parent_edge(v));
      }
      nearest_root[v] = std::min(nearest_root[v], sp.distance(v));
    }
  }

  // The class of the fundamental cycle of non-tree edge e = (a, b), into cls.
  void cycle_class(const std::vector<uint64_t>& prefix, int32_t a, int32_t b, int32_t e, Z2Vector& cls) const {
    for (int32_t k = 0; k < words; ++k) cls.words[k] = prefix[size_t(words) * a + k] ^ prefix[size_t(words) * b + k];
    add_edge(cls.words.data(), e);
  }

  // Fundamental cycles of the non-tree edges between settled vertices within the cutoff, of
  // one kind.
  void local_cycles(const ShortestPaths& sp, const std::vector<uint64_t>& prefix, std::vector<LocalCycle>& local) const {
    local.clear();
    Z2Vector cls(dim);
    for (int32_t a : sp.settled())
      for (int32_t i = s.adjacency_offsets[a]; i < s.adjacency_offsets[a + 1]; ++i) {
        const int32_t b = s.adjacency[i], e = s.adjacency_edge[i];
        if (b < a || !sp.is_settled(b) || sp.parent_edge(a) == e || sp.parent_edge(b) == e) continue;
        const double bound = sp.distance(a) + weight[e] + sp.distance(b);
        if (bound > cutoff) continue;
        cycle_class(prefix, a, b, e, cls);
        const int32_t kind = kind_of(cls);
        if (kind != kNeither && bound <= kind_cutoff[kind]) local.push_back({bound, e, kind});
      }
  }

  // The local cycles that extend their kind's basis of the shorter ones at this root (shortest
  // through the root first, ties by edge), found by union-find on the ball, into `found` (the
  // caller drops those spanned by shorter picks and numbers the rest).
  void take_local_cycles(RootWork& w, std::vector<Candidate>& found) const {
    auto& local = w.local;
    std::sort(local.begin(), local.end(),
              [](const LocalCycle& x, const LocalCycle& y) { return std::tie(x.bound, x.edge) < std::tie(y.bound, y.edge); });
    std::vector<int32_t> edges;
    std::vector<int8_t> group;
    for (const auto& c : local) edges.push_back(c.edge), group.push_back(int8_t(c.kind));
    w.ball.start(w.sp, edges, group);
    std::vector<uint8_t> keep;
    for (int32_t kind : {int32_t(kHandle), int32_t(kTunnel)}) {
      edges.clear();
      for (const auto& c : local)
        if (c.kind == kind) edges.push_back(c.edge);
      w.ball.independent(int8_t(kind), edges, keep);
      for (size_t i = 0; i < edges.size(); ++i) {
        if (!keep[i]) continue;
        const int32_t a = s.edge_vertices[2 * size_t(edges[i])], b = s.edge_vertices[2 * size_t(edges[i]) + 1];
        Z2Vector cls(dim);
        cycle_class(w.prefix, a, b, edges[i], cls);
        auto loop = tree_cycle(w, a, b);
        const double length = loop_length(s, loop, weight);
        found.push_back({length, kind, 0, std::move(loop), std::move(cls)});
      }
    }
  }

  // The simple cycle through non-tree edge (a, b): tree paths from a and b up to their lowest
  // common ancestor, as lca ... a, then b ... (child of lca).
  static std::vector<int32_t> tree_cycle(RootWork& w, int32_t a, int32_t b) {
    const ShortestPaths& sp = w.sp;
    ++w.mark_stamp;
    for (int32_t v = a; v >= 0; v = sp.parent(v)) w.mark[v] = w.mark_stamp;
    int32_t lca = b;
    while (w.mark[lca] != w.mark_stamp) lca = sp.parent(lca);
    std::vector<int32_t> loop;
    for (int32_t v = a; v != lca; v = sp.parent(v)) loop.push_back(v);
    loop.push_back(lca);
    std::reverse(loop.begin(), loop.end());
    std::vector<int32_t> down;
    for (int32_t v = b; v != lca; v = sp.parent(v)) down.push_back(v);
    loop.insert(loop.end(), down.begin(), down.end());
    return loop;
  }

  // Match loops with generator edges through their coefficients in the persistence basis.
  std::vector<SelectedLoop> match_to_generators(const std::array<std::vector<const Candidate*>, 2>& picked) const {
    std::vector<SelectedLoop> out;
    for (int32_t kind : {int32_t(kHandle), int32_t(kTunnel)}) {
      std::vector<std::vector<uint8_t>> coefficient(g, std::vector<uint8_t>(g, 0));
      for (int32_t k = 0; k < g; ++k)
        for (int32_t i = 0; i < g; ++i) coefficient[k][i] = picked[kind][k]->cls.get(kind == kHandle ? i : g + i);
      const auto cycle_of_loop = match(coefficient);
      for (int32_t k = 0; k < g; ++k) {
        SelectedLoop loop;
        loop.handle = kind == kHandle;
        loop.vertices = picked[kind][k]->vertices;
        loop.length = picked[kind][k]->length;
        loop.generator_edge = ordered[(kind == kHandle ? 0 : g) + cycle_of_loop[k]]->generator_edge;
        out.push_back(std::move(loop));
      }
    }
    return out;
  }
};

}  // namespace

std::vector<SelectedLoop> select_loops(const ClosedSurface& s, const SurfaceHomology& h, const std::vector<PersistentCycle>& cycles,
                                       const std::vector<double>& weight, int32_t max_roots, Progress* progress) {
  return LoopSelection(s, h, cycles, weight, max_roots, progress).run();
}

}  // namespace topstoc
