// libFuzzer target: topstoc::Mesh on arbitrary arrays, then a decimation with parameters taken
// from the input. Mesh must refuse bad arrays with std::invalid_argument (non-finite
// coordinates, indices out of range) and take everything else (degenerate, duplicate,
// non-manifold, huge coordinates); decimate must return arrays whose sizes and indices agree.
// The topology guarantees themselves are checked by the property tests (tests/python).
//
// Input layout: byte 0 vertex count - 1 (mod 48), byte 1 triangle count (mod 96), byte 2
// flags (bit 0 raw doubles instead of grid coordinates, bit 1 filtered placement, bit 2
// feature angle, bit 3 area-weighted), byte 3 target, bytes 4-11 seed, then coordinates
// (grid: 1 byte each, 0..15; raw: 8 bytes each) and 3 index bytes per triangle (mod n + 2,
// minus 1: -1 and n test the range check). Missing bytes read as 0.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/decimate.hpp"
#include "topstoc/decimate/features.hpp"

namespace {

class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  uint64_t u64() {
    uint64_t value = 0;
    for (int k = 0; k < 8; ++k) value |= uint64_t(byte()) << (8 * k);
    return value;
  }
  double raw_double() {
    const uint64_t bits = u64();
    double value;
    std::memcpy(&value, &bits, 8);
    return value;
  }

 private:
  const uint8_t* data_;
  size_t size_, at_ = 0;
};

void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz check failed: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace topstoc;
  Bytes in(data, size);
  const int32_t n = 1 + in.byte() % 48, m = in.byte() % 96;
  const uint8_t flags = in.byte();
  const int32_t target = 1 + in.byte() % n;
  const uint64_t seed = in.u64();
  std::vector<double> positions(3 * size_t(n));
  for (double& x : positions) x = (flags & 1) ? in.raw_double() : double(in.byte() % 16);
  std::vector<int32_t> triangles(3 * size_t(m));
  for (int32_t& v : triangles) v = int32_t(in.byte() % (n + 2)) - 1;

  bool finite = true;
  for (double x : positions) finite = finite && std::isfinite(x);
  bool in_range = true;
  for (int32_t v : triangles) in_range = in_range && v >= 0 && v < n;
  bool any_triangle = false;  // three distinct corners (Mesh drops the others and needs one)
  for (int32_t t = 0; t < m; ++t) {
    const int32_t* c = &triangles[3 * size_t(t)];
    any_triangle = any_triangle || (c[0] != c[1] && c[1] != c[2] && c[0] != c[2]);
  }
  const bool valid = finite && in_range && any_triangle;

  Mesh* mesh = nullptr;
  try {
    mesh = new Mesh(positions, triangles.data(), m);
  } catch (const std::invalid_argument&) {
    require(!valid, "Mesh refused finite, in-range arrays with a proper triangle");
    return 0;
  }
  require(valid, "Mesh accepted non-finite coordinates, indices out of range or no proper triangle");
  try {
    const auto layout = build_feature_layout(*mesh, nullptr, 0, nullptr, 0, (flags & 4) ? 0.5 : 0.0);
    DecimateParams params;
    params.target_vertices = target;
    params.sampling.seed = seed;
    params.sampling.area_weighted = flags & 8;
    params.placement = (flags & 2) ? Placement::Filtered : Placement::Subsample;
    const DecimateResult result = decimate(*mesh, *layout, params);
    const size_t kept = result.kept.size();
    require(result.vertices.size() == 3 * kept, "positions: 3 per kept vertex");
    require(result.triangles.size() % 3 == 0, "triangles: 3 per triangle");
    require(result.face_source.size() == result.triangles.size() / 3, "face_source size");
    require(result.corner_source.size() == result.triangles.size(), "corner_source size");
    require(result.labels.size() == size_t(n), "labels: one per input vertex");
    for (int32_t v : result.triangles) require(v >= 0 && size_t(v) < kept, "output index out of range");
    for (int32_t v : result.kept) require(v >= 0 && v < n, "kept vertex out of range");
    for (int32_t f : result.face_source) require(f >= 0 && f < m, "face_source out of range");
    for (int32_t label : result.labels) require(label >= -1 && label < int32_t(kept), "label out of range");
  } catch (const std::invalid_argument&) {
    // A clear refusal (e.g. a mesh without faces) is allowed.
  }
  delete mesh;
  return 0;
}
