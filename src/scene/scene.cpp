#include "scene/scene.h"

#include "accel/accelerator.h"

namespace sahara {

Scene::Scene() = default;
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

size_t Scene::primitive_count() const { return spheres.size() + triangles.size() + boxes.size() + planes.size(); }

void Scene::build_accelerator() {
    accel_ = std::make_unique<Accelerator>(*this);
    bounds_ = accel_->bounds();
}

namespace {

/// Unbounded planes live outside the tree and are tested linearly.
bool intersect_planes(const std::vector<Plane>& planes, Ray& ray, Hit& hit) {
    bool found = false;
    for (uint32_t i = 0; i < planes.size(); ++i) {
        const Plane& pl = planes[i];
        float denom = dot(pl.normal, ray.dir);
        if (denom == 0.0f) continue;
        float t = dot(pl.point - ray.origin, pl.normal) / denom;
        if (t > ray.tmin && t < ray.tmax) {
            ray.tmax = t;
            hit = Hit{t, make_prim_id(PrimKind::plane, i), 0, 0};
            found = true;
        }
    }
    return found;
}

}  // namespace

bool Scene::intersect(Ray& ray, Hit& hit) const {
    bool found = accel_ ? accel_->intersect(ray, hit) : false;
    found |= intersect_planes(planes, ray, hit);
    return found;
}

bool Scene::occluded(const Ray& ray) const {
    if (accel_ && accel_->occluded(ray)) return true;
    Ray r = ray;
    Hit h;
    return intersect_planes(planes, r, h);
}

}  // namespace sahara
