// Geomview OFF, ascii: [ST][C][N]OFF headers, the counts on the header line or the next,
// vertices "x y z [nx ny nz] [r g b [a]] [s t]", faces "k i1 .. ik [colour]" (polygons),
// '#' comments. Colours written as integers are bytes (scaled to [0, 1]), as decimals they are
// taken as they are. Normals, per-vertex texture coordinates and face colours are read past.
#include <algorithm>
#include <string>

#include "io_detail.hpp"

namespace topstoc::io_detail {

namespace {

struct OffHeader {
  bool texture = false, color = false, normal = false;
};

OffHeader parse_keyword(std::string_view keyword, size_t line) {
  OffHeader header;
  std::string_view k = keyword;
  if (k.substr(0, 2) == "ST") header.texture = true, k.remove_prefix(2);
  if (k.substr(0, 1) == "C") header.color = true, k.remove_prefix(1);
  if (k.substr(0, 1) == "N") header.normal = true, k.remove_prefix(1);
  if (k == "4OFF" || k == "nOFF" || k == "4nOFF")
    fail_at_line(line, "OFF files in other dimensions than 3 (" + quote(keyword) + ") are not supported");
  if (k != "OFF") fail_at_line(line, "not an OFF file: the header is " + quote(keyword));
  return header;
}

bool is_integer_literal(std::string_view token) {
  return token.find_first_of(".eEnNiI") == std::string_view::npos;
}

// Next line with content (comments removed); false at the end.
bool next_content(TextLines& lines, std::string_view& line) {
  while (lines.next(line)) {
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    std::string_view probe = line, token;
    if (next_token(probe, token)) return true;
  }
  return false;
}

// The counts must cover the whole file: more data after the faces means the header undercounts.
void check_nothing_follows(TextLines& lines, size_t counts_line, int64_t n, int64_t faces) {
  std::string_view line;
  if (!next_content(lines, line)) return;
  const size_t first_extra = lines.number();
  size_t extra = 1;
  while (next_content(lines, line)) ++extra;
  fail_at_line(first_extra, "the header (line " + std::to_string(counts_line) + ") says " + std::to_string(n) +
                                " vertices and " + std::to_string(faces) + " faces, but " + std::to_string(extra) +
                                " more line" + (extra == 1 ? "" : "s") + " of data follow them");
}

}  // namespace

MeshFile read_off(const char* data, size_t size) {
  if (size == 0) throw std::invalid_argument("the file is empty");
  TextLines lines(data, data + size);
  std::string_view line, token;
  if (!next_content(lines, line)) throw std::invalid_argument("the file has no OFF header");
  std::string_view rest = line;
  next_token(rest, token);
  const OffHeader header = parse_keyword(token, lines.number());
  std::string_view after_keyword = rest;
  if (next_token(after_keyword, token) && token == "BINARY")
    fail_at_line(lines.number(), "binary OFF files are not supported");

  int64_t counts[3] = {0, 0, 0};
  int found = 0;
  while (found < 2) {
    while (found < 3 && next_token(rest, token)) {
      if (!parse_int(token, counts[found]) || counts[found] < 0)
        fail_at_line(lines.number(), "expected the vertex, face and edge counts, got " + quote(token));
      ++found;
    }
    if (found >= 2) break;
    if (!next_content(lines, line)) throw std::invalid_argument("the file ends before the vertex and face counts");
    rest = line;
  }
  const size_t counts_line = lines.number();
  const int64_t n = counts[0], faces = counts[1];
  if (n > INT32_MAX || faces > INT32_MAX) fail_at_line(lines.number(), "too many vertices or faces");

  MeshFile mesh;
  mesh.vertices.reserve(std::min(3 * size_t(n), size));  // counts may lie: the file's size bounds them
  std::vector<double> colors;
  int color_channels = 0;
  bool integer_colors = true;
  const int normal_values = header.normal ? 3 : 0, texture_values = header.texture ? 2 : 0;
  std::vector<double> values;
  std::vector<std::string_view> tokens;
  for (int64_t v = 0; v < n; ++v) {
    if (!next_content(lines, line))
      throw std::invalid_argument("the file ends after " + std::to_string(v) + " of " + std::to_string(n) + " vertices");
    const size_t number = lines.number();
    values.clear();
    tokens.clear();
    rest = line;
    while (next_token(rest, token)) {
      double value;
      if (!parse_double(token, value)) fail_at_line(number, "vertex value " + quote(token) + " is not a number");
      values.push_back(value);
      tokens.push_back(token);
    }
    if (values.size() < 3) fail_at_line(number, "vertex needs 3 coordinates, got " + std::to_string(values.size()));
    mesh.vertices.insert(mesh.vertices.end(), values.begin(), values.begin() + 3);
    if (header.color) {
      const int channels = int(values.size()) - 3 - normal_values - texture_values;
      if (channels != 3 && channels != 4)
        fail_at_line(number, "COFF vertex needs 3 or 4 colour values, got " + std::to_string(std::max(channels, 0)));
      if (color_channels == 0) color_channels = channels;
      if (channels != color_channels)
        fail_at_line(number, "vertex has " + std::to_string(channels) + " colour values, earlier ones " +
                                 std::to_string(color_channels));
      for (int k = 0; k < channels; ++k) {
        colors.push_back(values[3 + normal_values + k]);
        integer_colors = integer_colors && is_integer_literal(tokens[3 + normal_values + k]);
      }
    }
  }
  if (header.color && n > 0) {
    mesh.color_channels = color_channels;
    mesh.vertex_colors = std::move(colors);
    if (integer_colors)
      for (double& c : mesh.vertex_colors) c /= 255.0;
  }

  std::vector<int32_t> corners;
  size_t first_skipped = 0;
  mesh.triangles.reserve(std::min(3 * size_t(faces), size));
  for (int64_t f = 0; f < faces; ++f) {
    if (!next_content(lines, line))
      throw std::invalid_argument("the file ends after " + std::to_string(f) + " of " + std::to_string(faces) + " faces");
    const size_t number = lines.number();
    rest = line;
    int64_t count = 0;
    next_token(rest, token);
    if (!parse_int(token, count) || count < 0) fail_at_line(number, "bad face corner count " + quote(token));
    corners.clear();
    for (int64_t i = 0; i < count; ++i) {
      int64_t index;
      if (!next_token(rest, token))
        fail_at_line(number, "face has " + std::to_string(i) + " of " + std::to_string(count) + " vertex indices");
      if (!parse_int(token, index)) fail_at_line(number, "vertex index " + quote(token) + " is not an integer");
      if (index < 0 || index >= n)
        fail_at_line(number, "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) +
                                 ", but the file has " + std::to_string(n) + " vertices");
      corners.push_back(int32_t(index));
    }
    add_polygon(mesh, corners.data(), corners.size(), nullptr, -1, false, false);
    if (count < 3 && mesh.skipped_faces == 1) first_skipped = number;
  }
  check_nothing_follows(lines, counts_line, n, faces);
  warn_skipped_faces(mesh, "line " + std::to_string(first_skipped));
  return mesh;
}

std::string write_off(const MeshFile& mesh) {
  const bool colors = mesh.color_channels > 0;
  bool byte_colors = colors;
  for (double c : mesh.vertex_colors) {
    const double k = std::round(c * 255.0);
    byte_colors = byte_colors && k >= 0 && k <= 255 && k / 255.0 == c;
  }
  const auto groups = polygon_groups(mesh);
  std::string out = colors ? "COFF\n" : "OFF\n";
  out.reserve(size_t(mesh.num_vertices()) * 64 + mesh.triangles.size() * 9);
  out += std::to_string(mesh.num_vertices()) + " " + std::to_string(groups.size()) + " 0\n";
  for (int64_t v = 0; v < mesh.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) {
      if (k) out += ' ';
      append_number(out, mesh.vertices[3 * v + k]);
    }
    for (int k = 0; k < mesh.color_channels; ++k) {
      const double c = mesh.vertex_colors[mesh.color_channels * v + k];
      out += ' ';
      if (byte_colors) {
        append_number(out, int64_t(std::lround(c * 255.0)));
      } else {
        // Decimal colours must not look like integers, which read as bytes.
        const size_t start = out.size();
        append_number(out, c);
        if (out.find_first_of(".eEnNiI", start) == std::string::npos) out += ".0";
      }
    }
    out += '\n';
  }
  std::vector<int64_t> corners;
  for (const auto& group : groups) {
    group_corners(group, corners);
    append_number(out, int64_t(corners.size()));
    for (int64_t c : corners) out += ' ', append_number(out, int64_t(mesh.triangles[c]));
    out += '\n';
  }
  return out;
}

}  // namespace topstoc::io_detail
