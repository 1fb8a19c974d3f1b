#pragma once
/// Strict, path-aware reading of JSON input: every accessor checks type and
/// range and, on failure, throws an InputError that names the file, the JSON
/// path of the value (e.g. `objects[3].radius`) and what was expected.
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "math/vec3.h"

namespace sahara {

/// Insertion-ordered JSON, so that names and indices follow the file's order.
using Json = nlohmann::ordered_json;

/// Parses JSON text; syntax errors, number overflow and duplicate object keys
/// throw InputError with "line L, column C" or the JSON path of the duplicate.
Json parse_json_text(const std::string& text, const std::string& file);

/// Allowed interval for a number, with its wording for messages ("> 0", "in (0, 180)").
struct NumberRange {
    double lo = -1e300, hi = 1e300;
    bool lo_open = false, hi_open = false;

    static NumberRange any() { return {}; }
    static NumberRange positive() { return {0, 1e300, true, false}; }
    static NumberRange non_negative() { return {0, 1e300, false, false}; }
    static NumberRange closed(double lo, double hi) { return {lo, hi, false, false}; }
    static NumberRange open(double lo, double hi) { return {lo, hi, true, true}; }
    bool contains(double v) const;
    /// "", " > 0", " >= 0", " in [0, 1]", " in (0, 180)" ...
    std::string describe() const;
};

/// One JSON value plus its file and path; cheap to copy (holds a reference).
class JsonValue {
   public:
    JsonValue(const Json& json, const std::string& file, std::string path)
        : json_(&json), file_(&file), path_(std::move(path)) {}

    const Json& json() const { return *json_; }
    const std::string& path() const { return path_; }
    const std::string& file() const { return *file_; }

    /// Throws "FILE: PATH: expected EXPECTED, got VALUE".
    [[noreturn]] void fail_expected(const std::string& expected) const;
    /// Throws "FILE: PATH: MESSAGE".
    [[noreturn]] void fail(const std::string& message) const;

    bool is_null() const { return json_->is_null(); }
    /// A finite number in `range` (double precision).
    double number(const NumberRange& range = NumberRange::any()) const;
    /// A number in `range` that is finite as a 32-bit float.
    float number_f(const NumberRange& range = NumberRange::any()) const;
    /// An integral number (640 or 640.0) in [lo, hi].
    int64_t integer(int64_t lo, int64_t hi) const;
    /// Any integral number in [0, 2^64).
    uint64_t unsigned_integer() const;
    bool boolean() const;
    std::string string() const;
    /// One of `names`; returns its index. The message lists the choices.
    size_t one_of(std::initializer_list<const char*> names) const;
    /// [x, y, z] of finite float numbers, each in `range`.
    Vec3 vec3(const NumberRange& range = NumberRange::any()) const;
    /// [x, y, z] as vec3() checks it, in double precision (positions, which
    /// the parser moves to the local origin before rounding to float).
    Vec3d vec3d(const NumberRange& range = NumberRange::any()) const;
    /// [x, y, z] with at least one non-zero component, as a direction: scaled
    /// so that its largest component is +-1.
    Vec3 nonzero_vec3() const;
    /// An array; `min_size`..`max_size` elements.
    std::vector<JsonValue> array(size_t min_size = 0, size_t max_size = SIZE_MAX) const;
    /// `what` for messages: "a number", "an object", ... of this value's JSON type.
    std::string kind() const;

   private:
    const Json* json_;
    const std::string* file_;
    std::string path_;
};

/// A JSON object whose keys are consumed one by one; `finish()` rejects any key
/// that was never asked for (typos must not be silently ignored).
class JsonObject {
   public:
    explicit JsonObject(const JsonValue& value);

    /// The value at `key`, or nothing when absent. Also declares `key` as allowed.
    std::optional<JsonValue> get(const char* key);
    /// Like get(), but null counts as absent (for "optional, null = default" keys).
    std::optional<JsonValue> get_non_null(const char* key);
    /// The value at `key`; missing -> "missing key 'KEY' (expected WHAT)".
    JsonValue require(const char* key, const std::string& what);
    bool has(const char* key) const { return value_.json().contains(key); }
    /// Throws for the first key that no get/require call asked for.
    void finish() const;
    const JsonValue& value() const { return value_; }
    /// JSON path of a (possibly absent) member.
    std::string child_path(const std::string& key) const;

   private:
    JsonValue value_;
    std::vector<std::string> allowed_;
};

/// Shortest faithful text of a number for messages ("0.5", "1e+39").
std::string format_number(double v);

/// Appends `.key` (or `["odd key"]`) to a JSON path.
std::string json_member_path(const std::string& parent, const std::string& key);

}  // namespace sahara
