#include "app/ray_batch.h"

#include <omp.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "accel/packet.h"

namespace sahara {

size_t RayAnswers::hits() const {
    size_t n = 0;
    for (uint32_t p : prim) n += p != kNoPrim;
    return n;
}

namespace {

/// CPU time of the calling thread.
double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Clears `out` to `count` misses and runs `loop()`, an orphaned `omp for` that fills
/// it, on `threads` threads with flush-to-zero as `ftz` asks; the pass's wall-clock
/// time and the threads' summed CPU time.
template <class Loop>
PassTime timed_parallel(size_t count, int threads, bool ftz, RayAnswers& out, Loop&& loop) {
    out.t.assign(count, kInfinity);
    out.prim.assign(count, kNoPrim);
    double cpu = 0;
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel num_threads(threads) reduction(+ : cpu)
    {
        const double cpu_start = thread_cpu_seconds();
        set_flush_denormals(ftz);
        loop();
        set_flush_denormals(false);
        cpu += thread_cpu_seconds() - cpu_start;
    }
    return {std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), cpu};
}

/// Runs `trace_one(i, t, prim)` for every ray index on `threads` threads and times the whole pass,
/// in chunks of 1024 rays: coherent primary rays stay together, dynamic balances the rest.
template <class TraceOne>
PassTime timed_pass(size_t count, int threads, bool ftz, RayAnswers& out, TraceOne&& trace_one) {
    return timed_parallel(count, threads, ftz, out, [&] {
#pragma omp for schedule(dynamic, 1024) nowait
        for (size_t i = 0; i < count; ++i) trace_one(i, out.t[i], out.prim[i]);
    });
}

/// Runs `trace_tile(packet, lane_to_ray)` for every 4x4 tile of the image on
/// `threads` threads and times the pass; the functor stores per-ray answers. Chunks of
/// 64 tiles = 1024 rays, as the single-ray passes.
template <class TraceTile>
PassTime timed_tile_pass(const std::vector<Ray>& rays, int width, int height, int threads, bool ftz,
                         RayAnswers& out, TraceTile&& trace_tile) {
    const int tiles_x = (width + 3) / 4, tiles_y = (height + 3) / 4;
    const int tiles = tiles_x * tiles_y;
    return timed_parallel(rays.size(), threads, ftz, out, [&] {
#pragma omp for schedule(dynamic, 64) nowait
        for (int tile = 0; tile < tiles; ++tile) {
            const int x0 = 4 * (tile % tiles_x), y0 = 4 * (tile / tiles_x);
            RayPacket p;
            size_t index[kPacketSize] = {};
            for (int i = 0; i < kPacketSize; ++i) {
                const int x = x0 + i % 4, y = y0 + i / 4;
                if (x >= width || y >= height) continue;
                index[i] = size_t(y) * size_t(width) + size_t(x);
                p.set(i, rays[index[i]]);
            }
            float t[kPacketSize];
            uint32_t prim[kPacketSize];
            trace_tile(p, t, prim);
            for (int i = 0; i < kPacketSize; ++i)
                if (p.active >> i & 1) out.t[index[i]] = t[i], out.prim[index[i]] = prim[i];
        }
    });
}

}  // namespace

PassTime trace_sahara_packets(const Accelerator& accel, const std::vector<Ray>& rays, int width, int height,
                              int threads, bool ftz, RayAnswers& out) {
    return timed_tile_pass(
        rays, width, height, threads, ftz, out, [&](RayPacket& p, float* t, uint32_t* prim) {
            HitPacket h;
            accel.intersect_packet(p, h);
            for (int i = 0; i < kPacketSize; ++i)
                t[i] = h.t[i], prim[i] = h.prim[i] == kNoPrim ? kNoPrim : prim_index(h.prim[i]);
        });
}

PassTime trace_embree_packets(const EmbreeReference& embree, const std::vector<Ray>& rays, int width,
                              int height, int threads, bool ftz, RayAnswers& out) {
    return timed_tile_pass(rays, width, height, threads, ftz, out,
                           [&](RayPacket& p, float* t, uint32_t* prim) { embree.intersect16(p, t, prim); });
}

PassTime trace_sahara(const Accelerator& accel, const std::vector<Ray>& rays, bool occlusion, int threads,
                      bool ftz, RayAnswers& out) {
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

PassTime trace_sahara_cached(const Accelerator& accel, const std::vector<Ray>& rays, int threads, bool ftz,
                             RayAnswers& out) {
    // One cache line per thread: the caches are written on most rays.
    struct alignas(64) ThreadCache {
        OcclusionCache cache;
    };
    std::vector<ThreadCache> caches(size_t(std::max(threads, 1)));
    return timed_pass(rays.size(), threads, ftz, out, [&](size_t i, float& t, uint32_t& prim) {
        if (accel.occluded(rays[i], caches[size_t(omp_get_thread_num())].cache)) t = 0.0f, prim = 0;
    });
}

PassTime trace_embree(const EmbreeReference& embree, const std::vector<Ray>& rays, bool occlusion,
                      int threads, bool ftz, RayAnswers& out) {
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

double nearest_hit_double(const Ray& ray, const TriangleMesh& mesh) {
    const Vec3d o(ray.origin), d(ray.dir);
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < mesh.triangle_count(); ++i) {
        Vec3d p[3];
        for (size_t k = 0; k < 3; ++k) p[k] = Vec3d(mesh.positions[mesh.indices[3 * i + k]]);
        const Vec3d e1 = p[1] - p[0], e2 = p[2] - p[0], pv = cross(d, e2);
        const double det = dot(e1, pv);
        if (det == 0.0) continue;
        const Vec3d tv = o - p[0], q = cross(tv, e1);
        const double u = dot(tv, pv) / det, v = dot(d, q) / det, t = dot(e2, q) / det;
        if (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > double(ray.tmin) && t < double(ray.tmax) && t < best)
            best = t;
    }
    return best;
}

namespace {

/// Whether answer (t, prim) of a pass agrees with the double-precision nearest hit `td`.
bool agrees_with_double(float t, uint32_t prim, double td, float tol) {
    if (prim == kNoPrim) return std::isinf(td);
    if (t == 0.0f) return !std::isinf(td);  // occlusion answer
    return std::fabs(td - double(t)) <= double(tol);
}

}  // namespace

Disagreements compare_answers(const RayAnswers& a, const RayAnswers& b, const std::vector<Ray>& rays,
                              const TriangleMesh& mesh) {
    // Arbitration is a brute-force loop per ray; beyond this many it is skipped.
    constexpr size_t kMaxArbitrations = 1000;
    Disagreements d;
    size_t arbitrations = 0;
    for (size_t i = 0; i < a.t.size(); ++i) {
        const bool ha = a.prim[i] != kNoPrim, hb = b.prim[i] != kNoPrim;
        if (!ha && !hb) continue;
        const float diff = std::fabs(a.t[i] - b.t[i]), scale = std::max(std::fabs(a.t[i]), std::fabs(b.t[i]));
        const Ray& r = rays[i];
        const float tol =
            1e-4f * (std::isinf(scale) ? 0.0f : scale) + 1e-6f * max_component(abs(r.origin)) / length(r.dir);
        if (ha == hb && a.prim[i] == b.prim[i] && diff <= tol) continue;
        if (ha == hb && a.prim[i] != b.prim[i] && diff <= 1e-6f * scale) {
            ++d.ties;
            continue;
        }
        if (arbitrations++ < kMaxArbitrations &&
            agrees_with_double(a.t[i], a.prim[i], nearest_hit_double(r, mesh),
                               tol + 1e-4f * std::fabs(a.t[i])))
            ++d.confirmed_for_a;
        else
            ++d.total;
    }
    return d;
}

}  // namespace sahara
