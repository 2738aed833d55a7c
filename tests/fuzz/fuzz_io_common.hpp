// What the reader fuzz targets check (fuzz_read_*.cpp, fuzz_round_trip.cpp): the reader either
// throws std::invalid_argument or returns arrays that agree with each other; what it returns is
// then written in a format (the same one, or each other one) and read again, and the second
// read must equal the first in everything the written format carries. A writer may refuse only
// what no file of that format can hold (an OBJ name that would not read back, a number that is
// not finite, a coordinate past binary STL's float32 range), and only when the mesh holds it.
// Any other exception, a disagreement or a sanitizer report ends the run (abort = a crash for
// libFuzzer, which keeps the input).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
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

inline bool carries_colors(MeshFormat f) { return f != MeshFormat::Stl; }
inline bool carries_uvs(MeshFormat f) { return f == MeshFormat::Obj || f == MeshFormat::Ply; }

// The mesh holds a number `target` carries but no file should (check_numbers_for_writing).
inline bool has_unwritable_numbers(const MeshFile& mesh, MeshFormat target) {
  for (double x : mesh.vertices)
    if (!std::isfinite(x)) return true;
  if (carries_colors(target))
    for (double x : mesh.vertex_colors)
      if (!std::isfinite(x)) return true;
  if (carries_uvs(target))
    for (double x : mesh.corner_uvs)
      if (std::isinf(x)) return true;
  return false;
}

// A corner position past float32's range (binary STL).
inline bool beyond_float32(const MeshFile& mesh) {
  for (int32_t v : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (std::isinf(float(mesh.vertices[3 * size_t(v) + k]))) return true;
  return false;
}

// Whether a writer's refusal is one of the allowed ones, for this mesh.
inline bool allowed_refusal(const MeshFile& mesh, MeshFormat target, const char* what) {
  if (target == MeshFormat::Obj && std::strstr(what, "cannot be written to OBJ")) return true;  // no escapes
  if (std::strstr(what, "cannot be written: ") && has_unwritable_numbers(mesh, target)) return true;
  if (target == MeshFormat::Stl && std::strstr(what, "cannot be written to binary STL") && beyond_float32(mesh))
    return true;
  return false;
}

// Writes `first` (as read) in `target`, reads it back and compares what `target` carries.
inline void check_written_as(const MeshFile& first, MeshFormat target) {
  std::string bytes;
  try {
    bytes = write_mesh_file(first, target);
  } catch (const std::invalid_argument& error) {
    if (allowed_refusal(first, target, error.what())) return;
    std::fprintf(stderr, "writer refused a mesh a reader returned: %s\n", error.what());
    std::abort();
  }
  MeshFile second;
  try {
    second = read_mesh_file(bytes.data(), bytes.size(), target);
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "written file does not read back: %s\n", error.what());
    std::abort();
  }
  check_consistent(second);
  require(second.warnings.empty(), "written file reads back with warnings");
  if (target == MeshFormat::Stl) {  // a float32 triangle soup
    require(second.triangles.size() == first.triangles.size(), "STL: triangle count differs");
    require(same_floats(float_soup(first), float_soup(second)), "STL: corner positions differ");
    return;
  }
  require(same_numbers(first.vertices, second.vertices), "positions differ");
  require(first.triangles == second.triangles, "triangles differ");
  require(polygon_starts(first) == polygon_starts(second), "polygons differ");
  if (carries_colors(target)) {
    // Without vertices there are no colours to keep: a PLY header may still declare RGBA.
    if (!first.vertices.empty()) require(first.color_channels == second.color_channels, "colour channels differ");
    require(same_numbers(first.vertex_colors, second.vertex_colors), "colours differ");
  } else {
    require(second.color_channels == 0, "colours appear");
  }
  // NaN is "no UV": a file whose UVs are all NaN and one without UVs say the same.
  if (carries_uvs(target)) {
    require(has_uvs(first) == has_uvs(second), "UVs appear or vanish");
    if (has_uvs(first)) require(same_numbers(first.corner_uvs, second.corner_uvs), "UVs differ");
  } else {
    require(!has_uvs(second), "UVs appear");
  }
  if (target == MeshFormat::Obj) {
    require(triangle_materials(first) == triangle_materials(second), "materials differ");
    require(first.material_libraries == second.material_libraries, "material libraries differ");
  }
}

inline void check_round_trip(const MeshFile& first, MeshFormat format) { check_written_as(first, format); }

// The whole check for one input: read, and if that succeeds, check and round-trip. `counts`
// (fuzz_counts.hpp) checks that what was read is what the bytes declare.
inline int run(const uint8_t* data, size_t size, MeshFormat format,
               void (*counts)(std::string_view, const MeshFile&) = nullptr) {
  MeshFile mesh;
  try {
    mesh = read_mesh_file(reinterpret_cast<const char*>(data), size, format);
  } catch (const std::invalid_argument&) {
    return 0;  // refused with a message: fine
  }
  check_consistent(mesh);
  if (counts) counts(std::string_view(reinterpret_cast<const char*>(data), size), mesh);
  check_round_trip(mesh, format);
  return 0;
}

}  // namespace topstoc::fuzz
