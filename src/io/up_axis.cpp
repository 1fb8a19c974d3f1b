#include "io/up_axis.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>

#include "math/bounds.h"

namespace sahara {

Vec3 up_vector(UpAxis a) {
    switch (a) {
        case UpAxis::x:
            return {1, 0, 0};
        case UpAxis::y:
            return {0, 1, 0};
        case UpAxis::z:
            return {0, 0, 1};
        case UpAxis::neg_x:
            return {-1, 0, 0};
        case UpAxis::neg_y:
            return {0, -1, 0};
        case UpAxis::neg_z:
            return {0, 0, -1};
    }
    return {0, 1, 0};
}

const char* up_axis_name(UpAxis a) {
    static constexpr std::array<const char*, 6> kNames = {"+x", "+y", "+z", "-x", "-y", "-z"};
    return kNames[size_t(a)];
}

std::optional<UpAxis> parse_up_axis(std::string_view s) {
    bool negative = false;
    if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
        negative = s[0] == '-';
        s.remove_prefix(1);
    }
    if (s.size() != 1) return std::nullopt;
    const char c = char(std::tolower(static_cast<unsigned char>(s[0])));
    if (c < 'x' || c > 'z') return std::nullopt;
    return UpAxis((c - 'x') + (negative ? 3 : 0));
}

namespace {

/// Exporters that name themselves in the header, with the up axis of their
/// default OBJ export. Tools whose exporter swaps axes by an option of unknown
/// default (3ds Max, SketchUp) are left to the geometry.
struct ExporterAxis {
    const char* name;  ///< matched case-insensitively in the header comments
    UpAxis up;
};
constexpr std::array<ExporterAxis, 5> kExporters = {{
    {"blender", UpAxis::y},    // exporter default: forward -Z, up Y
    {"milkshape", UpAxis::y},  // a Y-up modeller, written as is
    {"cinema 4d", UpAxis::y},  // a Y-up modeller
    {"rhino", UpAxis::z},      // Z-up; "Map Rhino Z to OBJ Y" is off unless chosen
    {"freecad", UpAxis::z},    // Z-up CAD, written as is
}};

std::string lowercase(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

Bounds3 model_bounds(const LoadedModel& model) {
    Bounds3 b;
    for (const TriangleMesh& m : model.meshes)
        for (const Vec3& p : m.positions) b.extend(p);
    return b;
}

/// Share of the box's footprint across `axis` (1 or 2) covered by flat faces
/// (normal within ~18 degrees of the axis) lying at the box's bottom along it,
/// as a ground, a floor slab or a pedestal does.
float ground_coverage(const LoadedModel& model, const Bounds3& box, int axis) {
    const Vec3 e = box.extent();
    const float band = 0.01f * std::max({e.x, e.y, e.z});
    const float bottom = box.lo[axis];
    double area = 0;
    for (const TriangleMesh& m : model.meshes) {
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            const Vec3& a = m.positions[m.indices[t]];
            const Vec3& b = m.positions[m.indices[t + 1]];
            const Vec3& c = m.positions[m.indices[t + 2]];
            if (std::max({a[axis], b[axis], c[axis]}) > bottom + band) continue;
            const Vec3 n = cross(b - a, c - a);
            const float len = length(n);
            if (len > 0 && std::abs(n[axis]) >= 0.95f * len) area += 0.5 * double(len);
        }
    }
    const float footprint = e[(axis + 1) % 3] * e[(axis + 2) % 3];
    return footprint > 0 ? float(area / double(footprint)) : 0.0f;
}

std::string percent(float share) {
    return std::to_string(int(std::lround(std::min(share, 9.99f) * 100))) + "%";
}

/// Rule 3: a ground or floor at the bottom of y or z, clearly more than at the
/// bottom of the other (a box-like model has flat sides too).
std::optional<UpAxisChoice> ground_rule(const LoadedModel& model, const Bounds3& box) {
    constexpr float kGround = 0.25f, kMargin = 1.25f;
    const float cover_y = ground_coverage(model, box, 1), cover_z = ground_coverage(model, box, 2);
    for (const bool z : {false, true}) {
        const float mine = z ? cover_z : cover_y, other = z ? cover_y : cover_z;
        if (mine >= kGround && mine > kMargin * other)
            return UpAxisChoice{z ? UpAxis::z : UpAxis::y,
                                std::string("flat faces at the bottom of ") + (z ? "z" : "y") + " cover " +
                                    percent(mine) + " of the footprint (at the bottom of " + (z ? "y" : "z") +
                                    ": " + percent(other) + "), as a ground or floor does"};
    }
    return std::nullopt;
}

}  // namespace

UpAxisChoice guess_obj_up_axis(const LoadedModel& model, std::string_view header) {
    const std::string comments = lowercase(header);
    for (const ExporterAxis& ex : kExporters)
        if (comments.find(ex.name) != std::string::npos)
            return {ex.up, std::string("the header names ") + ex.name + ", whose OBJ export is " +
                               up_axis_name(ex.up) + " up"};

    const Bounds3 box = model_bounds(model);
    if (box.empty()) return {UpAxis::y, "+y is the usual OBJ convention"};
    const Vec3 e = box.extent();
    // Rule 2: modellers put the ground at 0, so a model whose lowest point is
    // at y = 0 or z = 0 (but not both) stands on that plane.
    const float size = std::max({e.x, e.y, e.z});
    const bool on_y = std::abs(box.lo.y) <= 0.005f * size, on_z = std::abs(box.lo.z) <= 0.005f * size;
    if (on_y != on_z)
        return {on_z ? UpAxis::z : UpAxis::y,
                std::string("the model stands on the plane ") + (on_z ? "z" : "y") + " = 0"};
    if (auto c = ground_rule(model, box)) return *c;  // rule 3
    // Rule 4: a flat model (terrain, a site, a scan of a surface) lies across
    // its thin axis. A figure with spread arms is about 0.3 as deep as it is
    // wide, so the bar is below that.
    constexpr float kFlat = 0.25f;
    for (int axis : {1, 2}) {
        const float thin = e[axis], others = std::min(e[(axis + 1) % 3], e[(axis + 2) % 3]);
        if (thin < kFlat * others)
            return {axis == 2 ? UpAxis::z : UpAxis::y, std::string("the model is flat across ") +
                                                           (axis == 2 ? "z" : "y") + " (" +
                                                           percent(thin / others) + " of its width)"};
    }
    return {UpAxis::y,
            "no exporter named, not standing on 0, no ground, not flat: +y, the usual OBJ "
            "convention"};
}

std::string obj_header_comments(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::string out, line;
    // Exporters write their banner in the first few lines; 64 lines bound a long licence block.
    for (int n = 0; n < 64 && std::getline(in, line); ++n) {
        const size_t start = line.find_first_not_of(" \t\r");
        if (start == std::string::npos) continue;
        if (line[start] != '#') break;
        out += line.substr(start);
        out += '\n';
    }
    return out;
}

}  // namespace sahara
