// Peer timing for the decimation benchmark: meshoptimizer's simplifiers on a mesh file.
//
//   meshopt_bench IN TARGET_FRACTION [REPEATS]
//
// Reads IN with topstoc's reader (the same input our engine sees), converts it to meshopt's
// float positions and 32-bit indices, then times meshopt_simplify (edge collapse, topology
// kept, target_error 1 = unbounded) and meshopt_simplifySloppy (grid clustering) REPEATS times
// each for TARGET_FRACTION of the index count. Prints one JSON line with the median seconds,
// the vertices and triangles kept, and the minimum seconds.
#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "topstoc/io/io.hpp"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

size_t used_vertices(const std::vector<unsigned>& indices, size_t vertex_count) {
  std::vector<char> used(vertex_count, 0);
  for (unsigned i : indices) used[i] = 1;
  return size_t(std::count(used.begin(), used.end(), 1));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s IN TARGET_FRACTION [REPEATS]\n", argv[0]);
    return 2;
  }
  const double fraction = std::atof(argv[2]);
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 5;
  const topstoc::MeshFile mesh = topstoc::read_mesh_path(argv[1]);
  std::vector<float> positions(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<unsigned> indices(mesh.triangles.begin(), mesh.triangles.end());
  const size_t vertex_count = positions.size() / 3;
  const size_t target = size_t(fraction * double(indices.size())) / 3 * 3;
  std::printf("{\"vertices\": %zu, \"triangles\": %zu, \"target_index_count\": %zu", vertex_count,
              indices.size() / 3, target);
  for (int sloppy = 0; sloppy < 2; ++sloppy) {
    std::vector<double> seconds;
    std::vector<unsigned> out(indices.size());
    size_t count = 0;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      count = sloppy ? meshopt_simplifySloppy(out.data(), indices.data(), indices.size(), positions.data(),
                                              vertex_count, sizeof(float) * 3, target, 1.0f, nullptr)
                     : meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(), vertex_count,
                                        sizeof(float) * 3, target, 1.0f, 0, nullptr);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    out.resize(count);
    std::printf(", \"%s\": {\"median_seconds\": %.6f, \"min_seconds\": %.6f, \"vertices\": %zu, \"triangles\": %zu}",
                sloppy ? "simplify_sloppy" : "simplify", median(seconds),
                *std::min_element(seconds.begin(), seconds.end()), used_vertices(out, vertex_count), count / 3);
  }
  std::printf("}\n");
  return 0;
}
