// Peer for decimation: meshoptimizer's simplifiers on a mesh file.
//
//   meshopt_simplify IN OUT TARGET_INDEX_COUNT [sloppy]
//
// IN: OFF or PLY (ASCII or binary little-endian; polygons are fan-triangulated). Runs
// meshopt_simplify (edge collapse, topology-preserving; target_error 1, i.e. unbounded) or, with
// `sloppy`, meshopt_simplifySloppy (grid clustering), then drops unused vertices and writes OUT
// (OFF, PLY or OBJ by extension). Prints one JSON line: input and output counts, the error
// meshoptimizer reports (relative to the mesh extent) and the seconds of the simplification itself.
#include <meshoptimizer.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct MeshData {
  std::vector<float> positions;
  std::vector<unsigned> indices;
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void add_polygon(MeshData& mesh, const std::vector<unsigned>& polygon) {
  for (size_t k = 1; k + 1 < polygon.size(); ++k) mesh.indices.insert(mesh.indices.end(), {polygon[0], polygon[k], polygon[k + 1]});
}

bool read_off(std::ifstream& in, MeshData& mesh) {
  std::string header;
  in >> header;
  if (header != "OFF") return false;
  size_t nv = 0, nf = 0, ne = 0;
  in >> nv >> nf >> ne;
  mesh.positions.resize(3 * nv);
  for (auto& x : mesh.positions) in >> x;
  for (size_t f = 0; f < nf; ++f) {
    size_t k = 0;
    in >> k;
    std::vector<unsigned> polygon(k);
    for (auto& v : polygon) in >> v;
    std::string rest;
    std::getline(in, rest);  // optional colour
    add_polygon(mesh, polygon);
  }
  return bool(in);
}

// Reads one PLY scalar of `type` and returns it as a double.
double read_scalar(std::istream& in, const std::string& type, bool binary) {
  if (!binary) {
    double x = 0;
    in >> x;
    return x;
  }
  auto get = [&](auto value) {
    in.read(reinterpret_cast<char*>(&value), sizeof(value));
    return double(value);
  };
  if (type == "char" || type == "int8") return get(int8_t());
  if (type == "uchar" || type == "uint8") return get(uint8_t());
  if (type == "short" || type == "int16") return get(int16_t());
  if (type == "ushort" || type == "uint16") return get(uint16_t());
  if (type == "int" || type == "int32") return get(int32_t());
  if (type == "uint" || type == "uint32") return get(uint32_t());
  if (type == "float" || type == "float32") return get(float());
  return get(double());
}

bool read_ply(std::ifstream& in, MeshData& mesh) {
  struct Property {
    std::string name, type, count_type;
    bool list = false;
  };
  struct Element {
    std::string name;
    size_t count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
  std::string line, format;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") words >> format;
    if (word == "element") {
      elements.emplace_back();
      words >> elements.back().name >> elements.back().count;
    }
    if (word == "property" && !elements.empty()) {
      Property p;
      words >> p.type;
      if (p.type == "list") {
        p.list = true;
        words >> p.count_type >> p.type;
      }
      words >> p.name;
      elements.back().properties.push_back(p);
    }
    if (word == "end_header") break;
  }
  if (format != "ascii" && format != "binary_little_endian") return false;
  const bool binary = format != "ascii";
  for (const Element& e : elements)
    for (size_t i = 0; i < e.count; ++i) {
      float xyz[3] = {0, 0, 0};
      for (const Property& p : e.properties) {
        if (p.list) {
          const size_t k = size_t(read_scalar(in, p.count_type, binary));
          std::vector<unsigned> polygon(k);
          for (auto& v : polygon) v = unsigned(read_scalar(in, p.type, binary));
          if (e.name == "face") add_polygon(mesh, polygon);
          continue;
        }
        const double x = read_scalar(in, p.type, binary);
        if (e.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z")) xyz[p.name[0] - 'x'] = float(x);
      }
      if (e.name == "vertex") mesh.positions.insert(mesh.positions.end(), xyz, xyz + 3);
    }
  return bool(in);
}

bool read_mesh(const std::string& path, MeshData& mesh) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::string magic;
  std::getline(in, magic);
  in.seekg(0);
  if (magic.rfind("ply", 0) == 0) return read_ply(in, mesh);
  return read_off(in, mesh);
}

bool write_mesh(const std::string& path, const MeshData& mesh) {
  std::ofstream out(path);
  const size_t nv = mesh.positions.size() / 3, nf = mesh.indices.size() / 3;
  out.precision(9);
  if (ends_with(path, ".obj")) {
    for (size_t v = 0; v < nv; ++v)
      out << "v " << mesh.positions[3 * v] << ' ' << mesh.positions[3 * v + 1] << ' ' << mesh.positions[3 * v + 2] << '\n';
    for (size_t f = 0; f < nf; ++f)
      out << "f " << mesh.indices[3 * f] + 1 << ' ' << mesh.indices[3 * f + 1] + 1 << ' ' << mesh.indices[3 * f + 2] + 1 << '\n';
    return bool(out);
  }
  if (ends_with(path, ".ply"))
    out << "ply\nformat ascii 1.0\nelement vertex " << nv << "\nproperty float x\nproperty float y\nproperty float z\n"
        << "element face " << nf << "\nproperty list uchar int vertex_indices\nend_header\n";
  else
    out << "OFF\n" << nv << ' ' << nf << " 0\n";
  for (size_t v = 0; v < nv; ++v)
    out << mesh.positions[3 * v] << ' ' << mesh.positions[3 * v + 1] << ' ' << mesh.positions[3 * v + 2] << '\n';
  for (size_t f = 0; f < nf; ++f)
    out << "3 " << mesh.indices[3 * f] << ' ' << mesh.indices[3 * f + 1] << ' ' << mesh.indices[3 * f + 2] << '\n';
  return bool(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s IN OUT TARGET_INDEX_COUNT [sloppy]\n", argv[0]);
    return 2;
  }
  const bool sloppy = argc > 4 && std::strcmp(argv[4], "sloppy") == 0;
  MeshData mesh;
  if (!read_mesh(argv[1], mesh) || mesh.indices.empty()) {
    std::fprintf(stderr, "cannot read a triangle mesh from %s\n", argv[1]);
    return 1;
  }
  const size_t nv = mesh.positions.size() / 3;
  for (unsigned v : mesh.indices)
    if (v >= nv) {
      std::fprintf(stderr, "%s: vertex index %u out of range\n", argv[1], v);
      return 1;
    }
  const size_t target = size_t(std::atoll(argv[3]));
  std::vector<unsigned> indices(mesh.indices.size());
  float error = 0.0f;
  const auto start = std::chrono::steady_clock::now();
  const size_t count =
      sloppy ? meshopt_simplifySloppy(indices.data(), mesh.indices.data(), mesh.indices.size(), mesh.positions.data(),
                                      nv, 3 * sizeof(float), target, 1.0f, &error)
             : meshopt_simplify(indices.data(), mesh.indices.data(), mesh.indices.size(), mesh.positions.data(), nv,
                                3 * sizeof(float), target, 1.0f, 0, &error);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  indices.resize(count);
  // Keep only the vertices the result uses.
  MeshData result;
  result.indices = indices;
  result.positions.resize(mesh.positions.size());
  const size_t kept = meshopt_optimizeVertexFetch(result.positions.data(), result.indices.data(), count,
                                                  mesh.positions.data(), nv, 3 * sizeof(float));
  result.positions.resize(3 * kept);
  if (!write_mesh(argv[2], result)) {
    std::fprintf(stderr, "cannot write %s\n", argv[2]);
    return 1;
  }
  std::printf("{\"input\": {\"vertices\": %zu, \"triangles\": %zu}, \"output\": {\"vertices\": %zu, \"triangles\": %zu}, "
              "\"error\": %.9g, \"seconds\": %.6f, \"sloppy\": %s}\n",
              nv, mesh.indices.size() / 3, kept, count / 3, double(error), seconds, sloppy ? "true" : "false");
  return 0;
}
