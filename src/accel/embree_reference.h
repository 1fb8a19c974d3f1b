#pragma once
/// Embree 3 as a yardstick: the same triangles in an Embree scene, traced with
/// rtcIntersect1 / rtcOccluded1. Embree types stay inside embree_reference.cpp.
/// Without Embree (SAHARA_HAVE_EMBREE undefined) available() is false and the
/// constructor throws std::runtime_error.
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "accel/packet.h"
#include "math/ray.h"
#include "math/vec3.h"

namespace sahara {

/// The values EmbreeReference accepts for max_isa: Embree 3 falls back to SSE2 for any
/// name it does not know, so only names its device configuration documents are passed.
inline constexpr std::string_view kEmbreeIsas[] = {"best", "sse2", "avx", "avx2", "avx512"};

/// Embree's scene build quality (RTC_BUILD_QUALITY_*): low is its fast Morton build, medium
/// its default binned SAH build, high adds spatial splits (references of one triangle in
/// several leaves), which pays off on long thin triangles such as walls and floors.
enum class EmbreeQuality : uint8_t { low, medium, high };
inline constexpr std::string_view kEmbreeQualityNames[] = {"low", "medium", "high"};

class EmbreeReference {
   public:
    /// Whether this build has Embree.
    static bool available();
    /// Builds an Embree scene over the indexed triangles. `robust` sets
    /// RTC_SCENE_FLAG_ROBUST (Embree's slower, watertight-leaning mode); the
    /// default mode is the fast one and can let rays slip through shared edges.
    /// `build_threads` > 0 limits Embree's build threads (0: Embree's default, all cores).
    /// `max_isa` (one of kEmbreeIsas but "best"; empty or "best": Embree's choice, the widest
    /// the CPU has) caps the instruction set of Embree's kernels, its `max_isa` device setting.
    /// `quality` is the scene's build quality (rtcSetSceneBuildQuality).
    EmbreeReference(std::span<const Vec3> positions, std::span<const uint32_t> indices, bool robust = false,
                    int build_threads = 0, std::string_view max_isa = {},
                    EmbreeQuality quality = EmbreeQuality::medium);
    ~EmbreeReference();
    EmbreeReference(const EmbreeReference&) = delete;
    EmbreeReference& operator=(const EmbreeReference&) = delete;

    /// Nearest hit in [ray.tmin, ray.tmax]: t and triangle index; false on a miss.
    bool intersect(const Ray& ray, float& t, uint32_t& prim) const;
    /// rtcIntersect16 on the active lanes of `packet` (valid mask): per lane t
    /// (+inf on a miss) and triangle index (kNoPrim on a miss).
    void intersect16(const RayPacket& packet, float t[kPacketSize], uint32_t prim[kPacketSize]) const;
    /// Whether anything blocks the ray.
    bool occluded(const Ray& ray) const;
    /// Wall time of rtcCommitScene (Embree's BVH build), and of the whole construction
    /// (device, buffer copies, build).
    double build_ms() const { return build_ms_; }
    double setup_ms() const { return setup_ms_; }
    /// CPU time of rtcCommitScene summed over the process's threads (steadier than
    /// build_ms when other processes share the cores).
    double build_cpu_ms() const { return build_cpu_ms_; }
    /// Bytes Embree's scene build allocated and kept (BVH nodes and leaf triangles,
    /// without the vertex and index buffers), from its device memory monitor.
    size_t bvh_bytes() const { return bvh_bytes_; }

   private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    double build_ms_ = 0;
    double build_cpu_ms_ = 0;
    size_t bvh_bytes_ = 0;
    double setup_ms_ = 0;
};

/// Sets flush-to-zero and denormals-are-zero for the calling thread (Embree's
/// recommendation); the bench applies it to sahara and Embree alike.
void set_flush_denormals(bool on);

}  // namespace sahara
