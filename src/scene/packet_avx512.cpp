// The packet kernel (packet_kernel.h) compiled for AVX-512F: the header sits inside the
// target region, so its templates, and with them this instantiation, carry the target.
#include <immintrin.h>

#include <bit>
#include <cstring>

#pragma GCC push_options
#pragma GCC target("avx512f")
#pragma GCC optimize("fp-contract=off")
#include "scene/packet_kernel.h"

namespace sahara::packet_kernel {
template void trace_packet<kAvx512, 8>(const PacketContext&, const BvhWide<8>&, HitPacket&);
}  // namespace sahara::packet_kernel
#pragma GCC pop_options
