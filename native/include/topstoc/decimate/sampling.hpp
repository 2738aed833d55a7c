// Stochastic vertex selection (thesis 4.1, 4.3, 4.4, 4.6; docs/design.md §2.2-2.4).
//
// Every vertex gets a probability p(v) from its importance weight and the user's guidance, and
// a seeded fixed-size draw picks the samples. Without guidance the draw hits the target count
// exactly (Pareto sampling, Rosén 1997: keys (U/(1-U)) / (p/(1-p)), the smallest win, which
// keeps inclusion probabilities close to p). Guidance scales the probabilities (a density
// multiplier per vertex) and the rate is solved so that they still sum to the target: paint
// redistributes the budget. Only vertices that must stay (corners, control points u = 1) can
// push the count over it.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/decimate/features.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

enum class DensityMode { Off, Uniform, Adaptive, Euclidean };

/// View-dependent guidance (thesis 4.4).
struct ViewGuidance {
  bool enabled = false;
  bool perspective = true;
  double eye[3] = {0, 0, 0};         ///< camera position (perspective)
  double direction[3] = {0, 0, -1};  ///< viewing direction (orthographic)
  double back_ratio = 0.25;          ///< back-facing vertices: p *= back_ratio
  double silhouette_angle = 0.35;    ///< θ in radians: band |n·v| <= (1 - cos θ) / 2 keeps p = 1
  double silhouette_falloff = 0.1;   ///< width in |n·v| over which p returns to its value
  bool frustum = false;              ///< cull outside the view volume
  double view_projection[16] = {};   ///< row-major world -> clip matrix
  double outside_probability = 0.0;  ///< cap on p outside the frustum
};

/// A box region (thesis 4.6): vertices with |world_to_box * p|_inf <= 1 take guidance `value`.
struct BoxGuidance {
  double world_to_box[16];  ///< row-major affine matrix
  double value;             ///< u in [-1, 1]
};

struct SamplingParams {
  double adaptivity = 0.5;              ///< α in [0, 1]: 0 uniform, 1 fully weight-driven
  double flat_floor = 0.25;             ///< p never drops below flat_floor * k for u = 0 (the thesis' tweak)
  bool area_weighted = false;           ///< scale p by the vertex's share of the area (irregular meshes)
  const double* guidance = nullptr;     ///< u per caller vertex in [-1, 1], or null
  ViewGuidance view;
  std::vector<BoxGuidance> boxes;
  uint64_t seed = 0;
  DensityMode density = DensityMode::Off;
  int32_t density_rings = 0;            ///< ε (uniform) or ε_big (adaptive) in rings; 0 = from the target
  double density_ratio = 2.0;           ///< ε_big / ε_small for adaptive density (>= 2 per the thesis)
  double density_epsilon = 0.0;         ///< Euclidean ε; 0 = from the target and the mean edge length
  /// A first pass the collapses thin next: every feature curve vertex is drawn while they are at
  /// most a quarter of the count (sampling.cpp, force_curves).
  bool keep_curves = false;
};

struct SampleSet {
  std::vector<int32_t> samples;  ///< sorted vertex ids
  int32_t forced = 0;            ///< corners, u = 1 vertices, the curve bends and short loops' three kept (features.hpp)
  int32_t loop_forced = 0;       ///< of those, the three of each short boundary loop
  int32_t density_rejected = 0;  ///< candidates skipped by density control
  bool guided = false;           ///< guidance, view or boxes changed the probabilities
  double expected = 0.0;         ///< sum of the probabilities
  double rate = 0.0;             ///< the base rate k that was used
};

/// Guidance u as a density multiplier: ((1 + u) / (1 - u))^2 for -1 < u < 1 (u = 0.5: nine
/// times the density, -0.5: a ninth), 0 for u = -1 (never sampled), kForcedMultiplier for u = 1
/// (a control point); within 1/256 of +-1 counts as +-1 (8-bit painted colours). Paint redistributes the budget: the rate is solved so that the guided
/// probabilities min(1, k q m) still sum to the target.
constexpr double kForcedMultiplier = -1.0;
double guidance_multiplier(double u);

/// Whether painted guidance or boxes are given: the sources of guidance_multipliers.
inline bool has_multipliers(const SamplingParams& params) { return params.guidance || !params.boxes.empty(); }

/// m per internal vertex from the painted guidance and the boxes (boxes win where they hold it).
std::vector<double> guidance_multipliers(const Mesh& mesh, const SamplingParams& params);

/// True when any guidance source is active (then the count follows the probabilities).
bool is_guided(const Mesh& mesh, const SamplingParams& params);

/// p(v) for base rate k (fraction of vertices kept). Corners get 1, isolated vertices 0, feature
/// curve vertices sqrt(p) so that borders keep the spacing of the surface samples.
std::vector<double> sampling_probabilities(const Mesh& mesh, const FeatureLayout& layout,
                                           const SamplingParams& params, double k);

/// Draws the samples for a target vertex count (exact without guidance): the forced vertices
/// (p = 1, the sharpest curve bends, loose triangles' corners, three of each boundary loop too short
/// to expect three samples), then the smallest Pareto keys (sampling.cpp).
SampleSet select_samples(const Mesh& mesh, const FeatureLayout& layout, const SamplingParams& params,
                         int32_t target_vertices);

/// Checks parameter ranges; throws std::invalid_argument naming the parameter.
void validate_sampling_params(const Mesh& mesh, const SamplingParams& params);

}  // namespace topstoc
