#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/features.hpp"

namespace topstoc {

/// A bend turns the curve by more than this (radians), measured one and two edges around it.
constexpr double kBendAngle = 40.0 * 3.14159265358979323846 / 180.0;

/// The vertices of layout's traced mesh boundaries (corners excluded) where the curve turns by more than
/// kBendAngle over one edge and over two edges on each side, and more sharply than the two
/// vertices on either side of it along the curve; sharpest first. A draw that leaves such a
/// vertex out cuts the corner off the border (sampling.cpp forces them).
std::vector<int32_t> find_curve_bends(const Mesh& mesh, const FeatureLayout& layout);

/// Every vertex of layout's traced mesh boundaries (corners excluded) where the curve turns by
/// more than kBendAngle over one edge, two such turns side by side included (a strip's two
/// corners at its end), and one of its two edges is more than `edge_ratio` times as long as
/// the other; in curve order.
std::vector<int32_t> find_sharp_turns(const Mesh& mesh, const FeatureLayout& layout, double edge_ratio);

}  // namespace topstoc
