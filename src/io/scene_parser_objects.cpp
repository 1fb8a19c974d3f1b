// Objects, transforms, quadrics and lights of the scene format.
#include <cfloat>
#include <cmath>
#include <numbers>

#include "base/error.h"
#include "base/log.h"
#include "io/scene_parser_internal.h"

namespace sahara {

namespace {

Vec3d column(const Mat4& m, int c) { return {m.m[0][c], m.m[1][c], m.m[2][c]}; }

// --- transform -------------------------------------------------------------------

Mat4 parse_matrix(const JsonValue& v) {
    auto elems = v.array(16, 16);
    Mat4 m;
    for (int i = 0; i < 16; ++i) m.m[i / 4][i % 4] = elems[size_t(i)].number();
    if (m.m[3][0] != 0 || m.m[3][1] != 0 || m.m[3][2] != 0 || m.m[3][3] != 1)
        v.fail("expected an affine matrix: the last row (elements 12..15) must be 0, 0, 0, 1");
    if (std::abs(m.determinant3()) < 1e-12)
        v.fail("expected an invertible matrix (its 3x3 part is singular)");
    return m;
}

Vec3d parse_scale(const JsonValue& v) {
    const char* expected = "a non-zero number or [x, y, z] of non-zero numbers";
    Vec3d s(0.0);
    if (v.json().is_array())
        s = Vec3d(v.vec3());
    else if (v.json().is_number())
        s = Vec3d(double(v.number_f()));
    if (s.x == 0 || s.y == 0 || s.z == 0) v.fail_expected(expected);
    return s;
}

/// "transform": scale -> rotate (Euler X, Y, Z) -> translate, i.e. M = T * R * S; or "matrix".
Mat4 parse_transform(const JsonValue& v) {
    JsonObject o(v);
    auto matrix = o.get("matrix");
    auto scale = o.get("scale");
    auto rotate = o.get("rotate");
    auto translate = o.get("translate");
    o.finish();
    if (matrix && (scale || rotate || translate))
        v.fail(
            "\"matrix\" excludes \"scale\", \"rotate\" and \"translate\"; give the matrix alone or those "
            "three");
    if (matrix) return parse_matrix(*matrix);
    Mat4 s = scale ? Mat4::scale(parse_scale(*scale)) : Mat4::identity();
    Mat4 r = rotate ? Mat4::rotate_euler(Vec3d(rotate->vec3())) : Mat4::identity();
    Mat4 t = translate ? Mat4::translate(translate->vec3d()) : Mat4::identity();
    return t * r * s;
}

std::optional<Mat4> object_transform(JsonObject& o) {
    if (auto v = o.get("transform")) return parse_transform(*v);
    return std::nullopt;
}

uint32_t object_material(JsonObject& o, ParseContext& ctx) {
    if (auto v = o.get("material")) return ctx.material(*v);
    return 0;
}

/// A point that must stay finite in float after a transform.
Vec3 checked_point(const JsonValue& where, const Vec3& p) {
    if (!is_finite(p)) where.fail("the transformed value overflows 32-bit floats");
    return p;
}

/// A point read in double, moved by `local_from_object` (the object's transform
/// and the move to the local origin) and only then rounded to float.
Vec3 placed_point(const JsonValue& where, const Mat4& local_from_object, const Vec3d& p) {
    return checked_point(where, Vec3(local_from_object.map_point(p)));
}

// --- sphere, plane, box ---------------------------------------------------------------

void parse_sphere(JsonObject& o, ParseContext& ctx) {
    SphereDesc s;
    Vec3d center(0.0);
    if (auto v = o.get("center")) center = v->vec3d();
    s.center = ctx.local_point(center);
    if (auto v = o.get("radius")) s.radius = v->number_f(NumberRange::positive());
    if (auto v = o.get("velocity")) s.velocity = v->vec3();
    s.material = object_material(o, ctx);
    if (auto m = object_transform(o)) {
        // Only similarities (uniform scale, rotation, translation) keep a sphere a sphere.
        Vec3d c0 = column(*m, 0), c1 = column(*m, 1), c2 = column(*m, 2);
        double l = length(c0), tol = 1e-6 * l * l;
        bool similar = std::abs(dot(c1, c1) - l * l) <= tol && std::abs(dot(c2, c2) - l * l) <= tol &&
                       std::abs(dot(c0, c1)) <= tol && std::abs(dot(c0, c2)) <= tol &&
                       std::abs(dot(c1, c2)) <= tol;
        JsonValue where(o.value().json().at("transform"), ctx.file, o.child_path("transform"));
        if (!similar)
            where.fail("a sphere only takes a uniform scale (use an ellipsoid for non-uniform scale)");
        s.center = placed_point(where, ctx.local_from_object(m), center);
        s.velocity = checked_point(where, m->apply_vector(s.velocity));
        double r = double(s.radius) * l;
        if (!(r <= double(FLT_MAX))) where.fail("the transformed radius overflows 32-bit floats");
        s.radius = float(r);
    }
    ctx.scene->spheres.push_back(s);
}

void parse_plane(JsonObject& o, ParseContext& ctx) {
    PlaneDesc p;
    Vec3d point(0.0);
    if (auto v = o.get("point")) point = v->vec3d();
    p.point = ctx.local_point(point);
    if (auto v = o.get("normal")) p.normal = normalize(v->nonzero_vec3());
    p.material = object_material(o, ctx);
    if (auto m = object_transform(o)) {
        JsonValue where(o.value().json().at("transform"), ctx.file, o.child_path("transform"));
        p.point = placed_point(where, ctx.local_from_object(m), point);
        p.normal = m->apply_normal(p.normal);
    }
    ctx.scene->planes.push_back(p);
}

/// Whether the 3x3 part maps coordinate axes onto coordinate axes (scale,
/// mirror, rotation by multiples of 90 degrees): then a box stays a box.
bool keeps_axis_aligned(const Mat4& m) {
    for (int c = 0; c < 3; ++c) {
        Vec3d col = column(m, c);
        double big = std::max({std::abs(col.x), std::abs(col.y), std::abs(col.z)});
        int nonzero =
            (std::abs(col.x) > 1e-9 * big) + (std::abs(col.y) > 1e-9 * big) + (std::abs(col.z) > 1e-9 * big);
        if (nonzero != 1) return false;
    }
    return true;
}

/// A transformed box that is no longer axis-aligned becomes 12 triangles
/// (4 vertices per face so each face keeps flat normals and its own UVs).
TriangleMesh box_mesh(const Vec3d& lo, const Vec3d& hi, const Mat4& m, const std::string& name) {
    TriangleMesh mesh;
    mesh.name = name;
    // Each face: the axis it faces along, its sign; corners CCW seen from outside.
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            int u = (axis + 1) % 3, v = (axis + 2) % 3;
            if (side == 0) std::swap(u, v);  // flip winding on the negative face
            uint32_t base = uint32_t(mesh.positions.size());
            const float uc[4] = {0, 1, 1, 0}, vc[4] = {0, 0, 1, 1};
            for (int k = 0; k < 4; ++k) {
                Vec3d p;
                p[axis] = side ? hi[axis] : lo[axis];
                p[u] = uc[k] > 0 ? hi[u] : lo[u];
                p[v] = vc[k] > 0 ? hi[v] : lo[v];
                mesh.positions.push_back(Vec3(m.map_point(p)));
                mesh.uvs.push_back(Vec2{uc[k], vc[k]});
            }
            for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
        }
    if (m.determinant3() < 0)  // a mirroring transform turns the faces inside out
        for (size_t t = 0; t < mesh.indices.size(); t += 3)
            std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
    return mesh;
}

void parse_box(JsonObject& o, ParseContext& ctx, size_t index) {
    Vec3d lo(-1.0), hi(1.0);
    if (auto v = o.get("min")) lo = v->vec3d();
    auto max_v = o.get("max");
    if (max_v) hi = max_v->vec3d();
    if (hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z) {
        JsonValue where = max_v ? *max_v : o.value();
        where.fail("expected max > min in every component, got min [" + format_number(lo.x) + ", " +
                   format_number(lo.y) + ", " + format_number(lo.z) + "] and max [" + format_number(hi.x) +
                   ", " + format_number(hi.y) + ", " + format_number(hi.z) + "]");
    }
    uint32_t material = object_material(o, ctx);
    auto m = object_transform(o);
    if (!m) {
        ctx.scene->boxes.push_back(BoxDesc{ctx.local_point(lo), ctx.local_point(hi), material});
        return;
    }
    const Mat4 placed = ctx.local_from_object(m);
    JsonValue where(o.value().json().at("transform"), ctx.file, o.child_path("transform"));
    if (keeps_axis_aligned(*m)) {
        Bounds3 b;
        for (int c = 0; c < 8; ++c)
            b.extend(placed_point(where, placed,
                                  Vec3d(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z)));
        ctx.scene->boxes.push_back(BoxDesc{b.lo, b.hi, material});
        return;
    }
    TriangleMesh mesh = box_mesh(lo, hi, placed, ctx.file + ": objects[" + std::to_string(index) + "] (box)");
    for (const Vec3& p : mesh.positions) checked_point(where, p);
    mesh.material = material;
    ctx.scene->meshes.push_back(std::move(mesh));
}

// --- mesh --------------------------------------------------------------------------------

NamedObject parse_mesh(JsonObject& o, ParseContext& ctx) {
    JsonValue file = o.require("file", "a mesh file (.obj, .gltf or .glb)");
    std::filesystem::path path = ctx.resolve_existing(file);
    std::optional<uint32_t> material;
    if (auto v = o.get("material")) material = ctx.material(*v);
    std::optional<std::string> variant;
    if (auto v = o.get("variant")) variant = v->string();
    // The loaders apply the whole matrix in double, so the model lands at the local origin.
    const Mat4 m = ctx.local_from_object(object_transform(o));
    LoadedModel model;
    try {
        model = ctx.loaders->load_model(path, m, variant);
    } catch (const InputError& e) {
        file.fail(e.what());
    }
    if (model.dropped_degenerate > 0)
        log_info(path.string() + ": dropped " + std::to_string(model.dropped_degenerate) +
                 " degenerate triangles");
    if (!model.cameras.empty())
        log_info(path.string() + ": ignoring " + std::to_string(model.cameras.size()) +
                 " camera(s); the scene's camera is used");
    SceneDesc& scene = *ctx.scene;
    const size_t first_mesh = scene.meshes.size(), first_prototype = scene.prototypes.size(),
                 first_instance = scene.instances.size();
    merge_loaded_model(scene, std::move(model), material);
    NamedObject named;
    named.instanceable = true;
    std::vector<bool> prototyped(scene.meshes.size() - first_mesh, false);
    for (size_t p = first_prototype; p < scene.prototypes.size(); ++p)
        for (uint32_t mesh : scene.prototypes[p].meshes) prototyped[mesh - first_mesh] = true;
    for (size_t k = 0; k < prototyped.size(); ++k)
        if (!prototyped[k]) named.pending_meshes.push_back(uint32_t(first_mesh + k));
    named.parts.assign(scene.instances.begin() + ptrdiff_t(first_instance), scene.instances.end());
    return named;
}

// --- quadrics ------------------------------------------------------------------------------

/// Local frame with +z along `axis` and the origin at `origin`; the tangents
/// follow Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017).
Mat4 axis_frame(const Vec3d& origin, const Vec3& axis) {
    Vec3d n = normalize(Vec3d(axis));
    double sign = std::copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
    Vec3d t1(1 + sign * n.x * n.x * a, sign * b, -sign * n.x), t2(b, sign + n.y * n.y * a, -n.y);
    Mat4 f;
    for (int r = 0; r < 3; ++r) {
        f.m[r][0] = t1[r];
        f.m[r][1] = t2[r];
        f.m[r][2] = n[r];
        f.m[r][3] = origin[r];
    }
    return f;
}

void set_disc_bounds(QuadricDesc& q, double r, double z0, double z1) {
    q.local_bounds = Bounds3{Vec3(float(-r), float(-r), float(z0)), Vec3(float(r), float(r), float(z1))};
}

/// Reads the named form's keys and derives its canonical coefficients and clip box.
/// `origin` receives the named point in double (q.origin keeps it as written, in float).
void parse_named_quadric(JsonObject& o, QuadricDesc& q, const char* origin_key, Vec3d& origin) {
    const NumberRange pos = NumberRange::positive();
    if (auto v = o.get(origin_key)) {
        origin = v->vec3d();
        q.origin = v->vec3();
    }
    if (q.type != QuadricDesc::Type::ellipsoid)
        if (auto v = o.get("axis")) q.axis = normalize(v->nonzero_vec3());
    auto& c = q.coefficients;  // A B C D E F G H I J
    switch (q.type) {
        case QuadricDesc::Type::ellipsoid: {
            if (auto v = o.get("radii")) q.radii = v->vec3(pos);
            Vec3d r(q.radii);
            c = {1 / (r.x * r.x), 1 / (r.y * r.y), 1 / (r.z * r.z), 0, 0, 0, 0, 0, 0, -1};
            q.local_bounds = Bounds3{-q.radii, q.radii};
            break;
        }
        case QuadricDesc::Type::cylinder: {
            if (auto v = o.get("radius")) q.radius = v->number_f(pos);
            if (auto v = o.get("height")) q.height = v->number_f(pos);
            if (auto v = o.get("capped")) q.capped = v->boolean();
            double r = q.radius;
            c = {1, 1, 0, 0, 0, 0, 0, 0, 0, -r * r};
            set_disc_bounds(q, r, 0, double(q.height));
            break;
        }
        case QuadricDesc::Type::cone: {
            if (auto v = o.get("angle")) q.angle = v->number_f(NumberRange::open(0, 90));
            if (auto v = o.get("height")) q.height = v->number_f(pos);
            if (auto v = o.get("capped")) q.capped = v->boolean();
            double t = std::tan(double(q.angle) * std::numbers::pi / 180.0);
            c = {1, 1, -t * t, 0, 0, 0, 0, 0, 0, 0};
            set_disc_bounds(q, t * double(q.height), 0, double(q.height));
            break;
        }
        case QuadricDesc::Type::paraboloid: {
            if (auto v = o.get("radius")) q.radius = v->number_f(pos);
            if (auto v = o.get("height")) q.height = v->number_f(pos);
            double r = q.radius;
            c = {1, 1, 0, 0, 0, 0, 0, 0, -r * r / double(q.height), 0};
            set_disc_bounds(q, r, 0, double(q.height));
            break;
        }
        case QuadricDesc::Type::hyperboloid: {
            if (auto v = o.get("radius")) q.radius = v->number_f(pos);
            if (auto v = o.get("height")) q.height = v->number_f(pos);
            auto waist = o.get("waist");
            if (waist) q.waist = waist->number_f(pos);
            if (!(q.waist < q.radius)) {
                JsonValue where = waist ? *waist : o.value();
                where.fail("expected waist < radius (" + format_number(q.radius) + "), got waist " +
                           format_number(q.waist));
            }
            double r = q.radius, w = q.waist, half = 0.5 * double(q.height);
            c = {1, 1, -(r * r - w * w) / (half * half), 0, 0, 0, 0, 0, 0, -w * w};
            set_disc_bounds(q, r, -half, half);
            break;
        }
        case QuadricDesc::Type::general:
            break;
    }
}

void parse_general_quadric(JsonObject& o, QuadricDesc& q) {
    JsonValue coeffs = o.require("coefficients", "[A, B, C, D, E, F, G, H, I, J]");
    auto elems = coeffs.array(10, 10);
    for (size_t i = 0; i < 10; ++i) q.coefficients[i] = elems[i].number();
    bool quadratic = false;
    for (size_t i = 0; i < 6; ++i) quadratic |= q.coefficients[i] != 0;
    if (!quadratic)
        coeffs.fail("expected at least one of A..F (the quadratic terms) to be non-zero; use a plane");
    JsonObject b(o.require("bounds", "the clip box {\"min\": [x, y, z], \"max\": [x, y, z]}"));
    Vec3 lo = b.require("min", "[x, y, z]").vec3();
    JsonValue max_v = b.require("max", "[x, y, z]");
    Vec3 hi = max_v.vec3();
    b.finish();
    if (hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z) max_v.fail("expected max > min in every component");
    q.local_bounds = Bounds3{lo, hi};
}

void parse_quadric(JsonObject& o, ParseContext& ctx, QuadricDesc::Type type) {
    QuadricDesc q;
    q.type = type;
    static const char* origin_keys[] = {"center", "base", "apex", "vertex", "center", ""};
    Vec3d origin(0.0);
    if (type == QuadricDesc::Type::general)
        parse_general_quadric(o, q);
    else
        parse_named_quadric(o, q, origin_keys[int(type)], origin);
    q.material = object_material(o, ctx);
    Mat4 frame = type == QuadricDesc::Type::general     ? Mat4::identity()
                 : type == QuadricDesc::Type::ellipsoid ? Mat4::translate(origin)
                                                        : axis_frame(origin, q.axis);
    // "world" here is the scene's local frame (SceneDesc::origin).
    q.world_from_local = ctx.local_from_object(object_transform(o)) * frame;
    q.local_from_world = affine_inverse(q.world_from_local);
    const Bounds3& lb = q.local_bounds;
    for (int c = 0; c < 8; ++c)
        q.world_bounds.extend(q.world_from_local.apply_point(
            Vec3(c & 1 ? lb.hi.x : lb.lo.x, c & 2 ? lb.hi.y : lb.lo.y, c & 4 ? lb.hi.z : lb.lo.z)));
    if (!is_finite(q.world_bounds.lo) || !is_finite(q.world_bounds.hi))
        o.value().fail("the transformed shape overflows 32-bit floats");
    ctx.scene->quadrics.push_back(q);
}

void parse_object(JsonObject o, ParseContext& ctx, size_t index) {
    size_t type = o.require("type", "the object type")
                      .one_of({"sphere", "plane", "box", "mesh", "instance", "ellipsoid", "cylinder", "cone",
                               "paraboloid", "hyperboloid", "quadric"});
    NamedObject named;
    switch (type) {
        case 0:
            parse_sphere(o, ctx);
            break;
        case 1:
            parse_plane(o, ctx);
            break;
        case 2:
            parse_box(o, ctx, index);
            break;
        case 3:
            named = parse_mesh(o, ctx);
            break;
        case 4:
            named = parse_instance(o, ctx);
            break;
        default:
            parse_quadric(o, ctx, QuadricDesc::Type(type - 5));
            break;
    }
    // Read last, so that unknown-key messages list the type's own keys first.
    if (std::optional<JsonValue> name = o.get("name")) {
        const std::string text = name->string();
        if (ctx.named.count(text)) name->fail("\"" + text + "\" already names an earlier object");
        ctx.named[text] = std::move(named);
    }
    o.finish();
}

void parse_light(JsonObject o, ParseContext& ctx) {
    LightDesc l;
    l.type =
        LightDesc::Type(o.require("type", "\"point\" or \"directional\"").one_of({"point", "directional"}));
    if (l.type == LightDesc::Type::point) {
        if (auto v = o.get("position")) l.position = ctx.local_point(v->vec3d());
        l.intensity = Rgb(1.0f);
        if (auto v = o.get("intensity")) l.intensity = v->vec3(NumberRange::non_negative());
    } else {
        if (auto v = o.get("direction")) l.direction = normalize(v->nonzero_vec3());
        l.irradiance = Rgb(1.0f);
        if (auto v = o.get("irradiance")) l.irradiance = v->vec3(NumberRange::non_negative());
    }
    o.finish();
    ctx.scene->lights.push_back(l);
}

}  // namespace

void parse_objects(ParseContext& ctx, const JsonValue& objects) {
    auto list = objects.array();
    for (size_t i = 0; i < list.size(); ++i) parse_object(JsonObject(list[i]), ctx, i);
}

void parse_lights(ParseContext& ctx, const JsonValue& lights) {
    for (const JsonValue& v : lights.array()) parse_light(JsonObject(v), ctx);
}

Mat4 parse_object_transform(const JsonValue& v) { return parse_transform(v); }

void merge_loaded_model(SceneDesc& scene, LoadedModel&& model, std::optional<uint32_t> material_override) {
    const uint32_t material_offset = uint32_t(scene.materials.size());
    const int texture_offset = int(scene.textures.size());
    auto shift = [&](int& t) {
        if (t >= 0) t += texture_offset;
    };
    if (!material_override) {
        for (MaterialDesc& m : model.materials) {
            for_each_texture_slot(m, [&](const char*, int& t) { shift(t); });
            scene.materials.push_back(std::move(m));
        }
        for (TextureDesc& t : model.textures) scene.textures.push_back(std::move(t));
    }
    const auto mesh_offset = uint32_t(scene.meshes.size()),
               prototype_offset = uint32_t(scene.prototypes.size());
    for (PrototypeDesc& p : model.prototypes) {
        for (uint32_t& m : p.meshes) m += mesh_offset;
        scene.prototypes.push_back(std::move(p));
    }
    for (InstanceDesc& in : model.instances) {
        in.prototype += prototype_offset;
        scene.instances.push_back(in);
    }
    for (TriangleMesh& mesh : model.meshes) {
        if (material_override) {
            mesh.material_ids.clear();
            mesh.material = *material_override;
            // The mesh's colours tint whatever material it gets: `sahara info` says so.
            if (!mesh.colors.empty()) scene.materials[mesh.material].vertex_colors = true;
        } else {
            mesh.material += material_offset;
            for (uint32_t& id : mesh.material_ids) id += material_offset;
        }
        scene.meshes.push_back(std::move(mesh));
    }
    for (const LightDesc& l : model.lights) scene.lights.push_back(l);
}

}  // namespace sahara
