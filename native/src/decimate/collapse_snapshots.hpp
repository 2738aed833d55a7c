// What a kept collapse state holds, and the key of a run's start (see
// topstoc/decimate/collapse_snapshots.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "decimate/collapser.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/collapse_snapshots.hpp"

namespace topstoc {

struct CollapseSnapshots::Entry {
  std::vector<uint64_t> start;          ///< start_key of the run that kept it
  int32_t run_vertices = 0;             ///< that run's vertex target: the state serves it and lower ones
  int32_t collapses = 0;                ///< made from the start to this state
  std::vector<int32_t> triangles, corner_source;  ///< the arrays as the state left them
  std::unique_ptr<Collapser> state;     ///< works on the two arrays above
};

/// A digest of everything a Collapser starts from but the quotas (which only act at the
/// target): each field of the setup, the triangles and their corner sources. A field added to
/// CollapseSetup must be added here.
std::vector<uint64_t> start_key(const CollapseSetup& setup, const std::vector<int32_t>& triangles,
                                const std::vector<int32_t>& corner_source);

/// The key of the input's search structure (deviation.hpp's normalised_input): the mesh (its
/// serial, as the flood caches key it), the collapses' normalisation and the triangles' step.
std::vector<uint64_t> input_surface_key(const Mesh& mesh, const Collapser& collapser, int64_t step);

/// The entry for `collapser` at the point Collapser::run's before_tail reports.
std::shared_ptr<const CollapseSnapshots::Entry> snapshot(std::vector<uint64_t> start, int32_t run_vertices,
                                                         int32_t collapses, const Collapser& collapser);

/// A copy of the entry's state working on `triangles` and `corner_source` (set to the entry's),
/// with `quota`.
std::unique_ptr<Collapser> resumed(const CollapseSnapshots::Entry& entry, std::vector<int32_t>& triangles,
                                   std::vector<int32_t>& corner_source, std::vector<int32_t> quota);

}  // namespace topstoc
