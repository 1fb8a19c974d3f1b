#pragma once
/// Plain scene data: what the JSON parser, the built-in scenes and the mesh
/// loaders produce, and what the renderer builds its runtime Scene from.
/// No behaviour here and no BVH; indices refer into the vectors of SceneDesc.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/bvh_choice.h"
#include "math/bounds.h"
#include "math/transform.h"
#include "math/vec3.h"

namespace sahara {

/// A decoded image, linear float RGBA, row 0 at the top.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgba;  ///< width * height * 4 floats
};

enum class WrapMode : uint8_t { repeat, clamp, mirror };

/// An image texture addressed by UVs. Convention for everything in SceneDesc:
/// v = 0 is the image BOTTOM (as in OBJ), so the texel row is (1 - v') * height
/// with Image row 0 at the top. OBJ uvs are stored as written; glTF uvs (v = 0
/// at the top) are converted at load to v = 1 - v_gltf, and their
/// KHR_texture_transform is rewritten for the flipped space (gltf_loader.cpp).
struct TextureDesc {
    std::string path;  ///< for messages and `sahara info`
    std::shared_ptr<const Image> image;
    WrapMode wrap_u = WrapMode::repeat, wrap_v = WrapMode::repeat;
    /// uv' = [offset] + rotate(rotation) * (scale * uv), rotate(a) = [cos a, sin a; -sin a, cos a]
    /// as scene/texture.cpp applies it (glTF's transform, expressed in these v-up uvs).
    Vec2 uv_offset{0, 0}, uv_scale{1, 1};
    float uv_rotation = 0;
    int texcoord = 0;  ///< which UV set (only set 0 is stored on meshes today)
};

/// Where a colour comes from: a constant, a world-space 3-D checker, or a texture
/// (times `color`, which then acts as a factor).
struct ColorSource {
    enum class Kind : uint8_t { constant, checker, texture } kind = Kind::constant;
    Rgb color{0.5f, 0.5f, 0.5f};
    Rgb even{0.9f, 0.9f, 0.9f}, odd{0.1f, 0.1f, 0.1f};
    float checker_scale = 1.0f;  ///< size of one checker cell in scene units
    int texture = -1;            ///< index into SceneDesc::textures
    /// Added to the (local) position before the checker test: the local origin's
    /// world position modulo the checker period, so the cells stay where the
    /// world coordinates put them.
    Vec3 checker_offset{0, 0, 0};
};

/// unlit: glTF KHR_materials_unlit or the scene file's "unlit", the albedo shown
/// as it is to camera rays, invisible to every other ray (render/integrator.cpp).
enum class MaterialType : uint8_t { lambertian, metal, dielectric, emissive, pbr, unlit };

/// pbr only: the layers KHR_materials_clearcoat and KHR_materials_sheen put over
/// the base (render/bsdf_layers.h). A zero clearcoat and a black sheen colour
/// leave the material as it is, and cost nothing at render time.
struct PbrLayersDesc {
    float clearcoat = 0.0f;                ///< coat weight in [0, 1]
    int clearcoat_texture = -1;            ///< R scales clearcoat
    float clearcoat_roughness = 0.0f;      ///< perceptual (alpha = roughness^2)
    int clearcoat_roughness_texture = -1;  ///< G scales clearcoat_roughness
    int clearcoat_normal_texture = -1;     ///< the coat's own normal map; without it the coat is not bumped
    float clearcoat_normal_scale = 1.0f;
    Rgb sheen_color{0.0f, 0.0f, 0.0f};  ///< linear, in [0, 1]
    int sheen_color_texture = -1;       ///< RGB (sRGB-decoded) scales sheen_color
    float sheen_roughness = 0.0f;       ///< perceptual
    int sheen_roughness_texture = -1;   ///< A scales sheen_roughness

    bool any() const {
        return clearcoat > 0.0f || sheen_color.x > 0.0f || sheen_color.y > 0.0f || sheen_color.z > 0.0f;
    }
};

/// pbr only: KHR_materials_iridescence, a thin dielectric film over the
/// material (render/thin_film.h) whose Fresnel replaces the specular lobe's in
/// proportion `factor`. A zero factor or thickness leaves the material as it
/// is, and costs nothing at render time.
struct IridescenceDesc {
    float factor = 0.0f;        ///< in [0, 1]
    int texture = -1;           ///< R scales factor
    float ior = 1.3f;           ///< the film's
    float thickness_min = 100;  ///< nm, at thickness texture G = 0
    float thickness_max = 400;  ///< nm, at G = 1, and the thickness without a texture
    int thickness_texture = -1;

    bool any() const { return factor > 0.0f && (thickness_max > 0.0f || thickness_texture >= 0); }
};

struct MaterialDesc {
    std::string name;
    MaterialType type = MaterialType::lambertian;
    ColorSource albedo;      ///< lambertian and metal; pbr: base colour (factor x texture); unlit: the colour
    float roughness = 0.0f;  ///< metal; pbr: perceptual roughness (alpha = roughness^2)
    float ior = 1.5f;        ///< dielectric; pbr: ior of the dielectric layer (F0 0.04 at 1.5)
    /// emissive: radiance of the front side; pbr: emission (factor x texture x
    /// strength) added to what the surface reflects.
    ColorSource radiance{ColorSource::Kind::constant, Rgb(0.0f)};
    /// Lambertian only: radiance it also emits, from both sides. Not light-sampled
    /// (found by BSDF sampling only); meant for analytic scenes such as the closed
    /// glowing sphere whose radiance is emission / (1 - albedo).
    Rgb emission{0.0f, 0.0f, 0.0f};
    /// Cut-outs: alpha in [0,1] (times the texture's alpha when alpha_texture >= 0).
    float alpha = 1.0f;
    int alpha_texture = -1;
    std::optional<float> alpha_cutoff;  ///< set: MASK; unset with alpha < 1 or texture: stochastic
    bool vertex_alpha = false;          ///< alpha also times the mesh's COLOR_0 alpha (glTF MASK/BLEND)

    // --- pbr only: glTF 2.0 metallic-roughness (see docs/scene-format.md) ---
    float metallic = 1.0f;
    int metallic_roughness_texture = -1;  ///< G scales roughness, B scales metallic
    int normal_texture = -1;              ///< tangent-space normal map
    float normal_scale = 1.0f;
    bool vertex_colors = false;     ///< used by a mesh with vertex colours (any type: they tint the albedo)
    float transmission = 0.0f;      ///< KHR_materials_transmission
    int transmission_texture = -1;  ///< R scales transmission
    /// KHR_materials_volume: light inside decays to attenuation_color after this distance.
    float attenuation_distance = kInfinity;
    Rgb attenuation_color{1.0f, 1.0f, 1.0f};
    /// KHR_materials_specular: the dielectric layer reflects
    /// min(F0(ior) x specular_color, 1) x specular at normal incidence, and
    /// specular at grazing angles; the base gets what that layer leaves.
    float specular = 1.0f;
    int specular_texture = -1;  ///< A scales specular
    Rgb specular_color{1.0f, 1.0f, 1.0f};
    int specular_color_texture = -1;  ///< RGB (sRGB-decoded) scales specular_color
    bool double_sided = true;         ///< false: back faces are invisible
    bool thin_walled = false;         ///< transmission without refraction (no volume behind the surface)
    PbrLayersDesc layers;             ///< clearcoat and sheen
    /// KHR_materials_anisotropy: GGX roughness stretched along a direction in
    /// the tangent plane (render/bsdf_pbr.cpp); strength in [0, 1], 0 leaves
    /// the material isotropic. The rotation (radians) turns the direction
    /// counter-clockwise from the tangent; the texture's RG is a direction in
    /// tangent space ([0, 1] -> [-1, 1]) and its B scales the strength.
    float anisotropy = 0.0f;
    float anisotropy_rotation = 0.0f;
    int anisotropy_texture = -1;
    IridescenceDesc iridescence;
    /// KHR_materials_dispersion: 20 / the Abbe number of a volume's ior
    /// (render/dispersion.h); 0 (none) or more. Thin walls do not disperse.
    float dispersion = 0.0f;
    /// KHR_materials_diffuse_transmission: the share of the diffuse base that
    /// is a Lambertian transmission instead (factor x texture A), tinted by its
    /// colour (factor x texture RGB, sRGB).
    float diffuse_transmission = 0.0f;
    int diffuse_transmission_texture = -1;
    Rgb diffuse_transmission_color{1.0f, 1.0f, 1.0f};
    int diffuse_transmission_color_texture = -1;
    /// Inputs the source file gives that the renderer does not use (e.g. "occlusion map"),
    /// filled by the loaders so that `sahara info` can name them.
    std::vector<std::string> ignored;
    /// The file-format extensions the loader applied to this material (glTF
    /// KHR_materials_*, EXT_texture_webp), for `sahara info`.
    std::vector<std::string> extensions;
};

/// Calls f(role, index) with every texture index a material holds (-1 where a
/// slot is empty), by reference: one list for every pass that must see them all,
/// renumbering textures when a model joins a scene and `sahara info` alike, so a
/// new slot cannot be missed by one of them.
template <class Material, class F>
void for_each_texture_slot(Material& m, F&& f) {
    f("base colour", m.albedo.texture);
    f("metallic-roughness", m.metallic_roughness_texture);
    f("normal map", m.normal_texture);
    f("emission", m.radiance.texture);
    f("transmission", m.transmission_texture);
    f("specular", m.specular_texture);
    f("specular colour", m.specular_color_texture);
    f("clearcoat", m.layers.clearcoat_texture);
    f("clearcoat roughness", m.layers.clearcoat_roughness_texture);
    f("clearcoat normal map", m.layers.clearcoat_normal_texture);
    f("sheen colour", m.layers.sheen_color_texture);
    f("sheen roughness", m.layers.sheen_roughness_texture);
    f("anisotropy", m.anisotropy_texture);
    f("iridescence", m.iridescence.texture);
    f("iridescence thickness", m.iridescence.thickness_texture);
    f("diffuse transmission", m.diffuse_transmission_texture);
    f("diffuse transmission colour", m.diffuse_transmission_color_texture);
    f("alpha", m.alpha_texture);
}

/// Either form of the scene-format camera; the renderer turns both into one basis.
struct CameraDesc {
    Vec3 position{0, 0, 0};
    // look-at form
    Vec3 look_at{0, 1, 0};
    Vec3 up{0, 0, 1};
    float vfov = 40.0f;  ///< degrees
    // "20 minutes" form: rotations about X, Y, Z (degrees) of right=+X, up=+Y, front=+Z
    bool euler_form = false;
    Vec3 euler{0, 0, 0};
    float focal_length = 1.0f;  ///< view plane 1 unit wide at this distance
    // glTF-sourced cameras give an explicit basis instead (see SceneDesc loaders)
    bool has_basis = false;
    Vec3 basis_right, basis_up, basis_forward;
    bool orthographic = false;
    float ortho_height = 2.0f;  ///< full height of the orthographic view
    // lens and shutter
    float aperture = 0.0f;                ///< lens diameter; 0 = pinhole
    std::optional<float> focus_distance;  ///< default: distance to look_at
    float shutter_open = 0.0f, shutter_close = 1.0f;
};

struct BackgroundDesc {
    enum class Type : uint8_t { constant, gradient, envmap } type = Type::gradient;
    Rgb color{1, 1, 1};
    Rgb bottom{1, 1, 1}, top{0.5f, 0.7f, 1.0f};
    Vec3 up{0, 0, 1};
    std::string file;
    float strength = 1.0f;
    std::shared_ptr<const Image> image;  ///< envmap, linear RGB
};

struct SphereDesc {
    Vec3 center;
    float radius = 1;
    uint32_t material = 0;
    Vec3 velocity{0, 0, 0};  ///< centre(t) = center + velocity * t
};

struct PlaneDesc {
    Vec3 point, normal{0, 0, 1};
    uint32_t material = 0;
};

struct BoxDesc {
    Vec3 lo, hi;
    uint32_t material = 0;
};

/// Indexed triangles with optional per-vertex normals and UVs, already in
/// world space (transforms are applied at load).
struct TriangleMesh {
    std::string name;  ///< source file and element, for messages and stats
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;        ///< empty, or one per position
    std::vector<Vec2> uvs;            ///< empty, or one per position (texCoord set 0)
    std::vector<Vec2> uvs1;           ///< empty, or one per position (texCoord set 1)
    std::vector<Rgb> colors;          ///< empty, or one per position (glTF COLOR_0, linear)
    std::vector<float> color_alphas;  ///< empty, or one per position (COLOR_0's alpha)
    /// empty, or one per position: xyz the tangent, w (+1/-1) the sign of the
    /// bitangent (mirrored UVs), as glTF's TANGENT attribute.
    std::vector<std::array<float, 4>> tangents;
    std::vector<uint32_t> indices;       ///< 3 per triangle, counter-clockwise = front
    std::vector<uint32_t> material_ids;  ///< empty (all use `material`) or one per triangle
    uint32_t material = 0;

    size_t triangle_count() const { return indices.size() / 3; }
};

/// A bounded quadric surface: the format's ellipsoid, cylinder, cone, paraboloid,
/// hyperboloid and general `quadric` objects. Every type is reduced to one
/// canonical form for the renderer: the implicit surface
///   A x² + B y² + C z² + D xy + E xz + F yz + G x + H y + I z + J = 0
/// in a local frame, clipped to the axis-aligned box `local_bounds` of that frame,
/// placed by `world_from_local`. The named forms put their symmetry axis on local
/// +z with the named point (centre, base, apex, vertex) at the local origin.
/// The parameters as written in the scene are kept for messages and `sahara info`.
struct QuadricDesc {
    enum class Type : uint8_t { ellipsoid, cylinder, cone, paraboloid, hyperboloid, general };
    Type type = Type::general;
    // --- parameters as written (before the object's transform) ---
    Vec3 origin{0, 0,
                0};  ///< centre (ellipsoid, hyperboloid), base (cylinder), apex (cone), vertex (paraboloid)
    Vec3 axis{0, 0, 1};   ///< unit symmetry axis (not used by ellipsoid and general)
    Vec3 radii{1, 1, 1};  ///< ellipsoid semi-axes along the scene's x, y, z
    float radius = 1;     ///< cylinder; paraboloid at `height`; hyperboloid at both ends
    float height = 1;     ///< cylinder, cone, paraboloid: from origin along axis; hyperboloid: total, centred
    float angle = 45;     ///< cone: half-angle between axis and side, degrees, in (0, 90)
    float waist = 0.5f;   ///< hyperboloid: radius at the centre, 0 < waist < radius
    bool capped = false;  ///< cylinder: discs at both ends; cone: disc at the open end
    // --- canonical form ---
    std::array<double, 10> coefficients{};  ///< A..J above, in the local frame
    Bounds3 local_bounds;                   ///< clip box in the local frame
    Mat4 world_from_local, local_from_world;
    Bounds3 world_bounds;  ///< bounds of the transformed clip box (conservative)
    uint32_t material = 0;
};

struct LightDesc {
    enum class Type : uint8_t { point, directional } type = Type::point;
    Vec3 position{0, 0, 0};
    Vec3 direction{0, 0, -1};  ///< direction the light travels
    Rgb intensity{0, 0, 0};    ///< point: W/sr
    Rgb irradiance{0, 0, 0};   ///< directional: on a surface facing it
};

enum class IntegratorType : uint8_t { path, whitted, albedo, normals, depth, bvh_cost };
enum class Tonemap : uint8_t { clamp, reinhard, aces, filmic };
/// Where the per-sample random numbers come from: Owen-scrambled Sobol
/// (low discrepancy, the default) or independent uniform random numbers.
enum class SamplerType : uint8_t { sobol, independent };

struct RenderSettings {
    int width = 640, height = 480;
    int spp = 64;
    int max_depth = 8;  ///< rays per path, camera ray included
    uint64_t seed = 0;
    IntegratorType integrator = IntegratorType::path;
    std::optional<double> time_limit_s;
    std::optional<double> target_error;
    float exposure = 0.0f;  ///< stops
    Tonemap tonemap = Tonemap::clamp;
    SamplerType sampler = SamplerType::sobol;     ///< command line only (--sampler)
    BvhBuilder bvh_builder = kDefaultBvhBuilder;  ///< "bvh_builder" / --builder
    BvhLayout bvh_layout = kDefaultBvhLayout;     ///< command line only (--layout)
    /// Camera rays as 4x4 packets where the renderer finds them faster (the
    /// image is the same either way); command line only (--no-packets).
    bool packets = true;
};

/// Meshes drawn only through instances, in the prototype's own space: an instance
/// places all of them with its transform. Every instance of a prototype shares one
/// bottom-level tree (scene/instances.h).
struct PrototypeDesc {
    std::string name;              ///< for messages and `sahara info`
    std::vector<uint32_t> meshes;  ///< indices into SceneDesc::meshes (each in one prototype at most)
};

/// One placement of a prototype. Nested instances are resolved while parsing: every
/// instance here places a prototype directly, with the composed transform.
struct InstanceDesc {
    uint32_t prototype = 0;
    Mat4 world_from_object;  ///< invertible (the parser checks)
    /// Motion blur: at time t the instance sits at translate(velocity * t) * world_from_object.
    Vec3 velocity{0, 0, 0};
};

struct SceneDesc {
    std::string source;  ///< scene file path, or "<default>" for the built-in scene
    /// World position of the point every position in this description is
    /// relative to (the local origin, docs/scene-format.md "Coordinates far from
    /// the origin"): the parser subtracts it in double before rounding to float,
    /// so geometry far from the world origin keeps its precision. Zero unless
    /// the camera is far from the world origin.
    Vec3d origin{0, 0, 0};
    RenderSettings render;
    CameraDesc camera;
    BackgroundDesc background;
    std::vector<MaterialDesc> materials;  ///< index 0 is the default material
    std::vector<TextureDesc> textures;
    std::vector<SphereDesc> spheres;
    std::vector<PlaneDesc> planes;
    std::vector<BoxDesc> boxes;
    std::vector<TriangleMesh> meshes;
    std::vector<QuadricDesc> quadrics;  ///< bounded quadrics (ellipsoid, cylinder, cone, ...)
    std::vector<LightDesc> lights;
    std::vector<PrototypeDesc> prototypes;  ///< empty unless something is instanced
    std::vector<InstanceDesc> instances;
};

/// The default material of the scene format: lambertian [0.5, 0.5, 0.5].
inline MaterialDesc default_material() {
    MaterialDesc m;
    m.name = "default";
    return m;
}

}  // namespace sahara
