// STL, ascii and binary. STL stores three positions per facet and no shared vertices, so the
// reader welds corners with exactly equal coordinates (0.0 and -0.0 are equal) into one
// vertex, numbered in order of first appearance. Facets whose corners coincide are kept.
#include <cstring>
#include <string>

#include "io_detail.hpp"

namespace topstoc::io_detail {

namespace {

// Exact-position welding: the id of each distinct point, in order of first appearance. An
// open-addressing table of vertex ids keyed by the positions' bits (std::unordered_map took
// seconds on 4.6M corners).
class Welder {
 public:
  Welder(MeshFile& mesh, size_t expected_vertices) : mesh_(mesh) {
    size_t capacity = 1024;
    while (capacity < 2 * expected_vertices) capacity *= 2;
    slots_.assign(capacity, -1);
  }

  int32_t id(double x, double y, double z) {
    const double p[3] = {x + 0.0, y + 0.0, z + 0.0};  // + 0.0 turns -0.0 into 0.0
    uint64_t bits[3];
    std::memcpy(bits, p, sizeof bits);
    const size_t mask = slots_.size() - 1;
    for (size_t slot = hash(bits) & mask;; slot = (slot + 1) & mask) {
      const int32_t v = slots_[slot];
      if (v < 0) {
        const auto added = static_cast<int32_t>(mesh_.vertices.size() / 3);
        mesh_.vertices.insert(mesh_.vertices.end(), p, p + 3);
        slots_[slot] = added;
        if (2 * size_t(added + 1) > slots_.size()) grow();
        return added;
      }
      if (std::memcmp(&mesh_.vertices[3 * size_t(v)], p, sizeof p) == 0) return v;
    }
  }

 private:
  static size_t hash(const uint64_t* bits) {
    uint64_t h = bits[0] * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 29) ^ bits[1]) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 31) ^ bits[2]) * 0x94D049BB133111EBull;
    return size_t(h ^ (h >> 32));
  }

  void grow() {
    slots_.assign(2 * slots_.size(), -1);
    const size_t mask = slots_.size() - 1;
    const auto n = static_cast<int32_t>(mesh_.vertices.size() / 3);
    for (int32_t v = 0; v < n; ++v) {
      uint64_t bits[3];
      std::memcpy(bits, &mesh_.vertices[3 * size_t(v)], sizeof bits);
      size_t slot = hash(bits) & mask;
      while (slots_[slot] >= 0) slot = (slot + 1) & mask;
      slots_[slot] = v;
    }
  }

  MeshFile& mesh_;
  std::vector<int32_t> slots_;
};

uint32_t load_u32_le(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

float load_f32_le(const char* p) {
  const uint32_t bits = load_u32_le(p);
  float value;
  std::memcpy(&value, &bits, 4);
  return value;
}

void store_u32_le(std::string& out, uint32_t value) {
  for (int k = 0; k < 4; ++k) out += char((value >> (8 * k)) & 0xFF);
}

void store_f32_le(std::string& out, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, 4);
  store_u32_le(out, bits);
}

MeshFile read_binary(const char* data, uint32_t count) {
  MeshFile mesh;
  mesh.triangles.reserve(3 * size_t(count));
  mesh.triangle_polygon.reserve(count);
  Welder welder(mesh, size_t(count) / 2);  // a closed mesh has about half as many vertices as facets
  for (uint32_t t = 0; t < count; ++t) {
    const char* facet = data + 84 + 50 * size_t(t) + 12;  // skip the normal
    int32_t corners[3];
    for (int c = 0; c < 3; ++c)
      corners[c] = welder.id(load_f32_le(facet + 12 * c), load_f32_le(facet + 12 * c + 4), load_f32_le(facet + 12 * c + 8));
    add_polygon(mesh, corners, 3, nullptr, -1, false, false);
  }
  return mesh;
}

// ascii STL: "solid [name]", facets of exactly three vertices ("facet normal ..", "outer loop",
// 3 x "vertex x y z", "endloop", "endfacet"), "endsolid [name]"; several solids may follow each
// other. The file must end after an endsolid: a file cut between two facets would otherwise
// read as a smaller mesh.
MeshFile read_ascii(const char* data, size_t size) {
  MeshFile mesh;
  Welder welder(mesh, size / 500);  // about 250 bytes of text per facet
  TextLines lines(data, data + size);
  std::string_view line, rest, token;
  std::vector<int32_t> corners;
  bool in_solid = false, in_facet = false;
  size_t solid_line = 0;
  while (lines.next(line)) {
    const size_t number = lines.number();
    rest = line;
    if (!next_token(rest, token)) continue;
    if (token == "vertex") {
      if (!in_facet) fail_at_line(number, "vertex outside a facet");
      double p[3];
      for (double& x : p) {
        if (!next_token(rest, token)) fail_at_line(number, "vertex needs 3 coordinates");
        if (!parse_double(token, x)) fail_at_line(number, "vertex coordinate " + quote(token) + " is not a number");
      }
      if (next_token(rest, token)) fail_at_line(number, "unexpected " + quote(token) + " after the vertex coordinates");
      if (corners.size() == 3) fail_at_line(number, "a facet with more than 3 vertices");
      corners.push_back(welder.id(p[0], p[1], p[2]));
    } else if (token == "facet") {
      if (!in_solid) fail_at_line(number, "facet outside a solid (after endsolid, or before solid)");
      if (in_facet) fail_at_line(number, "facet inside a facet (missing endfacet)");
      in_facet = true;
      corners.clear();
    } else if (token == "endfacet") {
      if (!in_facet) fail_at_line(number, "endfacet without facet");
      if (corners.size() != 3)
        fail_at_line(number, "a facet with " + std::to_string(corners.size()) + " vertices (STL facets have 3)");
      in_facet = false;
      add_polygon(mesh, corners.data(), corners.size(), nullptr, -1, false, false);
    } else if (token == "outer" || token == "endloop") {
      if (!in_facet) fail_at_line(number, quote(token) + " outside a facet");
    } else if (token == "solid") {
      if (in_solid) fail_at_line(number, "solid inside a solid (missing endsolid)");
      in_solid = true;
      solid_line = number;
    } else if (token == "endsolid") {
      if (in_facet) fail_at_line(number, "'endsolid' inside a facet");
      if (!in_solid) fail_at_line(number, "endsolid without solid");
      in_solid = false;
    } else {
      fail_at_line(number, "unexpected " + quote(token));
    }
  }
  if (in_facet)
    throw std::invalid_argument("line " + std::to_string(lines.number()) + ": the file ends inside a facet");
  if (in_solid)
    throw std::invalid_argument("line " + std::to_string(lines.number()) + ": the file ends without the 'endsolid' of "
                                "the solid at line " + std::to_string(solid_line) + " (cut after facet " +
                                std::to_string(mesh.polygons) + "?)");
  return mesh;
}

bool starts_with_solid(const char* data, size_t size) {
  size_t i = 0;
  while (i < size && (is_space(data[i]) || data[i] == '\n')) ++i;
  return size - i >= 5 && std::memcmp(data + i, "solid", 5) == 0;
}

// Text holds no NUL byte; a binary STL's facets almost always do (attribute bytes, zeros).
bool looks_binary(const char* data, size_t size) { return std::memchr(data, '\0', size) != nullptr; }

// A binary STL whose size disagrees with its triangle count (the uint32 at byte 80).
[[noreturn]] void fail_binary_size(uint32_t count, size_t size) {
  const size_t expected = 84 + 50 * size_t(count);
  std::string message = "binary STL: the header says " + std::to_string(count) + " triangles (byte 80), ";
  if (size > expected && (size - 84) % 50 == 0)
    message += "the file holds " + std::to_string((size - 84) / 50) + " (" + std::to_string(size - expected) +
               " more bytes from byte " + std::to_string(expected) + ")";
  else if (size > expected)
    message += "but the file goes on for " + std::to_string(size - expected) + " bytes after them (byte " +
               std::to_string(expected) + ")";
  else
    message += "but the file ends at byte " + std::to_string(size) + ", inside triangle " +
               std::to_string((size - 84) / 50) + " (" + std::to_string(expected - size) + " bytes missing)";
  throw std::invalid_argument(message);
}

}  // namespace

// Binary or ascii: a binary file may start with "solid" too, so the exact size decides first;
// a file that starts with "solid" and holds a NUL byte is binary with a wrong count.
MeshFile read_stl(const char* data, size_t size) {
  if (size == 0) return MeshFile();  // what some tools write for an empty model
  if (size >= 84) {
    const uint32_t count = load_u32_le(data + 80);
    if (size == 84 + 50 * size_t(count)) return read_binary(data, count);
    if (!starts_with_solid(data, size) || looks_binary(data, size)) fail_binary_size(count, size);
  }
  if (!starts_with_solid(data, size))
    throw std::invalid_argument("not an STL file: too short for binary and not starting with 'solid'");
  return read_ascii(data, size);
}

std::string write_stl(const MeshFile& mesh) {
  std::string out = "binary STL written by TopStoc";
  out.resize(80, ' ');
  const int64_t m = mesh.num_triangles();
  if (m > int64_t(UINT32_MAX)) throw std::invalid_argument("too many triangles for STL");
  store_u32_le(out, uint32_t(m));
  out.reserve(84 + 50 * size_t(m));
  for (int64_t t = 0; t < m; ++t) {
    const double* p[3];
    for (int c = 0; c < 3; ++c) p[c] = &mesh.vertices[3 * size_t(mesh.triangles[3 * t + c])];
    const double a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    double normal[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    const double length = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    for (double& x : normal) x = length > 0 ? x / length : 0.0;
    for (double x : normal) store_f32_le(out, float(x));
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) {
        // float32: past its range a coordinate would be written as infinity. (Below its
        // precision values round, to zero under 1.4e-45: that is the format's precision.)
        const float x = float(p[c][k]);
        if (std::isinf(x))
          throw std::invalid_argument("vertex " + std::to_string(mesh.triangles[3 * t + c]) +
                                      " cannot be written to binary STL: coordinate " + shown_number(p[c][k]) +
                                      " is beyond float32's range (+-" +
                                      shown_number(std::numeric_limits<float>::max()) +
                                      "); scale the mesh, or write PLY, OBJ or OFF, which keep doubles");
        store_f32_le(out, x);
      }
    out += '\0';
    out += '\0';
  }
  return out;
}

}  // namespace topstoc::io_detail
