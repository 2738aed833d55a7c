// What the reader fuzz targets check besides fuzz_io_common.hpp (issue 37): an accepted file's
// data matched what the file declares. Each format's records are counted here from the bytes,
// independently of the reader (its own line and token walk), and compared with what the reader
// returned; and the file ended where the format says: the same bytes with one record more, or
// cut short, must be refused.
#pragma once

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_io_common.hpp"

namespace topstoc::fuzz {

// The formats' white space (a stray control byte is content, as in the readers' documentation).
inline bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == '\n'; }

inline std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  while (!text.empty()) {
    const size_t stop = text.find('\n');
    lines.push_back(text.substr(0, stop));
    text = stop == std::string_view::npos ? std::string_view() : text.substr(stop + 1);
  }
  return lines;
}

inline std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && blank(line[i])) ++i;
    size_t j = i;
    while (j < line.size() && !blank(line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

inline bool accepted(std::string_view bytes, MeshFormat format) {
  try {
    read_mesh_file(bytes.data(), bytes.size(), format);
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

inline uint32_t u32_le(std::string_view b, size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// STL: binary when the size is 84 + 50 x the count at byte 80 (then exactly that many facets),
// else ascii: as many facets as "endfacet" lines, three "vertex" lines each, the last content
// an "endsolid" line.
inline void check_stl_counts(std::string_view b, const MeshFile& mesh) {
  if (b.empty()) return;
  if (b.size() >= 84 && b.size() == 84 + 50 * size_t(u32_le(b, 80))) {
    require(mesh.polygons == int64_t(u32_le(b, 80)) && mesh.num_triangles() == mesh.polygons, "STL: binary count");
    require(!accepted(std::string(b) + '\0', MeshFormat::Stl), "STL: a byte after the facets accepted");
    return;
  }
  int64_t facets = 0, vertices = 0;
  std::string_view last;
  for (std::string_view line : split_lines(b)) {
    const auto w = words(line);
    if (w.empty()) continue;
    facets += w[0] == "endfacet";
    vertices += w[0] == "vertex";
    last = w[0];
  }
  require(mesh.polygons == facets && mesh.num_triangles() == facets && vertices == 3 * facets, "STL: ascii facets");
  require(last == "endsolid", "STL: ascii accepted without a final endsolid");
}

// OFF: the counts follow the keyword (on its line or the next ones); then exactly as many
// content lines ('#' comments removed) as vertices and faces.
inline void check_off_counts(std::string_view b, const MeshFile& mesh) {
  std::vector<std::vector<std::string_view>> content;
  for (std::string_view line : split_lines(b)) {
    line = line.substr(0, line.find('#'));
    if (auto w = words(line); !w.empty()) content.push_back(std::move(w));
  }
  require(!content.empty(), "OFF: accepted without a header");
  std::vector<int64_t> counts;
  size_t header = 0;  // content lines up to the one holding the face count
  for (size_t i = 1; counts.size() < 2; ++header) {
    require(header < content.size(), "OFF: accepted without counts");
    for (; i < content[header].size() && counts.size() < 3; ++i) counts.push_back(std::stoll(std::string(content[header][i])));
    i = 0;
  }
  require(mesh.num_vertices() == counts[0] && mesh.polygons == counts[1], "OFF: counts");
  require(int64_t(content.size() - header) == counts[0] + counts[1], "OFF: content lines differ from the counts");
  require(!accepted(std::string(b) + "\n0 0 0\n", MeshFormat::Off), "OFF: a line after the faces accepted");
}

// PLY: the element counts of the header against the vertices and faces returned; the body ends
// with the last row: one value more is refused, and so is one value (ascii) or byte (binary) less.
inline void check_ply_counts(std::string_view b, const MeshFile& mesh) {
  int64_t vertices = 0, faces = 0;
  bool ascii = false;
  size_t body = 0;
  for (std::string_view line : split_lines(b)) {
    body += line.size() + 1;
    const auto w = words(line);
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") ascii = w.size() > 1 && w[1] == "ascii";
    if (w[0] == "element" && w.size() > 2 && w[1] == "vertex") vertices = std::stoll(std::string(w[2]));
    if (w[0] == "element" && w.size() > 2 && w[1] == "face") faces = std::stoll(std::string(w[2]));
  }
  require(mesh.num_vertices() == vertices && mesh.polygons == faces, "PLY: element counts");
  const std::string bytes(b);
  require(!accepted(bytes + (ascii ? "\n7\n" : "\x07"), MeshFormat::Ply), "PLY: data after the rows accepted");
  if (body >= b.size() || b.back() == '\n') return;  // no body, or one line end the reader may tolerate
  size_t cut = b.size() - 1;
  if (ascii) {
    while (cut > body && blank(b[cut])) --cut;
    if (blank(b[cut])) return;  // no value in the body
    while (cut > body && !blank(b[cut - 1])) --cut;
  }
  require(!accepted(bytes.substr(0, cut), MeshFormat::Ply), "PLY: a body cut short accepted");
}

// OBJ has no counts: as many vertices and faces as "v" and "f"/"fo" statements (lines joined at
// a trailing '\\', '#' comments removed); skipped faces are warned about; an unterminated last
// face is complete (3 corners or more, its last corner whole: see the reader's cut-short rule).
inline void check_obj_counts(std::string_view b, const MeshFile& mesh) {
  int64_t vertices = 0, faces = 0;
  std::vector<std::string_view> last_face;
  std::string joined;
  const auto lines = split_lines(b);
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string_view line = lines[i];
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!line.empty() && line.back() == '\\') {
      joined.assign(line.substr(0, line.size() - 1));
      while (++i < lines.size()) {
        std::string_view next = lines[i];
        if (!next.empty() && next.back() == '\r') next.remove_suffix(1);
        const bool more = !next.empty() && next.back() == '\\';
        joined += ' ';
        joined.append(next.substr(0, next.size() - more));
        if (!more) break;
      }
      line = joined;
    }
    const auto w = words(line.substr(0, line.find('#')));
    last_face.clear();
    if (w.empty()) continue;
    vertices += w[0] == "v";
    if (w[0] == "f" || w[0] == "fo") ++faces, last_face.assign(w.begin() + 1, w.end());
  }
  require(mesh.num_vertices() == vertices && mesh.polygons == faces, "OBJ: statements");
  require((mesh.skipped_faces == 0) == mesh.warnings.empty(), "OBJ: skipped faces without a warning");
  if (b.empty() || b.back() == '\n' || last_face.empty()) return;
  const auto slashes = [](std::string_view c) { return std::count(c.begin(), c.end(), '/'); };
  const size_t k = last_face.size();
  require(k >= 3 && last_face[k - 1].back() != '/' && slashes(last_face[k - 1]) >= slashes(last_face[k - 2]),
          "OBJ: a cut last face accepted");
}

}  // namespace topstoc::fuzz
