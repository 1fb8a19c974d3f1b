#include "accel/packet.h"

#include <immintrin.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "scene/accelerator.h"
#include "scene/packet_kernel.h"

namespace sahara {

namespace {

/// Fills the common permutation and signs; false when the active rays do not
/// share them (or a direction is zero or not finite, or an origin not finite): such packets are traced ray by
/// ray.
bool packet_eligible(const RayPacket& p, PacketContext& c) {
    c.first = std::countr_zero(p.active);
    int key = -1;
    for (uint32_t m = p.active; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        const Vec3 d(p.dir[0][i], p.dir[1][i], p.dir[2][i]);
        if (!is_finite(d) || !is_finite(Vec3(p.org[0][i], p.org[1][i], p.org[2][i]))) return false;
        const int kz = max_dimension(abs(d));
        if (!(std::fabs(d[kz]) > 0.0f)) return false;
        const int k =
            kz | (std::signbit(d.x) ? 4 : 0) | (std::signbit(d.y) ? 8 : 0) | (std::signbit(d.z) ? 16 : 0);
        if (key >= 0 && k != key) return false;
        key = k;
    }
    c.kz = key & 3;
    c.kx = c.kz == 2 ? 0 : c.kz + 1;
    c.ky = c.kx == 2 ? 0 : c.kx + 1;
    for (int a = 0; a < 3; ++a) c.neg[a] = (key >> (2 + a)) & 1;
    if (c.neg[c.kz]) std::swap(c.kx, c.ky);  // as in TriangleRay: keeps the winding
    // lo_x, hi_x, lo_y, hi_y, lo_z, hi_z of an N-wide node start at N floats times 0, 1, ..., 5.
    for (int a = 0; a < 3; ++a) {
        c.near_off[a] = 2 * a + c.neg[a];
        c.far_off[a] = 2 * a + 1 - c.neg[a];
    }
    return true;
}

}  // namespace

void Accelerator::intersect_packet(RayPacket& packet, HitPacket& hits) const {
    for (int i = 0; i < kPacketSize; ++i) hits.prim[i] = kNoPrim, hits.t[i] = kInfinity;
    if (!packet.active) return;
    PacketContext c{};
    c.rays = &packet;
    c.blocks = blocks_.data();
    c.accel = this;
    c.one_sided = one_sided_.empty() ? nullptr : one_sided_.data();
    // The pairs layout, scenes with cut-outs (the alpha test is single-ray only),
    // mixed directions and near-empty packets: single rays.
    if (!layout_has_blocks(layout_) || wide8_.empty || has_cutouts() || std::popcount(packet.active) < 2 ||
        !packet_eligible(packet, c)) {
        for (uint32_t m = packet.active; m; m &= m - 1) {
            const int i = std::countr_zero(m);
            Ray r = packet.ray(i);
            Hit h;
            if (intersect(r, h)) {
                hits.t[i] = h.t, hits.prim[i] = h.prim, hits.u[i] = h.u, hits.v[i] = h.v;
                packet.tmax[i] = h.t;
            }
        }
        return;
    }
    switch (active_simd_path()) {
        case SimdPath::avx512:
            packet_kernel::trace_packet<packet_kernel::kAvx512>(c, wide8_, hits);
            break;
        case SimdPath::avx2:
            // One AVX box test per ray and child set beats 16 rays per box in two halves.
            trace_packet8_avx2(packet, hits);
            break;
        case SimdPath::sse2:
            packet_kernel::trace_packet<packet_kernel::kSse2>(c, wide8_, hits);
            break;
    }
    for (uint32_t m = packet.active; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        if (hits.prim[i] != kNoPrim) packet.tmax[i] = hits.t[i];
    }
}

}  // namespace sahara
