// What every reader fuzz target checks (fuzz_read_*.cpp): the reader either throws
// std::invalid_argument or returns arrays that agree with each other; what it returns is then
// written back in the same format and read again, and the second read must equal the first in
// everything the format carries. A writer may refuse only OBJ names that would not read back.
// Any other exception, a disagreement or a sanitizer report ends the run (abort = a crash for
// libFuzzer, which keeps the input).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "topstoc/io/io.hpp"

namespace topstoc::fuzz {

[[noreturn]] inline void fail(const char* what) {
  std::fprintf(stderr, "fuzz check failed: %s\n", what);
  std::abort();
}

inline void require(bool ok, const char* what) {
  if (!ok) fail(what);
}

// The arrays of one MeshFile agree in size and every index is in range.
inline void check_consistent(const MeshFile& mesh) {
  const size_t n = mesh.vertices.size() / 3, m = mesh.triangles.size() / 3;
  require(mesh.vertices.size() % 3 == 0, "positions not 3 per vertex");
  require(mesh.triangles.size() % 3 == 0, "triangles not 3 per triangle");
  require(mesh.triangle_polygon.size() == m, "triangle_polygon size");
  require(mesh.corner_uvs.empty() || mesh.corner_uvs.size() == 6 * m, "corner_uvs size");
  require(mesh.color_channels == 0 || mesh.color_channels == 3 || mesh.color_channels == 4, "color_channels");
  require(mesh.vertex_colors.size() == size_t(mesh.color_channels) * n, "vertex_colors size");
  require(mesh.triangle_material.empty() || mesh.triangle_material.size() == m, "triangle_material size");
  for (int32_t v : mesh.triangles) require(v >= 0 && size_t(v) < n, "triangle index out of range");
  for (int32_t id : mesh.triangle_material)
    require(id >= -1 && id < int32_t(mesh.material_names.size()), "material id out of range");
  for (size_t t = 1; t < m; ++t) require(mesh.triangle_polygon[t] >= mesh.triangle_polygon[t - 1], "polygon order");
  require(mesh.skipped_faces >= 0 && mesh.polygons >= mesh.skipped_faces, "face counts");
}

inline bool has_uvs(const MeshFile& mesh) {
  for (double x : mesh.corner_uvs)
    if (!std::isnan(x)) return true;
  return false;
}

inline bool same_number(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

inline bool same_numbers(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!same_number(a[i], b[i])) return false;
  return true;
}

// Triangles t and t-1 belong to the same polygon of the file.
inline std::vector<bool> polygon_starts(const MeshFile& mesh) {
  std::vector<bool> starts(mesh.triangle_polygon.size());
  for (size_t t = 0; t < starts.size(); ++t) starts[t] = t == 0 || mesh.triangle_polygon[t] != mesh.triangle_polygon[t - 1];
  return starts;
}

// Material name of each triangle ("" = none).
inline std::vector<std::string> triangle_materials(const MeshFile& mesh) {
  std::vector<std::string> names(mesh.triangles.size() / 3);
  for (size_t t = 0; t < mesh.triangle_material.size(); ++t)
    if (mesh.triangle_material[t] >= 0) names[t] = mesh.material_names[size_t(mesh.triangle_material[t])];
  return names;
}

// STL keeps a triangle soup of float32 positions: compare corner positions, not vertex ids.
inline std::vector<float> float_soup(const MeshFile& mesh) {
  std::vector<float> soup;
  for (int32_t v : mesh.triangles)
    for (int k = 0; k < 3; ++k) soup.push_back(float(mesh.vertices[3 * size_t(v) + k]));
  return soup;
}

inline bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  return true;
}

inline void check_round_trip(const MeshFile& first, MeshFormat format) {
  std::string bytes;
  try {
    bytes = write_mesh_file(first, format);
  } catch (const std::invalid_argument& error) {
    // OBJ has no escapes: names that would read back differently are refused, with a message.
    if (format == MeshFormat::Obj && std::strstr(error.what(), "cannot be written to OBJ")) return;
    std::fprintf(stderr, "writer refused a mesh its reader returned: %s\n", error.what());
    std::abort();
  }
  MeshFile second;
  try {
    second = read_mesh_file(bytes.data(), bytes.size(), format);
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "written file does not read back: %s\n", error.what());
    std::abort();
  }
  check_consistent(second);
  require(second.warnings.empty(), "written file reads back with warnings");
  if (format == MeshFormat::Stl) {
    require(same_floats(float_soup(first), float_soup(second)), "STL round trip: corner positions differ");
    return;
  }
  require(same_numbers(first.vertices, second.vertices), "round trip: positions differ");
  require(first.triangles == second.triangles, "round trip: triangles differ");
  require(polygon_starts(first) == polygon_starts(second), "round trip: polygons differ");
  require(first.color_channels == second.color_channels, "round trip: colour channels differ");
  require(same_numbers(first.vertex_colors, second.vertex_colors), "round trip: colours differ");
  if (format != MeshFormat::Off) {  // OFF stores no UVs
    // NaN is "no UV": a file whose UVs are all NaN and one without UVs say the same.
    require(has_uvs(first) == has_uvs(second), "round trip: UVs appear or vanish");
    if (has_uvs(first)) require(same_numbers(first.corner_uvs, second.corner_uvs), "round trip: UVs differ");
  }
  if (format == MeshFormat::Obj) {
    require(triangle_materials(first) == triangle_materials(second), "round trip: materials differ");
    require(first.material_libraries == second.material_libraries, "round trip: material libraries differ");
  }
}

// The whole check for one input: read, and if that succeeds, check and round-trip.
inline int run(const uint8_t* data, size_t size, MeshFormat format) {
  MeshFile mesh;
  try {
    mesh = read_mesh_file(reinterpret_cast<const char*>(data), size, format);
  } catch (const std::invalid_argument&) {
    return 0;  // refused with a message: fine
  }
  check_consistent(mesh);
  check_round_trip(mesh, format);
  return 0;
}

}  // namespace topstoc::fuzz
