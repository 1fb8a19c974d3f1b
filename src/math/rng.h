#pragma once
/// Small, fast, statistically good random numbers: PCG32 (O'Neill 2014) and a
/// 64-bit hash used to derive independent streams from (seed, pixel, sample).
#include <cstdint>

namespace sahara {

/// SplitMix64-style finaliser: a strong 64-bit mix.
constexpr uint64_t mix64(uint64_t x) {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return x;
}

/// Hash of several 64-bit words.
constexpr uint64_t hash_words(uint64_t a, uint64_t b, uint64_t c = 0, uint64_t d = 0) {
    return mix64(mix64(mix64(mix64(a) ^ b) ^ c) ^ d);
}

class Pcg32 {
   public:
    constexpr Pcg32() = default;
    constexpr explicit Pcg32(uint64_t seed, uint64_t stream = 1) { reseed(seed, stream); }
    constexpr void reseed(uint64_t seed, uint64_t stream = 1) {
        state_ = 0;
        inc_ = (stream << 1) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }
    constexpr uint32_t next_u32() {
        uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
    }
    /// Uniform in [0, 1): the top 24 bits, so the result never rounds up to 1.
    constexpr float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }

   private:
    uint64_t state_ = 0x853c49e6748fea9bull, inc_ = 0xda3e39cb94b95bdbull;
};

}  // namespace sahara
