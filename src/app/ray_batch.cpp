#include "app/ray_batch.h"

#include <omp.h>

#include <chrono>
#include <cmath>

namespace sahara {

size_t RayAnswers::hits() const {
    size_t n = 0;
    for (uint32_t p : prim) n += p != kNoPrim;
    return n;
}

namespace {

/// Runs `trace_one(i, t, prim)` for every ray index on `threads` threads and times the whole pass.
template <class TraceOne>
double timed_pass(size_t count, int threads, bool ftz, RayAnswers& out, TraceOne&& trace_one) {
    out.t.assign(count, kInfinity);
    out.prim.assign(count, kNoPrim);
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel num_threads(threads)
    {
        set_flush_denormals(ftz);
        // Chunks of 1024 rays: coherent primary rays stay together, dynamic balances the rest.
#pragma omp for schedule(dynamic, 1024)
        for (size_t i = 0; i < count; ++i) trace_one(i, out.t[i], out.prim[i]);
        set_flush_denormals(false);
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

double trace_sahara(const Accelerator& accel, const std::vector<Ray>& rays, bool occlusion, int threads, bool ftz,
                    RayAnswers& out) {
    return timed_pass(rays.size(), threads, ftz, out, [&](size_t i, float& t, uint32_t& prim) {
        if (occlusion) {
            if (accel.occluded(rays[i])) t = 0.0f, prim = 0;
            return;
        }
        Ray r = rays[i];
        Hit h;
        if (accel.intersect(r, h)) t = h.t, prim = prim_index(h.prim);
    });
}

double trace_embree(const EmbreeReference& embree, const std::vector<Ray>& rays, bool occlusion, int threads,
                    bool ftz, RayAnswers& out) {
    return timed_pass(rays.size(), threads, ftz, out, [&](size_t i, float& t, uint32_t& prim) {
        if (occlusion) {
            if (embree.occluded(rays[i])) t = 0.0f, prim = 0;
            return;
        }
        float th;
        uint32_t p;
        if (embree.intersect(rays[i], th, p)) t = th, prim = p;
    });
}

Disagreements compare_answers(const RayAnswers& a, const RayAnswers& b) {
    Disagreements d;
    for (size_t i = 0; i < a.t.size(); ++i) {
        const bool ha = a.prim[i] != kNoPrim, hb = b.prim[i] != kNoPrim;
        if (ha != hb) { ++d.total; continue; }
        if (!ha) continue;
        const float diff = std::fabs(a.t[i] - b.t[i]), scale = std::max(std::fabs(a.t[i]), std::fabs(b.t[i]));
        if (diff > 1e-4f * scale) { ++d.total; continue; }
        if (a.prim[i] == b.prim[i]) continue;
        if (diff <= 1e-6f * scale) ++d.ties;
        else ++d.total;
    }
    return d;
}

}  // namespace sahara
