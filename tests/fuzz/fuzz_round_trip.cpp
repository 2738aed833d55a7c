// libFuzzer target: across formats. The first byte picks the reader (OBJ, PLY, OFF, STL), the
// rest is the file; what reads is written in each of the three other formats and read back,
// equal in everything the written format carries: counts, positions (exact, float32 for STL),
// polygons, colours (OBJ, PLY, OFF), UVs (OBJ, PLY), materials (OBJ). See fuzz_io_common.hpp.
#include "fuzz_io_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using topstoc::MeshFormat;
  if (size < 1) return 0;
  const MeshFormat formats[4] = {MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Off, MeshFormat::Stl};
  const MeshFormat source = formats[data[0] % 4];
  topstoc::MeshFile mesh;
  try {
    mesh = topstoc::read_mesh_file(reinterpret_cast<const char*>(data + 1), size - 1, source);
  } catch (const std::invalid_argument&) {
    return 0;  // refused with a message: fine
  }
  topstoc::fuzz::check_consistent(mesh);
  for (MeshFormat target : formats)
    if (target != source) topstoc::fuzz::check_written_as(mesh, target);
  return 0;
}
