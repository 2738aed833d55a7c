// Per-vertex results leave the engine in the caller's vertex order (topstoc::Mesh works in its
// own locality-preserving order internally).
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc::python {

/// Per-vertex values (`width` per vertex) reordered from internal to caller order.
template <class Values>
std::vector<typename Values::value_type> by_caller(const Mesh& mesh, const Values& values, size_t width = 1) {
  std::vector<typename Values::value_type> out(values.size());
  const auto& source = mesh.vertex_source();
  for (size_t v = 0; v < source.size(); ++v)
    for (size_t k = 0; k < width; ++k) out[width * size_t(source[v]) + k] = values[width * v + k];
  return out;
}

/// Internal vertex ids replaced by the caller's.
template <class Ids>
std::vector<int32_t> caller_ids(const Mesh& mesh, const Ids& ids) {
  std::vector<int32_t> out(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) out[i] = mesh.vertex_source()[ids[i]];
  return out;
}

}  // namespace topstoc::python
