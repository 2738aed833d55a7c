// Wavefront OBJ: v (with optional r g b [a]), vt, f (any polygon, v, v/vt, v//vn, v/vt/vn,
// negative = relative indices), usemtl, mtllib. Other statements (vn, g, o, s, l, p, ...) are
// skipped. Materials are named by usemtl in order of first use; the .mtl file is not read.
#include <algorithm>
#include <string>
#include <unordered_map>

#include "io_detail.hpp"

namespace topstoc::io_detail {

namespace {

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

// An index as written (1-based, or negative = counted back from the last one defined so
// far) resolved to 0-based. Forward references are allowed and checked at the end.
int64_t resolve(std::string_view token, int64_t defined, size_t line, const char* what) {
  int64_t index = 0;
  if (!parse_int(token, index) || index == 0)
    fail_at_line(line, std::string("bad ") + what + " index " + quote(token));
  const int64_t resolved = index > 0 ? index - 1 : defined + index;
  if (resolved < 0)
    fail_at_line(line, std::string(what) + " index " + std::to_string(index) + " points before the first " + what);
  if (resolved > INT32_MAX) fail_at_line(line, std::string(what) + " index " + std::to_string(index) + " is too large");
  return resolved;
}

// Faces as read, before we know whether any corner has a UV or any face a material.
struct ObjFaces {
  std::vector<int32_t> corner_vertex, corner_uv;  // uv: -1 = none
  std::vector<int64_t> offsets{0};
  std::vector<int32_t> material;
  int64_t max_vertex = -1, max_uv = -1;
  size_t max_vertex_line = 0, max_uv_line = 0;
};

// OBJ has no counts, so a file cut short is found only on its last line, and only when that line
// has no line end (a cut at a line end leaves a complete-looking file): true for that line.
bool cut_short(const char* data, size_t size, const TextLines& lines) {
  return data[size - 1] != '\n' && lines.rest() == data + size;
}

// A corner of a face on a cut line: a trailing '/' ("12/", "12/3/") or fewer '/'-separated
// parts than the corner before it ("1/1/1 2/2/2 3/3") says the corner was cut.
void check_cut_corner(std::string_view corner, std::string_view previous, size_t line) {
  const auto parts = [](std::string_view c) { return std::count(c.begin(), c.end(), '/'); };
  if (corner.back() == '/' || (!previous.empty() && parts(corner) < parts(previous)))
    fail_at_line(line, "the file ends without a line end in the face corner " + quote(corner) +
                           ": it looks cut short");
}

// One OBJ file read statement by statement into a MeshFile.
class ObjReader {
 public:
  ObjReader(const char* data, size_t size) : data_(data), size_(size), lines_(data, data + size) {}

  MeshFile read() {
    std::string_view line;
    while (next_statement(line)) {
      const size_t number = lines_.number();
      if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      std::string_view rest = line, keyword;
      if (!next_token(rest, keyword)) continue;
      if (keyword == "v") read_vertex(rest, number);
      else if (keyword == "vt") read_uv(rest, number);
      else if (keyword == "f" || keyword == "fo") read_face(rest, number);
      else if (keyword == "usemtl") read_usemtl(rest, number);
      else if (keyword == "mtllib") read_mtllib(rest);
    }
    check_references();
    take_colors();
    add_polygons();
    warn_skipped_faces(mesh_, "line " + std::to_string(first_skipped_));
    return std::move(mesh_);
  }

 private:
  // The next line, with a statement continued over several lines by '\' joined into one.
  bool next_statement(std::string_view& line) {
    if (!lines_.next(line)) return false;
    if (line.empty() || line.back() != '\\') return true;
    joined_.assign(line.substr(0, line.size() - 1));
    joined_ += ' ';
    while (lines_.next(line)) {
      const bool more = !line.empty() && line.back() == '\\';
      joined_.append(line.substr(0, line.size() - (more ? 1 : 0)));
      if (!more) break;
      joined_ += ' ';
    }
    line = joined_;
    return true;
  }

  void read_vertex(std::string_view rest, size_t number) {
    double values[7];
    int count = 0;
    std::string_view token;
    while (next_token(rest, token)) {
      if (count == 7) fail_at_line(number, "vertex has more than 7 numbers");
      if (!parse_double(token, values[count])) fail_at_line(number, "vertex coordinate " + quote(token) + " is not a number");
      ++count;
    }
    if (count < 3) fail_at_line(number, "vertex needs 3 coordinates, got " + std::to_string(count));
    mesh_.vertices.insert(mesh_.vertices.end(), values, values + 3);
    // "v x y z r g b [a]" is the common colour extension; "v x y z w" has no colour.
    if (count >= 6) {
      colors_.insert(colors_.end(), {values[3], values[4], values[5], count == 7 ? values[6] : 1.0});
      if (count == 7) channels_ = 4;
      ++colored_;
    }
  }

  void read_uv(std::string_view rest, size_t number) {
    double uv[2] = {0.0, 0.0};
    int count = 0;
    std::string_view token;
    while (next_token(rest, token)) {
      double value;
      if (!parse_double(token, value)) fail_at_line(number, "texture coordinate " + quote(token) + " is not a number");
      if (count < 2) uv[count] = value;
      ++count;
    }
    if (count < 1) fail_at_line(number, "vt needs at least one coordinate");
    uv_table_.insert(uv_table_.end(), uv, uv + 2);
  }

  // One corner "v", "v/vt", "v//vn" or "v/vt/vn", resolved and appended.
  void read_corner(std::string_view token, size_t number) {
    const size_t slash = token.find('/');
    const int64_t v = resolve(token.substr(0, slash), mesh_.num_vertices(), number, "vertex");
    if (v > faces_.max_vertex) faces_.max_vertex = v, faces_.max_vertex_line = number;
    int64_t t = -1;
    if (slash != std::string_view::npos) {
      std::string_view uv_token = token.substr(slash + 1);
      uv_token = uv_token.substr(0, uv_token.find('/'));
      if (!uv_token.empty()) {
        t = resolve(uv_token, int64_t(uv_table_.size() / 2), number, "texture coordinate");
        if (t > faces_.max_uv) faces_.max_uv = t, faces_.max_uv_line = number;
      }
    }
    faces_.corner_vertex.push_back(int32_t(v));
    faces_.corner_uv.push_back(int32_t(t));
  }

  void read_face(std::string_view rest, size_t number) {
    const int64_t first_corner = int64_t(faces_.corner_vertex.size());
    std::string_view token, last, before_last;  // corners, for the cut-short check
    while (next_token(rest, token)) {
      before_last = last;
      last = token;
      read_corner(token, number);
    }
    const int64_t corners = int64_t(faces_.corner_vertex.size()) - first_corner;
    const bool cut = cut_short(data_, size_, lines_);
    if (cut && !last.empty()) check_cut_corner(last, before_last, number);
    if (cut && corners < 3)
      fail_at_line(number, "the file ends without a line end in a face of " + std::to_string(corners) +
                               " corners: it looks cut short");
    if (corners < 3 && first_skipped_ == 0) first_skipped_ = number;
    faces_.offsets.push_back(int64_t(faces_.corner_vertex.size()));
    faces_.material.push_back(material_);
  }

  void read_usemtl(std::string_view rest, size_t number) {
    const std::string name(trim(rest));
    if (name.empty()) fail_at_line(number, "usemtl without a material name");
    any_material_ = true;
    if (name == "(null)") {  // how the writer spells "no material" after a named one
      material_ = -1;
      return;
    }
    material_ = material_ids_.emplace(name, int32_t(mesh_.material_names.size())).first->second;
    if (material_ == int32_t(mesh_.material_names.size())) mesh_.material_names.push_back(name);
  }

  void read_mtllib(std::string_view rest) {
    const std::string name(trim(rest));
    if (!name.empty()) mesh_.material_libraries.push_back(name);
  }

  // Forward references are allowed while reading; here every index must exist.
  void check_references() const {
    const int64_t n = mesh_.num_vertices();
    if (faces_.max_vertex >= n)
      fail_at_line(faces_.max_vertex_line, "face refers to vertex " + std::to_string(faces_.max_vertex + 1) +
                                               ", but the file has " + std::to_string(n) + " vertices");
    if (faces_.max_uv >= int64_t(uv_table_.size() / 2))
      fail_at_line(faces_.max_uv_line, "face refers to texture coordinate " + std::to_string(faces_.max_uv + 1) +
                                           ", but the file has " + std::to_string(uv_table_.size() / 2));
  }

  // Vertex colours are kept only when every vertex has one.
  void take_colors() {
    const int64_t n = mesh_.num_vertices();
    if (colored_ != n || n == 0) return;
    mesh_.color_channels = int32_t(channels_);
    mesh_.vertex_colors.reserve(size_t(channels_ * n));
    for (int64_t v = 0; v < n; ++v)
      for (int64_t k = 0; k < channels_; ++k) mesh_.vertex_colors.push_back(colors_[4 * size_t(v) + k]);
  }

  void add_polygons() {
    const bool with_uvs = faces_.max_uv >= 0;
    std::vector<double> uvs;
    const int64_t count = int64_t(faces_.offsets.size()) - 1;
    for (int64_t f = 0; f < count; ++f) {
      const int64_t begin = faces_.offsets[f], end = faces_.offsets[f + 1];
      if (with_uvs) {
        uvs.clear();
        for (int64_t c = begin; c < end; ++c) {
          const int32_t t = faces_.corner_uv[c];
          uvs.push_back(t >= 0 ? uv_table_[2 * size_t(t)] : kNaN);
          uvs.push_back(t >= 0 ? uv_table_[2 * size_t(t) + 1] : kNaN);
        }
      }
      add_polygon(mesh_, faces_.corner_vertex.data() + begin, size_t(end - begin), with_uvs ? uvs.data() : nullptr,
                  faces_.material[f], with_uvs, any_material_);
    }
  }

  const char* data_;
  size_t size_;
  TextLines lines_;
  std::string joined_;  // a statement continued over several lines with '\'
  MeshFile mesh_;
  std::vector<double> uv_table_;
  std::vector<double> colors_;  // 4 per coloured vertex, alpha 1 unless given; kept if all are
  int64_t colored_ = 0, channels_ = 3;
  ObjFaces faces_;
  std::unordered_map<std::string, int32_t> material_ids_;
  int32_t material_ = -1;
  bool any_material_ = false;
  size_t first_skipped_ = 0;  // line of the first face with fewer than 3 corners
};

}  // namespace

MeshFile read_obj(const char* data, size_t size) { return ObjReader(data, size).read(); }

std::string obj_name_problem(std::string_view name, bool material) {
  if (name.empty()) return "it is empty";
  if (name.find('\n') != std::string_view::npos) return "it holds a line break";
  if (name.find('#') != std::string_view::npos) return "it holds '#', which starts a comment in OBJ";
  if (is_space(name.front()) || is_space(name.back())) return "it starts or ends with white space";
  if (name.back() == '\\') return "it ends with a backslash, which continues the line in OBJ";
  if (material && name == "(null)") return "'(null)' is how OBJ files say \"no material\"";
  return {};
}

std::string write_obj(const MeshFile& mesh) {
  // OBJ has no escapes: a name that would read back differently is refused, not altered.
  const auto check_names = [](const std::vector<std::string>& names, bool material) {
    for (const auto& name : names)
      if (const std::string problem = obj_name_problem(name, material); !problem.empty())
        throw std::invalid_argument(std::string(material ? "material name " : "material library name ") +
                                    quote(name) + " cannot be written to OBJ: " + problem);
  };
  check_names(mesh.material_names, true);
  check_names(mesh.material_libraries, false);
  std::string out = "# written by TopStoc\n";
  out.reserve(size_t(mesh.num_vertices()) * 64 + mesh.triangles.size() * (mesh.corner_uvs.empty() ? 9 : 24));
  for (const auto& library : mesh.material_libraries) out += "mtllib " + library + "\n";
  const int64_t n = mesh.num_vertices();
  for (int64_t v = 0; v < n; ++v) {
    out += "v";
    for (int k = 0; k < 3; ++k) out += ' ', append_number(out, mesh.vertices[3 * v + k]);
    for (int k = 0; k < mesh.color_channels; ++k) out += ' ', append_number(out, mesh.vertex_colors[mesh.color_channels * v + k]);
    out += '\n';
  }

  // One vt per distinct UV (bit pattern), in order of first use.
  const bool with_uvs = !mesh.corner_uvs.empty();
  std::vector<int64_t> corner_vt;
  if (with_uvs) {
    struct PairHash {
      size_t operator()(const std::pair<uint64_t, uint64_t>& p) const { return p.first * 0x9E3779B97F4A7C15ull ^ p.second; }
    };
    std::unordered_map<std::pair<uint64_t, uint64_t>, int64_t, PairHash> ids;
    corner_vt.assign(mesh.triangles.size(), -1);
    for (size_t c = 0; c < mesh.triangles.size(); ++c) {
      const double u = mesh.corner_uvs[2 * c], w = mesh.corner_uvs[2 * c + 1];
      if (std::isnan(u) && std::isnan(w)) continue;  // no UV (one NaN coordinate is written as read)
      std::pair<uint64_t, uint64_t> key;
      std::memcpy(&key.first, &u, 8);
      std::memcpy(&key.second, &w, 8);
      const auto [it, added] = ids.emplace(key, int64_t(ids.size()));
      if (added) {
        out += "vt ";
        append_number(out, u);
        out += ' ';
        append_number(out, w);
        out += '\n';
      }
      corner_vt[c] = it->second;
    }
  }

  int32_t material = -1;
  std::vector<int64_t> corners;
  for (const auto& group : polygon_groups(mesh)) {
    if (!mesh.triangle_material.empty() && mesh.triangle_material[group.begin] != material) {
      material = mesh.triangle_material[group.begin];
      // OBJ cannot go back to "no material"; "(null)" reads back as -1 (see read_obj).
      out += "usemtl ";
      out += material < 0                        ? std::string("(null)")
             : mesh.material_names.empty() ? "material_" + std::to_string(material)
                                                 : mesh.material_names[material];
      out += '\n';
    }
    group_corners(group, corners);
    out += 'f';
    for (int64_t c : corners) {  // "v/vt" where the corner has a UV, "v" where it has none
      out += ' ';
      append_number(out, int64_t(mesh.triangles[c]) + 1);
      if (with_uvs && corner_vt[c] >= 0) out += '/', append_number(out, corner_vt[c] + 1);
    }
    out += '\n';
  }
  return out;
}

}  // namespace topstoc::io_detail
