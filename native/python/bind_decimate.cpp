// Bindings for decimation, sampling probabilities and triangle quality.
#include <pybind11/stl.h>

#include <cmath>

#include "caller_order.hpp"
#include <stdexcept>

#include "convert.hpp"
#include "topstoc/core/validate.hpp"
#include "topstoc/decimate/decimate.hpp"
#include "topstoc/core/quality.hpp"

namespace topstoc::python {

namespace {

DensityMode density_from(const std::string& name) {
  if (name == "off") return DensityMode::Off;
  if (name == "uniform") return DensityMode::Uniform;
  if (name == "adaptive") return DensityMode::Adaptive;
  if (name == "euclidean") return DensityMode::Euclidean;
  throw std::invalid_argument("density must be 'off', 'uniform', 'adaptive' or 'euclidean', got '" + name + "'");
}

Placement placement_from(const std::string& name) {
  if (name == "subsample") return Placement::Subsample;
  if (name == "filtered") return Placement::Filtered;
  throw std::invalid_argument("placement must be 'subsample' or 'filtered', got '" + name + "'");
}

template <size_t N>
void fill(const py::handle& object, double (&out)[N], const char* what) {
  auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!values || size_t(values.size()) != N)
    throw std::invalid_argument(std::string(what) + " must hold " + std::to_string(N) + " numbers");
  for (size_t i = 0; i < N; ++i) out[i] = values.data()[i];
}

ViewGuidance view_from(const py::handle& object) {
  ViewGuidance view;
  if (object.is_none()) return view;
  py::dict d = py::cast<py::dict>(object);
  view.enabled = true;
  view.perspective = d.contains("perspective") ? py::cast<bool>(d["perspective"]) : true;
  if (d.contains("eye")) fill(d["eye"], view.eye, "view eye");
  if (d.contains("direction")) fill(d["direction"], view.direction, "view direction");
  if (d.contains("back_ratio")) view.back_ratio = py::cast<double>(d["back_ratio"]);
  if (d.contains("silhouette_angle")) view.silhouette_angle = py::cast<double>(d["silhouette_angle"]);
  if (d.contains("silhouette_falloff")) view.silhouette_falloff = py::cast<double>(d["silhouette_falloff"]);
  if (d.contains("view_projection") && !d["view_projection"].is_none()) {
    fill(d["view_projection"], view.view_projection, "view_projection");
    view.frustum = true;
  }
  if (d.contains("outside_probability")) view.outside_probability = py::cast<double>(d["outside_probability"]);
  return view;
}

std::vector<BoxGuidance> boxes_from(const py::handle& object) {
  std::vector<BoxGuidance> boxes;
  if (object.is_none()) return boxes;
  for (const auto& item : object) {
    auto pair = py::cast<py::tuple>(item);
    if (pair.size() != 2) throw std::invalid_argument("each box must be (world_to_box 4x4 matrix, value)");
    BoxGuidance box{};
    fill(pair[0], box.world_to_box, "box matrix");
    box.value = py::cast<double>(pair[1]);
    boxes.push_back(box);
  }
  return boxes;
}

py::dict issues_dict(const PartitionIssues& i) {
  py::dict d;
  d["unreached"] = i.unreached;
  d["non_disk"] = i.non_disk;
  d["bad_edge"] = i.bad_edge;
  d["duplicate"] = i.duplicate;
  d["bad_link"] = i.bad_link;
  d["short_loop"] = i.short_loop;
  d["isolated"] = i.isolated;
  d["sliver"] = i.sliver;
  d["absorbed"] = i.absorbed;
  d["bad_component"] = i.bad_component;
  d["pillows"] = i.pillows;
  return d;
}

py::dict result_dict(DecimateResult&& r) {
  py::dict d;
  d["samples"] = to_array(std::move(r.samples));
  d["kept"] = to_array(std::move(r.kept));
  d["vertices"] = to_array(std::move(r.vertices), 3);
  d["triangles"] = to_array(std::move(r.triangles), 3);
  d["face_source"] = to_array(std::move(r.face_source));
  d["corner_source"] = to_array(std::move(r.corner_source), 3);
  d["labels"] = to_array(std::move(r.labels));
  d["target_vertices"] = r.target_vertices;
  d["selected"] = r.selected;
  d["forced"] = r.forced;
  d["density_rejected"] = r.density_rejected;
  d["guided"] = r.guided;
  d["expected_vertices"] = r.expected_vertices;
  d["rate"] = r.rate;
  d["fast_path"] = r.fast_path;
  d["flood_updated"] = r.flood_updated;
  d["top_up"] = r.top_up;
  d["refine_vertices"] = r.refine_vertices;
  d["refine_triangles"] = r.refine_triangles;
  d["refine_collapses"] = r.refine_collapses;
  d["repair_rounds"] = r.repair_rounds;
  d["repairs"] = r.repairs;
  d["issues_found"] = issues_dict(r.issues_found);
  d["issues_remaining"] = issues_dict(r.issues_remaining);
  const OutputCheck& c = r.output_check;
  py::dict check;
  check["nonfinite"] = c.nonfinite;
  check["repeated_corner"] = c.repeated_corner;
  check["duplicate"] = c.duplicate;
  check["zero_area"] = c.zero_area;
  check["nonmanifold_edges"] = c.nonmanifold_edges;
  check["nonmanifold_vertices"] = c.nonmanifold_vertices;
  check["inconsistent_edges"] = c.inconsistent_edges;
  check["mixed_triangles"] = c.mixed_triangles;
  check["lost_components"] = c.lost_components;
  check["split_components"] = c.split_components;
  check["euler_changed"] = c.euler_changed;
  check["boundary_loops_changed"] = c.boundary_loops_changed;
  check["pinched_fans_changed"] = c.pinched_fans_changed;
  d["output_check"] = check;
  d["output_checked"] = r.output_checked;
  py::dict seconds;
  seconds["sampling"] = r.seconds_sampling;
  seconds["clustering"] = r.seconds_clustering;
  seconds["checking"] = r.seconds_checking;
  seconds["output"] = r.seconds_output;
  seconds["verify"] = r.seconds_verify;
  seconds["refine"] = r.seconds_refine;
  d["seconds"] = seconds;
  return d;
}

SamplingParams sampling_from(const Mesh& mesh, uint64_t seed, double adaptivity, double flat_floor, bool area_weighted,
                             const std::vector<double>& guidance, const std::string& density, int32_t density_rings,
                             double density_ratio, double density_epsilon, const py::handle& view,
                             const py::handle& boxes) {
  SamplingParams s;
  s.seed = seed;
  s.adaptivity = adaptivity;
  s.flat_floor = flat_floor;
  s.area_weighted = area_weighted;
  s.guidance = guidance.empty() ? nullptr : guidance.data();
  s.density = density_from(density);
  s.density_rings = density_rings;
  s.density_ratio = density_ratio;
  s.density_epsilon = density_epsilon;
  s.view = view_from(view);
  s.boxes = boxes_from(boxes);
  validate_sampling_params(mesh, s);
  return s;
}

// Attributes for the collapse cost: `values` flat, 3 corners per caller triangle times
// `weights` channels (shapes are checked in Python), or None.
struct AttributeArrays {
  std::vector<double> values, weights;
  CornerAttributes view(int64_t triangles) const {
    CornerAttributes a;
    if (values.empty() || weights.empty()) return a;
    if (int64_t(values.size()) != 3 * triangles * int64_t(weights.size()))
      throw std::invalid_argument("attributes must hold 3 values per triangle corner and channel");
    a.values = values.data();
    a.channels = static_cast<int>(weights.size());
    a.weights = weights.data();
    return a;
  }
};

AttributeArrays attributes_from(const Mesh& mesh, const py::handle& values, const py::handle& weights) {
  AttributeArrays a;
  if (values.is_none()) return a;
  if (weights.is_none()) throw std::invalid_argument("attributes need attribute_weights");
  a.weights = scalars_from(weights, static_cast<int64_t>(py::len(weights)), "attribute_weights");
  const int64_t count = 3 * int64_t(mesh.report().input_triangles) * int64_t(a.weights.size());
  a.values = scalars_from(values, count, "attributes");
  return a;
}

}  // namespace

void bind_decimate(py::module_& m) {
  py::class_<FloodCachePool>(m, "FloodCachePool",
                             "Floods of earlier decimations of one mesh and feature layout, reused by nearby targets.")
      .def(py::init<size_t>(), py::arg("capacity") = 2)
      .def("clear", &FloodCachePool::clear, "Frees the caches not in use.")
      .def_property_readonly("size", &FloodCachePool::size, "Caches held (in use or not).");

  m.def(
      "decimate",
      [](const Mesh& mesh, const FeatureLayout& layout, int32_t target_vertices, int32_t target_triangles,
         uint64_t seed, double adaptivity, double flat_floor, bool area_weighted, const py::handle& guidance,
         const std::string& density,
         int32_t density_rings, double density_ratio, double density_epsilon, const py::handle& view,
         const py::handle& boxes, const std::string& placement, int fast_path, int32_t max_repair_rounds,
         double refine, int32_t refine_collapses, const py::handle& attributes, const py::handle& attribute_weights,
         const py::handle& flood_caches, bool draft) {
        const auto u = scalars_from(guidance, mesh.num_vertices(), "guidance");
        DecimateParams params;
        params.sampling = sampling_from(mesh, seed, adaptivity, flat_floor, area_weighted, u, density, density_rings,
                                        density_ratio,
                                        density_epsilon, view, boxes);
        params.placement = placement_from(placement);
        params.fast_path = fast_path;
        params.max_repair_rounds = max_repair_rounds;
        params.target_vertices = target_vertices;
        params.refine = refine;
        params.refine_collapses = refine_collapses;
        const AttributeArrays arrays = attributes_from(mesh, attributes, attribute_weights);
        params.attributes = arrays.view(mesh.report().input_triangles);
        params.flood_caches = flood_caches.is_none() ? nullptr : flood_caches.cast<FloodCachePool*>();
        params.draft = draft;
        DecimateResult r;
        {
          EngineCall call;
          r = target_triangles > 0 ? decimate_to_triangles(mesh, layout, params, target_triangles)
                                   : decimate(mesh, layout, params);
        }
        return result_dict(std::move(r));
      },
      py::arg("mesh"), py::arg("layout"), py::arg("target_vertices") = 0, py::arg("target_triangles") = 0,
      py::arg("seed") = 0, py::arg("adaptivity") = 0.5, py::arg("flat_floor") = 0.25, py::arg("area_weighted") = false,
      py::arg("guidance") = py::none(), py::arg("density") = "off", py::arg("density_rings") = 0, py::arg("density_ratio") = 2.0,
      py::arg("density_epsilon") = 0.0, py::arg("view") = py::none(), py::arg("boxes") = py::none(),
      py::arg("placement") = "subsample", py::arg("fast_path") = 0, py::arg("max_repair_rounds") = 200,
      py::arg("refine") = 0.0, py::arg("refine_collapses") = 0, py::arg("attributes") = py::none(),
      py::arg("attribute_weights") = py::none(), py::arg("flood_caches") = py::none(), py::arg("draft") = false,
      "TopStoc decimation to a vertex target (or a triangle target when target_triangles > 0).");

  m.def(
      "decimate_with_samples",
      [](const Mesh& mesh, const FeatureLayout& layout, const py::handle& samples, const std::string& placement,
         int32_t max_repair_rounds, int32_t refine_vertices, const py::handle& guidance, int32_t refine_triangles,
         const py::handle& attributes, const py::handle& attribute_weights) {
        auto ids = ids_from(samples, -1, "samples");
        const auto u = scalars_from(guidance, mesh.num_vertices(), "guidance");
        if (refine_vertices < 0) throw std::invalid_argument("refine_vertices must be >= 0");
        if (refine_triangles < 0) throw std::invalid_argument("refine_triangles must be >= 0");
        const AttributeArrays arrays = attributes_from(mesh, attributes, attribute_weights);
        DecimateResult r;
        {
          EngineCall call;
          r = decimate_with_samples(mesh, layout, std::move(ids), placement_from(placement), max_repair_rounds,
                                    refine_vertices, u.empty() ? nullptr : u.data(),
                                    arrays.view(mesh.report().input_triangles), refine_triangles);
        }
        return result_dict(std::move(r));
      },
      py::arg("mesh"), py::arg("layout"), py::arg("samples"), py::arg("placement") = "subsample",
      py::arg("max_repair_rounds") = 200, py::arg("refine_vertices") = 0, py::arg("guidance") = py::none(),
      py::arg("refine_triangles") = 0, py::arg("attributes") = py::none(), py::arg("attribute_weights") = py::none(),
      "Re-creates a decimation from its saved sample list.");

  m.def(
      "sampling_probabilities",
      [](const Mesh& mesh, const FeatureLayout& layout, double rate, uint64_t seed, double adaptivity,
         double flat_floor, bool area_weighted, const py::handle& guidance, const py::handle& view,
         const py::handle& boxes) {
        const auto u = scalars_from(guidance, mesh.num_vertices(), "guidance");
        auto s = sampling_from(mesh, seed, adaptivity, flat_floor, area_weighted, u, "off", 0, 2.0, 0.0, view, boxes);
        std::vector<double> p;
        {
          EngineCall call;
          p = by_caller(mesh, sampling_probabilities(mesh, layout, s, rate));
        }
        return to_array(std::move(p));
      },
      py::arg("mesh"), py::arg("layout"), py::arg("rate"), py::arg("seed") = 0, py::arg("adaptivity") = 0.5,
      py::arg("flat_floor") = 0.25, py::arg("area_weighted") = false, py::arg("guidance") = py::none(), py::arg("view") = py::none(),
      py::arg("boxes") = py::none(), "Per-vertex sampling probability p(v) for base rate k (docs/design.md §2.2).");

  m.def(
      "aspect_ratio_stats",
      [](const py::handle& vertices, const py::handle& triangles) {
        auto p = positions_from(vertices, "vertices");
        auto t = indices_from(triangles, 3, "triangles");
        const int64_t n = int64_t(p.size() / 3);
        require_indices_in_range(t.data(), int64_t(t.size() / 3), 3, n, "triangle");
        AspectStats s = aspect_ratio_stats(p.data(), t.data(), int64_t(t.size() / 3));
        py::dict d;
        d["mean"] = s.mean;
        d["max"] = s.max;
        d["degenerate"] = s.degenerate;
        return d;
      },
      py::arg("vertices"), py::arg("triangles"), "Aspect ratio (thesis eq. 4.2): mean, max, degenerate count.");
}

}  // namespace topstoc::python
