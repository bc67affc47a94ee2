// Shared pieces of the Python module lcsim._lcsim (python/src/*.cpp): the
// model handle every function takes and the numpy helpers. The module only
// converts Python values and calls the library; checks, defaults and
// messages are the library's.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
#include <utility>
#include <vector>

namespace lcsim::python {

namespace py = pybind11;

// A model with, for a URDF scene, what it was linearised from (the Python
// `lcsim.Model`). Shared: a trajectory keeps its model for to_csv/to_json.
using ModelHandle = std::shared_ptr<scene::LoadedModel>;

// A numpy array owning `data` (moved, not copied): the capsule frees it
// when the last array viewing it is gone.
template <class T>
py::array_t<T> numpy_owning(std::vector<T>&& data, std::vector<py::ssize_t> shape) {
  auto* heap = new std::vector<T>(std::move(data));
  py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), heap->data(), owner);
}

// Raises lcsim.InputError with `message` (the library's).
[[noreturn]] void raise_input_error(const std::string& message);

void bind_model(py::module_& m);
void bind_simulate(py::module_& m);
void bind_tools(py::module_& m);
void bind_bench(py::module_& m);
void bind_study(py::module_& m);

}  // namespace lcsim::python
