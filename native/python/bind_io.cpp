// Bindings for mesh file reading and writing (bytes in memory; the Python layer opens,
// decompresses and names the file).
#include <pybind11/stl.h>

#include <stdexcept>

#include "convert.hpp"
#include "topstoc/io/io.hpp"

namespace topstoc::python {

namespace {

MeshFormat format_from(const std::string& name) {
  if (name == "obj") return MeshFormat::Obj;
  if (name == "ply") return MeshFormat::Ply;
  if (name == "off") return MeshFormat::Off;
  if (name == "stl") return MeshFormat::Stl;
  throw std::invalid_argument("format must be 'obj', 'ply', 'off' or 'stl', got '" + name + "'");
}

// (rows, columns) float array (or None -> empty) as row-major doubles.
std::vector<double> floats_from(const py::handle& object, int64_t rows, int64_t columns, const char* what) {
  if (object.is_none()) return {};
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a || a.ndim() != 2 || a.shape(0) != rows || a.shape(1) != columns)
    throw std::invalid_argument(std::string(what) + " must be a float array of shape (" + std::to_string(rows) + ", " +
                          std::to_string(columns) + ")");
  return std::vector<double>(a.data(), a.data() + a.size());
}

// Names as the file's bytes: their encoding is the Python layer's business (io.py).
py::list bytes_list(const std::vector<std::string>& names) {
  py::list out;
  for (const auto& name : names) out.append(py::bytes(name));
  return out;
}

py::object optional_array(std::vector<double>&& values, int64_t columns) {
  if (values.empty()) return py::none();
  return to_array(std::move(values), columns);
}

}  // namespace

void bind_io(py::module_& m) {
  m.def(
      "read_mesh",
      [](const py::buffer& data, const std::string& format) {
        const MeshFormat kind = format_from(format);
        const py::buffer_info info = data.request();
        if (info.itemsize != 1 || info.ndim != 1) throw std::invalid_argument("data must be a bytes-like object");
        MeshFile file;
        {
          EngineCall call;
          file = read_mesh_file(static_cast<const char*>(info.ptr), size_t(info.size), kind);
        }
        py::dict d;
        d["polygons"] = file.polygons;
        d["skipped_faces"] = file.skipped_faces;
        d["material_names"] = bytes_list(file.material_names);
        d["material_libraries"] = bytes_list(file.material_libraries);
        d["warnings"] = file.warnings;  // built from quote(): plain ASCII
        const int32_t channels = file.color_channels;
        d["vertices"] = to_array(std::move(file.vertices), 3);
        d["triangles"] = to_array(std::move(file.triangles), 3);
        d["triangle_polygon"] = to_array(std::move(file.triangle_polygon));
        d["corner_uvs"] = optional_array(std::move(file.corner_uvs), 6);
        d["vertex_colors"] = optional_array(std::move(file.vertex_colors), channels);
        d["triangle_material"] =
            file.triangle_material.empty() ? py::object(py::none()) : py::object(to_array(std::move(file.triangle_material)));
        return d;
      },
      py::arg("data"), py::arg("format"),
      "Parses a mesh file's bytes ('obj', 'ply', 'off', 'stl'): a dict of arrays in the file's vertex order; "
      "material_names and material_libraries as bytes, warnings as str.");

  m.def(
      "write_mesh",
      [](const std::string& format, const py::handle& vertices, const py::handle& triangles,
         const py::handle& triangle_polygon, const py::handle& corner_uvs, const py::handle& vertex_colors,
         const py::handle& triangle_material, const std::vector<std::string>& material_names,
         const std::vector<std::string>& material_libraries) {
        const MeshFormat kind = format_from(format);
        MeshFile file;
        file.vertices = positions_from(vertices, "vertices");
        file.triangles = indices_from(triangles, 3, "triangles");
        const int64_t n = file.num_vertices(), t = file.num_triangles();
        file.triangle_polygon = ids_from(triangle_polygon, t, "triangle_polygon");
        file.corner_uvs = floats_from(corner_uvs, t, 6, "corner_uvs");
        if (!vertex_colors.is_none()) {
          auto a = py::array::ensure(vertex_colors);
          if (!a || a.ndim() != 2 || (a.shape(1) != 3 && a.shape(1) != 4))
            throw std::invalid_argument("vertex_colors must be a float array of shape (n, 3) or (n, 4)");
          file.color_channels = int32_t(a.shape(1));
          file.vertex_colors = floats_from(vertex_colors, n, file.color_channels, "vertex_colors");
        }
        file.triangle_material = ids_from(triangle_material, t, "triangle_material");
        file.material_names = material_names;
        file.material_libraries = material_libraries;
        std::string out;
        {
          EngineCall call;
          out = write_mesh_file(file, kind);
        }
        return py::bytes(out);
      },
      py::arg("format"), py::arg("vertices"), py::arg("triangles"), py::arg("triangle_polygon") = py::none(),
      py::arg("corner_uvs") = py::none(), py::arg("vertex_colors") = py::none(),
      py::arg("triangle_material") = py::none(), py::arg("material_names") = std::vector<std::string>(),
      py::arg("material_libraries") = std::vector<std::string>(),
      "Serialises a mesh ('obj', 'ply', 'off', 'stl') and returns the file's bytes. corner_uvs: (m, 6).");
}

}  // namespace topstoc::python
