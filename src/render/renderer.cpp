#include "render/renderer.h"

#include <omp.h>

#include <algorithm>

#include "render/camera.h"
#include "render/integrator.h"
#include "render/progress.h"
#include "render/sampler.h"

namespace sahara {

void render_pass(const Scene& scene, Film& film, int sample_begin, int sample_end, int threads, Progress* progress) {
    const int w = film.width(), h = film.height();
    const Camera camera(scene.camera, w, h);
    const int tiles_x = (w + kTileSize - 1) / kTileSize, tiles_y = (h + kTileSize - 1) / kTileSize;
    const int tile_count = tiles_x * tiles_y;
    const int max_depth = scene.render.max_depth;

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int tile = 0; tile < tile_count; ++tile) {
        Sampler sampler(scene.render.seed, scene.render.sampler);
        const int x0 = (tile % tiles_x) * kTileSize, y0 = (tile / tiles_x) * kTileSize;
        const int x1 = std::min(x0 + kTileSize, w), y1 = std::min(y0 + kTileSize, h);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                for (int s = sample_begin; s < sample_end; ++s) {
                    sampler.start(uint32_t(x), uint32_t(y), uint32_t(s));
                    const Vec2 jitter = sampler.next_2d();
                    const Vec2 lens = sampler.next_2d();
                    const float time_u = sampler.next_1d();
                    const Ray ray = camera.generate_ray(float(x) + jitter.x, float(y) + jitter.y, lens, time_u);
                    film.add_sample(x, y, estimate_radiance(scene, ray, sampler, max_depth));
                }
                film.add_count(x, y, uint32_t(sample_end - sample_begin));
            }
        if (progress)
            progress->advance(uint64_t(x1 - x0) * uint64_t(y1 - y0) * uint64_t(sample_end - sample_begin),
                              uint64_t(x1 - x0) * uint64_t(y1 - y0) * uint64_t(sample_end - sample_begin));
    }
}

RenderResult render_image(const Scene& scene, Film& film, const RenderOptions& options) {
    const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
    const int spp = scene.render.spp;
    const uint64_t pixels = uint64_t(film.width()) * uint64_t(film.height());
    Progress progress(pixels * uint64_t(spp), "samples", options.progress);
    // Progressive passes of doubling size: an early pass gives a full preview,
    // and later passes amortise the per-pass overhead.
    int done = 0, pass = 1;
    while (done < spp) {
        const int end = std::min(spp, done + pass);
        render_pass(scene, film, done, end, threads, &progress);
        done = end;
        pass = std::min(pass * 2, 64);
    }
    progress.finish();
    RenderResult r;
    r.seconds = progress.elapsed_seconds();
    r.samples = pixels * uint64_t(spp);
    r.spp_done = spp;
    r.nonfinite = film.nonfinite_samples();
    return r;
}

}  // namespace sahara
