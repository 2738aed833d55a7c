// Stanford PLY: ascii, binary_little_endian and binary_big_endian, any scalar types.
// vertex: x y z, colours (red green blue [alpha], r g b [a] or diffuse_*; bytes scaled to
// [0, 1]), UVs (s t, u v, texture_u texture_v, texture_s texture_t); face: vertex_indices (or
// vertex_index) as a list of any integer types, and MeshLab's per-corner `texcoord` list;
// tristrips: vertex_indices, strips separated by -1 (older scanners' files).
// Other elements and properties are read past and ignored.
#include <algorithm>
#include <cstring>
#include <string>

#include "io_detail.hpp"

namespace topstoc::io_detail {

namespace {

enum class PlyType : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64, None };

enum class Role : uint8_t { Other, X, Y, Z, Red, Green, Blue, Alpha, U, V, Indices, TexCoord };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::None;
  PlyType count_type = PlyType::None;  // a list when not None
  Role role = Role::Other;
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  size_t line = 0;  // of the header, for messages
  std::vector<PlyProperty> properties;
};

enum class Encoding { Ascii, BinaryLittle, BinaryBig };

bool host_is_little_endian() {
  const uint16_t probe = 1;
  uint8_t first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

PlyType type_from(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType::Int8;
  if (name == "uchar" || name == "uint8") return PlyType::UInt8;
  if (name == "short" || name == "int16") return PlyType::Int16;
  if (name == "ushort" || name == "uint16") return PlyType::UInt16;
  if (name == "int" || name == "int32") return PlyType::Int32;
  if (name == "uint" || name == "uint32") return PlyType::UInt32;
  if (name == "float" || name == "float32") return PlyType::Float32;
  if (name == "double" || name == "float64") return PlyType::Float64;
  return PlyType::None;
}

bool is_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64 && t != PlyType::None; }

Role vertex_role(std::string_view name) {
  if (name == "x") return Role::X;
  if (name == "y") return Role::Y;
  if (name == "z") return Role::Z;
  if (name == "red" || name == "r" || name == "diffuse_red") return Role::Red;
  if (name == "green" || name == "g" || name == "diffuse_green") return Role::Green;
  if (name == "blue" || name == "b" || name == "diffuse_blue") return Role::Blue;
  if (name == "alpha" || name == "a" || name == "diffuse_alpha") return Role::Alpha;
  if (name == "s" || name == "u" || name == "texture_u" || name == "texture_s") return Role::U;
  if (name == "t" || name == "v" || name == "texture_v" || name == "texture_t") return Role::V;
  return Role::Other;
}

// Divisor that maps a stored colour value to [0, 1] (a division, so that byte k reads as
// exactly k / 255.0, which the writer tests for).
double color_divisor(PlyType t) {
  switch (t) {
    case PlyType::Float32:
    case PlyType::Float64: return 1.0;
    case PlyType::Int16:
    case PlyType::UInt16: return 65535.0;
    default: return 255.0;
  }
}

struct PlyHeader {
  Encoding encoding = Encoding::Ascii;
  std::vector<PlyElement> elements;
  const char* body = nullptr;
  size_t body_line = 0;  // line number where an ascii body starts
  std::vector<std::string> warnings;
};

PlyHeader parse_header(const char* data, size_t size) {
  if (size == 0) throw std::invalid_argument("the file is empty");
  PlyHeader header;
  TextLines lines(data, data + size);
  std::string_view line, rest, token;
  if (!lines.next(line) || line.substr(0, 3) != "ply" || line.find_first_not_of(" \t", 3) != std::string_view::npos)
    throw std::invalid_argument("not a PLY file: it does not start with 'ply'");
  bool has_format = false;
  while (true) {
    if (!lines.next(line)) throw std::invalid_argument("the header has no end_header line");
    const size_t number = lines.number();
    rest = line;
    if (!next_token(rest, token)) continue;
    if (token == "end_header") {
      // The body starts after this line's end: bytes on the line itself would be skipped unread.
      if (next_token(rest, token)) fail_at_line(number, "unexpected " + quote(token) + " after end_header");
      break;
    }
    if (token == "comment" || token == "obj_info") continue;
    if (token == "format") {
      std::string_view kind, version;
      next_token(rest, kind);
      next_token(rest, version);
      if (kind == "ascii") header.encoding = Encoding::Ascii;
      else if (kind == "binary_little_endian") header.encoding = Encoding::BinaryLittle;
      else if (kind == "binary_big_endian") header.encoding = Encoding::BinaryBig;
      else fail_at_line(number, "unknown PLY format " + quote(kind));
      has_format = true;
    } else if (token == "element") {
      PlyElement element;
      std::string_view name, count;
      if (!next_token(rest, name) || !next_token(rest, count) || !parse_int(count, element.count) || element.count < 0)
        fail_at_line(number, "element needs a name and a count");
      element.name = std::string(name);
      element.line = number;
      // The body reader keeps one array per vertex property and one face list: a second block
      // would be read into arrays sized for the first.
      if (element.name == "vertex" || element.name == "face")
        for (const auto& other : header.elements)
          if (other.name == element.name)
            fail_at_line(number, "a second '" + element.name + "' element; a PLY file must have one");
      header.elements.push_back(std::move(element));
    } else if (token == "property") {
      if (header.elements.empty()) fail_at_line(number, "property before any element");
      PlyElement& element = header.elements.back();
      PlyProperty property;
      std::string_view type, name;
      if (!next_token(rest, type)) fail_at_line(number, "property without a type");
      if (type == "list") {
        std::string_view count_type;
        if (!next_token(rest, count_type) || !next_token(rest, type)) fail_at_line(number, "list property needs two types");
        property.count_type = type_from(count_type);
        if (!is_integer(property.count_type))
          fail_at_line(number, "list count type " + quote(count_type) + " is not an integer type");
      }
      property.type = type_from(type);
      if (property.type == PlyType::None) fail_at_line(number, "unknown property type " + quote(type));
      if (!next_token(rest, name)) fail_at_line(number, "property without a name");
      property.name = std::string(name);
      for (const auto& other : element.properties)
        if (other.name == property.name)
          fail_at_line(number, "property " + quote(name) + " declared twice in element '" + element.name + "'");
      const bool list = property.count_type != PlyType::None;
      if (element.name == "vertex" && !list) property.role = vertex_role(name);
      const bool indexed = element.name == "face" || element.name == "tristrips";
      if (indexed && list && (name == "vertex_indices" || name == "vertex_index")) {
        if (!is_integer(property.type)) fail_at_line(number, element.name + " vertex indices must have an integer type");
        property.role = Role::Indices;
      }
      if (element.name == "face" && list && name == "texcoord") property.role = Role::TexCoord;
      // Two index lists would be read as one polygon of both.
      if (property.role == Role::Indices)
        for (const auto& other : element.properties)
          if (other.role == Role::Indices)
            fail_at_line(number, "the " + element.name + " element has two vertex index lists ('" + other.name + "' and " +
                                     quote(name) + ")");
      element.properties.push_back(std::move(property));
    } else {
      // Not a keyword: old exporters wrote free text here (Blender 2.4x: "Created by Blender3D
      // 247 - www.blender.org, source file: ..."). It defines nothing, so it is skipped.
      header.warnings.push_back("line " + std::to_string(number) + ": skipped unknown PLY header line " +
                                quote(line));
    }
  }
  if (!has_format) throw std::invalid_argument("the header has no format line");
  header.body = lines.rest();
  header.body_line = lines.number() + 1;
  return header;
}

// Values of a binary body; throws on truncation.
class BinarySource {
 public:
  BinarySource(const char* file, const char* begin, const char* end, bool swap)
      : file_(file), cursor_(begin), end_(end), swap_(swap) {}

  double number(PlyType type) {
    switch (type) {
      case PlyType::Int8: return load<int8_t>();
      case PlyType::UInt8: return load<uint8_t>();
      case PlyType::Int16: return load<int16_t>();
      case PlyType::UInt16: return load<uint16_t>();
      case PlyType::Int32: return load<int32_t>();
      case PlyType::UInt32: return load<uint32_t>();
      case PlyType::Float32: return load<float>();
      case PlyType::Float64: return load<double>();
      case PlyType::None: break;
    }
    throw std::invalid_argument("bad property type");
  }

  int64_t integer(PlyType type) {
    // Every PLY integer type is exact in a double.
    if (type == PlyType::Float32 || type == PlyType::Float64 || type == PlyType::None)
      throw std::invalid_argument("bad integer type");
    return static_cast<int64_t>(number(type));
  }

  std::string where() const { return "byte " + std::to_string(cursor_ - file_) + ", "; }
  size_t remaining() const { return size_t(end_ - cursor_); }
  /// What follows the last row ("" when nothing does). One line end is tolerated: some tools
  /// end every file with one.
  std::string rest() const {
    const size_t left = remaining();
    if (left == 0 || (left == 1 && cursor_[0] == '\n') || (left == 2 && cursor_[0] == '\r' && cursor_[1] == '\n'))
      return "";
    return std::to_string(left) + " more bytes from byte " + std::to_string(cursor_ - file_);
  }
  /// Fewest bytes a value of this property takes (an empty list: just its count).
  static size_t min_bytes(const PlyProperty& p) {
    return type_size(p.count_type != PlyType::None ? p.count_type : p.type);
  }

 private:
  static size_t type_size(PlyType t) {
    switch (t) {
      case PlyType::Int8:
      case PlyType::UInt8: return 1;
      case PlyType::Int16:
      case PlyType::UInt16: return 2;
      case PlyType::Int32:
      case PlyType::UInt32:
      case PlyType::Float32: return 4;
      default: return 8;
    }
  }

  template <class T>
  T load() {
    if (size_t(end_ - cursor_) < sizeof(T)) throw std::invalid_argument("the file ends in the middle of the data");
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, cursor_, sizeof(T));
    if (swap_) std::reverse(bytes, bytes + sizeof(T));
    cursor_ += sizeof(T);
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

  const char* file_;
  const char* cursor_;
  const char* end_;
  bool swap_;
};

// Whitespace-separated values of an ascii body, counting lines for messages.
class AsciiSource {
 public:
  AsciiSource(const char* begin, const char* end, size_t line) : cursor_(begin), end_(end), line_(line) {}

  double number(PlyType type) {
    const std::string_view token = next();
    double value;
    if (is_integer(type)) {
      int64_t i;
      if (!parse_int(token, i)) throw std::invalid_argument("expected an integer, got " + quote(token));
      return double(i);
    }
    if (!parse_double(token, value)) throw std::invalid_argument("expected a number, got " + quote(token));
    return value;
  }

  int64_t integer(PlyType) {
    const std::string_view token = next();
    int64_t value;
    if (!parse_int(token, value)) throw std::invalid_argument("expected an integer, got " + quote(token));
    return value;
  }

  std::string where() const { return "line " + std::to_string(line_) + ", "; }
  size_t remaining() const { return size_t(end_ - cursor_); }
  /// What follows the last row ("" when only white space does).
  std::string rest() {
    skip_space();
    if (cursor_ == end_) return "";
    const size_t first = line_;
    size_t lines = 0;
    for (; cursor_ < end_; ++lines) {
      const char* stop = static_cast<const char*>(std::memchr(cursor_, '\n', size_t(end_ - cursor_)));
      cursor_ = stop ? stop + 1 : end_;
      skip_space();
    }
    return std::to_string(lines) + " more line" + (lines == 1 ? "" : "s") + " of data from line " + std::to_string(first);
  }
  /// Fewest bytes a value takes: one character and a separator.
  static size_t min_bytes(const PlyProperty&) { return 2; }

 private:
  void skip_space() {
    while (cursor_ < end_ && (is_space(*cursor_) || *cursor_ == '\n')) {
      if (*cursor_ == '\n') ++line_;
      ++cursor_;
    }
  }

  std::string_view next() {
    skip_space();
    if (cursor_ == end_) throw std::invalid_argument("the file ends in the middle of the data");
    const char* start = cursor_;
    while (cursor_ < end_ && !is_space(*cursor_) && *cursor_ != '\n') ++cursor_;
    return std::string_view(start, size_t(cursor_ - start));
  }

  const char* cursor_;
  const char* end_;
  size_t line_;
};

// The file must end with the last row the header declares: more data means a count too small.
template <class Source>
void check_ends_after_rows(const PlyHeader& header, Source& source) {
  const std::string rest = source.rest();
  if (rest.empty()) return;
  std::string counts;
  for (const auto& element : header.elements)
    counts += (counts.empty() ? "line " : ", line ") + std::to_string(element.line) + ": element " + element.name +
              " " + std::to_string(element.count);
  throw std::invalid_argument("the file goes on after the rows its header declares (" + counts + "): " + rest);
}

// A triangle strip's triangles: each three consecutive indices, every second one turned so that
// all face one way. -1 starts a new strip; a triangle with a repeated corner (how strips are
// joined) is no face. with_uvs: the faces have per-corner UVs, which a strip's corners lack.
void add_strip(MeshFile& mesh, const std::vector<int32_t>& indices, bool with_uvs) {
  const double none[6] = {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  size_t start = 0;
  for (size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] < 0) start = i + 1;
    if (indices[i] < 0 || i < start + 2) continue;
    int32_t c[3] = {indices[i - 2], indices[i - 1], indices[i]};
    if ((i - start) % 2 == 1) std::swap(c[0], c[1]);
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    add_polygon(mesh, c, 3, with_uvs ? none : nullptr, -1, with_uvs, false);
  }
}

template <class Source>
MeshFile read_body(const PlyHeader& header, Source& source) {
  MeshFile mesh;
  mesh.warnings = header.warnings;
  std::vector<double> vertex_uvs;
  bool face_texcoords = false;
  for (const auto& element : header.elements) {
    if (element.name == "face")
      for (const auto& p : element.properties) face_texcoords = face_texcoords || p.role == Role::TexCoord;
  }
  std::vector<int32_t> corners;
  std::vector<double> uvs;
  int64_t first_skipped = 0;
  for (const auto& element : header.elements) {
    const bool is_vertex = element.name == "vertex", is_face = element.name == "face";
    const bool is_strip = element.name == "tristrips";
    bool has[12] = {};
    for (const auto& p : element.properties) has[int(p.role)] = true;
    const bool colors = is_vertex && has[int(Role::Red)] && has[int(Role::Green)] && has[int(Role::Blue)];
    const bool uv = is_vertex && has[int(Role::U)] && has[int(Role::V)];
    if ((is_face || is_strip) && !has[int(Role::Indices)] && element.count > 0)
      throw std::invalid_argument("the " + element.name + " element has no vertex_indices list");
    if (is_vertex && !(has[int(Role::X)] && has[int(Role::Y)] && has[int(Role::Z)]) && element.count > 0)
      throw std::invalid_argument("the vertex element has no x, y and z properties");
    if (element.properties.empty()) continue;  // nothing to read, however many rows
    // Refuse counts the rest of the file cannot hold before allocating for them.
    size_t row_bytes = 0;
    for (const auto& p : element.properties) row_bytes += source.min_bytes(p);
    if (size_t(element.count) > source.remaining() / row_bytes + 1)
      throw std::invalid_argument("element '" + element.name + "' announces " + std::to_string(element.count) +
                                  " rows, more than the " + std::to_string(source.remaining()) +
                                  " bytes left in the file can hold");
    if (is_vertex) {
      mesh.vertices.assign(3 * size_t(element.count), 0.0);
      if (colors) {
        mesh.color_channels = has[int(Role::Alpha)] ? 4 : 3;
        mesh.vertex_colors.assign(size_t(mesh.color_channels * element.count), 1.0);
      }
      if (uv) vertex_uvs.assign(2 * size_t(element.count), 0.0);
    }
    if (is_face) {  // most files hold triangles
      mesh.triangles.reserve(3 * size_t(element.count));
      mesh.triangle_polygon.reserve(size_t(element.count));
    }
    int64_t row = 0;
    try {
      for (; row < element.count; ++row) {
        corners.clear();
        uvs.clear();
        for (const auto& p : element.properties) {
          if (p.count_type != PlyType::None) {
            const int64_t count = source.integer(p.count_type);
            if (count < 0) throw std::invalid_argument("negative list length " + std::to_string(count));
            for (int64_t i = 0; i < count; ++i) {
              if (p.role == Role::Indices) {
                const int64_t v = source.integer(p.type);
                if (is_strip && v == -1) {  // a strip's restart
                  corners.push_back(-1);
                  continue;
                }
                if (v < 0 || v > INT32_MAX)
                  throw std::invalid_argument("vertex index " + std::to_string(v) + " is out of range");
                corners.push_back(int32_t(v));
              } else if (p.role == Role::TexCoord) {
                uvs.push_back(source.number(p.type));
              } else {
                source.number(p.type);
              }
            }
            continue;
          }
          const double value = source.number(p.type);
          if (!is_vertex) continue;
          switch (p.role) {
            case Role::X: mesh.vertices[3 * row] = value; break;
            case Role::Y: mesh.vertices[3 * row + 1] = value; break;
            case Role::Z: mesh.vertices[3 * row + 2] = value; break;
            case Role::Red:
            case Role::Green:
            case Role::Blue:
            case Role::Alpha:
              if (colors)
                mesh.vertex_colors[mesh.color_channels * row + (int(p.role) - int(Role::Red))] = value / color_divisor(p.type);
              break;
            case Role::U: if (uv) vertex_uvs[2 * row] = value; break;
            case Role::V: if (uv) vertex_uvs[2 * row + 1] = value; break;
            default: break;
          }
        }
        if (is_strip) add_strip(mesh, corners, face_texcoords);
        if (is_face) {
          if (face_texcoords && uvs.size() != 2 * corners.size())
            throw std::invalid_argument("texcoord holds " + std::to_string(uvs.size()) + " values for " +
                                        std::to_string(corners.size()) + " corners");
          add_polygon(mesh, corners.data(), corners.size(), face_texcoords ? uvs.data() : nullptr, -1, face_texcoords,
                      false);
          if (corners.size() < 3 && mesh.skipped_faces == 1) first_skipped = row;
        }
      }
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(source.where() + "element '" + element.name + "' row " + std::to_string(row) +
                                  ": " + error.what());
    }
  }
  check_ends_after_rows(header, source);
  check_triangle_indices(mesh, "face");
  warn_skipped_faces(mesh, "face " + std::to_string(first_skipped));
  if (!face_texcoords && !vertex_uvs.empty()) {
    mesh.corner_uvs.resize(2 * mesh.triangles.size());
    for (size_t c = 0; c < mesh.triangles.size(); ++c) {
      mesh.corner_uvs[2 * c] = vertex_uvs[2 * size_t(mesh.triangles[c])];
      mesh.corner_uvs[2 * c + 1] = vertex_uvs[2 * size_t(mesh.triangles[c]) + 1];
    }
  }
  return mesh;
}

// Little-endian binary output.
class BinaryWriter {
 public:
  explicit BinaryWriter(std::string& out) : out_(out), swap_(!host_is_little_endian()) {}

  template <class T>
  void put(T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if (swap_) std::reverse(bytes, bytes + sizeof(T));
    out_.append(bytes, sizeof(T));
  }

  void put_real(double value, bool as_float) { as_float ? put(float(value)) : put(value); }

 private:
  std::string& out_;
  bool swap_;
};

bool all_floats(const std::vector<double>& values) {
  for (double x : values)
    if (!(double(float(x)) == x || std::isnan(x))) return false;
  return true;
}

// Every colour is exactly k / 255, as the reader produces from bytes.
bool all_bytes(const std::vector<double>& values) {
  for (double x : values) {
    const double k = std::round(x * 255.0);
    if (!(k >= 0 && k <= 255 && k / 255.0 == x)) return false;
  }
  return true;
}

// One UV per vertex (no NaN, the same at every corner), or empty when there is none.
std::vector<double> per_vertex_uvs(const MeshFile& mesh) {
  std::vector<double> uv(2 * size_t(mesh.num_vertices()), 0.0);
  std::vector<uint8_t> seen(size_t(mesh.num_vertices()), 0);
  for (size_t c = 0; c < mesh.triangles.size(); ++c) {
    const size_t v = size_t(mesh.triangles[c]);
    const double u = mesh.corner_uvs[2 * c], w = mesh.corner_uvs[2 * c + 1];
    if (std::isnan(u) || std::isnan(w)) return {};
    if (seen[v] && !(uv[2 * v] == u && uv[2 * v + 1] == w)) return {};
    seen[v] = 1;
    uv[2 * v] = u;
    uv[2 * v + 1] = w;
  }
  return uv;
}

}  // namespace

MeshFile read_ply(const char* data, size_t size) {
  const PlyHeader header = parse_header(data, size);
  const char* end = data + size;
  if (header.encoding == Encoding::Ascii) {
    AsciiSource source(header.body, end, header.body_line);
    return read_body(header, source);
  }
  const bool little = header.encoding == Encoding::BinaryLittle;
  BinarySource source(data, header.body, end, little != host_is_little_endian());
  return read_body(header, source);
}

std::string write_ply(const MeshFile& mesh) {
  const int64_t n = mesh.num_vertices();
  const auto groups = polygon_groups(mesh);
  const bool float_positions = all_floats(mesh.vertices);
  const bool colors = mesh.color_channels > 0;
  const bool byte_colors = colors && all_bytes(mesh.vertex_colors);
  const bool float_colors = colors && all_floats(mesh.vertex_colors);
  const bool with_uvs = !mesh.corner_uvs.empty();
  const std::vector<double> vertex_uvs = with_uvs ? per_vertex_uvs(mesh) : std::vector<double>();
  const bool face_uvs = with_uvs && vertex_uvs.empty();
  const bool float_uvs = with_uvs && all_floats(mesh.corner_uvs);
  size_t largest = 0;
  for (const auto& g : groups) largest = std::max(largest, size_t(g.end - g.begin + 2));
  const bool byte_counts = largest <= 255 / (face_uvs ? 2 : 1);

  const char* real = float_positions ? "float" : "double";
  const char* uv_type = float_uvs ? "float" : "double";
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by TopStoc\n";
  out += "element vertex " + std::to_string(n) + "\n";
  for (const char* axis : {"x", "y", "z"}) out += std::string("property ") + real + " " + axis + "\n";
  if (colors) {
    const char* names[4] = {"red", "green", "blue", "alpha"};
    for (int k = 0; k < mesh.color_channels; ++k)
      out += std::string("property ") + (byte_colors ? "uchar " : float_colors ? "float " : "double ") + names[k] + "\n";
  }
  if (!vertex_uvs.empty()) out += std::string("property ") + uv_type + " s\nproperty " + uv_type + " t\n";
  out += "element face " + std::to_string(groups.size()) + "\n";
  out += std::string("property list ") + (byte_counts ? "uchar" : "int") + " int vertex_indices\n";
  if (face_uvs) out += std::string("property list ") + (byte_counts ? "uchar " : "int ") + uv_type + " texcoord\n";
  out += "end_header\n";

  out.reserve(out.size() + size_t(n) * (3 * 8 + 4 * 8 + 2 * 8) + groups.size() * 16 + mesh.triangles.size() * 4);
  BinaryWriter writer(out);
  for (int64_t v = 0; v < n; ++v) {
    for (int k = 0; k < 3; ++k) writer.put_real(mesh.vertices[3 * v + k], float_positions);
    for (int k = 0; k < mesh.color_channels; ++k) {
      const double c = mesh.vertex_colors[mesh.color_channels * v + k];
      if (byte_colors) writer.put(uint8_t(std::lround(c * 255.0)));
      else writer.put_real(c, float_colors);
    }
    if (!vertex_uvs.empty())
      for (int k = 0; k < 2; ++k) writer.put_real(vertex_uvs[2 * v + k], float_uvs);
  }
  std::vector<int64_t> corners;
  for (const auto& group : groups) {
    group_corners(group, corners);
    const auto put_count = [&](size_t count) { byte_counts ? writer.put(uint8_t(count)) : writer.put(int32_t(count)); };
    put_count(corners.size());
    for (int64_t c : corners) writer.put(mesh.triangles[c]);
    if (face_uvs) {
      put_count(2 * corners.size());
      for (int64_t c : corners)
        for (int k = 0; k < 2; ++k) writer.put_real(mesh.corner_uvs[2 * c + k], float_uvs);
    }
  }
  return out;
}

}  // namespace topstoc::io_detail
