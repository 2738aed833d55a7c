// Mesh file dispatch and what the format readers and writers share (see io.hpp).
#include "topstoc/io/io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "io_detail.hpp"

namespace topstoc {

namespace io_detail {

namespace {

// Same UV (bit for bit, NaN equal to NaN) at two corners.
bool same_uv(const MeshFile& mesh, int64_t a, int64_t b) {
  if (mesh.corner_uvs.empty()) return true;
  for (int k = 0; k < 2; ++k) {
    const double x = mesh.corner_uvs[2 * size_t(a) + k], y = mesh.corner_uvs[2 * size_t(b) + k];
    if (!(x == y || (std::isnan(x) && std::isnan(y)))) return false;
  }
  return true;
}

// True when triangle t continues the fan that started at triangle `first` with `previous`.
bool continues_fan(const MeshFile& mesh, int64_t first, int64_t previous, int64_t t) {
  if (mesh.triangle_polygon.empty() || mesh.triangle_polygon[t] != mesh.triangle_polygon[first]) return false;
  if (!mesh.triangle_material.empty() && mesh.triangle_material[t] != mesh.triangle_material[first]) return false;
  const int32_t* tri = mesh.triangles.data();
  return tri[3 * t] == tri[3 * first] && tri[3 * t + 1] == tri[3 * previous + 2] &&
         same_uv(mesh, 3 * t, 3 * first) && same_uv(mesh, 3 * t + 1, 3 * previous + 2);
}

}  // namespace

std::vector<PolygonGroup> polygon_groups(const MeshFile& mesh) {
  std::vector<PolygonGroup> groups;
  const int64_t m = mesh.num_triangles();
  int64_t t = 0;
  while (t < m) {
    const int64_t begin = t++;
    while (t < m && continues_fan(mesh, begin, t - 1, t)) ++t;
    groups.push_back({begin, t});
  }
  return groups;
}

void group_corners(const PolygonGroup& group, std::vector<int64_t>& corners) {
  corners.assign({3 * group.begin, 3 * group.begin + 1, 3 * group.begin + 2});
  for (int64_t t = group.begin + 1; t < group.end; ++t) corners.push_back(3 * t + 2);
}

void validate_for_writing(const MeshFile& mesh) {
  const auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  if (mesh.vertices.size() % 3) fail("positions must hold 3 numbers per vertex");
  if (mesh.triangles.size() % 3) fail("triangles must hold 3 indices per triangle");
  const int64_t n = mesh.num_vertices(), m = mesh.num_triangles();
  if (!mesh.triangle_polygon.empty() && int64_t(mesh.triangle_polygon.size()) != m)
    fail("triangle_polygon has " + std::to_string(mesh.triangle_polygon.size()) + " entries, expected " +
         std::to_string(m));
  if (!mesh.corner_uvs.empty() && int64_t(mesh.corner_uvs.size()) != 6 * m)
    fail("corner_uvs must hold 6 numbers per triangle");
  // Writers index colours by color_channels alone: both must agree (0 = no colours).
  if ((!mesh.vertex_colors.empty() || mesh.color_channels != 0) &&
      ((mesh.color_channels != 3 && mesh.color_channels != 4) ||
       int64_t(mesh.vertex_colors.size()) != mesh.color_channels * n))
    fail("vertex_colors must hold 3 or 4 numbers per vertex");
  if (!mesh.triangle_material.empty() && int64_t(mesh.triangle_material.size()) != m)
    fail("triangle_material has " + std::to_string(mesh.triangle_material.size()) + " entries, expected " +
         std::to_string(m));
  for (int64_t i = 0; i < 3 * m; ++i) {
    const int32_t v = mesh.triangles[i];
    if (v < 0 || v >= n)
      fail("triangle " + std::to_string(i / 3) + " refers to vertex " + std::to_string(v) + ", outside [0, " +
           std::to_string(n) + ")");
  }
  const auto names = int64_t(mesh.material_names.size());
  for (int64_t t = 0; t < int64_t(mesh.triangle_material.size()); ++t) {
    const int32_t id = mesh.triangle_material[t];
    if (id < -1 || (names > 0 && id >= names))
      fail("triangle " + std::to_string(t) + " has material " + std::to_string(id) + ", outside [-1, " +
           std::to_string(names) + ")");
  }
  // Names matter to OBJ only, which checks them itself (obj_name_problem).
}

// A reader may hand NaN or infinity through (an OBJ "nan"), but no file should carry them on:
// other programs read them as garbage or not at all.
void check_numbers_for_writing(const MeshFile& mesh, bool colors, bool uvs) {
  const auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!std::isfinite(mesh.vertices[i]))
      fail("vertex " + std::to_string(i / 3) + " cannot be written: coordinate " + shown_number(mesh.vertices[i]) +
           " is not finite");
  for (size_t i = 0; colors && i < mesh.vertex_colors.size(); ++i)
    if (!std::isfinite(mesh.vertex_colors[i]))
      fail("vertex " + std::to_string(i / mesh.color_channels) + " cannot be written: colour " +
           shown_number(mesh.vertex_colors[i]) + " is not finite");
  for (size_t i = 0; uvs && i < mesh.corner_uvs.size(); ++i)
    if (std::isinf(mesh.corner_uvs[i]))
      fail("triangle " + std::to_string(i / 6) + " corner " + std::to_string(i / 2 % 3) +
           " cannot be written: UV " + shown_number(mesh.corner_uvs[i]) +
           " is infinite (NaN marks a corner without a UV)");
}

std::string shown_number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", x);
  return buffer;
}

}  // namespace io_detail

MeshFile read_mesh_file(const char* data, size_t size, MeshFormat format) {
  switch (format) {
    case MeshFormat::Obj: return io_detail::read_obj(data, size);
    case MeshFormat::Ply: return io_detail::read_ply(data, size);
    case MeshFormat::Off: return io_detail::read_off(data, size);
    case MeshFormat::Stl: return io_detail::read_stl(data, size);
  }
  throw std::invalid_argument("unknown mesh format");
}

std::string write_mesh_file(const MeshFile& mesh, MeshFormat format) {
  io_detail::validate_for_writing(mesh);
  // Numbers are checked where the format carries them (OFF has no UVs, STL only positions).
  const bool colors = format != MeshFormat::Stl, uvs = format == MeshFormat::Obj || format == MeshFormat::Ply;
  io_detail::check_numbers_for_writing(mesh, colors, uvs);
  switch (format) {
    case MeshFormat::Obj: return io_detail::write_obj(mesh);
    case MeshFormat::Ply: return io_detail::write_ply(mesh);
    case MeshFormat::Off: return io_detail::write_off(mesh);
    case MeshFormat::Stl: return io_detail::write_stl(mesh);
  }
  throw std::invalid_argument("unknown mesh format");
}

MeshFormat mesh_format_from_name(const std::string& name) {
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* suffix : {".gz", ".bz2"}) {
    const std::string s(suffix);
    if (lower.size() > s.size() && lower.compare(lower.size() - s.size(), s.size(), s) == 0)
      lower.resize(lower.size() - s.size());
  }
  const auto ends_with = [&](const char* suffix) {
    const std::string s(suffix);
    return lower.size() > s.size() && lower.compare(lower.size() - s.size(), s.size(), s) == 0;
  };
  if (ends_with(".obj")) return MeshFormat::Obj;
  if (ends_with(".ply")) return MeshFormat::Ply;
  if (ends_with(".off")) return MeshFormat::Off;
  if (ends_with(".stl")) return MeshFormat::Stl;
  throw std::invalid_argument(name + ": unknown mesh file extension (expected .obj, .ply, .off or .stl, "
                                     "optionally followed by .gz or .bz2)");
}

MeshFile read_mesh_path(const std::string& path) {
  const MeshFormat format = mesh_format_from_name(path);
  for (const char* suffix : {".gz", ".bz2"}) {
    const std::string s(suffix);
    if (path.size() > s.size() && path.compare(path.size() - s.size(), s.size(), s) == 0)
      throw std::invalid_argument(path + ": compressed files are read through topstoc.core.api.io (Python)");
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot open the file");
  std::string data(size_t(in.tellg()), '\0');
  in.seekg(0);
  if (!in.read(data.data(), std::streamsize(data.size()))) throw std::runtime_error(path + ": cannot read the file");
  try {
    return read_mesh_file(data.data(), data.size(), format);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(path + ": " + error.what());
  }
}

}  // namespace topstoc
