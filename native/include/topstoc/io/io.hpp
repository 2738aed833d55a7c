// Mesh files: OBJ, PLY (ascii, binary little and big endian), OFF and STL (ascii, binary),
// read into plain arrays and written back.
//
// The readers keep the file's raw complex: every face of the file, in the file's order, over
// the file's vertices in the file's order (STL, which has no shared vertices, is welded by
// exact position, in order of first appearance). Polygons are fan-triangulated and each
// triangle remembers its polygon; nothing is dropped or repaired here (degenerate, duplicate
// and non-manifold faces are kept; topstoc::Mesh decides what to do with them).
//
// Why not OpenMesh's readers (measured with an OpenMesh::IO::BaseImporter that collects raw
// arrays, OpenMesh 9.0): every reader hands positions over as float32 (OFF/OBJ/PLY doubles lose
// digits silently); the OBJ reader passes texture file indices, not usemtl material names; the
// STL reader drops faces whose welded corners coincide; the PLY reader turns float colours into
// bytes and was several times slower than this reader on a large binary PLY (bench_io.py);
// and on a malformed ascii STL (tests/data/nonmanifold_degenerate/openscad_unparseable.stl) it
// reported success with one triangle. So every format is parsed here, from memory (the Python
// layer decompresses .gz/.bz2), with errors that name the line or element.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace topstoc {

enum class MeshFormat { Obj, Ply, Off, Stl };

/// A mesh file's contents as plain arrays. Optional arrays are empty when the file has none.
struct MeshFile {
  std::vector<double> vertices;           ///< positions, 3 per vertex, in the file's vertex order
  std::vector<int32_t> triangles;         ///< 3 per triangle: polygons fan-triangulated (v0, vi, vi+1)
  std::vector<int32_t> triangle_polygon;  ///< per triangle: index of its face in the file
  int64_t polygons = 0;                   ///< faces in the file, including skipped ones
  int64_t skipped_faces = 0;              ///< faces with fewer than 3 corners (points, lines): no triangles
  std::vector<double> corner_uvs;         ///< 6 per triangle (u, v per corner), NaN where a corner has none
  std::vector<double> vertex_colors;      ///< color_channels per vertex, in [0, 1] for byte sources
  int32_t color_channels = 0;             ///< 0, 3 (RGB) or 4 (RGBA)
  std::vector<int32_t> triangle_material; ///< per triangle: index into material_names, -1 = none
  std::vector<std::string> material_names;      ///< OBJ usemtl names in order of first use
  std::vector<std::string> material_libraries;  ///< OBJ mtllib arguments, as written
  std::vector<std::string> warnings;  ///< what a reader skipped in a sloppy file (e.g. unknown PLY header lines)

  int64_t num_vertices() const { return int64_t(vertices.size() / 3); }
  int64_t num_triangles() const { return int64_t(triangles.size() / 3); }
};

/// Parses `size` bytes of a file in `format`. Throws std::invalid_argument naming the line
/// (text) or byte / element row (binary) and the problem: unparseable content, truncated data,
/// indices out of range, element layouts it cannot read unambiguously (a PLY with two
/// `vertex` or `face` elements, a property declared twice). The data must match the counts
/// the file declares exactly, and the file must end where its format says (docs/robustness.md,
/// "Mesh files"): a binary STL's size is 84 + 50 x its triangle count; an ascii STL ends after
/// an `endsolid`; a PLY or OFF file holds no data past its declared rows (white space, OFF
/// comments and one line end after a binary PLY body aside); an OBJ whose last line has no line
/// end and ends in an incomplete face is cut short. Counts are checked against the bytes left
/// before anything is allocated for them. An empty OBJ is an empty mesh; an empty PLY, OFF or
/// STL is an error. Sloppiness real files show is tolerated and noted in MeshFile::warnings: a
/// PLY header line that is no keyword (old Blender wrote "Created by Blender3D ..."), faces with
/// fewer than 3 corners (skipped). Names (OBJ usemtl, mtllib) are kept as bytes.
MeshFile read_mesh_file(const char* data, size_t size, MeshFormat format);

/// Serialises `mesh` in `format` and returns the file's bytes:
/// OBJ: v (with r g b when coloured), vt (deduplicated), f with polygons rebuilt from
///      triangle_polygon where the triangles form the original fan, usemtl, mtllib;
/// PLY: binary little endian; float32 properties when every value is exactly a float32, else
///      float64; colours as bytes when every value is k/255; UVs per vertex when every vertex
///      has one UV, else MeshLab's per-face `texcoord` list; materials are not stored;
/// OFF: polygons and colours (COFF); no UVs or materials;
/// STL: binary, float32 positions and facet normals, triangles only.
/// Throws std::invalid_argument when arrays disagree in size, an index is out of range, or an
/// OBJ material or library name would not read back as written (see obj_name_problem).
std::string write_mesh_file(const MeshFile& mesh, MeshFormat format);

/// Format from a file name's extension (.obj .ply .off .stl, any case; a trailing .gz or
/// .bz2 is ignored). Throws std::invalid_argument for anything else.
MeshFormat mesh_format_from_name(const std::string& name);

/// Reads an uncompressed mesh file from disk (for C++ tools and peers; Python uses
/// read_mesh_file on decompressed bytes). Throws std::invalid_argument or std::runtime_error
/// (file cannot be opened) with the path in the message.
MeshFile read_mesh_path(const std::string& path);

}  // namespace topstoc
