/// The compiled part of `import sahara` (the package's __init__.py wraps it).
#include <pybind11/pybind11.h>

#include "python/bindings.h"
#include "python/raycaster.h"

PYBIND11_MODULE(_sahara, m) {
    m.doc() = "sahara: a CPU path tracer and ray caster";
    m.attr("__version__") = SAHARA_VERSION;
    sahara::python::bind_errors(m);
    sahara::python::bind_render(m);
    sahara::python::bind_raycaster(m);
}
