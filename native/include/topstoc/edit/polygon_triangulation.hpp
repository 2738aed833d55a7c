// Triangulation of a simple polygon in the plane: the 2D step of hole filling (thesis 4.2.2
// projects a hole's boundary on a plane and triangulates it there). Ear clipping gives a valid
// triangulation of any simple polygon, convex or not; Lawson flips then make it the constrained
// Delaunay triangulation (the polygon's sides are the constraints), which avoids slivers.
// Corners may be collinear (a flat corner is never an ear tip, so no triangle has zero area).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace topstoc {

/// Says whether the diagonal between corners a and b is forbidden (e.g. the surface already
/// has that edge, which would become non-manifold). Empty: nothing is forbidden.
using ForbiddenDiagonal = std::function<bool(int32_t a, int32_t b)>;

/// True when the closed polygon (xy: 2 coordinates per corner, at least 3 corners) is simple:
/// no two sides meet except consecutive sides at their shared corner, no corner repeats a
/// position, no side folds back onto the previous one, and the area is not zero. Near-touching
/// within a relative tolerance counts as touching (the caller then uses another method).
bool polygon_is_simple(const std::vector<double>& xy);

/// Signed area (positive when the corners run counter-clockwise).
double polygon_area(const std::vector<double>& xy);

/// Triangulates a simple counter-clockwise polygon without using the `forbidden` diagonals;
/// every triangle is counter-clockwise with positive area. Appends corner-index triples to
/// `triangles` and returns true; returns false (appending nothing) when no such triangulation
/// was found, e.g. when every possible diagonal at some corner is forbidden.
bool triangulate_polygon(const std::vector<double>& xy, const ForbiddenDiagonal& forbidden,
                         std::vector<std::array<int32_t, 3>>& triangles);

}  // namespace topstoc
