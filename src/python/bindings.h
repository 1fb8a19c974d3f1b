#pragma once
/// The parts of `import sahara` besides the ray caster: rendering, scenes,
/// image writing and the exception types.
#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <string>

#include "io/json_reader.h"

namespace sahara::python {

/// sahara.InputError (a ValueError): bad scene input, with the CLI's message.
void bind_errors(pybind11::module_& m);
/// sahara.Scene, render and write_image (the _sahara functions __init__.py wraps).
void bind_render(pybind11::module_& m);

/// The name of a value's type, for messages.
std::string type_name(const pybind11::handle& h);
/// An integer keyword argument in [lo, hi] (the command line's range), or nullopt for None;
/// TypeError/ValueError naming `name` otherwise.
std::optional<int64_t> int_arg(const pybind11::object& v, const char* name, int64_t lo, int64_t hi);

/// A Python dict/list/str/number/bool/None tree as JSON, for the scene parser.
/// Raises TypeError/ValueError naming `what` and the key path of a value that
/// has no JSON form (a set, a non-string key, a self-containing list...).
Json json_from_python(const pybind11::handle& value, const std::string& what);

/// A JSON document as the equivalent Python dict/list/... tree (keys in the document's order).
pybind11::object python_from_json(const nlohmann::json& value);
pybind11::object python_from_json(const Json& value);

}  // namespace sahara::python
