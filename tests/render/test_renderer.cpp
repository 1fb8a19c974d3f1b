// The render loop: stopping, resuming, time limits, adaptive sampling, stats.
#include <doctest/doctest.h>

#include <atomic>

#include "base/counters.h"
#include "render/renderer.h"
#include "render/stats.h"
#include "io/scene_parser.h"

using namespace sahara;

namespace {

Scene small_scene(int spp, int w = 20, int h = 14) {
    SceneDesc d = default_scene();
    d.render.width = w;
    d.render.height = h;
    d.render.spp = spp;
    return build_scene(d);
}

bool same_state(const Film& a, const Film& b) {
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            if (a.count(x, y) != b.count(x, y) || !(a.sum(x, y) == b.sum(x, y)) ||
                a.sum_sq(x, y) != b.sum_sq(x, y))
                return false;
    return true;
}

}  // namespace

TEST_CASE("renderer: a stopped render continued later equals one uninterrupted render") {
    const Scene scene = small_scene(24);
    Film once(20, 14);
    render_image(scene, once, {});

    // Stop after the first tick, mid-pass: pixels hold different sample counts.
    Film parts(20, 14);
    RenderOptions stop_early;
    stop_early.tick_seconds = 0.0;
    stop_early.on_tick = [](RenderSession& s) { s.request_stop(); };
    const RenderResult first = render_image(scene, parts, stop_early);
    CHECK(first.stop == StopReason::interrupted);
    CHECK(first.spp_done < 24);
    const RenderResult rest = render_image(scene, parts, {});
    CHECK(rest.stop == StopReason::complete);
    CHECK(rest.spp_done == 24);
    CHECK(first.samples + rest.samples == 20u * 14u * 24u);  // no sample taken twice
    CHECK(same_state(once, parts));
}

TEST_CASE("renderer: the thread count does not change the film") {
    const Scene scene = small_scene(5);
    Film a(20, 14), b(20, 14);
    RenderOptions one, two;
    one.threads = 1;
    two.threads = 2;
    render_image(scene, a, one);
    render_image(scene, b, two);
    CHECK(same_state(a, b));
}

TEST_CASE("renderer: an external stop flag stops the render with a valid film") {
    const Scene scene = small_scene(1 << 20);
    Film film(20, 14);
    std::atomic<bool> stop{true};
    RenderOptions o;
    o.stop = &stop;
    const RenderResult r = render_image(scene, film, o);
    CHECK(r.stop == StopReason::interrupted);
    CHECK(r.spp_done < (1 << 20));
    CHECK(double(r.samples) == doctest::Approx(r.spp_mean * 20 * 14));
}

TEST_CASE("renderer: a zero time limit stops at once") {
    SceneDesc d = default_scene();
    d.render.width = 20;
    d.render.height = 14;
    d.render.spp = 1 << 20;
    d.render.time_limit_s = 0.0;
    const Scene scene = build_scene(d);
    Film film(20, 14);
    const RenderResult r = render_image(scene, film, {});
    CHECK(r.stop == StopReason::time_limit);
    CHECK(r.spp_max < (1 << 20));
}

TEST_CASE("renderer: adaptive sampling spends samples where the error is high and meets its target") {
    SceneDesc d = default_scene();
    d.render.width = 24;
    d.render.height = 16;
    d.render.spp = 512;
    d.render.target_error = 0.05;
    const Scene scene = build_scene(d);
    Film film(24, 16);
    const RenderResult r = render_image(scene, film, {});
    CHECK(r.stop == StopReason::converged);
    CHECK(r.spp_done >= kAdaptiveMinSpp);
    CHECK(r.spp_max > r.spp_done);  // not uniform
    CHECK(estimated_relative_error(film) <= 0.05);
    // Pixels left at the minimum count are the ones whose estimate says they are done.
    const std::vector<float> err = relative_error_map(film);
    double at_min_converged = 0, at_min = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 24; ++x) {
            const float e = err[size_t(y) * 24 + size_t(x)];
            if (film.count(x, y) > uint32_t(kAdaptiveMinSpp)) continue;
            // A pixel left at the minimum must itself look converged.
            at_min += 1;
            at_min_converged += e <= 0.05f * 3.0f;
        }
    CHECK(at_min_converged == at_min);
}

TEST_CASE("renderer: relative error to a reference is zero for the same image") {
    const Scene scene = small_scene(4);
    Film film(20, 14);
    render_image(scene, film, {});
    CHECK(relative_error_to(film, film.to_rgb()) == doctest::Approx(0.0).epsilon(1e-6));
    std::vector<float> black(20 * 14 * 3, 0.0f);
    CHECK(relative_error_to(film, black) > 0.1);
}

TEST_CASE("renderer: counters count one camera ray per sample") {
    const Scene scene = small_scene(3);
    Film film(20, 14);
    reset_counters();
    render_image(scene, film, {});
    const Counters c = counter_totals();
    CHECK(c.rays[int(RayKind::camera)] == 20u * 14u * 3u);
    CHECK(c.rays[int(RayKind::closest_hit)] >= c.rays[int(RayKind::camera)]);
}

TEST_CASE("stats: grouped report prints and converts to JSON") {
    StatsReport s;
    s.add_count("Render", "Camera rays", 42);
    s.add_bytes("Memory", "Film", 2048);
    const nlohmann::json j = s.to_json();
    CHECK(j["Render"]["Camera rays"] == 42);
    CHECK(j["Memory"]["Film"] == 2048);
    CHECK(format_bytes(2048) == "2.0 KiB");
    const Scene scene = small_scene(1);
    const SceneMemory m = estimate_scene_memory(scene);
    CHECK(m.spheres == 2 * sizeof(Sphere));
    CHECK(m.total() >= m.spheres);
}
