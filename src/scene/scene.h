#pragma once
/// The runtime scene: primitives in flat arrays, one acceleration structure
/// over all bounded primitives, unbounded planes tested beside it, plus the
/// camera, materials, lights and background the integrators need.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "accel/packet.h"  // RayPacket, HitPacket: the packet interface render uses
#include "geometry/box.h"
#include "geometry/hit.h"
#include "geometry/plane.h"
#include "geometry/quadric.h"
#include "geometry/sphere.h"
#include "math/distribution.h"
#include "desc/scene_desc.h"

namespace sahara {

/// Everything shading needs about the accepted hit.
struct SurfaceInteraction {
    Vec3 p;   ///< hit point
    Vec3 ng;  ///< geometric normal, unit, facing against the incoming ray
    Vec3 ns;  ///< shading normal, unit, same hemisphere as ng
    Vec2 uv;
    Vec2 uv1;                        ///< the second UV set (glTF TEXCOORD_1), or zero
    Rgb color{1.0f, 1.0f, 1.0f};     ///< interpolated vertex colour (glTF COLOR_0), white without
    Vec3 tangent{0.0f, 0.0f, 0.0f};  ///< interpolated tangent for normal maps; zero: none
    float tangent_sign = 1;          ///< cross(normal, tangent) * sign points along increasing v
    uint32_t material = 0;
    bool front_face = true;  ///< the ray hit the outward (front) side
};

/// All triangles of all meshes, merged; triangle i uses indices[3i..3i+2].
struct TriangleSoup {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;                   ///< empty or per position
    std::vector<Vec2> uvs;                       ///< empty or per position
    std::vector<Vec2> uvs1;                      ///< empty or per position (second UV set)
    std::vector<Rgb> colors;                     ///< empty or per position (vertex colours)
    std::vector<float> color_alphas;             ///< empty or per position (vertex colours' alpha)
    std::vector<std::array<float, 4>> tangents;  ///< empty or per position (xyz, bitangent sign)
    std::vector<uint32_t> indices;
    std::vector<uint32_t> material;  ///< per triangle
    size_t size() const { return indices.size() / 3; }
};

/// Which rendering machinery a scene needs, decided once at build time so that
/// the integrator runs a kernel specialised for it instead of testing flags
/// per ray (see render/integrator.cpp).
struct SceneFeatures {
    bool has_lights = false;             ///< point or directional lights
    bool has_emitters = false;           ///< any emissive surface (sampled or not)
    bool has_area_lights = false;        ///< emitters that are sampled directly (spheres, triangles, boxes)
    bool has_envmap = false;             ///< an image background, importance-sampled
    bool has_delta_lights_only = false;  ///< light sampling needed, but never MIS
    bool has_motion = false;             ///< something moves while the shutter is open
    bool has_lens = false;               ///< thin-lens depth of field
    bool has_textures = false;           ///< checker or image colour sources
    bool has_metal = false, has_rough_metal = false, has_dielectric = false;
    bool has_pbr = false;         ///< glTF metallic-roughness materials
    bool has_unlit = false;       ///< glTF unlit materials (seen by camera rays only)
    bool lambertian_only = true;  ///< no metal, no dielectric, no pbr, no unlit
    bool forced_all = false;      ///< everything on (prepare_lighting(true)), for measurements
};

/// Something that light sampling can pick: a light, an emissive primitive, or the envmap.
struct Emitter {
    enum class Kind : uint8_t {
        point,
        directional,
        sphere,
        triangle,
        box,
        envmap,
        instanced_triangle
    } kind = Kind::point;
    uint32_t index = 0;  ///< into lights, spheres, triangles, boxes or instanced_emitters
};

/// An emissive triangle of a prototype as one instance places it: light sampling
/// picks it like a triangle of the flat tree.
struct InstancedEmitter {
    Vec3 p0, p1, p2;  ///< world space at time 0
    Vec3 velocity;    ///< the instance's: the triangle at time t is moved by velocity * t
    uint32_t instance = 0, triangle = 0, material = 0;  ///< triangle: in the prototype
};
inline constexpr uint32_t kNoEmitter = 0xFFFFFFFFu;

class Accelerator;  // scene/accelerator.h: the BVH over bounded primitives
class InstanceSet;  // scene/instances.h: the instance level of a two-level BVH

class Scene {
   public:
    Scene();
    ~Scene();
    Scene(Scene&&) noexcept;
    Scene& operator=(Scene&&) noexcept;

    /// Nearest hit with t in (ray.tmin, ray.tmax); on a hit, ray.tmax becomes hit.t.
    bool intersect(Ray& ray, Hit& hit) const;
    /// intersect() for the active lanes of a 16-ray packet (accel/packet.h):
    /// the same hits, up to ties between primitives at exactly the same distance.
    /// Not for scenes with instances (a HitPacket has no instance id; packets_pay_off()
    /// is false there): throws std::logic_error.
    void intersect_packet(RayPacket& packet, HitPacket& hits) const;
    /// Whether anything blocks the ray in (ray.tmin, ray.tmax).
    bool occluded(const Ray& ray) const;
    /// occluded() that first tests the primitive that stopped the last ray of the same
    /// cache (one per light and thread, geometry/hit.h); the answers are the same.
    /// Instanced occluders are not remembered.
    bool occluded(const Ray& ray, OcclusionCache& cache) const;
    /// Shading data for an accepted hit.
    SurfaceInteraction interact(const Ray& ray, const Hit& hit) const;

    // What render asks about the acceleration structure, so that it never sees
    // the Accelerator itself (tests/test_layers.cpp keeps it that way).
    /// The work of intersect() on a copy of `ray`, as BVH nodes visited plus
    /// primitives tested (planes, tested beside the tree, do not count); 0
    /// before build_accelerator(). For the bvh-cost image.
    uint64_t traversal_steps(const Ray& ray) const;
    /// Whether intersect_packet() traces camera rays faster than single rays
    /// here: packets are enabled (accel/packet.h), the scene has no instances, the
    /// tree has the block layout (wide8) without cut-outs, and the instruction set is AVX2 or
    /// AVX-512 (the SSE2 packet kernel is slower than single rays).
    bool packets_pay_off() const;
    /// Triangles whose hits pass the alpha test (cut-outs); 0 when traversal
    /// runs without it.
    size_t cutout_triangle_count() const;

    /// Bounds of all bounded primitives (planes excluded), instances included.
    Bounds3 bounds() const { return bounds_; }
    size_t primitive_count() const;
    /// Rays a render with the scene's settings traces, roughly (the automatic BVH
    /// builder's workload): a path's camera ray, bounces and light samples, about four
    /// per sample.
    double expected_render_rays() const {
        return 4.0 * double(render.width) * double(render.height) * double(render.spp);
    }

    // geometry
    std::vector<Sphere> spheres;
    TriangleSoup triangles;
    std::vector<Plane> planes;
    std::vector<Box> boxes;
    std::vector<Quadric> quadrics;
    // appearance (kept as plain data for now)
    std::vector<MaterialDesc> materials;
    std::vector<TextureDesc> textures;
    BackgroundDesc background;
    std::vector<LightDesc> lights;
    CameraDesc camera;
    RenderSettings render;
    std::string source;

    // lighting, derived from the above by prepare_lighting()
    SceneFeatures features;
    std::vector<Emitter> emitters;           ///< what light sampling picks from
    Distribution1D emitter_distribution;     ///< over emitters, by estimated power
    std::vector<uint32_t> sphere_emitter;    ///< emitter id per sphere (kNoEmitter: none); empty if none emit
    std::vector<uint32_t> triangle_emitter;  ///< same per triangle
    std::vector<uint32_t> box_emitter;       ///< same per box
    std::vector<InstancedEmitter> instanced_emitters;  ///< Emitter::Kind::instanced_triangle's entries
    uint32_t envmap_emitter = kNoEmitter;
    Distribution2D envmap_distribution;  ///< over the envmap's (u, v), luminance * sin(theta)
    float scene_radius = 1;              ///< bounding-sphere radius of the bounded geometry

    /// Builds the acceleration structure over the current geometry.
    void build_accelerator();
    /// Collects emitters, builds the light and envmap distributions and the
    /// feature set; `force_all_features` turns every feature on.
    void prepare_lighting(bool force_all_features);
    const Accelerator* accelerator() const { return accel_.get(); }
    /// The instance level; null for scenes without instances (the flat tree alone).
    const InstanceSet* instances() const { return instances_.get(); }
    /// For memory reports: the bottom-level scenes the instances place (each once;
    /// none without instances) and the bytes of the instance level's trees and records.
    std::vector<const Scene*> prototypes() const;
    size_t instance_level_bytes() const;
    /// Adds the instance level; call before build_accelerator() (bounds include it).
    void set_instances(std::unique_ptr<InstanceSet> instances);
    /// Emitter id of triangle `triangle` of the prototype that `instance` places
    /// (kNoEmitter: it does not emit); set by prepare_lighting().
    uint32_t instanced_emitter(uint32_t instance, uint32_t triangle) const;

   private:
    void collect_instanced_emitters(std::vector<float>& power);
    /// occluded()'s part beyond the flat tree: instances and planes.
    bool occluded_outside_tree(const Ray& ray) const;
    std::vector<uint32_t> instance_emitter_base_;                ///< per instance; empty if none emits
    std::vector<std::vector<uint32_t>> prototype_emitter_slot_;  ///< per prototype, per triangle
    std::unique_ptr<Accelerator> accel_;
    std::unique_ptr<InstanceSet> instances_;
    Bounds3 bounds_;
};

/// The runtime quadric for a parsed quadric object.
Quadric make_quadric(const QuadricDesc& desc);

/// Builds the runtime scene from plain data (merges the meshes that are not in a
/// prototype, builds the BVH; with instances, also the instance level).
Scene build_scene(const SceneDesc& desc);

}  // namespace sahara
