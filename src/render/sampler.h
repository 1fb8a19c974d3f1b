#pragma once
/// Per-sample random numbers. The stream of a pixel sample depends only on
/// (seed, pixel, sample index, dimension), never on the thread or the order of
/// work, so the same seed and settings give the same image with any thread
/// count and any split of the samples into passes.
#include <cstdint>

#include "math/rng.h"
#include "math/vec3.h"
#include "render/sobol.h"
#include "desc/scene_desc.h"

namespace sahara {

class Sampler {
   public:
    explicit Sampler(uint64_t seed = 0, SamplerType type = SamplerType::sobol) : seed_(seed), type_(type) {}

    /// Positions the sampler at the start of sample `index` of pixel (x, y).
    void start(uint32_t x, uint32_t y, uint32_t index) {
        const uint64_t pixel = (uint64_t(y) << 32) | x;
        reversed_index_ = sobol::reverse_bits(index);
        dimension_ = 0;
        if (type_ == SamplerType::independent) {
            rng_.reseed(hash_words(seed_, pixel, index), 0x5a4a5a4a);
        } else if (!has_pixel_ || pixel != pixel_) {
            // The key depends on the pixel only: hashed once for all its samples.
            pixel_key_ = hash_words(seed_, pixel, 0x50b01u);
            pixel_ = pixel;
            has_pixel_ = true;
        }
    }
    /// The next dimension of the current sample, in [0, 1).
    float next_1d() {
        if (type_ == SamplerType::independent) return rng_.next_float();
        const Keys k = next_keys();
        return sobol::to_unit_float(sobol::scrambled_dim0(k.index, k.scramble_x));
    }
    /// The next two dimensions of the current sample, in [0, 1)^2; with the
    /// Sobol sampler they are a scrambled (0,2)-sequence over the pixel's samples.
    Vec2 next_2d() {
        if (type_ == SamplerType::independent) {
            float a = rng_.next_float();
            return {a, rng_.next_float()};
        }
        const Keys k = next_keys();
        return {sobol::to_unit_float(sobol::scrambled_dim0(k.index, k.scramble_x)),
                sobol::to_unit_float(sobol::scrambled_dim1(k.index, k.scramble_y))};
    }
    /// Skips one dimension as next_1d() would consume it, without computing the
    /// value: later dimensions stay exactly as if it had been drawn.
    void skip_1d() {
        if (type_ == SamplerType::independent)
            rng_.next_float();
        else
            ++dimension_;
    }
    /// Skips two dimensions as next_2d() would consume them (see skip_1d).
    void skip_2d() {
        if (type_ == SamplerType::independent) {
            rng_.next_float();
            rng_.next_float();
        } else {
            ++dimension_;
        }
    }
    SamplerType type() const { return type_; }

   private:
    struct Keys {
        uint32_t index, scramble_x, scramble_y;
    };
    /// Per pixel and dimension (pair): a shuffled sample index (Burley 2020,
    /// sec. 4: Owen-scrambling the index keeps every aligned power-of-two block
    /// of samples stratified, since the top k bits of a Sobol point depend only
    /// on the low k index bits) and two independent scrambling seeds.
    Keys next_keys() {
        const uint64_t h = mix64(pixel_key_ ^ (uint64_t(dimension_) * 0x9e3779b97f4a7c15ull));
        ++dimension_;
        const uint32_t lo = uint32_t(h), hi = uint32_t(h >> 32);
        // The third seed needs no full-strength hash: the LK permutation mixes it in.
        const uint32_t index = sobol::reverse_bits(sobol::laine_karras_permutation(reversed_index_, lo));
        return {index, hi, (lo ^ hi) * 0x9e3779b9u + 0x7f4a7c15u};
    }

    uint64_t seed_;
    SamplerType type_;
    Pcg32 rng_;
    uint64_t pixel_key_ = 0;
    uint64_t pixel_ = 0;  ///< the pixel pixel_key_ belongs to (Sobol only)
    bool has_pixel_ = false;
    uint32_t reversed_index_ = 0, dimension_ = 0;  ///< sample index, bit-reversed
};

}  // namespace sahara
