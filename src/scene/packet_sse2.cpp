// The packet kernel (packet_kernel.h) compiled for SSE2, the x86-64 baseline.
#include <immintrin.h>

#include <bit>
#include <cstring>

#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#include "scene/packet_kernel.h"

namespace sahara::packet_kernel {
template void trace_packet<kSse2, 8>(const PacketContext&, const BvhWide<8>&, HitPacket&);
}  // namespace sahara::packet_kernel
#pragma GCC pop_options
