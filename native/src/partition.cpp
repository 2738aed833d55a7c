#include "topstoc/partition.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <unordered_map>

namespace topstoc {

namespace {

inline uint64_t pair_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

// Adds one sample per group of unreached vertices (the lowest id of each group).
void seed_unreached(const Mesh& mesh, const Clustering& c, Partition& out) {
  const int32_t n = mesh.num_vertices();
  const auto& vfo = mesh.vertex_face_offsets();
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  std::vector<uint8_t> seen(n, 0);
  std::vector<int32_t> stack;
  for (int32_t v = 0; v < n; ++v) {
    if (c.label[v] >= 0 || vfo[v] == vfo[v + 1] || seen[v]) continue;
    out.new_samples.push_back(v);
    seen[v] = 1;
    stack.push_back(v);
    while (!stack.empty()) {
      const int32_t x = stack.back();
      stack.pop_back();
      ++out.issues.unreached;
      for (int32_t i = ao[x]; i < ao[x + 1]; ++i) {
        const int32_t u = adj[i];
        if (!seen[u] && c.label[u] < 0) {
          seen[u] = 1;
          stack.push_back(u);
        }
      }
    }
  }
}

// Does the set of oriented link arcs a -> b around one sample form a single path or cycle?
bool single_fan(std::vector<std::array<int32_t, 2>>& arcs) {
  if (arcs.empty()) return false;
  std::sort(arcs.begin(), arcs.end());
  for (size_t i = 1; i < arcs.size(); ++i)
    if (arcs[i][0] == arcs[i - 1][0]) return false;  // two arcs leave the same neighbour
  std::vector<int32_t> targets;
  for (const auto& a : arcs) targets.push_back(a[1]);
  std::sort(targets.begin(), targets.end());
  for (size_t i = 1; i < targets.size(); ++i)
    if (targets[i] == targets[i - 1]) return false;  // two arcs enter the same neighbour
  // Start at the one source that is nobody's target (a path), or anywhere (a cycle).
  int32_t start = arcs[0][0];
  int32_t starts = 0;
  for (const auto& a : arcs)
    if (!std::binary_search(targets.begin(), targets.end(), a[0])) {
      start = a[0];
      ++starts;
    }
  if (starts > 1) return false;
  auto next = [&](int32_t v) {
    auto it = std::lower_bound(arcs.begin(), arcs.end(), std::array<int32_t, 2>{v, INT32_MIN});
    return (it != arcs.end() && (*it)[0] == v) ? (*it)[1] : INT32_MIN;
  };
  size_t walked = 0;
  for (int32_t v = start; walked <= arcs.size();) {
    const int32_t w = next(v);
    if (w == INT32_MIN) break;  // end of a path
    ++walked;
    if (w == start) break;  // closed the cycle
    v = w;
  }
  return walked == arcs.size();
}

}  // namespace

Partition check_partition(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                          const Clustering& c, const std::vector<uint8_t>& required, bool check_slivers,
                          const std::vector<int32_t>* candidate_faces) {
  Partition out;
  const int32_t n = mesh.num_vertices();
  const int32_t k = static_cast<int32_t>(samples.size());
  const auto& label = c.label;
  for (int32_t v = 0; v < n; ++v)
    if (label[v] < 0 && mesh.vertex_face_offsets()[v] != mesh.vertex_face_offsets()[v + 1]) {
      seed_unreached(mesh, c, out);
      return out;  // the other checks need every vertex in a cluster
    }

  std::vector<uint8_t> split(k, 0);
  auto mark = [&](int32_t s) { split[s] = 1; };

  // --- one pass over vertices and over faces with more than one cluster -----------------------
  std::vector<int64_t> chi6(k, 0);
  for (int32_t v = 0; v < n; ++v)
    if (label[v] >= 0) chi6[label[v]] += layout.chi_constant[v];
  const auto& faces = mesh.faces();
  const auto& fe = mesh.face_edges();
  const auto& efo = mesh.edge_face_offsets();
  const auto& ef = mesh.edge_faces();
  const auto& ev = mesh.edge_vertices();
  struct FeaturePair {
    int32_t copies = 0;
    bool seen = false;
  };
  std::unordered_map<uint64_t, FeaturePair> feature_pairs;
  auto visit_face = [&](int32_t f) {
    const int32_t la = label[faces[3 * f]], lb = label[faces[3 * f + 1]], lc = label[faces[3 * f + 2]];
    if (la == lb && lb == lc) return;
    chi6[la] -= 2, chi6[lb] -= 2, chi6[lc] -= 2;
    if (la != lb && lb != lc && lc != la) {
      out.triangles.insert(out.triangles.end(), {la, lb, lc});
      out.source_face.push_back(f);
    }
    for (int s = 0; s < 3; ++s) {
      const int32_t e = fe[3 * f + s];
      if (ef[efo[e]] != f) continue;  // each edge once, from its first face
      const int32_t lx = label[ev[2 * e]], ly = label[ev[2 * e + 1]];
      if (lx == ly) continue;
      const int32_t copies = layout.edge_copies(mesh, e);
      chi6[lx] += 3 * copies, chi6[ly] += 3 * copies;
      if (layout.edge_feature[e]) feature_pairs[pair_key(lx, ly)].copies += copies;
    }
  };
  if (candidate_faces) {
    for (int32_t f : *candidate_faces) visit_face(f);
  } else {
    for (int32_t f = 0; f < mesh.num_faces(); ++f) visit_face(f);
  }
  for (int32_t s = 0; s < k; ++s)
    if (chi6[s] != 6 * int64_t(layout.sectors[samples[s]])) {
      ++out.issues.non_disk;
      mark(s);
    }

  // --- pillows and duplicates ---------------------------------------------------------------
  // Three clusters can meet at two faces: a small cluster sits between two others that wrap
  // around it, touching it along its whole border. The nerve then holds their triangle twice,
  // facing opposite ways, and the small cluster has no other triangle. Dropping both copies
  // gives the nerve of the partition in which the small cluster joined its neighbours, so no
  // sample is needed. Any other repetition is a real violation.
  {
    const int32_t emitted = static_cast<int32_t>(out.source_face.size());
    std::vector<int32_t> bucket_offsets(k + 1, 0), bucket(emitted);
    auto lowest = [&](int32_t i) {
      return std::min({out.triangles[3 * i], out.triangles[3 * i + 1], out.triangles[3 * i + 2]});
    };
    for (int32_t i = 0; i < emitted; ++i) ++bucket_offsets[lowest(i) + 1];
    for (int32_t s = 0; s < k; ++s) bucket_offsets[s + 1] += bucket_offsets[s];
    {
      std::vector<int32_t> fill(bucket_offsets.begin(), bucket_offsets.end() - 1);
      for (int32_t i = 0; i < emitted; ++i) bucket[fill[lowest(i)]++] = i;
    }
    // Rotate so the lowest rank comes first; then same orientation <=> same (b, c).
    auto rotated = [&](int32_t i) {
      const int32_t* t = &out.triangles[3 * size_t(i)];
      const int j = t[0] == lowest(i) ? 0 : t[1] == lowest(i) ? 1 : 2;
      return std::array<int32_t, 2>{t[(j + 1) % 3], t[(j + 2) % 3]};
    };
    std::vector<uint8_t> drop(emitted, 0);
    // Triangles per cluster before dropping: a pillow is the artifact only when one of its
    // clusters has nothing else (that cluster is then absorbed by its neighbours).
    std::vector<int32_t> incident(k, 0);
    for (int32_t x : out.triangles) ++incident[x];
    for (int32_t s = 0; s < k; ++s)
      for (int32_t a = bucket_offsets[s]; a < bucket_offsets[s + 1]; ++a) {
        const auto ra = rotated(bucket[a]);
        int32_t same = 0, opposite = -1, repeats = 0;
        for (int32_t b = bucket_offsets[s]; b < bucket_offsets[s + 1]; ++b) {
          if (a == b) continue;
          const auto rb = rotated(bucket[b]);
          if (rb == ra) ++same, ++repeats;
          if (rb[0] == ra[1] && rb[1] == ra[0]) opposite = bucket[b], ++repeats;
        }
        if (repeats == 0) continue;
        const int32_t* tri = &out.triangles[3 * size_t(bucket[a])];
        const bool absorbs = incident[tri[0]] == 2 || incident[tri[1]] == 2 || incident[tri[2]] == 2;
        if (repeats == 1 && same == 0 && absorbs) {
          if (!drop[bucket[a]]) ++out.issues.pillows;
          drop[bucket[a]] = drop[opposite] = 1;
        } else if (!drop[bucket[a]]) {
          ++out.issues.duplicate;
          for (int j = 0; j < 3; ++j) mark(out.triangles[3 * size_t(bucket[a]) + j]);
        }
      }
    int32_t kept = 0;
    for (int32_t i = 0; i < emitted; ++i) {
      if (drop[i]) continue;
      for (int j = 0; j < 3; ++j) out.triangles[3 * size_t(kept) + j] = out.triangles[3 * size_t(i) + j];
      out.source_face[kept++] = out.source_face[i];
    }
    out.triangles.resize(3 * size_t(kept));
    out.source_face.resize(kept);
  }

  // --- decimated triangles around each sample ----------------------------------------------
  const int32_t t = static_cast<int32_t>(out.source_face.size());
  std::vector<int32_t> around_offsets(k + 1, 0), around;
  for (int32_t x : out.triangles) ++around_offsets[x + 1];
  for (int32_t s = 0; s < k; ++s) around_offsets[s + 1] += around_offsets[s];
  around.resize(out.triangles.size());
  {
    std::vector<int32_t> fill(around_offsets.begin(), around_offsets.end() - 1);
    for (int32_t i = 0; i < t; ++i)
      for (int j = 0; j < 3; ++j) around[fill[out.triangles[3 * i + j]]++] = i;
  }
  // Euler characteristic of the output per input component, to compare with the input's.
  const int32_t num_components = mesh.num_components();
  std::vector<int64_t> component_chi(num_components, 0);
  out.absorbed.assign(k, 0);
  for (int32_t s = 0; s < k; ++s)
    if (around_offsets[s] < around_offsets[s + 1]) ++component_chi[mesh.component()[samples[s]]];
  for (int32_t i = 0; i < t; ++i) ++component_chi[mesh.component()[samples[out.triangles[3 * i]]]];
  std::vector<std::pair<int32_t, int32_t>> neighbour_count;
  std::vector<std::array<int32_t, 2>> link;
  for (int32_t s = 0; s < k; ++s) {
    const int32_t b = around_offsets[s], e = around_offsets[s + 1];
    if (b == e) {
      // No triangle: the neighbours absorbed this cluster (the pillow case), unless the sample
      // must stay. The Euler characteristic check below confirms the topology either way.
      if (required[samples[s]] || layout.vertex_corner[samples[s]]) {
        ++out.issues.isolated;
        mark(s);
      } else {
        ++out.issues.absorbed;
        out.absorbed[s] = 1;
      }
      continue;
    }
    neighbour_count.clear();
    link.clear();
    for (int32_t i = b; i < e; ++i) {
      const int32_t* tri = &out.triangles[3 * size_t(around[i])];
      const int j = tri[0] == s ? 0 : tri[1] == s ? 1 : 2;
      const int32_t next = tri[(j + 1) % 3], prev = tri[(j + 2) % 3];
      link.push_back({next, prev});
      for (int32_t other : {next, prev}) {
        auto it = std::find_if(neighbour_count.begin(), neighbour_count.end(),
                               [&](const auto& p) { return p.first == other; });
        if (it == neighbour_count.end()) neighbour_count.push_back({other, 1});
        else ++it->second;
      }
    }
    for (const auto& [other, count] : neighbour_count)
      if (other > s) --component_chi[mesh.component()[samples[s]]];  // each edge once
    for (const auto& [other, count] : neighbour_count) {
      if (other < s) continue;  // each pair once
      int32_t expected = 2;
      auto it = feature_pairs.find(pair_key(s, other));
      if (it != feature_pairs.end()) {
        expected = it->second.copies;
        it->second.seen = true;
      }
      if (count != expected) {
        ++out.issues.bad_edge;
        mark(s), mark(other);
      }
    }
    if (mesh.manifold_vertex()[samples[s]] && !single_fan(link)) {
      ++out.issues.bad_link;
      mark(s);
    }
  }
  for (const auto& [key, pair] : feature_pairs)
    if (!pair.seen) {
      ++out.issues.bad_edge;
      mark(int32_t(key >> 32)), mark(int32_t(key & 0xffffffffu));
    }

  for (int32_t comp = 0; comp < num_components; ++comp)
    if (component_chi[comp] != mesh.component_euler()[comp]) ++out.issues.bad_component;
  if (out.issues.bad_component > 0 && out.issues.topological() == out.issues.bad_component) {
    // No local check names a culprit: split the widest cluster of each failing component.
    std::vector<int32_t> widest(num_components, -1);
    for (int32_t v = 0; v < n; ++v) {
      const int32_t comp = mesh.component()[v];
      if (label[v] < 0 || component_chi[comp] == mesh.component_euler()[comp]) continue;
      if (widest[comp] < 0 || c.dist[v] > c.dist[widest[comp]]) widest[comp] = v;
    }
    for (int32_t v : widest)
      if (v >= 0) out.new_samples.push_back(v);
  }

  // --- closed feature curves need three clusters to stay loops -----------------------------
  for (int32_t curve = 0; curve < layout.num_curves(); ++curve) {
    if (!layout.curve_closed[curve]) continue;
    const int32_t b = layout.curve_offsets[curve], e = layout.curve_offsets[curve + 1];
    int32_t changes = 0, farthest = -1;
    for (int32_t i = b; i < e; ++i) {
      const int32_t v = layout.curve_vertices[i];
      const int32_t w = layout.curve_vertices[i + 1 < e ? i + 1 : b];
      changes += label[v] != label[w];
      if (c.dist[v] > 0 && (farthest < 0 || c.dist[v] > c.dist[farthest])) farthest = v;
    }
    if (changes < 3) {
      ++out.issues.short_loop;
      if (farthest >= 0) out.new_samples.push_back(farthest);
    }
  }

  // --- triangles of zero area (collinear samples) ------------------------------------------
  if (check_slivers) {
    for (int32_t i = 0; i < t; ++i) {
      const double* p[3];
      for (int j = 0; j < 3; ++j) p[j] = mesh.position(samples[out.triangles[3 * i + j]]);
      double u[3], w[3], longest = 0;
      for (int a = 0; a < 3; ++a) {
        u[a] = p[1][a] - p[0][a];
        w[a] = p[2][a] - p[0][a];
      }
      for (int j = 0; j < 3; ++j) {
        const double* q0 = p[j];
        const double* q1 = p[(j + 1) % 3];
        longest = std::max(longest, (q1[0] - q0[0]) * (q1[0] - q0[0]) + (q1[1] - q0[1]) * (q1[1] - q0[1]) +
                                        (q1[2] - q0[2]) * (q1[2] - q0[2]));
      }
      const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2], cz = u[0] * w[1] - u[1] * w[0];
      const double area2 = std::sqrt(cx * cx + cy * cy + cz * cz);
      if (area2 <= 1e-9 * longest) {
        ++out.issues.sliver;
        for (int j = 0; j < 3; ++j) mark(out.triangles[3 * i + j]);
      }
    }
  }

  for (int32_t s = 0; s < k; ++s)
    if (split[s]) out.split_clusters.push_back(s);
  return out;
}

}  // namespace topstoc
