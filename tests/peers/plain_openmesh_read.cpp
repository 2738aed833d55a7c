// Peer for bench_io.py: reads a mesh file with OpenMesh's readers (through a BaseImporter that
// only collects raw arrays, so no mesh kernel drops faces) and with topstoc::read_mesh_path, in
// the same process, and prints the median times and what each produced as one JSON line.
//
//   plain_openmesh_read FILE [RUNS]
#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "topstoc/io/io.hpp"

namespace {

using namespace OpenMesh;

// Collects positions and polygons; ignores every attribute.
class RawImporter : public IO::BaseImporter {
 public:
  std::vector<double> positions;
  std::vector<int32_t> corners;
  int64_t faces = 0;
  bool float_positions = false;  // the reader passed Vec3f

  VertexHandle add_vertex(const Vec3f& p) override {
    float_positions = true;
    positions.insert(positions.end(), {double(p[0]), double(p[1]), double(p[2])});
    return VertexHandle(int(positions.size() / 3) - 1);
  }
  VertexHandle add_vertex(const Vec3d& p) override {
    positions.insert(positions.end(), {p[0], p[1], p[2]});
    return VertexHandle(int(positions.size() / 3) - 1);
  }
  VertexHandle add_vertex() override {
    positions.insert(positions.end(), {0.0, 0.0, 0.0});
    return VertexHandle(int(positions.size() / 3) - 1);
  }
  void set_point(VertexHandle v, const Vec3f& p) override {
    float_positions = true;
    for (int k = 0; k < 3; ++k) positions[3 * size_t(v.idx()) + k] = p[k];
  }
  FaceHandle add_face(const VHandles& vertices) override {
    for (const auto& v : vertices) corners.push_back(v.idx());
    return FaceHandle(int(faces++));
  }
  size_t n_vertices() const override { return positions.size() / 3; }
  size_t n_faces() const override { return size_t(faces); }
  size_t n_edges() const override { return 0; }

  // Everything else is not needed here.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_status(VertexHandle, const Attributes::StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(HalfedgeHandle, const Attributes::StatusInfo&) override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_status(EdgeHandle, const Attributes::StatusInfo&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void set_status(FaceHandle, const Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE [RUNS]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  std::vector<double> openmesh_times, topstoc_times;
  RawImporter last;
  bool openmesh_ok = true;
  topstoc::MeshFile ours;
  for (int run = 0; run < runs; ++run) {
    RawImporter importer;
    IO::Options options;
    auto start = std::chrono::steady_clock::now();
    openmesh_ok = IO::IOManager().read(path, importer, options) && openmesh_ok;
    openmesh_times.push_back(seconds_since(start));
    last = std::move(importer);

    start = std::chrono::steady_clock::now();
    try {
      ours = topstoc::read_mesh_path(path);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "topstoc: %s\n", error.what());
      return 1;
    }
    topstoc_times.push_back(seconds_since(start));
  }
  std::printf(
      "{\"file\": \"%s\", \"runs\": %d, \"openmesh\": {\"ok\": %s, \"median_seconds\": %.6f, \"vertices\": %zu, "
      "\"faces\": %lld, \"float_positions\": %s}, \"topstoc\": {\"median_seconds\": %.6f, \"vertices\": %lld, "
      "\"polygons\": %lld, \"triangles\": %lld}}\n",
      path.c_str(), runs, openmesh_ok ? "true" : "false", median(openmesh_times), last.n_vertices(),
      static_cast<long long>(last.faces), last.float_positions ? "true" : "false", median(topstoc_times),
      static_cast<long long>(ours.num_vertices()), static_cast<long long>(ours.polygons),
      static_cast<long long>(ours.num_triangles()));
  return 0;
}
