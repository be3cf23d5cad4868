// numpy arrays for the bindings: results handed to Python without a copy
// where the C++ side has them as contiguous doubles (docs/python.md
// "Copies and views").
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <type_traits>
#include <vector>

#include "odemag/vec3.h"

namespace odemag::python {

namespace py = pybind11;

static_assert(sizeof(Vec3) == 3 * sizeof(double) && std::is_standard_layout_v<Vec3>,
              "an (N, 3) numpy view over std::vector<Vec3> needs three packed doubles");

// An (N, 3) float64 array over the vector's own buffer: the vector moves into
// a capsule that is the array's base, so numpy frees it with the array.
inline py::array_t<double> vec3_array(std::vector<Vec3>&& v) {
  auto* owner = new std::vector<Vec3>(std::move(v));
  py::capsule base(owner, [](void* p) { delete static_cast<std::vector<Vec3>*>(p); });
  const py::ssize_t n = static_cast<py::ssize_t>(owner->size());
  return py::array_t<double>({n, py::ssize_t{3}}, owner->empty() ? nullptr : &owner->front().x, base);
}

// An (N, K) float64 array owning a vector of N * K doubles, or (N,) for K = 0.
inline py::array_t<double> double_array(std::vector<double>&& v, py::ssize_t columns = 0) {
  auto* owner = new std::vector<double>(std::move(v));
  py::capsule base(owner, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  const py::ssize_t size = static_cast<py::ssize_t>(owner->size());
  const double* data = owner->empty() ? nullptr : owner->data();
  if (columns == 0) return py::array_t<double>({size}, data, base);
  return py::array_t<double>({size / columns, columns}, data, base);
}

// A 1-D array of N values, copied (ints, bools: small per-body or per-step lists).
template <class T, class U>
py::array_t<T> copied_array(const std::vector<U>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  auto out = a.template mutable_unchecked<1>();
  for (size_t i = 0; i < v.size(); ++i) out(static_cast<py::ssize_t>(i)) = static_cast<T>(v[i]);
  return a;
}

}  // namespace odemag::python
