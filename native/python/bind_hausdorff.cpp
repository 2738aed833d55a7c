// Bindings for the Hausdorff measurement: surfaces, their samples, closest points, distances.
#include <cmath>

#include <stdexcept>

#include "convert.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc::python {

namespace {

std::shared_ptr<Surface> make_surface(const py::handle& vertices, const py::handle& triangles) {
  auto positions = positions_from(vertices, "vertices");
  auto tris = indices_from(triangles, 3, "triangles");
  EngineCall call;
  return std::make_shared<Surface>(std::move(positions), std::move(tris));
}

py::dict one_sided_dict(OneSidedDistance&& d) {
  py::dict out;
  out["max"] = d.max;
  out["mean"] = d.mean;
  out["rms"] = d.rms;
  out["percentile"] = d.percentile;
  out["max_point"] = copy_array(std::vector<double>(d.max_point, d.max_point + 3));
  out["samples"] = d.samples;
  out["max_upper"] = d.max_upper;
  out["refine_queries"] = d.refine_queries;
  out["vertex_distance"] = to_array(std::move(d.vertex_distance));
  out["face_max"] = to_array(std::move(d.face_max));
  return out;
}

// One side's bracket: lower, upper, the point at distance lower, queries, converged.
py::dict bracket_dict(const OneSidedBracket& r) {
  py::dict out;
  out["lower"] = r.lower;
  out["upper"] = r.upper;
  out["lower_point"] = copy_array(std::vector<double>(r.lower_point, r.lower_point + 3));
  out["queries"] = r.queries;
  out["converged"] = r.converged;
  return out;
}

py::dict result_dict(HausdorffResult&& r) {
  py::dict out;
  out["forward"] = one_sided_dict(std::move(r.forward));
  out["backward"] = one_sided_dict(std::move(r.backward));
  py::dict symmetric;
  symmetric["max"] = r.symmetric_max;
  symmetric["max_upper"] = r.symmetric_max_upper;
  symmetric["mean"] = r.symmetric_mean;
  symmetric["rms"] = r.symmetric_rms;
  symmetric["percentile"] = r.symmetric_percentile;
  out["symmetric"] = symmetric;
  out["diagonal"] = r.diagonal;
  out["step"] = r.step;
  return out;
}

// The surfaces, their samples and closest-point queries.
void bind_surfaces(py::module_& m) {
  py::class_<Surface, std::shared_ptr<Surface>>(
      m, "Surface", "Triangle mesh validated for measurement (caller's arrays as given), with a closest-point index.")
      .def(py::init(&make_surface), py::arg("vertices"), py::arg("triangles"))
      .def_property_readonly("num_vertices", &Surface::num_vertices)
      .def_property_readonly("num_triangles", &Surface::num_triangles)
      .def_property_readonly("diagonal", &Surface::diagonal)
      .def_property_readonly("area", &Surface::area)
      .def_property_readonly("edges", [](const Surface& s) { return copy_array(s.edges(), 2); });

  py::class_<SurfaceSamples, std::shared_ptr<SurfaceSamples>>(
      m, "SurfaceSamples", "Sample points of a surface: vertices, then edge points, then face points.")
      .def_property_readonly("step", [](const SurfaceSamples& s) { return s.step; })
      .def_property_readonly("size", &SurfaceSamples::size)
      .def_property_readonly("num_vertex_samples", [](const SurfaceSamples& s) { return s.num_vertex_samples; })
      .def_property_readonly("num_edge_samples", [](const SurfaceSamples& s) { return s.num_edge_samples; })
      .def_property_readonly("num_face_samples", [](const SurfaceSamples& s) { return s.num_face_samples; })
      .def_property_readonly("points", [](const SurfaceSamples& s) { return copy_array(s.points, 3); })
      .def_property_readonly("element", [](const SurfaceSamples& s) { return copy_array(s.element); })
      .def_property_readonly("face_offsets", [](const SurfaceSamples& s) { return copy_array(s.face_offsets); })
      .def_property_readonly("face_weight", [](const SurfaceSamples& s) { return copy_array(s.face_weight); });

  m.def(
      "sample_surface",
      [](const Surface& surface, double step) {
        EngineCall call;
        return std::make_shared<SurfaceSamples>(sample_surface(surface, step));
      },
      py::arg("surface"), py::arg("step"), "Samples a surface with spacing `step` (Aspert et al. 2002).");

  m.def(
      "step_for_sample_count",
      [](const Surface& surface, int64_t samples) {
        EngineCall call;
        return step_for_sample_count(surface, samples);
      },
      py::arg("surface"), py::arg("samples"), "Sample spacing that gives about `samples` samples.");

  m.def(
      "closest_points",
      [](const Surface& surface, const py::handle& points, const py::object& within) {
        const auto p = positions_from(points, "points");
        const double stop = within.is_none() ? -1.0 : within.cast<double>();
        if (!within.is_none() && !(stop >= 0.0))
          throw std::invalid_argument("within must be a distance >= 0, got " + std::to_string(stop));
        const int64_t n = int64_t(p.size() / 3);
        for (int64_t i = 0; i < n; ++i)
          if (!std::isfinite(p[3 * i]) || !std::isfinite(p[3 * i + 1]) || !std::isfinite(p[3 * i + 2]))
            throw std::invalid_argument("point " + std::to_string(i) + " has a non-finite coordinate");
        std::vector<ClosestHit> hits;
        {
          EngineCall call;
          hits = closest_points(surface, p.data(), n, stop);
        }
        std::vector<double> distance(n), closest(3 * n);
        std::vector<int32_t> triangle(n);
        for (int64_t i = 0; i < n; ++i) {
          distance[i] = std::sqrt(hits[i].distance2);
          triangle[i] = hits[i].triangle;
          for (int k = 0; k < 3; ++k) closest[3 * i + k] = hits[i].point[k];
        }
        py::dict out;
        out["distance"] = to_array(std::move(distance));
        out["triangle"] = to_array(std::move(triangle));
        out["point"] = to_array(std::move(closest), 3);
        return out;
      },
      py::arg("surface"), py::arg("points"), py::arg("within") = py::none(),
      "Nearest point on the surface of each point: distance, triangle, point. within: a point that\n"
      "close to the surface may get any point within it (attained), a farther one its exact nearest.");
}

}  // namespace

void bind_hausdorff(py::module_& m) {
  bind_surfaces(m);

  m.def(
      "hausdorff",
      [](const Surface& a, const Surface& b, int64_t samples, double step, double percentile, double max_tolerance) {
        HausdorffParams params;
        params.samples = samples;
        params.step = step;
        params.percentile = percentile;
        params.max_tolerance = max_tolerance;
        HausdorffResult r;
        {
          EngineCall call;
          r = hausdorff(a, b, params);
        }
        return result_dict(std::move(r));
      },
      py::arg("a"), py::arg("b"), py::arg("samples") = 1000000, py::arg("step") = 0.0, py::arg("percentile") = 0.95,
      py::arg("max_tolerance") = 1e-3,
      "Forward (A to B), backward (B to A) and symmetric Hausdorff distance.");

  m.def(
      "bracket_one_sided_max",
      [](const Surface& from, const Surface& to, double tolerance, int64_t max_queries, double threshold) {
        OneSidedBracket r;
        {
          EngineCall call;
          r = bracket_one_sided_max(from, to, tolerance, max_queries, threshold);
        }
        return bracket_dict(r);
      },
      py::arg("from_surface"), py::arg("to_surface"), py::arg("tolerance"), py::arg("max_queries") = 4000000,
      py::arg("threshold") = -1.0,
      "Guaranteed bracket (lower, upper) of the one-sided max distance from one surface to the other "
      "(threshold >= 0: only as tight as deciding whether the max exceeds it needs).");

  m.def(
      "bracket_symmetric_max",
      [](const Surface& a, const Surface& b, double tolerance, double resolution, int64_t max_queries) {
        SymmetricBracket r;
        {
          EngineCall call;
          r = bracket_symmetric_max(a, b, tolerance, resolution, max_queries);
        }
        py::dict out;
        out["forward"] = bracket_dict(r.forward);
        out["backward"] = bracket_dict(r.backward);
        return out;
      },
      py::arg("a"), py::arg("b"), py::arg("tolerance"), py::arg("resolution") = 1e-13,
      py::arg("max_queries") = 20000000,
      "Guaranteed brackets of both one-sided maxima, each side from its surface's vertices (bounds under "
      "resolution x the larger diagonal count as settled).");

  m.def(
      "quick_hausdorff_bound",
      [](const Surface& a, const Surface& b, double tolerance, double resolution) {
        if (!(tolerance > 0.0)) throw std::invalid_argument("tolerance must be positive, got " + std::to_string(tolerance));
        if (!(resolution >= 0.0))
          throw std::invalid_argument("resolution must be zero or positive, got " + std::to_string(resolution));
        QuickBound r;
        {
          EngineCall call;
          r = quick_hausdorff_bound(a, b, tolerance, resolution);
        }
        py::dict out;
        out["forward_lower"] = r.forward_lower;
        out["forward_upper"] = r.forward_upper;
        out["backward_lower"] = r.backward_lower;
        out["backward_upper"] = r.backward_upper;
        out["forward_mean"] = r.forward_mean;
        out["queries"] = r.queries;
        out["grid_queries"] = r.grid_queries;
        out["refined"] = r.refined;
        return out;
      },
      py::arg("a"), py::arg("b"), py::arg("tolerance"), py::arg("resolution") = 1e-12,
      "Guaranteed upper bound of the symmetric max between a big surface A and a small one B without a "
      "search structure over A's triangles (bounds under resolution x the larger diagonal count as "
      "settled; at least 1e-12); the lower values are distances attained.");

  m.def(
      "hausdorff_with_samples",
      [](const Surface& a, const SurfaceSamples& a_samples, const Surface& b, double percentile, double max_tolerance) {
        HausdorffResult r;
        {
          EngineCall call;
          r = hausdorff(a, a_samples, b, percentile, max_tolerance);
        }
        return result_dict(std::move(r));
      },
      py::arg("a"), py::arg("a_samples"), py::arg("b"), py::arg("percentile") = 0.95, py::arg("max_tolerance") = 1e-3,
      "Hausdorff distance reusing samples of A taken earlier (B is sampled with their step).");
}

}  // namespace topstoc::python
