// The engine on the command line, C++ alone (no Python): reads a mesh file, decimates it and
// writes the result. Built for every target (Linux, Windows under Wine, macOS) from the same
// source; the same input, target and seed give the same bytes on all of them
// (tests/python/test_native_driver.py compares the Linux and the Windows build's files).
//
//   topstoc_decimate IN OUT (--vertices N | --ratio R) [--seed S] [--mode fast|quality|best]
//
// IN and OUT: .obj .ply .off .stl (uncompressed). fast: the thesis' TopStoc (input positions);
// quality: filtered placement and quadric collapses, as the Python API's mode="quality"; best:
// quality with the large results' fit too, as mode="best".
// OUT is written to OUT.partial and renamed over OUT; it may not be IN.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "topstoc/core/mesh.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/decimate/decimate.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/io/io.hpp"

namespace fs = std::filesystem;
using namespace topstoc;

namespace {

// The Python API's quality mode (addon/core/job.py: QUALITY_REFINE, QUALITY_COLLAPSES).
constexpr double kQualityRefine = 1.0;
constexpr int32_t kQualityCollapses = 10000;

const char* const kUsage =
    "usage: topstoc_decimate IN OUT (--vertices N | --ratio R) [--seed S] [--mode fast|quality|best]\n";

struct Options {
  std::string in, out, mode = "fast";
  int64_t vertices = 0;
  double ratio = 0.0;
  uint64_t seed = 0;
};

struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// A whole-string number, or a UsageError naming the option.
template <class T>
T number(const std::string& option, const std::string& text) {
  size_t used = 0;
  T value{};
  try {
    if constexpr (std::is_floating_point_v<T>) value = T(std::stod(text, &used));
    else if constexpr (std::is_unsigned_v<T>) value = T(std::stoull(text, &used));
    else value = T(std::stoll(text, &used));
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || (!text.empty() && text[0] == '-'))
    throw UsageError(option + " needs a non-negative number, got '" + text + "'");
  return value;
}

Options parse(int argc, char** argv) {
  Options o;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool takes_value = arg == "--vertices" || arg == "--ratio" || arg == "--seed" || arg == "--mode";
    if (takes_value && i + 1 >= argc) throw UsageError(arg + " needs a value");
    if (arg == "--vertices") o.vertices = number<int64_t>(arg, argv[++i]);
    else if (arg == "--ratio") o.ratio = number<double>(arg, argv[++i]);
    else if (arg == "--seed") o.seed = number<uint64_t>(arg, argv[++i]);
    else if (arg == "--mode") o.mode = argv[++i];
    else if (arg.size() > 1 && arg[0] == '-') throw UsageError("unknown option " + arg);
    else if (positional < 2) (positional++ == 0 ? o.in : o.out) = arg;
    else throw UsageError("one input and one output file, got also '" + arg + "'");
  }
  if (positional != 2) throw UsageError("give an input and an output file");
  if ((o.vertices > 0) == (o.ratio > 0)) throw UsageError("give one target: --vertices N (N >= 1) or --ratio R");
  if (o.ratio > 1 || o.vertices > INT32_MAX) throw UsageError("the target must lie in (0, 1] or [1, 2^31)");
  if (o.mode != "fast" && o.mode != "quality" && o.mode != "best")
    throw UsageError("--mode must be fast, quality or best, got '" + o.mode + "'");
  return o;
}

// The vertex count: N, or the ratio of the vertices in triangles rounded as Python's round().
int32_t target_of(const Options& o, const Mesh& mesh) {
  if (o.vertices > 0) return int32_t(o.vertices);
  const double active = double(mesh.num_vertices() - mesh.report().isolated_vertices);
  return std::max<int32_t>(1, int32_t(std::nearbyint(o.ratio * active)));
}

MeshFile decimated(const Options& o, const MeshFile& input, const Mesh& mesh) {
  // Materials of the file stay apart, as in the Python API (its regions).
  const std::vector<int32_t>& regions = input.triangle_material;
  const auto layout = build_feature_layout(mesh, regions.empty() ? nullptr : regions.data(),
                                           int64_t(regions.size()), nullptr, 0);
  DecimateParams params;
  params.target_vertices = target_of(o, mesh);
  params.sampling.seed = o.seed;
  if (o.mode != "fast") {
    params.placement = Placement::Filtered;
    params.refine = kQualityRefine;
    params.refine_collapses = kQualityCollapses;
    params.large_fit = o.mode == "best";
  }
  RunningCall call;
  use_free_cores();
  DecimateResult result = decimate(mesh, *layout, params);
  restore_winding(mesh, result);  // the input's flipped patches, as the Python API gives them
  MeshFile out;
  out.vertices = std::move(result.vertices);
  out.triangles = std::move(result.triangles);
  return out;
}

// Writes bytes to path through path.partial and a rename, so that path is whole or untouched.
void write_atomically(const fs::path& path, const std::string& bytes) {
  fs::path partial = path;
  partial += ".partial";
  {
    std::ofstream file(partial, std::ios::binary | std::ios::trunc);  // binary: '\n' stays '\n' on Windows
    if (!file || !file.write(bytes.data(), std::streamsize(bytes.size())) || !file.flush())
      throw std::runtime_error(partial.string() + ": cannot write the file");
  }
  std::error_code error;
  fs::rename(partial, path, error);
  if (error) {
    fs::remove(partial);
    throw std::runtime_error(path.string() + ": cannot replace the file: " + error.message());
  }
}

int run(const Options& o) {
  const fs::path in(o.in), out(o.out);
  std::error_code same_error;
  if (fs::exists(out) && fs::equivalent(in, out, same_error))
    throw std::invalid_argument(o.out + ": is the input file; write the result elsewhere");
  const MeshFormat out_format = mesh_format_from_name(o.out);
  const MeshFile input = read_mesh_path(o.in);
  const Mesh mesh(input.vertices, input.triangles.data(), input.num_triangles());
  const MeshFile output = decimated(o, input, mesh);
  write_atomically(out, write_mesh_file(output, out_format));
  std::printf("%s: %lld vertices, %lld triangles -> %s: %lld vertices, %lld triangles (seed %llu, %s)\n",
              o.in.c_str(), (long long)input.num_vertices(), (long long)input.num_triangles(), o.out.c_str(),
              (long long)output.num_vertices(), (long long)output.num_triangles(), (unsigned long long)o.seed,
              o.mode.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const UsageError& error) {
    std::fprintf(stderr, "topstoc_decimate: error: %s\n%s", error.what(), kUsage);
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "topstoc_decimate: error: %s\n", error.what());
    return 1;
  }
}
