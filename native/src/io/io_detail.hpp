// Helpers shared by the mesh file readers and writers (io_*.cpp); not part of the public API.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "topstoc/io/io.hpp"

namespace topstoc::io_detail {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Whitespace of the text formats. Other control bytes are content, so that a stray byte in
/// a number makes it unparseable instead of silently splitting it.
inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Walks text line by line (\n or \r\n), counting lines from 1 for error messages.
class TextLines {
 public:
  TextLines(const char* begin, const char* end) : cursor_(begin), end_(end) {}

  /// Next line without its end-of-line bytes; false at the end of the text.
  bool next(std::string_view& line) {
    if (cursor_ >= end_) return false;
    const char* stop = static_cast<const char*>(std::memchr(cursor_, '\n', size_t(end_ - cursor_)));
    if (!stop) stop = end_;
    line = std::string_view(cursor_, size_t(stop - cursor_));
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    cursor_ = stop < end_ ? stop + 1 : end_;
    ++number_;
    return true;
  }

  size_t number() const { return number_; }
  /// Bytes after the current line (binary payloads that follow a text header).
  const char* rest() const { return cursor_; }

 private:
  const char* cursor_;
  const char* end_;
  size_t number_ = 0;
};

/// Splits the next whitespace-separated token off `text`; false when none is left.
inline bool next_token(std::string_view& text, std::string_view& token) {
  size_t i = 0;
  while (i < text.size() && is_space(text[i])) ++i;
  if (i == text.size()) {
    text = {};
    return false;
  }
  size_t j = i;
  while (j < text.size() && !is_space(text[j])) ++j;
  token = text.substr(i, j - i);
  text.remove_prefix(j);
  return true;
}

/// Drops one leading '+' of a number, unless a sign follows it ("+-1" is no number).
inline void skip_plus(std::string_view& token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') token.remove_prefix(1);
}

/// Parses a whole token as a number (a leading '+' is allowed); false if anything is left over.
inline bool parse_double(std::string_view token, double& out) {
  skip_plus(token);
  const auto result = std::from_chars(token.data(), token.data() + token.size(), out);
  return result.ec == std::errc() && result.ptr == token.data() + token.size() && !token.empty();
}

inline bool parse_int(std::string_view token, int64_t& out) {
  skip_plus(token);
  const auto result = std::from_chars(token.data(), token.data() + token.size(), out);
  return result.ec == std::errc() && result.ptr == token.data() + token.size() && !token.empty();
}

/// A token for an error message: quoted, control bytes escaped, long tokens cut.
inline std::string quote(std::string_view token) {
  static const char* hex = "0123456789abcdef";
  std::string out = "'";
  for (size_t i = 0; i < token.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c < 32 || c >= 127) {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += char(c);
    }
  }
  if (token.size() > 40) out += "...";
  return out + "'";
}

[[noreturn]] inline void fail_at_line(size_t line, const std::string& message) {
  throw std::invalid_argument("line " + std::to_string(line) + ": " + message);
}

/// Appends the fan triangulation of one polygon of the file (its index is mesh.polygons,
/// which this increments). uvs: 2 per corner or nullptr. Polygons with fewer than three
/// corners only count as skipped.
inline void add_polygon(MeshFile& mesh, const int32_t* corners, size_t count, const double* uvs, int32_t material,
                        bool with_uvs, bool with_material) {
  const auto polygon = static_cast<int32_t>(mesh.polygons++);
  if (count < 3) {
    ++mesh.skipped_faces;
    return;
  }
  for (size_t i = 1; i + 1 < count; ++i) {
    const size_t slots[3] = {0, i, i + 1};
    for (size_t slot : slots) mesh.triangles.push_back(corners[slot]);
    mesh.triangle_polygon.push_back(polygon);
    if (with_uvs) {
      for (size_t slot : slots) {
        mesh.corner_uvs.push_back(uvs ? uvs[2 * slot] : kNaN);
        mesh.corner_uvs.push_back(uvs ? uvs[2 * slot + 1] : kNaN);
      }
    }
    if (with_material) mesh.triangle_material.push_back(material);
  }
}

/// The warning for faces with fewer than three corners, which read as no triangle: the count
/// and where the first one is (`first`, e.g. "line 12" or "face 3"). Nothing when none.
inline void warn_skipped_faces(MeshFile& mesh, const std::string& first) {
  if (mesh.skipped_faces == 0) return;
  mesh.warnings.push_back("skipped " + std::to_string(mesh.skipped_faces) + " face" +
                          (mesh.skipped_faces == 1 ? "" : "s") + " with fewer than 3 corners (the first at " +
                          first + ")");
}

/// Throws when a triangle refers to a vertex outside [0, n). `what` names the element kind.
inline void check_triangle_indices(const MeshFile& mesh, const char* what) {
  const int64_t n = mesh.num_vertices();
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const int32_t v = mesh.triangles[i];
    if (v < 0 || v >= n)
      throw std::invalid_argument(std::string(what) + " " + std::to_string(mesh.triangle_polygon[i / 3]) +
                                  " refers to vertex " + std::to_string(v) + ", but the file has " +
                                  std::to_string(n) + " vertices");
  }
}

/// Appends the shortest text that reads back as exactly `value`.
inline void append_number(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

inline void append_number(std::string& out, int64_t value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

/// Consecutive triangles that re-form one polygon of the file: triangles [begin, end) share
/// their polygon id, material and first corner and chain as the fan (v0, vi, vi+1), with the
/// same UVs at shared corners. Writers emit one face per group, so a file read and written
/// back keeps its polygons and re-reads into the identical triangles.
struct PolygonGroup {
  int64_t begin, end;
};
std::vector<PolygonGroup> polygon_groups(const MeshFile& mesh);

/// Corners of a polygon group, in order (v0, v1, ..., vk-1), as corner indices 3 t + slot
/// (into a reused vector: writers call this once per face).
void group_corners(const PolygonGroup& group, std::vector<int64_t>& corners);

/// Checks array sizes and index ranges of a mesh about to be written.
void validate_for_writing(const MeshFile& mesh);

/// Checks the numbers a format carries (positions always; colours, UVs when asked): no file
/// should carry a coordinate or colour that is not finite, nor an infinite UV (NaN is a corner
/// without one). Refusals say "cannot be written" and name the vertex or corner.
void check_numbers_for_writing(const MeshFile& mesh, bool colors, bool uvs);

/// "%.6g" of a number, for messages (1e-09, 3.40282e+38, nan).
std::string shown_number(double x);

/// Why `name` (a usemtl material when `material`, else an mtllib argument) would not read back
/// from an OBJ file exactly as written; empty when it would. The reader takes the rest of the
/// line, comments ('#') removed, a trailing '\\' joining the next line, white space trimmed,
/// and "(null)" meaning no material.
std::string obj_name_problem(std::string_view name, bool material);

// One reader and one writer per format (io_obj.cpp, io_ply.cpp, io_off.cpp, io_stl.cpp).
MeshFile read_obj(const char* data, size_t size);
MeshFile read_ply(const char* data, size_t size);
MeshFile read_off(const char* data, size_t size);
MeshFile read_stl(const char* data, size_t size);
std::string write_obj(const MeshFile& mesh);
std::string write_ply(const MeshFile& mesh);
std::string write_off(const MeshFile& mesh);
std::string write_stl(const MeshFile& mesh);

}  // namespace topstoc::io_detail
