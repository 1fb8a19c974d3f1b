#pragma once
/// Helpers for the statistical rendering tests: scene building blocks and
/// mean / standard error of many radiance samples.
#include <cmath>
#include <functional>

#include "render/film.h"
#include "render/integrator.h"
#include "render/renderer.h"
#include "render/sampler.h"
#include "scene/scene.h"

namespace sahara::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr int kSampleScale = 4;  // sanitizers run ~5-10x slower: fewer samples, wider error bars
#else
inline constexpr int kSampleScale = 1;
#endif

/// n divided by the sanitizer slow-down factor.
inline int scaled(int n) { return n / kSampleScale; }

inline MaterialDesc lambertian(Rgb albedo, Rgb emission = Rgb(0.0f)) {
    MaterialDesc m;
    m.type = MaterialType::lambertian;
    m.albedo.color = albedo;
    m.emission = emission;
    return m;
}
inline MaterialDesc emissive(Rgb radiance) {
    MaterialDesc m;
    m.type = MaterialType::emissive;
    m.radiance.color = radiance;
    return m;
}
inline MaterialDesc metal(Rgb albedo, float roughness) {
    MaterialDesc m;
    m.type = MaterialType::metal;
    m.albedo.color = albedo;
    m.roughness = roughness;
    return m;
}
inline MaterialDesc dielectric(float ior) {
    MaterialDesc m;
    m.type = MaterialType::dielectric;
    m.ior = ior;
    return m;
}

/// A scene description with a constant background and the default material at index 0.
inline SceneDesc empty_scene(Rgb background) {
    SceneDesc d;
    d.materials.push_back(default_material());
    d.background.type = BackgroundDesc::Type::constant;
    d.background.color = background;
    return d;
}

/// Sample mean and its standard error, per channel.
struct Stat {
    Rgb mean{0.0f}, se{0.0f};
};

/// Statistics of n independent samples f(sampler) with streams from (seed, i).
inline Stat sample_stats(int n, uint64_t seed, const std::function<Rgb(Sampler&)>& f) {
    Vec3d sum(0.0), sum_sq(0.0);
    Sampler sampler(seed, SamplerType::independent);  // standard errors assume independent samples
    for (int i = 0; i < n; ++i) {
        sampler.start(uint32_t(i), 7, uint32_t(i));
        const Vec3d v(f(sampler));
        sum += v;
        sum_sq += v * v;
    }
    const Vec3d mean = sum / double(n);
    const Vec3d var = (sum_sq / double(n) - mean * mean) * (double(n) / double(n - 1));
    const Vec3d se(std::sqrt(std::max(0.0, var.x) / n), std::sqrt(std::max(0.0, var.y) / n),
                   std::sqrt(std::max(0.0, var.z) / n));
    return {Rgb(mean), Rgb(se)};
}

/// One estimate_radiance sample along `ray` in the scene built from `d` with
/// `integrator`: the exact value wherever the path is deterministic (emission
/// seen directly, mirrors, pass-through surfaces).
inline Rgb radiance_along(SceneDesc d, IntegratorType integrator, const Ray& ray, int max_depth) {
    d.render.integrator = integrator;
    const Scene scene = build_scene(d);
    Sampler sampler(3, SamplerType::independent);
    sampler.start(0, 0, 0);
    return estimate_radiance(scene, ray, sampler, max_depth);
}

/// Renders the scene built from `d` into `film` on two threads (what the
/// image-level tests compare: instanced against flat, frames against blur).
inline void render_into(const SceneDesc& d, Film& film) {
    const Scene scene = build_scene(d);
    RenderOptions o;
    o.threads = 2;
    render_image(scene, film, o);
}

/// Statistics of estimate_radiance along one ray.
inline Stat radiance_stats(const Scene& scene, const Ray& ray, int n, int max_depth, uint64_t seed = 1) {
    return sample_stats(n, seed, [&](Sampler& s) { return estimate_radiance(scene, ray, s, max_depth); });
}

/// |a - b| <= k standard errors (+ a relative slack for float rounding) in every channel.
inline bool within(const Stat& s, const Rgb& expected, float k, float rel = 1e-4f) {
    for (int c = 0; c < 3; ++c)
        if (std::abs(s.mean[c] - expected[c]) > k * s.se[c] + rel * std::abs(expected[c]) + 1e-7f)
            return false;
    return true;
}

/// Two independent estimates agree within k combined standard errors.
inline bool agree(const Stat& a, const Stat& b, float k) {
    for (int c = 0; c < 3; ++c) {
        const float se = std::sqrt(a.se[c] * a.se[c] + b.se[c] * b.se[c]);
        if (std::abs(a.mean[c] - b.mean[c]) > k * se + 1e-6f) return false;
    }
    return true;
}

}  // namespace sahara::test
