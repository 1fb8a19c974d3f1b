#pragma once
/// Coherent ray packets: 16 rays (typically a 4x4 pixel tile of camera rays)
/// traced together through the 8-wide BVH. Each node's child boxes are tested
/// against all active rays at once and leaf triangles are broadcast against
/// the rays (Wald, Slusallek, Benthin and Wagner, "Interactive Rendering with
/// Coherent Ray Tracing", 2001; Wald, Benthin and Boulos, "Getting Rid of
/// Packets", 2008, for the wide-node variant). Per ray, the box test and the
/// watertight triangle test (Woop, Benthin and Wald 2013) perform exactly the
/// float operations of the single-ray code, so every ray gets the hit
/// distance a single ray gets; only which of two primitives at exactly the
/// same distance wins may differ (traversal order differs).
///
/// The instruction set is the single-ray traversal's, active_simd_path()
/// (accel/simd_path.h): AVX-512 (one 16-lane register), AVX2 (the single-ray
/// box and leaf tests per ray, packet_wide8.cpp) or SSE2 (four 4-lane quarters).
#include <cstdint>

#include "geometry/hit.h"
#include "math/ray.h"

namespace sahara {

/// Rays per packet.
inline constexpr int kPacketSize = 16;

/// 16 rays in structure-of-arrays form; lanes whose bit is clear in `active` are ignored.
struct alignas(64) RayPacket {
    float org[3][kPacketSize];
    float dir[3][kPacketSize];
    float tmin[kPacketSize];
    float tmax[kPacketSize];  ///< lowered to the hit distance by intersect_packet
    float time[kPacketSize];
    uint32_t active = 0;  ///< bit i: lane i holds a ray

    /// Stores `r` in lane `i` and marks it active.
    void set(int i, const Ray& r) {
        org[0][i] = r.origin.x, org[1][i] = r.origin.y, org[2][i] = r.origin.z;
        dir[0][i] = r.dir.x, dir[1][i] = r.dir.y, dir[2][i] = r.dir.z;
        tmin[i] = r.tmin, tmax[i] = r.tmax, time[i] = r.time;
        active |= 1u << i;
    }
    /// The ray of lane `i`.
    Ray ray(int i) const {
        return Ray{Vec3(org[0][i], org[1][i], org[2][i]), Vec3(dir[0][i], dir[1][i], dir[2][i]), tmin[i],
                   tmax[i], time[i]};
    }
};

/// Per-lane results of a packet trace (prim[i] == kNoPrim: lane i missed or was inactive).
struct alignas(64) HitPacket {
    float t[kPacketSize];
    float u[kPacketSize];
    float v[kPacketSize];
    uint32_t prim[kPacketSize];

    /// The hit of lane `i` as a single-ray Hit.
    Hit hit(int i) const { return Hit{t[i], prim[i], u[i], v[i]}; }
};

}  // namespace sahara
