// Peer for the Hausdorff measurement: CGAL's figures for two triangle meshes, as JSON.
//
//   cgal_hausdorff A B [ERROR_BOUND_FRACTION [MEAN_SAMPLES [SEED [skip-bounded]]]]
//
// For each direction (forward = A to B, backward = B to A):
//   max_bounded  CGAL::Polygon_mesh_processing::bounded_error_Hausdorff_distance with an error
//                bound of ERROR_BOUND_FRACTION (default 0.001) times A's bounding-box diagonal:
//                the true one-sided Hausdorff distance lies within that bound of it;
//   mean, rms, sampled_max  over MEAN_SAMPLES (default 1,000,000) points drawn uniformly by area
//                on the source surface (CGAL's sample_triangle_mesh, random uniform, SEED), each
//                measured with an AABB tree over the target (accelerated distance queries);
//   query_seconds the time of those MEAN_SAMPLES distance queries (tree built beforehand),
//   tree_seconds, bounded_seconds.
// CGAL runs sequentially here (no TBB).
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <string>
#include <vector>

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<SurfaceMesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Reads a polygon soup and makes a mesh of it; non-manifold vertices are duplicated (orienting
// the soup), which changes no point of the surface and so no distance.
bool load(const char* path, SurfaceMesh& mesh) {
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  if (!CGAL::IO::read_polygon_soup(path, points, polygons) || polygons.empty()) return false;
  PMP::orient_polygon_soup(points, polygons);
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  if (mesh.is_empty()) return false;
  if (!CGAL::is_triangle_mesh(mesh)) PMP::triangulate_faces(mesh);
  return true;
}

struct Direction {
  double max_bounded = -1, bounded_seconds = 0;
  double mean = 0, rms = 0, sampled_max = 0, query_seconds = 0, tree_seconds = 0;
  std::size_t samples = 0;
};

Direction measure(const SurfaceMesh& from, const SurfaceMesh& to, double error_bound, std::size_t samples,
                  unsigned seed, bool bounded) {
  Direction d;
  if (bounded) {
    auto start = std::chrono::steady_clock::now();
    d.max_bounded = PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(from, to, error_bound);
    d.bounded_seconds = seconds_since(start);
  }
  std::vector<Point> points;
  PMP::sample_triangle_mesh(from, std::back_inserter(points),
                            CGAL::parameters::use_random_uniform_sampling(true)
                                .number_of_points_on_faces(samples)
                                .do_sample_vertices(false)
                                .do_sample_edges(false)
                                .random_seed(seed));
  auto start = std::chrono::steady_clock::now();
  Tree tree(faces(to).first, faces(to).second, to);
  tree.accelerate_distance_queries();
  d.tree_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  double sum = 0, sum2 = 0, max = 0;
  for (const Point& p : points) {
    const double d2 = CGAL::to_double(tree.squared_distance(p));
    const double x = std::sqrt(d2);
    sum += x;
    sum2 += d2;
    max = std::max(max, x);
  }
  d.query_seconds = seconds_since(start);
  d.samples = points.size();
  d.mean = points.empty() ? 0 : sum / double(points.size());
  d.rms = points.empty() ? 0 : std::sqrt(sum2 / double(points.size()));
  d.sampled_max = max;
  return d;
}

void print(const char* name, const Direction& d, bool last) {
  std::printf("  \"%s\": {\"max_bounded\": %.17g, \"bounded_seconds\": %.6f, \"mean\": %.17g, \"rms\": %.17g, "
              "\"sampled_max\": %.17g, \"samples\": %zu, \"query_seconds\": %.6f, \"tree_seconds\": %.6f}%s\n",
              name, d.max_bounded, d.bounded_seconds, d.mean, d.rms, d.sampled_max, d.samples, d.query_seconds,
              d.tree_seconds, last ? "" : ",");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s A B [ERROR_BOUND_FRACTION [MEAN_SAMPLES [SEED [skip-bounded]]]]\n", argv[0]);
    return 2;
  }
  const double fraction = argc > 3 ? std::atof(argv[3]) : 0.001;
  const std::size_t samples = argc > 4 ? std::size_t(std::atoll(argv[4])) : 1000000;
  const unsigned seed = argc > 5 ? unsigned(std::atoi(argv[5])) : 1;
  const bool bounded = !(argc > 6 && std::string(argv[6]) == "skip-bounded");
  SurfaceMesh a, b;
  if (!load(argv[1], a)) {
    std::fprintf(stderr, "cannot read %s\n", argv[1]);
    return 1;
  }
  if (!load(argv[2], b)) {
    std::fprintf(stderr, "cannot read %s\n", argv[2]);
    return 1;
  }
  const CGAL::Bbox_3 box = PMP::bbox(a);
  const double diagonal = std::sqrt((box.xmax() - box.xmin()) * (box.xmax() - box.xmin()) +
                                    (box.ymax() - box.ymin()) * (box.ymax() - box.ymin()) +
                                    (box.zmax() - box.zmin()) * (box.zmax() - box.zmin()));
  const double error_bound = fraction * diagonal;
  const Direction forward = measure(a, b, error_bound, samples, seed, bounded);
  const Direction backward = measure(b, a, error_bound, samples, seed + 1, bounded);
  std::printf("{\n  \"diagonal\": %.17g,\n  \"error_bound\": %.17g,\n", diagonal, error_bound);
  print("forward", forward, false);
  print("backward", backward, true);
  std::printf("}\n");
  return 0;
}
