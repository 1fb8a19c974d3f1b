// The scene format's `instance` object: places an earlier named mesh or instance
// again, sharing its triangles (the scene's instance level, scene/instances.h).
#include <cmath>

#include "io/scene_parser_internal.h"

namespace sahara {

void make_prototype(ParseContext& ctx, const std::string& name, NamedObject& named) {
    if (named.pending_meshes.empty()) return;
    SceneDesc& scene = *ctx.scene;
    const auto prototype = uint32_t(scene.prototypes.size());
    scene.prototypes.push_back({name, std::move(named.pending_meshes)});
    named.pending_meshes.clear();
    // The named object is still drawn where it stands: by an identity instance.
    const InstanceDesc in_place{prototype, Mat4::identity()};
    scene.instances.push_back(in_place);
    named.parts.push_back(in_place);
}

NamedObject parse_instance(JsonObject& o, ParseContext& ctx) {
    const JsonValue of = o.require("of", "the name of an earlier mesh or instance");
    const std::string target = of.string();
    auto it = ctx.named.find(target);
    if (it == ctx.named.end()) of.fail("no earlier object is named \"" + target + "\"");
    if (!it->second.instanceable)
        of.fail("\"" + target + "\" is not a mesh or an instance (only those can be instanced)");
    Mat4 m = Mat4::identity();
    if (auto v = o.get("transform")) {
        m = parse_object_transform(*v);
        const double det = m.determinant3();
        if (!(std::isfinite(det) && det != 0.0))
            v->fail("is singular (an instance's transform must be invertible)");
    }
    // Motion blur as a sphere's: velocity in the frame the transform maps into.
    Vec3 velocity(0.0f);
    if (auto v = o.get("velocity")) velocity = v->vec3();
    // The named object's geometry is stored relative to the local origin, so
    // the world-space transform is conjugated into that frame.
    m = Mat4::translate(-ctx.origin) * m * Mat4::translate(ctx.origin);
    make_prototype(ctx, target, it->second);
    NamedObject placed;
    placed.instanceable = true;
    // An instance's transform applies after the named object's own; nested
    // instances compose here, so every InstanceDesc places a prototype directly.
    for (const InstanceDesc& part : it->second.parts) {
        const InstanceDesc in{part.prototype, m * part.world_from_object,
                              m.apply_vector(part.velocity) + velocity};
        ctx.scene->instances.push_back(in);
        placed.parts.push_back(in);
    }
    return placed;
}

}  // namespace sahara
