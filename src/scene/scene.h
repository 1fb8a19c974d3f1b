#pragma once
/// The runtime scene: primitives in flat arrays, one acceleration structure
/// over all bounded primitives, unbounded planes tested beside it, plus the
/// camera, materials, lights and background the integrators need.
#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/hit.h"
#include "geometry/quadric.h"
#include "geometry/sphere.h"
#include "scene/scene_desc.h"

namespace sahara {

/// Everything shading needs about the accepted hit.
struct SurfaceInteraction {
    Vec3 p;            ///< hit point
    Vec3 ng;           ///< geometric normal, unit, facing against the incoming ray
    Vec3 ns;           ///< shading normal, unit, same hemisphere as ng
    Vec2 uv;
    uint32_t material = 0;
    bool front_face = true;  ///< the ray hit the outward (front) side
};

/// All triangles of all meshes, merged; triangle i uses indices[3i..3i+2].
struct TriangleSoup {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;  ///< empty or per position
    std::vector<Vec2> uvs;      ///< empty or per position
    std::vector<uint32_t> indices;
    std::vector<uint32_t> material;  ///< per triangle
    size_t size() const { return indices.size() / 3; }
};

struct Plane {
    Vec3 point, normal;
    uint32_t material = 0;
};

struct Box {
    Bounds3 box;
    uint32_t material = 0;
};

class Accelerator;  // accel/: the BVH over bounded primitives

class Scene {
public:
    Scene();
    ~Scene();
    Scene(Scene&&) noexcept;
    Scene& operator=(Scene&&) noexcept;

    /// Nearest hit with t in (ray.tmin, ray.tmax); on a hit, ray.tmax becomes hit.t.
    bool intersect(Ray& ray, Hit& hit) const;
    /// Whether anything blocks the ray in (ray.tmin, ray.tmax).
    bool occluded(const Ray& ray) const;
    /// Shading data for an accepted hit.
    SurfaceInteraction interact(const Ray& ray, const Hit& hit) const;

    /// Bounds of all bounded primitives (planes excluded).
    Bounds3 bounds() const { return bounds_; }
    size_t primitive_count() const;

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

    /// Builds the acceleration structure over the current geometry.
    void build_accelerator();
    const Accelerator* accelerator() const { return accel_.get(); }

private:
    std::unique_ptr<Accelerator> accel_;
    Bounds3 bounds_;
};

/// The runtime quadric for a parsed quadric object.
Quadric make_quadric(const QuadricDesc& desc);

/// Builds the runtime scene from plain data (merges meshes, builds the BVH).
Scene build_scene(const SceneDesc& desc);

}  // namespace sahara
