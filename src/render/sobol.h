#pragma once
/// Scrambled Sobol (0,2)-sequence points, following Burley, "Practical
/// Hash-based Owen Scrambling" (JCGT 2020). The first two Sobol dimensions form
/// a (0,2)-sequence in base 2: every aligned block of 2^k points falls one per
/// elementary interval of area 2^-k. Higher dimensions are "padded": each pair
/// of dimensions gets its own independent Owen scrambling and its own shuffle
/// of the sample order, so pairs are decorrelated from each other.
#include <cstdint>

namespace sahara::sobol {

/// Reverses the 32 bits of x.
constexpr uint32_t reverse_bits(uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/// Laine and Karras' hash ("Stratified sampling for stochastic transparency",
/// 2011) with Burley's constants: every step (adding, xor with a multiple by an
/// even constant) only carries information from low bits to higher bits, so
/// each output bit depends on itself and the bits below it only. Applied to a
/// bit-reversed value that is exactly a nested uniform (Owen) scramble.
constexpr uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/// Owen scrambling of a 32-bit binary fraction x: each bit is flipped as a
/// random function (keyed by seed) of the more significant bits.
constexpr uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
    return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

/// Dimension 0 of the Sobol sequence (van der Corput): the identity generator
/// matrix, i.e. the bit-reversed index as a 32-bit fraction.
constexpr uint32_t sobol_dim0(uint32_t index) { return reverse_bits(index); }

/// Dimension 1 of the Sobol sequence (primitive polynomial x + 1): direction
/// number v_{j+1} = v_j ^ (v_j >> 1), starting from v_0 = 2^31. Bit by bit;
/// sobol_dim1 below is the same with byte tables.
constexpr uint32_t sobol_dim1_bitwise(uint32_t index) {
    uint32_t v = 1u << 31, result = 0;
    for (; index != 0; index >>= 1, v ^= v >> 1)
        if (index & 1u) result ^= v;
    return result;
}

namespace detail {
/// t[b][v]: XOR of the direction numbers selected by byte value v at byte b of
/// the index (the generator matrix is linear over GF(2)), stored bit-reversed
/// when `reversed` (what the scrambler works on).
struct Dim1Tables {
    uint32_t t[4][256];
    constexpr explicit Dim1Tables(bool reversed) : t{} {
        for (uint32_t b = 0; b < 4; ++b)
            for (uint32_t v = 0; v < 256; ++v) {
                const uint32_t x = sobol_dim1_bitwise(v << (8 * b));
                t[b][v] = reversed ? reverse_bits(x) : x;
            }
    }
    constexpr uint32_t operator()(uint32_t i) const {
        return t[0][i & 0xff] ^ t[1][(i >> 8) & 0xff] ^ t[2][(i >> 16) & 0xff] ^ t[3][i >> 24];
    }
};
inline constexpr Dim1Tables kDim1{false}, kDim1Reversed{true};
}  // namespace detail

/// Dimension 1 of the Sobol sequence by four table lookups (shuffled indices
/// use all 32 bits, so the bitwise loop would run 32 times).
constexpr uint32_t sobol_dim1(uint32_t index) { return detail::kDim1(index); }

/// Owen-scrambled dimension 1, with the bit reversal folded into the table.
constexpr uint32_t scrambled_dim1(uint32_t index, uint32_t seed) {
    return reverse_bits(laine_karras_permutation(detail::kDim1Reversed(index), seed));
}

/// Owen-scrambled dimension 0: scramble(reverse(i)) = reverse(LK(i)), two
/// bit reversals fewer.
constexpr uint32_t scrambled_dim0(uint32_t index, uint32_t seed) {
    return reverse_bits(laine_karras_permutation(index, seed));
}

/// A 32-bit fraction to a float in [0, 1): the top 24 bits, so it never rounds to 1.
constexpr float to_unit_float(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

}  // namespace sahara::sobol
