#pragma once
/// Per-sample random numbers. The stream of a pixel sample depends only on
/// (seed, pixel, sample index), never on the thread or the order of work, so
/// the same seed and settings give the same image with any thread count.
#include <cstdint>

#include "math/rng.h"
#include "math/vec3.h"

namespace sahara {

enum class SamplerType : uint8_t { independent };

class Sampler {
public:
    explicit Sampler(uint64_t seed = 0, SamplerType type = SamplerType::independent) : seed_(seed), type_(type) {}

    /// Positions the sampler at the start of sample `index` of pixel (x, y).
    void start(uint32_t x, uint32_t y, uint32_t index) {
        rng_.reseed(hash_words(seed_, (uint64_t(y) << 32) | x, index), 0x5a4a5a4a);
    }
    float next_1d() { return rng_.next_float(); }
    Vec2 next_2d() {
        float a = rng_.next_float();
        return {a, rng_.next_float()};
    }
    SamplerType type() const { return type_; }

private:
    uint64_t seed_;
    SamplerType type_;
    Pcg32 rng_;
};

}  // namespace sahara
