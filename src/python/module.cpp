/// The compiled part of `import sahara` (the package's __init__.py re-exports it).
#include <pybind11/pybind11.h>

#include "python/raycaster.h"

PYBIND11_MODULE(_sahara, m) {
    m.doc() = "sahara: a CPU path tracer and ray caster";
    sahara::python::bind_raycaster(m);
}
