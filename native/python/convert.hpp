// Conversions between numpy arrays and the native library's plain vectors. Input arrays are
// checked for dtype and shape here so that every entry point reports the same clear message;
// the caller's arrays are only read.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "topstoc/core/parallel.hpp"
#include "topstoc/core/progress.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace topstoc::python {

namespace py = pybind11;

/// (n, 3) float32/float64 -> 3n doubles. `what` names the argument in errors.
std::vector<double> positions_from(const py::handle& array, const char* what = "vertices");

/// Same checks, without the copy: the caller's array when it already is C-ordered float64 (a
/// converted copy otherwise). Keep the returned array alive while reading its data().
py::array_t<double, py::array::c_style> positions_array(const py::handle& array, const char* what = "vertices");

/// (m, k) integer array -> k*m int32 values (k = columns, e.g. 3 for triangles, 2 for edges).
/// Values outside int32 raise ValueError naming the row.
std::vector<int32_t> indices_from(const py::handle& array, int64_t columns, const char* what);

/// Same checks, without the copy: the caller's array when it already is C-ordered int32 (a
/// checked, converted copy otherwise). Keep the returned array alive while reading its data().
py::array_t<int32_t, py::array::c_style> indices_array(const py::handle& array, int64_t columns, const char* what);

/// 1-D float array of length n (or None -> empty). NaN raises ValueError naming the entry.
std::vector<double> scalars_from(const py::handle& array, int64_t n, const char* what);

/// 1-D integer array of length n (or None -> empty).
std::vector<int32_t> ids_from(const py::handle& array, int64_t n, const char* what);

/// A ProgressCallback that calls the Python callable ``callback(fraction, stage)`` from an engine
/// thread, taking the GIL only for the call (Progress throttles them); its answer False cancels.
/// None gives no callback. The callable is held so that copying the callback between threads
/// never touches Python reference counts without the GIL.
ProgressCallback progress_from(const py::object& callback, const char* what = "progress");

/// Scope of one engine call: releases the GIL and sizes OpenMP teams to this call's share of
/// the cores free now.
struct EngineCall {
  RunningCall running;
  EngineCall() { use_free_cores(); }
  py::gil_scoped_release release;
};

/// Moves a vector into a numpy array without copying; shape given by `rows` x `columns`
/// (columns == 0 gives a 1-D array). Strides are given explicitly: pybind11 2.10 derives them
/// from the dtype's item size with NumPy 1's struct layout, which reads 0 under NumPy 2.
template <class T>
py::array_t<T> to_array(std::vector<T>&& data, int64_t columns = 0) {
  auto* owned = new std::vector<T>(std::move(data));
  py::capsule release(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  const int64_t item = sizeof(T);
  if (columns == 0) return py::array_t<T>({int64_t(owned->size())}, {item}, owned->data(), release);
  return py::array_t<T>({int64_t(owned->size()) / columns, columns}, {columns * item, item}, owned->data(), release);
}

template <class T, class Allocator>
py::array_t<T> copy_array(const std::vector<T, Allocator>& data, int64_t columns = 0) {
  return to_array(std::vector<T>(data.begin(), data.end()), columns);
}

// One binding function per concept; each lives in its own bind_*.cpp.
void bind_mesh(py::module_& m);
void bind_mesh_edges(py::module_& m);
void bind_decimate(py::module_& m);
void bind_io(py::module_& m);
void bind_hausdorff(py::module_& m);
void bind_topology(py::module_& m);
void bind_loops(py::module_& m);
void bind_edit(py::module_& m);

}  // namespace topstoc::python
