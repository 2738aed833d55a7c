// Checks every entry point makes on the caller's arrays, with the same messages everywhere.
#pragma once

#include <cstdint>

namespace topstoc {

/// Throws std::invalid_argument naming vertex v if a coordinate is NaN or infinite.
void require_finite_position(const double* positions, int64_t v);

/// Throws std::invalid_argument naming the first vertex with a NaN or infinite coordinate.
void require_finite_positions(const double* positions, int64_t num_vertices);

/// Throws std::invalid_argument naming the first row (`what`: "triangle", "edge", ...) that
/// refers to a vertex outside [0, num_vertices). `columns` indices per row.
void require_indices_in_range(const int32_t* indices, int64_t rows, int columns, int64_t num_vertices,
                              const char* what);

}  // namespace topstoc
