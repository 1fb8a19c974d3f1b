#include "python/raycaster.h"

namespace sahara::python {

void bind_raycaster(pybind11::module_&) {}

}  // namespace sahara::python
