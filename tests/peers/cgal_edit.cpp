// CGAL peer for topology editing (tests and benchmarks only).
//
//   cgal_edit self-intersections MESH.off
//       prints the pairs of triangles (indices in file order) that intersect other than along a
//       shared edge or vertex, one "i j" per line, then "pairs N".
//   cgal_edit fill-holes MESH.off [REPEATS [OUT.off]]
//       fills every hole with CGAL's triangulate_hole (Liepa's minimum-weight triangulation,
//       no refinement, no fairing) on a fresh copy of the mesh REPEATS times (default 1) and
//       prints "holes H triangles T seconds S cpu C": medians of wall and process CPU time of
//       the filling alone (reading, finding the holes and copying excluded).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <ctime>
#include <chrono>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

// Triangles in file order (polygons fan-triangulated), so face i of the mesh is triangle i.
bool read(const std::string& path, Mesh& mesh) {
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  if (!CGAL::IO::read_polygon_soup(path, points, polygons)) return false;
  std::vector<Mesh::Vertex_index> ids;
  for (const Point& p : points) ids.push_back(mesh.add_vertex(p));
  for (const auto& polygon : polygons)
    for (std::size_t i = 1; i + 1 < polygon.size(); ++i)
      if (mesh.add_face(ids[polygon[0]], ids[polygon[i]], ids[polygon[i + 1]]) == Mesh::null_face()) {
        std::cerr << "cgal_edit: triangle " << mesh.number_of_faces() << " is not manifold-compatible\n";
        return false;
      }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: cgal_edit self-intersections MESH.off | fill-holes MESH.off [REPEATS [OUT.off]]\n";
    return 2;
  }
  const std::string mode = argv[1];
  Mesh mesh;
  if (!read(argv[2], mesh)) {
    std::cerr << "cgal_edit: cannot read " << argv[2] << " as a manifold triangle mesh\n";
    return 1;
  }
  if (mode == "self-intersections") {
    std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
    PMP::self_intersections(mesh, std::back_inserter(pairs));
    for (const auto& p : pairs) std::cout << std::size_t(p.first) << " " << std::size_t(p.second) << "\n";
    std::cout << "pairs " << pairs.size() << "\n";
    return 0;
  }
  if (mode == "fill-holes") {
    const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 1;
    std::vector<double> walls, cpus;
    std::size_t holes = 0, added = 0;
    Mesh filled;
    for (int run = 0; run < repeats; ++run) {
      Mesh copy = mesh;
      std::vector<Mesh::Halfedge_index> borders;
      std::vector<bool> seen(copy.number_of_halfedges(), false);
      for (Mesh::Halfedge_index h : copy.halfedges())
        if (copy.is_border(h) && !seen[std::size_t(h)]) {
          borders.push_back(h);
          for (Mesh::Halfedge_index g : CGAL::halfedges_around_face(h, copy)) seen[std::size_t(g)] = true;
        }
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpu_start = std::clock();
      added = 0;
      for (Mesh::Halfedge_index h : borders) {
        std::vector<Mesh::Face_index> patch;
        PMP::triangulate_hole(copy, h, std::back_inserter(patch));
        added += patch.size();
      }
      cpus.push_back(double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
      walls.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      holes = borders.size();
      filled = std::move(copy);
    }
    std::sort(walls.begin(), walls.end());
    std::sort(cpus.begin(), cpus.end());
    std::cout << "holes " << holes << " triangles " << added << " seconds " << walls[walls.size() / 2] << " cpu "
              << cpus[cpus.size() / 2] << "\n";
    if (argc > 4) CGAL::IO::write_polygon_mesh(argv[4], filled, CGAL::parameters::stream_precision(17));
    return 0;
  }
  std::cerr << "cgal_edit: unknown mode " << mode << "\n";
  return 2;
}
