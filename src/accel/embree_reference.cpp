#include "accel/embree_reference.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>

#include "base/process_usage.h"

#if SAHARA_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace sahara {

void set_flush_denormals(bool on) {
    _MM_SET_FLUSH_ZERO_MODE(on ? _MM_FLUSH_ZERO_ON : _MM_FLUSH_ZERO_OFF);
    _MM_SET_DENORMALS_ZERO_MODE(on ? _MM_DENORMALS_ZERO_ON : _MM_DENORMALS_ZERO_OFF);
}

#if SAHARA_HAVE_EMBREE

struct EmbreeReference::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::atomic<int64_t> allocated{0};  ///< Embree's net allocations (its memory monitor)
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

bool EmbreeReference::available() { return true; }

EmbreeReference::EmbreeReference(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                 bool robust, int build_threads, std::string_view max_isa,
                                 EmbreeQuality quality)
    : impl_(std::make_unique<Impl>()) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    std::string config = build_threads > 0 ? "threads=" + std::to_string(build_threads) : "";
    if (!max_isa.empty() && max_isa != "best") {
        if (!config.empty()) config += ",";
        config += "max_isa=" + std::string(max_isa);
    }
    impl_->device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (!impl_->device) throw std::runtime_error("embree: rtcNewDevice failed");
    rtcSetDeviceMemoryMonitorFunction(
        impl_->device,
        [](void* user, ssize_t bytes, bool) {
            static_cast<Impl*>(user)->allocated.fetch_add(int64_t(bytes), std::memory_order_relaxed);
            return true;
        },
        impl_.get());
    impl_->scene = rtcNewScene(impl_->device);
    if (robust) rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
    const RTCBuildQuality build_quality = quality == EmbreeQuality::low    ? RTC_BUILD_QUALITY_LOW
                                          : quality == EmbreeQuality::high ? RTC_BUILD_QUALITY_HIGH
                                                                           : RTC_BUILD_QUALITY_MEDIUM;
    rtcSetSceneBuildQuality(impl_->scene, build_quality);
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // The geometry's quality too: Embree picks its builder from both.
    rtcSetGeometryBuildQuality(geom, build_quality);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), positions.size()));
    for (size_t i = 0; i < positions.size(); ++i) {
        v[3 * i] = positions[i].x;
        v[3 * i + 1] = positions[i].y;
        v[3 * i + 2] = positions[i].z;
    }
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), indices.size() / 3));
    if (!indices.empty()) std::memcpy(idx, indices.data(), indices.size() * sizeof(uint32_t));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
    const int64_t before_commit = impl_->allocated.load();
    const auto commit = Clock::now();
    const double cpu_before_commit = process_cpu_ms();
    rtcCommitScene(impl_->scene);
    build_cpu_ms_ = process_cpu_ms() - cpu_before_commit;
    const auto end = Clock::now();
    // What the build added and keeps: the BVH and its leaf triangles (the vertex and
    // index buffers were allocated before).
    bvh_bytes_ = size_t(std::max<int64_t>(impl_->allocated.load() - before_commit, 0));
    if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE)
        throw std::runtime_error("embree: scene build failed");
    build_ms_ = std::chrono::duration<double, std::milli>(end - commit).count();
    setup_ms_ = std::chrono::duration<double, std::milli>(end - start).count();
}

EmbreeReference::~EmbreeReference() = default;

namespace {
void fill_ray(RTCRay& r, const Ray& ray) {
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tnear = ray.tmin;
    r.tfar = ray.tmax;
    r.time = ray.time;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
}
}  // namespace

bool EmbreeReference::intersect(const Ray& ray, float& t, uint32_t& prim) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    fill_ray(rh.ray, ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    t = rh.ray.tfar;
    prim = rh.hit.primID;
    return true;
}

void EmbreeReference::intersect16(const RayPacket& packet, float t[kPacketSize],
                                  uint32_t prim[kPacketSize]) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    alignas(64) int valid[kPacketSize];
    alignas(64) RTCRayHit16 rh;
    for (int i = 0; i < kPacketSize; ++i) {
        const bool on = packet.active >> i & 1;
        valid[i] = on ? -1 : 0;
        rh.ray.org_x[i] = on ? packet.org[0][i] : 0.0f;
        rh.ray.org_y[i] = on ? packet.org[1][i] : 0.0f;
        rh.ray.org_z[i] = on ? packet.org[2][i] : 0.0f;
        rh.ray.dir_x[i] = on ? packet.dir[0][i] : 0.0f;
        rh.ray.dir_y[i] = on ? packet.dir[1][i] : 0.0f;
        rh.ray.dir_z[i] = on ? packet.dir[2][i] : 1.0f;
        rh.ray.tnear[i] = on ? packet.tmin[i] : 0.0f;
        rh.ray.tfar[i] = on ? packet.tmax[i] : 0.0f;
        rh.ray.time[i] = on ? packet.time[i] : 0.0f;
        rh.ray.mask[i] = 0xFFFFFFFFu;
        rh.ray.id[i] = 0;
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, impl_->scene, &ctx, &rh);
    for (int i = 0; i < kPacketSize; ++i) {
        const bool hit = valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        t[i] = hit ? rh.ray.tfar[i] : kInfinity;
        prim[i] = hit ? rh.hit.primID[i] : kNoPrim;
    }
}

bool EmbreeReference::occluded(const Ray& ray) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    fill_ray(r, ray);
    rtcOccluded1(impl_->scene, &ctx, &r);
    return r.tfar == -kInfinity;
}

#else

struct EmbreeReference::Impl {};
bool EmbreeReference::available() { return false; }
EmbreeReference::EmbreeReference(std::span<const Vec3>, std::span<const uint32_t>, bool, int,
                                 std::string_view, EmbreeQuality) {
    throw std::runtime_error("this sahara was built without Embree");
}
EmbreeReference::~EmbreeReference() = default;
bool EmbreeReference::intersect(const Ray&, float&, uint32_t&) const { return false; }
void EmbreeReference::intersect16(const RayPacket&, float[kPacketSize], uint32_t[kPacketSize]) const {}
bool EmbreeReference::occluded(const Ray&) const { return false; }

#endif

}  // namespace sahara
