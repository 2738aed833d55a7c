#include "convert.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>

namespace topstoc::python {

namespace {

std::string describe(const py::array& a) {
  std::string shape = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
  if (a.ndim() == 1) shape += ",";
  return std::string(py::str(a.dtype())) + " array of shape " + shape + ")";
}

py::array as_array(const py::handle& object, const char* what) {
  if (object.is_none()) throw std::invalid_argument(std::string(what) + " is None");
  try {
    return py::array::ensure(object);
  } catch (const py::error_already_set&) {
  }
  throw std::invalid_argument(std::string(what) + " must be an array");
}

}  // namespace

py::array_t<double, py::array::c_style> positions_array(const py::handle& object, const char* what) {
  py::array a = as_array(object, what);
  if (!a || a.ndim() != 2 || a.shape(1) != 3 || (a.dtype().kind() != 'f'))
    throw std::invalid_argument(std::string(what) + " must be a float32 or float64 array of shape (n, 3), got " +
                          (a ? describe(a) : std::string("something else")));
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

std::vector<double> positions_from(const py::handle& object, const char* what) {
  const auto d = positions_array(object, what);
  return std::vector<double>(d.data(), d.data() + d.size());
}

std::vector<int32_t> indices_from(const py::handle& object, int64_t columns, const char* what) {
  py::array a = as_array(object, what);
  if (!a || a.ndim() != 2 || a.shape(1) != columns || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw std::invalid_argument(std::string(what) + " must be an int32 or int64 array of shape (m, " +
                          std::to_string(columns) + "), got " + (a ? describe(a) : std::string("something else")));
  // int32 in C order (what io and Blender hand over) is copied as is: no int64 detour.
  if (py::isinstance<py::array_t<int32_t, py::array::c_style>>(a)) {
    auto d = py::array_t<int32_t, py::array::c_style>::ensure(a);
    return std::vector<int32_t>(d.data(), d.data() + d.size());
  }
  auto d = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  std::vector<int32_t> out(d.size());
  for (py::ssize_t i = 0; i < d.size(); ++i) {
    const int64_t x = d.data()[i];
    if (x < INT32_MIN || x > INT32_MAX)
      throw std::invalid_argument(std::string(what) + " row " + std::to_string(i / columns) + " holds " + std::to_string(x) +
                            ", outside the 32-bit index range");
    out[i] = static_cast<int32_t>(x);
  }
  return out;
}

py::array_t<int32_t, py::array::c_style> indices_array(const py::handle& object, int64_t columns, const char* what) {
  py::array a = as_array(object, what);
  if (a && py::isinstance<py::array_t<int32_t, py::array::c_style>>(a) && a.ndim() == 2 && a.shape(1) == columns)
    return py::array_t<int32_t, py::array::c_style>::ensure(a);
  return py::array_t<int32_t, py::array::c_style>::ensure(to_array(indices_from(object, columns, what), columns));
}

std::vector<double> scalars_from(const py::handle& object, int64_t n, const char* what) {
  if (object.is_none()) return {};
  py::array a = as_array(object, what);
  if (!a || a.ndim() != 1 || (a.dtype().kind() != 'f' && a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw std::invalid_argument(std::string(what) + " must be a 1-D float array, got " +
                          (a ? describe(a) : std::string("something else")));
  if (a.shape(0) != n)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(a.shape(0)) + " entries, expected " +
                          std::to_string(n));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  std::vector<double> out(d.data(), d.data() + d.size());
  for (size_t i = 0; i < out.size(); ++i)
    if (std::isnan(out[i])) throw std::invalid_argument(std::string(what) + " entry " + std::to_string(i) + " is NaN");
  return out;
}

std::vector<int32_t> ids_from(const py::handle& object, int64_t n, const char* what) {
  if (object.is_none()) return {};
  py::array a = as_array(object, what);
  if (!a || a.ndim() != 1 || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw std::invalid_argument(std::string(what) + " must be a 1-D integer array, got " +
                          (a ? describe(a) : std::string("something else")));
  if (n >= 0 && a.shape(0) != n)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(a.shape(0)) + " entries, expected " +
                          std::to_string(n));
  auto d = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  std::vector<int32_t> out(d.size());
  for (py::ssize_t i = 0; i < d.size(); ++i) {
    const int64_t x = d.data()[i];
    if (x < INT32_MIN || x > INT32_MAX)
      throw std::invalid_argument(std::string(what) + " entry " + std::to_string(i) + " is outside the 32-bit range");
    out[i] = static_cast<int32_t>(x);
  }
  return out;
}

ProgressCallback progress_from(const py::object& callback, const char* what) {
  if (callback.is_none()) return {};
  if (!PyCallable_Check(callback.ptr()))
    throw py::type_error(std::string(what) + " must be callable as " + what + "(fraction, stage), got " +
                         std::string(py::str(py::type::of(callback).attr("__name__"))));
  std::shared_ptr<py::object> held(new py::object(callback), [](py::object* p) {
    py::gil_scoped_acquire gil;
    delete p;
  });
  return [held](double fraction, const char* stage) {
    py::gil_scoped_acquire gil;
    const py::object answer = (*held)(fraction, stage);
    return answer.is_none() || py::cast<bool>(answer);
  };
}

}  // namespace topstoc::python
