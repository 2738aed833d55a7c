// Readers and writers: a mesh written in each format reads back with equal arrays (what the
// format stores: OBJ and OFF polygons and colours, PLY also UVs, STL float32 positions only).
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshes.hpp"
#include "topstoc/io/io.hpp"

using namespace topstoc;

namespace {

MeshFile sample_file(bool float32_exact) {
  const auto grid = topstoc_test::grid(3, 2);
  MeshFile f;
  f.vertices = grid.positions;
  std::mt19937 random(31);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  for (double& x : f.vertices) x = float32_exact ? double(float(x + jitter(random))) : x + jitter(random) / 3.0;
  f.triangles = grid.triangles;
  for (int32_t t = 0; t < f.num_triangles(); ++t) f.triangle_polygon.push_back(t);
  f.polygons = f.num_triangles();
  return f;
}

MeshFile round_trip(const MeshFile& f, MeshFormat format) {
  const std::string bytes = write_mesh_file(f, format);
  return read_mesh_file(bytes.data(), bytes.size(), format);
}

}  // namespace

TEST_CASE("OBJ, PLY and OFF round trips keep positions, triangles and polygons exactly") {
  const MeshFile f = sample_file(false);  // doubles that float32 would change
  for (MeshFormat format : {MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Off}) {
    CAPTURE(int(format));
    const MeshFile back = round_trip(f, format);
    CHECK(back.vertices == f.vertices);
    CHECK(back.triangles == f.triangles);
    CHECK(back.triangle_polygon == f.triangle_polygon);
    CHECK(back.polygons == f.polygons);
  }
}

TEST_CASE("STL round trip: float32 positions, triangles welded back in order of first use") {
  const MeshFile f = sample_file(true);
  const MeshFile back = round_trip(f, MeshFormat::Stl);
  REQUIRE(back.num_triangles() == f.num_triangles());
  // STL stores corners, not shared vertices: compare the corner positions triangle by triangle.
  for (int64_t t = 0; t < f.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k)
        CHECK(back.vertices[3 * size_t(back.triangles[3 * t + c]) + k] ==
              f.vertices[3 * size_t(f.triangles[3 * t + c]) + k]);
  CHECK(back.num_vertices() == f.num_vertices());  // every grid vertex is used, so welding finds them all
}

TEST_CASE("colours round-trip through OBJ, PLY and OFF, UVs through OBJ and PLY") {
  MeshFile f = sample_file(false);
  for (int64_t v = 0; v < f.num_vertices(); ++v)
    for (int c = 0; c < 3; ++c) f.vertex_colors.push_back(double((7 * v + 50 * c) % 256) / 255.0);
  f.color_channels = 3;
  for (int64_t t = 0; t < f.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c) {  // per-vertex UVs: the same at every corner of a vertex
      const int32_t v = f.triangles[3 * t + c];
      f.corner_uvs.insert(f.corner_uvs.end(), {0.125 * v, 0.25 * (v % 3)});
    }
  for (MeshFormat format : {MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Off}) {
    CAPTURE(int(format));
    const MeshFile back = round_trip(f, format);
    CHECK(back.color_channels == 3);
    REQUIRE(back.vertex_colors.size() == f.vertex_colors.size());
    for (size_t i = 0; i < f.vertex_colors.size(); ++i)
      CHECK(back.vertex_colors[i] == doctest::Approx(f.vertex_colors[i]).epsilon(1e-6));
    if (format != MeshFormat::Off) CHECK(back.corner_uvs == f.corner_uvs);
  }
}

TEST_CASE("OBJ round trip keeps material names per triangle") {
  MeshFile f = sample_file(false);
  f.material_names = {"wood", "steel"};
  for (int64_t t = 0; t < f.num_triangles(); ++t) f.triangle_material.push_back(t < 4 ? -1 : int32_t(t % 2));
  const MeshFile back = round_trip(f, MeshFormat::Obj);
  CHECK(back.material_names == f.material_names);
  CHECK(back.triangle_material == f.triangle_material);
}

TEST_CASE("a written file read with a byte or line more, or cut short, is refused (issue 37)") {
  const MeshFile f = sample_file(true);
  const auto refused = [](const std::string& bytes, MeshFormat format) {
    try {
      read_mesh_file(bytes.data(), bytes.size(), format);
    } catch (const std::invalid_argument&) {
      return true;
    }
    return false;
  };
  for (MeshFormat format : {MeshFormat::Ply, MeshFormat::Off, MeshFormat::Stl}) {
    const std::string bytes = write_mesh_file(f, format);
    CHECK_FALSE(refused(bytes, format));
    CHECK(refused(bytes + (format == MeshFormat::Off ? "3 0 1 2\n" : "x"), format));
    CHECK(refused(bytes.substr(0, bytes.size() - (format == MeshFormat::Off ? 8 : 1)), format));
  }
  // Binary PLY: one line end after the body is what some tools write, and still reads.
  const std::string ply = write_mesh_file(f, MeshFormat::Ply);
  CHECK_FALSE(refused(ply + "\n", MeshFormat::Ply));
  CHECK_FALSE(refused(ply + "\r\n", MeshFormat::Ply));
  CHECK(refused(ply + "\n\n", MeshFormat::Ply));
  // OBJ has no counts: an unterminated last face line that is incomplete was cut.
  const std::string obj = write_mesh_file(f, MeshFormat::Obj);
  const std::string cut = obj.substr(0, obj.rfind(' '));  // the last face without its last corner
  CHECK(refused(cut, MeshFormat::Obj));
  CHECK_FALSE(refused(obj.substr(0, obj.size() - 1), MeshFormat::Obj));  // whole, no final line end
}
