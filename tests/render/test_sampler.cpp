#include <doctest/doctest.h>

#include <cmath>
#include <set>
#include <tuple>
#include <vector>

#include "render/sampler.h"

using namespace sahara;

namespace {

/// The first `n` 2-D points of dimension pair `pair` of pixel (x, y), starting at sample `first`.
std::vector<Vec2> pixel_points(Sampler& s, uint32_t x, uint32_t y, uint32_t first, uint32_t n, int pair) {
    std::vector<Vec2> pts;
    for (uint32_t i = first; i < first + n; ++i) {
        s.start(x, y, i);
        Vec2 p{};
        for (int d = 0; d <= pair; ++d) p = s.next_2d();
        pts.push_back(p);
    }
    return pts;
}

/// Whether the points fall exactly one per cell of every 2^a x 2^(k-a) grid.
bool one_per_elementary_interval(const std::vector<Vec2>& pts, int k) {
    for (int a = 0; a <= k; ++a) {
        const int nx = 1 << a, ny = 1 << (k - a);
        std::vector<int> cells(size_t(nx) * size_t(ny), 0);
        for (const Vec2& p : pts) {
            const int cx = int(p.x * float(nx)), cy = int(p.y * float(ny));
            if (++cells[size_t(cy) * size_t(nx) + size_t(cx)] > 1) return false;
        }
    }
    return true;
}

/// A smooth function on [0,1] with integral 1.
double smooth1(float u) {
    return 1.0 + 0.5 * std::cos(2.0 * 3.14159265358979 * double(u)) + (double(u) - 0.5);
}

/// Smooth integrands over [0,1]^4 with integral 1: within one dimension pair,
/// and a product across two pairs.
double smooth_pair(Vec2 a, Vec2) { return smooth1(a.x) * smooth1(a.y); }
double smooth_product(Vec2 a, Vec2 b) { return smooth1(a.x) * smooth1(a.y) * smooth1(b.x) * smooth1(b.y); }

/// RMS error over `pixels` pixels of the n-sample mean of f.
double rms_error(double (*f)(Vec2, Vec2), SamplerType type, uint32_t n, int pixels) {
    Sampler s(7, type);
    double sum_sq = 0;
    for (int px = 0; px < pixels; ++px) {
        double mean = 0;
        for (uint32_t i = 0; i < n; ++i) {
            s.start(uint32_t(px), 3, i);
            const Vec2 a = s.next_2d(), b = s.next_2d();
            mean += f(a, b);
        }
        mean /= double(n);
        sum_sq += (mean - 1.0) * (mean - 1.0);
    }
    return std::sqrt(sum_sq / pixels);
}

}  // namespace

TEST_CASE("sobol: scrambling is a bijection that keeps elementary intervals") {
    // Owen scrambling maps the 2^k aligned intervals of [0,1) onto themselves.
    std::set<uint32_t> seen;
    for (uint32_t i = 0; i < 256; ++i) seen.insert(sobol::nested_uniform_scramble(i << 24, 12345u) >> 24);
    CHECK(seen.size() == 256);
    CHECK(sobol::reverse_bits(1u) == 0x80000000u);
    CHECK(sobol::sobol_dim1(1) == 0x80000000u);
    CHECK(sobol::sobol_dim1(2) == 0xC0000000u);  // 0.75, as in Sobol's second dimension
    CHECK(sobol::sobol_dim1(3) == 0x40000000u);  // 0.25
    for (uint32_t i : {5u, 77u, 0xdeadbeefu, 0xffffffffu, 1u << 31}) {
        CHECK(sobol::sobol_dim1(i) == sobol::sobol_dim1_bitwise(i));
        CHECK(sobol::scrambled_dim0(i, 99u) == sobol::nested_uniform_scramble(sobol::sobol_dim0(i), 99u));
        CHECK(sobol::scrambled_dim1(i, 99u) == sobol::nested_uniform_scramble(sobol::sobol_dim1(i), 99u));
    }
}

TEST_CASE("sobol sampler: every power-of-two block of a pixel is a (0,2) net") {
    Sampler s(42, SamplerType::sobol);
    for (int pair : {0, 1, 5}) {
        for (int k = 0; k <= 8; ++k) {
            const uint32_t n = 1u << k;
            CHECK(one_per_elementary_interval(pixel_points(s, 3, 9, 0, n, pair), k));
            // A later aligned block (samples of a later render pass) is stratified too.
            CHECK(one_per_elementary_interval(pixel_points(s, 3, 9, 4 * n, n, pair), k));
        }
    }
}

TEST_CASE("sobol sampler: 1-D draws are stratified over a pixel's samples") {
    Sampler s(1, SamplerType::sobol);
    const int n = 64;
    std::vector<int> bins(n, 0);
    for (int i = 0; i < n; ++i) {
        s.start(0, 0, uint32_t(i));
        (void)s.next_2d();  // consume a pair first: 1-D dimensions sit after it
        const float u = s.next_1d();
        REQUIRE(u >= 0.0f);
        REQUIRE(u < 1.0f);
        ++bins[size_t(u * float(n))];
    }
    for (int b : bins) CHECK(b == 1);
}

TEST_CASE("sampler: pixels and dimension pairs are decorrelated") {
    // Same sample index, different pixels or pairs: different points.
    Sampler s(5, SamplerType::sobol);
    s.start(0, 0, 0);
    const Vec2 a0 = s.next_2d(), a1 = s.next_2d();
    s.start(1, 0, 0);
    const Vec2 b0 = s.next_2d();
    CHECK(a0.x != a1.x);
    CHECK(a0.x != b0.x);
    // Correlation between dimension 0 and dimension 2 over a pixel's samples is small.
    const int n = 1024;
    double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
    for (int i = 0; i < n; ++i) {
        s.start(2, 2, uint32_t(i));
        const double x = s.next_2d().x, y = s.next_2d().x;
        sx += x;
        sy += y;
        sxy += x * y;
        sxx += x * x;
        syy += y * y;
    }
    const double cov = sxy / n - sx / n * sy / n;
    const double corr = cov / std::sqrt((sxx / n - sx / n * sx / n) * (syy / n - sy / n * sy / n));
    CHECK(std::abs(corr) < 0.1);
}

TEST_CASE("sampler: the stream depends only on seed, pixel, sample index and dimension") {
    for (SamplerType type : {SamplerType::sobol, SamplerType::independent}) {
        Sampler a(9, type), b(9, type), c(10, type);
        // b visits other pixels and samples in between: must not matter.
        b.start(5, 5, 77);
        (void)b.next_2d();
        a.start(12, 34, 56);
        b.start(12, 34, 56);
        c.start(12, 34, 56);
        const Vec2 a0 = a.next_2d(), b0 = b.next_2d(), c0 = c.next_2d();
        CHECK(a0.x == b0.x);
        CHECK(a0.y == b0.y);
        CHECK(a.next_1d() == b.next_1d());
        CHECK(a0.x != c0.x);  // another seed: another stream
    }
}

TEST_CASE("sobol sampler converges faster than independent on smooth integrands") {
    const double sobol_64 = rms_error(smooth_pair, SamplerType::sobol, 64, 200);
    const double indep_64 = rms_error(smooth_pair, SamplerType::independent, 64, 200);
    const double sobol_256 = rms_error(smooth_pair, SamplerType::sobol, 256, 200);
    MESSAGE("2-D: RMSE at 64 spp: sobol " << sobol_64 << ", independent " << indep_64
                                          << "; sobol at 256: " << sobol_256);
    CHECK(sobol_64 < 0.1 * indep_64);
    // Owen-scrambled nets of a smooth integrand converge at about N^-1.5: x4
    // samples would only halve the error at the Monte Carlo rate.
    CHECK(sobol_256 < 0.25 * sobol_64);
    // Across padded dimension pairs the interaction part converges at the Monte
    // Carlo rate, but the within-pair parts still gain: never worse than random.
    const double sobol_prod = rms_error(smooth_product, SamplerType::sobol, 64, 200);
    const double indep_prod = rms_error(smooth_product, SamplerType::independent, 64, 200);
    MESSAGE("4-D product: RMSE at 64 spp: sobol " << sobol_prod << ", independent " << indep_prod);
    CHECK(sobol_prod < 0.7 * indep_prod);
}

#include "render/film.h"
#include "render/renderer.h"
#include "io/scene_parser.h"

TEST_CASE("sobol sampler: same image with any thread count and any split into passes") {
    SceneDesc d = default_scene();
    d.render.width = 24;
    d.render.height = 16;
    d.render.sampler = SamplerType::sobol;
    const Scene scene = build_scene(d);
    Film a(24, 16), b(24, 16);
    render_pass(scene, a, 0, 8, 1, nullptr);
    render_pass(scene, b, 0, 1, 2, nullptr);
    render_pass(scene, b, 1, 3, 2, nullptr);
    render_pass(scene, b, 3, 8, 2, nullptr);
    // Sums are accumulated in the same per-pixel order, so the images match bit for bit.
    CHECK(a.to_rgb() == b.to_rgb());
}

TEST_CASE("sampler: skipped dimensions leave every later dimension unchanged") {
    for (SamplerType type : {SamplerType::sobol, SamplerType::independent}) {
        INFO(int(type));
        Sampler drawn(3, type), skipped(3, type);
        // Pixels revisited out of order: the cached Sobol pixel key must follow.
        for (const auto& [x, y, i] :
             {std::tuple{4u, 7u, 0u}, {4u, 7u, 1u}, {9u, 7u, 5u}, {4u, 7u, 2u}, {4u, 8u, 2u}}) {
            drawn.start(x, y, i);
            skipped.start(x, y, i);
            const Vec2 a = drawn.next_2d(), b = skipped.next_2d();
            CHECK(a.x == b.x);
            (void)drawn.next_2d();  // what the camera's lens would take
            skipped.skip_2d();
            (void)drawn.next_1d();  // and the shutter time
            skipped.skip_1d();
            for (int d = 0; d < 3; ++d) {
                const Vec2 p = drawn.next_2d(), q = skipped.next_2d();
                CHECK(p.x == q.x);
                CHECK(p.y == q.y);
                CHECK(drawn.next_1d() == skipped.next_1d());
            }
            Sampler fresh(3, type);  // no cached key: same stream as a sampler that moved between pixels
            fresh.start(x, y, i);
            CHECK(fresh.next_2d().x == a.x);
        }
    }
}
