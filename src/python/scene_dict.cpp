/// Python objects to and from JSON: a scene given as a dict goes through the
/// same parser (io/scene_parser.h) as a scene file, so it is checked the same way.
#include <cmath>
#include <string>

#include "base/error.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace sahara::python {

namespace {

/// Deeper nesting than any scene needs; a list that contains itself stops here.
constexpr int kMaxDepth = 64;

std::string type_name(const py::handle& h) { return py::str(py::type::handle_of(h).attr("__name__")); }

std::string where(const std::string& what, const std::string& path) {
    return path.empty() ? what : what + ": " + path;
}

Json convert(const py::handle& h, const std::string& what, const std::string& path, int depth) {
    if (depth > kMaxDepth)
        throw py::value_error(where(what, path) + ": nested too deeply (does it contain itself?)");
    if (h.is_none()) return nullptr;
    if (py::isinstance<py::bool_>(h)) return h.cast<bool>();
    if (py::isinstance<py::int_>(h)) {
        try {
            return h.cast<int64_t>();
        } catch (const py::cast_error&) {
        }
        try {
            return h.cast<uint64_t>();  // a seed may use all 64 bits
        } catch (const py::cast_error&) {
            throw py::value_error(where(what, path) + ": integer too large (" + std::string(py::str(h)) +
                                  ")");
        }
    }
    if (py::isinstance<py::float_>(h)) {
        // JSON has no NaN or infinity: the parser would see null and say so.
        const double v = h.cast<double>();
        if (!std::isfinite(v))
            throw InputError(where(what, path) + ": expected a finite number, got " +
                             std::string(py::repr(h)));
        return v;
    }
    if (py::isinstance<py::str>(h)) return h.cast<std::string>();
    if (py::isinstance<py::dict>(h)) {
        Json object = Json::object();
        for (const auto& [key, value] : h.cast<py::dict>()) {
            if (!py::isinstance<py::str>(key))
                throw py::type_error(where(what, path) + ": keys must be strings, got " + type_name(key));
            const std::string name = key.cast<std::string>();
            object[name] = convert(value, what, path.empty() ? name : path + "." + name, depth + 1);
        }
        return object;
    }
    if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
        Json array = Json::array();
        size_t i = 0;
        for (const auto& item : h)
            array.push_back(convert(item, what, path + "[" + std::to_string(i++) + "]", depth + 1));
        return array;
    }
    // numpy arrays and scalars (vertex lists, colours) turn into lists and numbers.
    if (py::hasattr(h, "tolist") && !py::isinstance<py::str>(h))
        return convert(h.attr("tolist")(), what, path, depth + 1);
    throw py::type_error(where(what, path) + ": " + type_name(h) +
                         " has no JSON form (expected dict, list, str, number, bool or None)");
}

}  // namespace

Json json_from_python(const py::handle& value, const std::string& what) {
    return convert(value, what, "", 0);
}

py::object python_from_json(const nlohmann::json& value) {
    return py::module_::import("json").attr("loads")(value.dump());
}

py::object python_from_json(const Json& value) {
    return py::module_::import("json").attr("loads")(value.dump());
}

}  // namespace sahara::python
