#pragma once
/// The acceleration structure over all bounded primitives of a Scene
/// (spheres, triangles, boxes). Planes are unbounded and handled by Scene.
#include "geometry/hit.h"
#include "math/bounds.h"

namespace sahara {

class Scene;

class Accelerator {
public:
    explicit Accelerator(const Scene& scene);
    bool intersect(Ray& ray, Hit& hit) const;
    bool occluded(const Ray& ray) const;
    Bounds3 bounds() const { return bounds_; }

private:
    const Scene* scene_;
    Bounds3 bounds_;
};

}  // namespace sahara
