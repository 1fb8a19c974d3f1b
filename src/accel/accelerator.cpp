#include "accel/accelerator.h"

#include "scene/scene.h"

namespace sahara {

// Placeholder: a flat loop over spheres until the BVH lands.
Accelerator::Accelerator(const Scene& scene) : scene_(&scene) {
    for (const Sphere& s : scene.spheres) bounds_.extend(s.bounds(scene.camera.shutter_open, scene.camera.shutter_close));
}

bool Accelerator::intersect(Ray& ray, Hit& hit) const {
    bool found = false;
    for (uint32_t i = 0; i < scene_->spheres.size(); ++i) {
        const Sphere& s = scene_->spheres[i];
        double t = intersect_sphere(ray, s.center_at(ray.time), s.radius);
        if (t > 0) {
            ray.tmax = float(t);
            hit = Hit{float(t), make_prim_id(PrimKind::sphere, i), 0, 0};
            found = true;
        }
    }
    return found;
}

bool Accelerator::occluded(const Ray& ray) const {
    Ray r = ray;
    Hit h;
    return intersect(r, h);
}

}  // namespace sahara
