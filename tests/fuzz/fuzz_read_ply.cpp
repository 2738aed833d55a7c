// libFuzzer target: the PLY reader on arbitrary bytes, then PLY writer -> reader round trip
// (see fuzz_io_common.hpp for what is checked).
#include "fuzz_io_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return topstoc::fuzz::run(data, size, topstoc::MeshFormat::Ply);
}
