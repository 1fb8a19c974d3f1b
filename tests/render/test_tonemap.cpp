#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "render/tonemap.h"

using namespace sahara;

namespace {

constexpr Tonemap kCurves[] = {Tonemap::clamp, Tonemap::reinhard, Tonemap::aces, Tonemap::filmic};

/// IEC 61966-2-1 encoding, written out in double as the standard states it.
double srgb_reference(double v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

}  // namespace

TEST_CASE("tonemap: every curve maps 0 to 0, is monotone and stays in [0,1]") {
    for (Tonemap curve : kCurves) {
        const std::string name(tonemap_name(curve));
        CAPTURE(name);
        CHECK(tonemap_value(0.0f, curve) == 0.0f);
        CHECK(tonemap_value(-1.0f, curve) == 0.0f);
        CHECK(tonemap_value(std::nanf(""), curve) == 0.0f);
        CHECK(tonemap_value(INFINITY, curve) == 1.0f);
        // Log-spaced sweep from 1e-6 to 1e4, plus the small linear range near 0.
        float prev = 0.0f;
        int decreases = 0, out_of_range = 0;
        for (int i = 0; i <= 20000; ++i) {
            const float v = std::pow(10.0f, -6.0f + 10.0f * float(i) / 20000.0f);
            const float y = tonemap_value(v, curve);
            decreases += y < prev;
            out_of_range += !(y >= 0.0f && y <= 1.0f);
            prev = y;
        }
        CHECK(decreases == 0);
        CHECK(out_of_range == 0);
        CHECK(tonemap_value(1e-6f, curve) > 0.0f);  // not flattened to black
        CHECK(tonemap_value(1e4f, curve) > 0.95f);  // bright goes (nearly) white
        CHECK(tonemap_value(0.18f, curve) < tonemap_value(1.0f, curve));
    }
    CHECK(tonemap_value(0.5f, Tonemap::clamp) == 0.5f);
    CHECK(tonemap_value(1.0f, Tonemap::reinhard) == doctest::Approx(0.5f));
    // The curves with a shoulder compress highlights relative to clamp.
    CHECK(tonemap_value(0.9f, Tonemap::reinhard) < 0.9f);
    CHECK(tonemap_value(0.9f, Tonemap::filmic) < 0.9f);
    // Filmic equals Hable's published form N(x)/D(x) - E/F, with bias 2 and white 11.2.
    auto hable = [](double x) {
        return (x * (0.15 * x + 0.05) + 0.004) / (x * (0.15 * x + 0.5) + 0.06) - 0.02 / 0.3;
    };
    for (double v : {0.05, 0.18, 1.0, 3.0})
        CHECK(double(tonemap_value(float(v), Tonemap::filmic)) ==
              doctest::Approx(hable(2 * v) / hable(11.2)).epsilon(1e-5));
    // ACES equals Narkowicz's fit.
    CHECK(double(tonemap_value(1.0f, Tonemap::aces)) == doctest::Approx(2.54 / 3.16).epsilon(1e-6));
}

TEST_CASE("tonemap: names round-trip") {
    for (Tonemap curve : kCurves) CHECK(tonemap_from_name(tonemap_name(curve)) == curve);
    CHECK_FALSE(tonemap_from_name("agx").has_value());
}

TEST_CASE("tonemap: sRGB encoding matches IEC 61966-2-1") {
    CHECK(srgb_encode(0.0f) == 0.0f);
    CHECK(srgb_encode(1.0f) == doctest::Approx(1.0f).epsilon(1e-6));
    CHECK(srgb_encode(0.5f) == doctest::Approx(0.735357).epsilon(1e-5));
    CHECK(srgb_encode(0.18f) == doctest::Approx(0.461356).epsilon(1e-5));
    CHECK(srgb_encode(0.0031308f) == doctest::Approx(0.0404500).epsilon(1e-4));
    CHECK(srgb_encode(0.001f) == doctest::Approx(0.01292f).epsilon(1e-6));
    for (int i = 0; i <= 1000; ++i) {
        const float v = float(i) / 1000.0f;
        CHECK(double(srgb_encode(v)) == doctest::Approx(srgb_reference(double(v))).epsilon(2e-6));
        CHECK(srgb_decode(srgb_encode(v)) == doctest::Approx(v).epsilon(1e-5));
    }
}

TEST_CASE("tonemap: exposure scales by 2^stops and clipped pixels are counted") {
    // Four pixels: dark, exactly 1 after exposure, one channel over 1, all over 1.
    const std::vector<float> rgb = {0.1f, 0.2f, 0.3f, 0.5f, 0.5f, 0.5f, 0.2f, 0.6f, 0.1f, 4.0f, 5.0f, 6.0f};
    size_t clipped = 99;
    const std::vector<float> out = tonemap_image(rgb, 1.0f, Tonemap::clamp, &clipped);
    REQUIRE(out.size() == rgb.size());
    CHECK(out[0] == doctest::Approx(0.2f));
    CHECK(out[3] == 1.0f);
    CHECK(out[7] == 1.0f);
    CHECK(out[9] == 1.0f);
    CHECK(clipped == 2);  // pixel 1 reaches 1.0 exactly: not clipped
    tonemap_image(rgb, 0.0f, Tonemap::clamp, &clipped);
    CHECK(clipped == 1);
    tonemap_image(rgb, -3.0f, Tonemap::clamp, &clipped);
    CHECK(clipped == 0);
    // Reinhard never saturates; ACES and filmic saturate only far above 1.
    tonemap_image(rgb, 1.0f, Tonemap::reinhard, &clipped);
    CHECK(clipped == 0);
    tonemap_image(rgb, 0.0f, Tonemap::aces, &clipped);
    CHECK(clipped == 0);
    tonemap_image(rgb, 2.0f, Tonemap::aces, &clipped);
    CHECK(clipped == 1);
    CHECK(tonemap_clips(7.2f, Tonemap::aces) == false);  // the fit crosses 1 at v = 7.24
    CHECK(tonemap_clips(7.3f, Tonemap::aces) == true);
    tonemap_image(rgb, 0.0f, Tonemap::filmic, &clipped);
    CHECK(clipped == 1);  // 6 * 2 (exposure bias) > 11.2 (linear white)
    CHECK(tonemap_clips(5.59f, Tonemap::filmic) == false);
    CHECK(tonemap_clips(5.61f, Tonemap::filmic) == true);
}

TEST_CASE("tonemap: auto exposure maps a uniform grey image to 0.18") {
    for (float grey : {1e-4f, 0.01f, 0.18f, 1.0f, 37.5f, 1e4f}) {
        CAPTURE(grey);
        const std::vector<float> rgb(3 * 64, grey);
        const float stops = auto_exposure_stops(rgb);
        CHECK(double(grey) * std::exp2(double(stops)) == doctest::Approx(0.18).epsilon(1e-5));
    }
    // Luminance, not the channel mean: pure green of value g has luminance 0.7152 g.
    const std::vector<float> green = {0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 0.0f};
    CHECK(std::exp2(double(auto_exposure_stops(green))) * 0.7152 == doctest::Approx(0.18).epsilon(1e-5));
    // Log-average: half the pixels at 4, half at 1 give a log-average of 2.
    const std::vector<float> mixed = {4, 4, 4, 1, 1, 1};
    CHECK(2.0 * std::exp2(double(auto_exposure_stops(mixed))) == doctest::Approx(0.18).epsilon(1e-5));
    // Black pixels are left out; a black image needs no exposure change.
    const std::vector<float> with_black = {0, 0, 0, 0.5f, 0.5f, 0.5f};
    CHECK(0.5 * std::exp2(double(auto_exposure_stops(with_black))) == doctest::Approx(0.18).epsilon(1e-5));
    CHECK(auto_exposure_stops(std::vector<float>(30, 0.0f)) == 0.0f);
    CHECK(auto_exposure_stops({}) == 0.0f);
}
