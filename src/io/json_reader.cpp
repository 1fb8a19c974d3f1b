#include "base/text.h"
#include "io/json_reader.h"

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <unordered_set>

#include "base/error.h"

namespace sahara {

namespace {

/// "line L, column C" of the 1-based byte offset that nlohmann reports.
std::string line_column(const std::string& text, size_t byte) {
    size_t end = std::min(byte == 0 ? 0 : byte - 1, text.size());
    size_t line = 1, line_start = 0;
    for (size_t i = 0; i < end; ++i)
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    return "line " + std::to_string(line) + ", column " + std::to_string(end - line_start + 1);
}

/// nlohmann's what() starts with "[json.exception.parse_error.101] parse error at
/// line 3, column 0: "; its own line/column can be off, so keep only the reason.
std::string strip_nlohmann_prefix(const std::string& what) {
    size_t bracket = what.find("] ");
    size_t start = bracket == std::string::npos ? 0 : bracket + 2;
    size_t colon = what.find(": ", start);
    if (what.compare(start, 11, "parse error") == 0 && colon != std::string::npos) start = colon + 2;
    return what.substr(start);
}

bool is_identifier(const std::string& s) {
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
    return std::all_of(s.begin(), s.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
    });
}

/// The container frames the parser is inside; rebuilds the JSON path of a
/// duplicate key, which nlohmann would otherwise silently overwrite.
class DuplicateKeyCheck {
   public:
    explicit DuplicateKeyCheck(const std::string& file) : file_(file) {}

    bool operator()(int, nlohmann::detail::parse_event_t event, Json& parsed) {
        using E = nlohmann::detail::parse_event_t;
        switch (event) {
            case E::object_start:
                frames_.push_back({true, 0, {}, {}});
                break;
            case E::array_start:
                frames_.push_back({false, 0, {}, {}});
                break;
            case E::key:
                on_key(parsed.get<std::string>());
                break;
            case E::object_end:
            case E::array_end:
                frames_.pop_back();
                element_done();
                break;
            case E::value:
                element_done();
                break;
        }
        return true;
    }

   private:
    struct Frame {
        bool object;
        size_t index;
        std::string key;
        std::unordered_set<std::string> seen;
    };

    void element_done() {
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
    }
    void on_key(const std::string& key) {
        Frame& top = frames_.back();
        if (!top.seen.insert(key).second) {
            std::string path;
            for (size_t i = 0; i + 1 < frames_.size(); ++i)
                path = frames_[i].object ? json_member_path(path, frames_[i].key)
                                         : path + "[" + std::to_string(frames_[i].index) + "]";
            throw input_error(file_, json_member_path(path, key), "duplicate key (each key may appear once)");
        }
        top.key = key;
    }

    const std::string& file_;
    std::vector<Frame> frames_;
};

}  // namespace

Json parse_json_text(const std::string& text, const std::string& file) {
    DuplicateKeyCheck check(file);
    try {
        return Json::parse(text, std::ref(check), true, false);
    } catch (const Json::parse_error& e) {
        throw input_error(file, line_column(text, e.byte),
                          "invalid JSON: " + strip_nlohmann_prefix(e.what()));
    } catch (const Json::out_of_range& e) {
        // "number overflow parsing '1e999'": locate the literal for the position.
        std::string what = strip_nlohmann_prefix(e.what());
        size_t q1 = what.find('\''), q2 = what.rfind('\'');
        std::string where;
        if (q1 != std::string::npos && q2 > q1) {
            size_t at = text.find(what.substr(q1 + 1, q2 - q1 - 1));
            if (at != std::string::npos) where = line_column(text, at + 1);
        }
        throw input_error(file, where, "invalid JSON: " + what + " (numbers must be finite doubles)");
    }
}

std::string format_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string json_member_path(const std::string& parent, const std::string& key) {
    if (!is_identifier(key)) return parent + "[" + Json(key).dump() + "]";
    return parent.empty() ? key : parent + "." + key;
}

// --- NumberRange ---------------------------------------------------------

bool NumberRange::contains(double v) const {
    bool above = lo_open ? v > lo : v >= lo;
    bool below = hi_open ? v < hi : v <= hi;
    return above && below;
}

std::string NumberRange::describe() const {
    bool has_lo = lo > -1e299, has_hi = hi < 1e299;
    if (has_lo && has_hi)
        return " in " + std::string(lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
               (hi_open ? ")" : "]");
    if (has_lo) return (lo_open ? " > " : " >= ") + format_number(lo);
    if (has_hi) return (hi_open ? " < " : " <= ") + format_number(hi);
    return "";
}

// --- JsonValue -----------------------------------------------------------

void JsonValue::fail_expected(const std::string& expected) const {
    std::string got = json_->dump();
    if (got.size() > 60) got = got.substr(0, 57) + "...";
    throw input_error(*file_, path_, "expected " + expected + ", got " + got);
}

void JsonValue::fail(const std::string& message) const { throw input_error(*file_, path_, message); }

std::string JsonValue::kind() const {
    switch (json_->type()) {
        case Json::value_t::null:
            return "null";
        case Json::value_t::boolean:
            return "a boolean";
        case Json::value_t::string:
            return "a string";
        case Json::value_t::array:
            return "an array";
        case Json::value_t::object:
            return "an object";
        default:
            return "a number";
    }
}

double JsonValue::number(const NumberRange& range) const {
    if (!json_->is_number()) fail_expected("a number" + range.describe());
    double v = json_->get<double>();
    if (!std::isfinite(v) || !range.contains(v)) fail_expected("a number" + range.describe());
    return v;
}

float JsonValue::number_f(const NumberRange& range) const {
    double v = number(range);
    if (std::abs(v) > double(FLT_MAX))
        fail_expected("a number" + range.describe() + " that fits a 32-bit float");
    return float(v);
}

int64_t JsonValue::integer(int64_t lo, int64_t hi) const {
    std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (lo == 0 && hi == INT64_MAX) expected = "an integer >= 0";
    if (lo == 1 && hi == INT32_MAX) expected = "an integer >= 1";
    if (!json_->is_number()) fail_expected(expected);
    double v = json_->get<double>();
    if (!std::isfinite(v) || v != std::floor(v) || v < double(lo) || v > double(hi)) fail_expected(expected);
    if (json_->is_number_integer()) {
        // exact path for big integers that a double would round
        if (json_->is_number_unsigned()) {
            uint64_t u = json_->get<uint64_t>();
            if (u > uint64_t(hi)) fail_expected(expected);
            return int64_t(u);
        }
        int64_t i = json_->get<int64_t>();
        if (i < lo || i > hi) fail_expected(expected);
        return i;
    }
    return int64_t(v);
}

uint64_t JsonValue::unsigned_integer() const {
    const std::string expected = "an integer in [0, 18446744073709551615]";
    if (json_->is_number_unsigned()) return json_->get<uint64_t>();
    if (json_->is_number_integer()) fail_expected(expected);  // negative
    if (!json_->is_number()) fail_expected(expected);
    double v = json_->get<double>();
    if (!std::isfinite(v) || v != std::floor(v) || v < 0 || v >= 18446744073709551616.0)
        fail_expected(expected);
    return uint64_t(v);
}

bool JsonValue::boolean() const {
    if (!json_->is_boolean()) fail_expected("true or false");
    return json_->get<bool>();
}

std::string JsonValue::string() const {
    if (!json_->is_string()) fail_expected("a string");
    return json_->get<std::string>();
}

size_t JsonValue::one_of(std::initializer_list<const char*> names) const {
    std::string choices;
    for (const char* n : names) choices += (choices.empty() ? "\"" : ", \"") + std::string(n) + "\"";
    if (json_->is_string()) {
        const std::string& s = json_->get_ref<const std::string&>();
        size_t i = 0;
        for (const char* n : names) {
            if (s == n) return i;
            ++i;
        }
    }
    fail_expected("one of " + choices);
}

Vec3 JsonValue::vec3(const NumberRange& range) const {
    const std::string expected =
        "[x, y, z]: 3 numbers" + (range.describe().empty() ? "" : " each" + range.describe());
    if (!json_->is_array() || json_->size() != 3) fail_expected(expected);
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
        JsonValue e((*json_)[size_t(i)], *file_, path_ + "[" + std::to_string(i) + "]");
        v[i] = e.number_f(range);
    }
    return v;
}

Vec3d JsonValue::vec3d(const NumberRange& range) const {
    vec3(range);  // the same checks and messages
    Vec3d v;
    for (int i = 0; i < 3; ++i) v[i] = JsonValue((*json_)[size_t(i)], *file_, path_).number();
    return v;
}

Vec3 JsonValue::nonzero_vec3() const {
    const Vec3d v = vec3d();
    const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    if (largest == 0) fail_expected("a non-zero vector [x, y, z]");
    // Scaled to at most 1 per component: every caller normalises, and the float
    // square of 1e20 or 1e-20 would overflow or vanish there.
    return Vec3(v / largest);
}

std::vector<JsonValue> JsonValue::array(size_t min_size, size_t max_size) const {
    std::string expected = "an array";
    if (min_size == max_size)
        expected += " of " + std::to_string(min_size) + " elements";
    else if (min_size > 0)
        expected += " of at least " + std::to_string(min_size) + " elements";
    if (!json_->is_array() || json_->size() < min_size || json_->size() > max_size) fail_expected(expected);
    std::vector<JsonValue> out;
    out.reserve(json_->size());
    for (size_t i = 0; i < json_->size(); ++i)
        out.emplace_back((*json_)[i], *file_, path_ + "[" + std::to_string(i) + "]");
    return out;
}

// --- JsonObject ----------------------------------------------------------

JsonObject::JsonObject(const JsonValue& value) : value_(value) {
    if (!value.json().is_object()) value.fail_expected("an object");
}

std::string JsonObject::child_path(const std::string& key) const {
    return json_member_path(value_.path(), key);
}

std::optional<JsonValue> JsonObject::get(const char* key) {
    allowed_.emplace_back(key);
    auto it = value_.json().find(key);
    if (it == value_.json().end()) return std::nullopt;
    return JsonValue(*it, value_.file(), child_path(key));
}

std::optional<JsonValue> JsonObject::get_non_null(const char* key) {
    auto v = get(key);
    if (v && v->is_null()) return std::nullopt;
    return v;
}

JsonValue JsonObject::require(const char* key, const std::string& what) {
    auto v = get(key);
    if (!v)
        throw input_error(value_.file(), value_.path(),
                          "missing key \"" + std::string(key) + "\" (expected " + what + ")");
    return *v;
}

void JsonObject::finish() const {
    for (const auto& [key, v] : value_.json().items()) {
        if (std::find(allowed_.begin(), allowed_.end(), key) != allowed_.end()) continue;
        const std::string list = join(allowed_);
        throw input_error(value_.file(), child_path(key),
                          "unknown key" + (list.empty() ? std::string(" (no keys are allowed here)")
                                                        : " (allowed here: " + list + ")"));
    }
}

}  // namespace sahara
