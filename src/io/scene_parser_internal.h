#pragma once
/// Shared state of one scene parse, split over scene_parser.cpp (settings,
/// camera, background, materials) and scene_parser_objects.cpp (objects, lights).
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>

#include "io/json_reader.h"
#include "io/scene_parser.h"

namespace sahara {

/// What an object's "name" gives a later `instance` to place.
struct NamedObject {
    bool instanceable = false;  ///< meshes and instances; other shapes can be named but not placed
    /// A mesh object's own meshes, not yet in a prototype: they become one at the first
    /// instance (so a name alone changes nothing), drawn in place by an identity instance.
    std::vector<uint32_t> pending_meshes;
    /// The prototypes the object draws, each with its transform to the world (a
    /// glTF's own instances, a placed object's parts).
    std::vector<InstanceDesc> parts;
};

struct ParseContext {
    std::string file;            ///< scene file name as given, for messages
    std::filesystem::path base;  ///< directory relative paths resolve against
    const SceneLoaders* loaders = nullptr;
    SceneDesc* scene = nullptr;
    std::unordered_map<std::string, uint32_t> material_by_name;
    std::map<std::pair<std::string, bool>, int> texture_by_path;  ///< (resolved path, srgb) -> index
    Vec3d origin{0, 0, 0};  ///< the scene's local origin (SceneDesc::origin), set with the camera

    /// A world point relative to the local origin, subtracted in double, then rounded.
    Vec3 local_point(const Vec3d& world) const { return Vec3(world - origin); }
    /// An object's transform (identity when absent) followed by the move to the local origin.
    Mat4 local_from_object(const std::optional<Mat4>& object) const {
        return Mat4::translate(-origin) * object.value_or(Mat4::identity());
    }
    std::unordered_map<std::string, NamedObject> named;  ///< objects by their "name"

    /// Resolves a relative path from `where` and checks that the file exists.
    std::filesystem::path resolve_existing(const JsonValue& where) const;
    /// Texture index for the image file named by `where` (loaded once per path and mode).
    int texture(const JsonValue& where, bool srgb);
    /// Material index for a `"material": "name"` value.
    uint32_t material(const JsonValue& where) const;
};

/// The keys of a `pbr` material (scene_parser_pbr.cpp), after "type".
void parse_pbr_material(JsonObject& o, ParseContext& ctx, MaterialDesc& m);

void parse_objects(ParseContext& ctx, const JsonValue& objects);
/// An object's "transform" value (scale, rotate, translate or matrix).
Mat4 parse_object_transform(const JsonValue& v);
/// An `instance` object (scene_parser_instances.cpp): places the parts of the earlier
/// object named by "of"; returns what its own name would place.
NamedObject parse_instance(JsonObject& o, ParseContext& ctx);
/// Prototypes `named`'s pending meshes (see NamedObject) so that it can be placed.
void make_prototype(ParseContext& ctx, const std::string& name, NamedObject& named);
void parse_lights(ParseContext& ctx, const JsonValue& lights);

/// "alpha": a number in [0, 1] or {"texture": FILE} (the image's alpha channel,
/// linear); shared by the lambertian and pbr materials.
void parse_alpha(const JsonValue& v, ParseContext& ctx, MaterialDesc& m);

}  // namespace sahara
