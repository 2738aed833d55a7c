#include "topology/coarse_surface.hpp"

#include <algorithm>
#include <cmath>

#include "topstoc/decimate/features.hpp"
#include "topstoc/core/self_intersections.hpp"

namespace topstoc {

namespace {

void describe(const Mesh& mesh, CoarseMesh& coarse) {
  const auto& d = coarse.decimation;
  coarse.topology_kept = d.issues_remaining.topological() == 0;
  coarse.mesh = std::make_unique<Mesh>(d.vertices, d.triangles.data(), int64_t(d.triangles.size() / 3));
  coarse.components = component_vertices(*coarse.mesh);
  coarse.checks = check_closed_surfaces(*coarse.mesh, coarse.components);
  coarse.fine_component.clear();
  for (const auto& vertices : coarse.components) {
    const int32_t output_vertex = coarse.mesh->vertex_source()[vertices.front()];
    coarse.fine_component.push_back(mesh.component()[mesh.vertex_index()[d.kept[output_vertex]]]);
  }
}

// Coarse vertices (output ids) of the triangles that intersect within a wanted component. A
// coarse vertex belongs to the component of the input vertex it was made from, so this needs
// no prepared coarse mesh.
std::vector<int32_t> intersecting_vertices(const Mesh& mesh, const DecimateResult& d, const std::vector<uint8_t>& wanted,
                                           int32_t& pairs) {
  const int32_t num_triangles = int32_t(d.triangles.size() / 3);
  const int32_t num_vertices = int32_t(d.vertices.size() / 3);
  auto component_of_triangle = [&](int32_t t) {
    return mesh.component()[mesh.vertex_index()[d.kept[d.triangles[3 * size_t(t)]]]];
  };
  std::vector<uint8_t> flagged(num_vertices, 0);
  pairs = 0;
  for (const auto& [s, t] : self_intersections(d.vertices.data(), num_vertices, d.triangles.data(), num_triangles)) {
    const int32_t c = component_of_triangle(s);
    if (c != component_of_triangle(t) || !wanted[c]) continue;
    ++pairs;
    for (int32_t k = 0; k < 3; ++k) {
      flagged[d.triangles[3 * size_t(s) + k]] = 1;
      flagged[d.triangles[3 * size_t(t) + k]] = 1;
    }
  }
  std::vector<int32_t> out;
  for (int32_t v = 0; v < num_vertices; ++v)
    if (flagged[v]) out.push_back(v);
  return out;
}

}  // namespace

std::unique_ptr<CoarseMesh> make_coarse_mesh(const Mesh& mesh, int32_t target, uint64_t seed,
                                             const std::vector<uint8_t>& wanted, int32_t max_rounds, Progress* progress) {
  auto coarse = std::make_unique<CoarseMesh>();
  const auto layout = build_feature_layout(mesh, nullptr, 0, nullptr, 0);
  DecimateParams params;
  params.target_vertices = target;
  params.sampling.seed = seed;
  coarse->decimation = decimate(mesh, *layout, params);
  const auto& source = mesh.vertex_source();
  for (;;) {
    const auto flagged = intersecting_vertices(mesh, coarse->decimation, wanted, coarse->intersecting);
    if (flagged.empty() || coarse->rounds >= max_rounds) break;
    if (progress) progress->update(double(coarse->rounds + 1) / double(max_rounds + 1));
    // Split each flagged cluster in three: add the member farthest from its sample, then the
    // member farthest from both (one new sample per cluster leaves a long tail of rounds).
    const auto& d = coarse->decimation;
    std::vector<int32_t> slot(d.kept.size(), -1);
    for (size_t i = 0; i < flagged.size(); ++i) slot[flagged[i]] = int32_t(i);
    std::vector<uint8_t> is_sample(mesh.num_vertices(), 0);  // by caller id
    for (int32_t s : d.samples) is_sample[s] = 1;
    auto squared = [](const double* p, const double* q) {
      return (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
    };
    std::vector<int32_t> first(flagged.size(), -1), second(flagged.size(), -1);
    for (std::vector<int32_t>* pick : {&first, &second}) {
      std::vector<double> reach(flagged.size(), 0.0);
      for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
        const int32_t caller = source[v];
        const int32_t c = d.labels[caller];
        if (c < 0 || slot[c] < 0 || is_sample[caller]) continue;
        const int32_t i = slot[c];
        double r = squared(mesh.position(v), mesh.position(mesh.vertex_index()[d.kept[c]]));
        if (pick == &second) {
          if (first[i] < 0 || caller == first[i]) continue;
          r = std::min(r, squared(mesh.position(v), mesh.position(mesh.vertex_index()[first[i]])));
        }
        if (r > reach[i]) {
          reach[i] = r;
          (*pick)[i] = caller;
        }
      }
    }
    std::vector<int32_t> samples = d.samples;
    const size_t before = samples.size();
    for (size_t i = 0; i < flagged.size(); ++i)
      for (int32_t v : {first[i], second[i]})
        if (v >= 0) samples.push_back(v);
    std::sort(samples.begin() + before, samples.end());
    samples.erase(std::unique(samples.begin() + before, samples.end()), samples.end());
    coarse->samples_added += int32_t(samples.size() - before);
    if (samples.size() == before) break;
    coarse->decimation = decimate_with_samples(mesh, *layout, std::move(samples), Placement::Subsample);
    ++coarse->rounds;
  }
  describe(mesh, *coarse);
  return coarse;
}

}  // namespace topstoc
