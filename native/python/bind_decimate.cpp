// Bindings for decimation, sampling probabilities and triangle quality.
#include <pybind11/stl.h>

#include <cmath>

#include "caller_order.hpp"
#include <stdexcept>

#include "convert.hpp"
#include "topstoc/decimate/moved_sources.hpp"
#include "topstoc/core/progress.hpp"
#include "topstoc/core/validate.hpp"
#include "topstoc/decimate/decimate.hpp"
#include "topstoc/core/quality.hpp"

namespace topstoc::python {

namespace {

// The Python side's CancelFlag (std::atomic is neither copyable nor movable: held by pointer).
struct CancelToken {
  CancelFlag flag{false};
};

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
  d["loop_forced"] = r.loop_forced;
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
  d["refine_keeps_positions"] = r.refine_keeps_positions;
  d["shape_floor"] = r.shape_floor;
  d["far_guard"] = r.far_guard;
  d["fold_floor"] = r.fold_floor;
  d["collapses_skipped"] = r.collapses_skipped;
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

// The float64 arrays of a call (core/api/job.py made them contiguous float64 of the right size),
// held while the engine reads them in place.
struct JobArrays {
  py::array_t<double, py::array::c_style | py::array::forcecast> guidance, attributes, attribute_weights;
};

const double* data_of(py::array_t<double, py::array::c_style | py::array::forcecast>& array, const py::handle& from) {
  if (from.is_none()) return nullptr;
  array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(from);
  return array.data();
}

// Attributes for the collapse cost (core/api/job.py's attribute_arrays: flat float64, 3 corners per
// caller triangle times one value per channel, and the channels' weights), or none.
CornerAttributes attributes_of(const Mesh& mesh, JobArrays& arrays, const py::handle& values,
                               const py::handle& weights) {
  CornerAttributes a;
  a.values = data_of(arrays.attributes, values);
  a.weights = data_of(arrays.attribute_weights, weights);
  if (!a.values || !a.weights) return {};
  a.channels = static_cast<int>(arrays.attribute_weights.size());
  if (arrays.attributes.size() != 3 * int64_t(mesh.report().input_triangles) * a.channels)
    throw std::invalid_argument("attributes must hold 3 values per triangle corner and channel");
  return a;
}

// The sampling half of a DecimationJob (core/api/job.py); its ranges were checked when it was made,
// the engine checks its own invariants (validate_sampling_params).
SamplingParams sampling_from(const py::handle& job, JobArrays& arrays) {
  SamplingParams s;
  s.seed = job.attr("seed").cast<uint64_t>();
  s.adaptivity = job.attr("adaptivity").cast<double>();
  s.flat_floor = job.attr("flat_floor").cast<double>();
  s.area_weighted = job.attr("area_weighted").cast<bool>();
  s.guidance = data_of(arrays.guidance, job.attr("guidance"));
  s.density = density_from(job.attr("density").cast<std::string>());
  s.density_rings = job.attr("density_rings").cast<int32_t>();
  s.density_ratio = job.attr("density_ratio").cast<double>();
  s.density_epsilon = job.attr("density_epsilon").cast<double>();
  s.view = view_from(job.attr("view"));
  s.boxes = boxes_from(job.attr("boxes"));
  return s;
}

// A DecimationJob (core/api/job.py) as the engine's DecimateParams; `arrays` holds what they point into.
DecimateParams params_from(const Mesh& mesh, const py::handle& job, JobArrays& arrays) {
  DecimateParams params;
  params.sampling = sampling_from(job, arrays);
  params.target_vertices = job.attr("target").attr("vertex_count").cast<int32_t>();
  params.placement = placement_from(job.attr("placement").cast<std::string>());
  params.fast_path = job.attr("fast_path").cast<int>();
  params.max_repair_rounds = job.attr("max_repair_rounds").cast<int32_t>();
  params.refine = job.attr("refine").cast<double>();
  params.refine_collapses = job.attr("refine_collapses").cast<int32_t>();
  params.draft = job.attr("draft").cast<bool>();
  params.large_fit = job.attr("large_fit").cast<bool>();
  params.attributes = attributes_of(mesh, arrays, job.attr("attributes"), job.attr("attribute_weights"));
  return params;
}

// What a mesh keeps between decimations (floods, collapse states) and the cancel flag.
void bind_decimation_state(py::module_& m) {
  py::class_<FloodCachePool>(m, "FloodCachePool",
                             "Floods of earlier decimations of one mesh and feature layout, reused by nearby targets.")
      .def(py::init<size_t>(), py::arg("capacity") = 2)
      .def("clear", &FloodCachePool::clear, "Frees the caches not in use.")
      .def_property_readonly("size", &FloodCachePool::size, "Caches held (in use or not).");

  py::class_<CollapseSnapshots>(m, "CollapseSnapshots",
                                 "Collapse states of earlier quality decimations of one mesh and feature layout, "
                                 "from which lower targets resume.")
      .def(py::init<size_t>(), py::arg("capacity") = 2)
      .def("clear", &CollapseSnapshots::clear, "Frees the kept states.")
      .def_property_readonly("size", &CollapseSnapshots::size, "States kept.")
      .def_property_readonly("surfaces", &CollapseSnapshots::surfaces,
                             "Input surfaces kept (the distance passes' and the fit's search structures).")
      .def_property_readonly("resumed", &CollapseSnapshots::resumed, "Runs that resumed from a kept state.")
      .def_property_readonly("surfaces_made", &CollapseSnapshots::surfaces_made, "Input surfaces made.");

  py::class_<CancelToken>(m, "CancelFlag",
                          "Set from any thread, stops the decimation given it at its next check (raises Cancelled).")
      .def(py::init<>())
      .def("set", [](CancelToken& token) { token.flag = true; }, "Asks the decimation to stop.")
      .def_property_readonly("is_set", [](const CancelToken& token) { return token.flag.load(); });
}

// Where moved output vertices take their attributes from (moved_sources.hpp).
void bind_moved_sources(py::module_& m) {
  m.def(
      "moved_sources",
      [](const py::handle& vertices, const py::handle& triangles, const py::handle& labels,
         const py::handle& output, const py::handle& moved) {
        const auto input = positions_array(vertices, "vertices");
        const auto tris = indices_array(triangles, 3, "triangles");
        const int64_t n = int64_t(input.size() / 3), m = int64_t(tris.size() / 3);
        const auto label = ids_from(labels, n, "labels");
        const auto out = positions_array(output, "output");
        const int64_t k = int64_t(out.size() / 3);
        const auto flags = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(moved);
        if (!flags || flags.size() != k) throw std::invalid_argument("moved must hold one flag per output vertex");
        require_indices_in_range(tris.data(), m, 3, n, "triangle");
        for (int32_t l : label)
          if (l >= k) throw std::invalid_argument("labels name an output vertex out of range");
        MovedSources sources;
        {
          EngineCall call;
          sources = moved_sources(input.data(), tris.data(), m, label.data(), out.data(), flags.data(), k);
        }
        return py::make_tuple(to_array(std::move(sources.face)), to_array(std::move(sources.weights), 3));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("labels"), py::arg("output"), py::arg("moved"),
      "For each moved output vertex, the closest input triangle touching its cluster and the clamped barycentric "
      "weights there (addon/core/carry/attributes.py moved_vertices): (face, weights).");

  m.def(
      "moved_sources_of_mesh",
      [](const Mesh& mesh, const py::handle& labels, const py::handle& kept, const py::handle& output) {
        const int64_t n = mesh.report().input_vertices;
        const auto label = ids_from(labels, n, "labels");
        const auto out = positions_array(output, "output");
        const int64_t k = int64_t(out.size() / 3);
        const auto kept_ids = ids_from(kept, k, "kept");
        if (int64_t(label.size()) != n || int64_t(kept_ids.size()) != k)
          throw std::invalid_argument("labels and kept must be given");
        for (int32_t l : label)
          if (l >= k) throw std::invalid_argument("labels name an output vertex out of range");
        for (int32_t v : kept_ids)
          if (v < 0 || v >= n || mesh.vertex_index()[v] < 0) throw std::invalid_argument("kept names no mesh vertex");
        MovedSources sources;
        {
          EngineCall call;
          sources = moved_sources(mesh, label.data(), kept_ids.data(), out.data(), k);
        }
        return py::make_tuple(to_array(std::move(sources.face)), to_array(std::move(sources.weights), 3));
      },
      py::arg("mesh"), py::arg("labels"), py::arg("kept"), py::arg("output"),
      "moved_sources read from the prepared mesh (one that dropped no triangle) instead of the caller's arrays; "
      "moved: the output vertices not at their kept input vertex.");
}

}  // namespace

void bind_decimate(py::module_& m) {
  bind_decimation_state(m);
  bind_moved_sources(m);
  m.def(
      "decimate",
      [](const Mesh& mesh, const FeatureLayout& layout, const py::handle& job, const py::handle& flood_caches,
         const py::handle& cancel, const py::handle& collapse_snapshots) {
        JobArrays arrays;
        DecimateParams params = params_from(mesh, job, arrays);
        params.flood_caches = flood_caches.is_none() ? nullptr : flood_caches.cast<FloodCachePool*>();
        params.collapse_snapshots =
            collapse_snapshots.is_none() ? nullptr : collapse_snapshots.cast<CollapseSnapshots*>();
        const py::object triangles = job.attr("target").attr("triangles");
        const int32_t target_triangles = triangles.is_none() ? 0 : triangles.cast<int32_t>();
        const CancelFlag* flag = cancel.is_none() ? nullptr : &cancel.cast<CancelToken&>().flag;
        DecimateResult r;
        {
          EngineCall call;
          CancelScope scope(flag);
          r = target_triangles > 0 ? decimate_to_triangles(mesh, layout, params, target_triangles)
                                   : decimate(mesh, layout, params);
          restore_winding(mesh, r);
        }
        return result_dict(std::move(r));
      },
      py::arg("mesh"), py::arg("layout"), py::arg("job"), py::arg("flood_caches") = py::none(),
      py::arg("cancel") = py::none(), py::arg("collapse_snapshots") = py::none(),
      "TopStoc decimation of a topstoc.core.api.job.DecimationJob (a triangle target when it has one); "
      "cancel: a CancelFlag another thread may set (Cancelled is raised); collapse_snapshots: a "
      "CollapseSnapshots of this mesh and layout (the same result, lower targets sooner).");

  m.def(
      "warm_up",
      [](const Mesh& mesh, const FeatureLayout& layout, const py::handle& job, CollapseSnapshots& collapse_snapshots,
         const py::handle& cancel) {
        JobArrays arrays;
        DecimateParams params = params_from(mesh, job, arrays);
        params.collapse_snapshots = &collapse_snapshots;
        params.warm_up = true;
        const py::object triangles = job.attr("target").attr("triangles");
        if (!triangles.is_none()) return false;  // a triangle target keeps no state
        const CancelFlag* flag = cancel.is_none() ? nullptr : &cancel.cast<CancelToken&>().flag;
        EngineCall call;
        CancelScope scope(flag);
        return decimate(mesh, layout, params).refine_vertices > 0;
      },
      py::arg("mesh"), py::arg("layout"), py::arg("job"), py::arg("collapse_snapshots"),
      py::arg("cancel") = py::none(),
      "Builds in collapse_snapshots what a later decimate of this job, or of it at a lower vertex target, "
      "resumes from (DecimateParams::warm_up), the same result either way; False where none is kept. "
      "cancel: a CancelFlag (Cancelled is raised).");

  m.def(
      "decimate_with_samples",
      [](const Mesh& mesh, const FeatureLayout& layout, const py::handle& replay) {
        // its counts, guidance and attributes were checked in Python (core/api/decimate.py, core/api/job.py)
        const py::object samples = replay.attr("samples");
        auto ids = ids_from(samples, -1, "samples");
        JobArrays arrays;
        const double* u = data_of(arrays.guidance, replay.attr("guidance"));
        const CornerAttributes corner_attributes =
            attributes_of(mesh, arrays, replay.attr("attributes"), replay.attr("attribute_weights"));
        const Placement placement = placement_from(replay.attr("placement").cast<std::string>());
        const int32_t max_repair_rounds = replay.attr("max_repair_rounds").cast<int32_t>();
        const int32_t refine_vertices = replay.attr("refine_vertices").cast<int32_t>();
        const int32_t refine_triangles = replay.attr("refine_triangles").cast<int32_t>();
        const bool refine_keeps_positions = replay.attr("refine_keeps_positions").cast<bool>();
        const bool large_fit = replay.attr("large_fit").cast<bool>();
        DecimateResult r;
        {
          EngineCall call;
          r = decimate_with_samples(mesh, layout, std::move(ids), placement, max_repair_rounds, refine_vertices, u,
                                    corner_attributes, refine_triangles, refine_keeps_positions, large_fit);
          restore_winding(mesh, r);
        }
        return result_dict(std::move(r));
      },
      py::arg("mesh"), py::arg("layout"), py::arg("replay"),
      "Re-creates a decimation from a topstoc.core.api.decimate.SampleReplay (its saved sample list).");

  m.def(
      "sampling_probabilities",
      [](const Mesh& mesh, const FeatureLayout& layout, double rate, const py::handle& job) {
        JobArrays arrays;
        const SamplingParams s = sampling_from(job, arrays);
        std::vector<double> p;
        {
          EngineCall call;
          p = by_caller(mesh, sampling_probabilities(mesh, layout, s, rate));
        }
        return to_array(std::move(p));
      },
      py::arg("mesh"), py::arg("layout"), py::arg("rate"), py::arg("job"),
      "Per-vertex sampling probability p(v) for base rate k of a DecimationJob's sampling (docs/design.md §2.2).");

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
