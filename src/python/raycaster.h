#pragma once
/// sahara.RayCaster: rays cast into a triangle mesh from numpy arrays.
#include <pybind11/pybind11.h>

namespace sahara::python {

void bind_raycaster(pybind11::module_& m);

}  // namespace sahara::python
