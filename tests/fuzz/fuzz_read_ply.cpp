// libFuzzer target: the PLY reader on arbitrary bytes, then PLY writer -> reader round trip
// (see fuzz_io_common.hpp for what is checked), and that an accepted file held
// exactly what it declares (fuzz_counts.hpp).
#include "fuzz_counts.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return topstoc::fuzz::run(data, size, topstoc::MeshFormat::Ply, topstoc::fuzz::check_ply_counts);
}
