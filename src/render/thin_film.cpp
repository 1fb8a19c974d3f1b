#include "render/thin_film.h"

#include <algorithm>
#include <cmath>

#include "math/sampling.h"
#include "render/bsdf.h"

namespace sahara {

namespace {

float sq(float x) { return x * x; }

float schlick(float f0, float cos_theta) { return fresnel_schlick(Rgb(f0), cos_theta).x; }

/// Reflectance at normal incidence of an interface between iors a and b.
float normal_reflectance(float a, float b) { return sq((a - b) / (a + b)); }

/// The ior giving reflectance f0 from air (f0 kept below 1, where the ior is infinite).
float ior_of_reflectance(float f0) {
    const float s = std::sqrt(std::clamp(f0, 0.0f, 0.9999f));
    return (1.0f + s) / (1.0f - s);
}

/// Rec.709 RGB of the CIE XYZ sensitivities' Fourier transform at the optical
/// path difference opd (nm), shifted in phase by `shift` per channel: the
/// spectral integral of cos(2 pi opd / lambda + shift) against the colour
/// matching functions, each fitted by Gaussians (Belcour and Barla, section 4),
/// normalised so that opd 0, shift 0 gives the white of equal energy.
Rgb sensitivity(float opd, const Rgb& shift) {
    const float phase = 2.0f * kPi * opd * 1e-9f;
    const float phase2 = phase * phase;
    const Rgb val(5.4856e-13f, 4.4201e-13f, 5.2481e-13f);
    const Rgb pos(1.6810e+06f, 1.7953e+06f, 2.2084e+06f);
    const Rgb var(4.3278e+09f, 9.3046e+09f, 6.6121e+09f);
    Rgb xyz;
    for (int c = 0; c < 3; ++c)
        xyz[c] = val[c] * std::sqrt(2.0f * kPi * var[c]) * std::cos(pos[c] * phase + shift[c]) *
                 std::exp(-phase2 * var[c]);
    // X has a second, smaller lobe in the blue.
    xyz.x += 9.7470e-14f * std::sqrt(2.0f * kPi * 4.5282e+09f) * std::cos(2.2399e+06f * phase + shift.x) *
             std::exp(-4.5282e+09f * phase2);
    xyz = xyz * (1.0f / 1.0685e-7f);
    return {3.2404542f * xyz.x - 1.5371385f * xyz.y - 0.4985314f * xyz.z,
            -0.9692660f * xyz.x + 1.8760108f * xyz.y + 0.0415560f * xyz.z,
            0.0556434f * xyz.x - 0.2040259f * xyz.y + 1.0572252f * xyz.z};
}

}  // namespace

Rgb thin_film_reflectance(float cos_theta, float film_ior, float thickness_nm, const Rgb& base_f0,
                          float outside_ior) {
    const float cos1 = std::clamp(cos_theta, 0.0f, 1.0f);
    // Snell's law into the film; none gets in past the critical angle.
    const float sin2_sq = sq(outside_ior / film_ior) * (1.0f - cos1 * cos1);
    if (sin2_sq >= 1.0f) return Rgb(1.0f);
    const float cos2 = std::sqrt(1.0f - sin2_sq);

    // Outside/film interface: reflected R12 (= R21), transmitted there and back T121.
    const float r12 = schlick(normal_reflectance(outside_ior, film_ior), cos1);
    const float t121 = 1.0f - r12;
    // Reflection off a denser medium shifts the phase by pi; the two passes
    // through the first interface contribute phi21 = pi - phi12 in all.
    const float phi12 = film_ior < outside_ior ? kPi : 0.0f;
    const float phi21 = kPi - phi12;
    const float opd = 2.0f * film_ior * thickness_nm * cos2;  // optical path difference, nm

    Rgb r23, phi;
    for (int c = 0; c < 3; ++c) {
        const float base_ior = ior_of_reflectance(base_f0[c]);
        r23[c] = schlick(normal_reflectance(film_ior, base_ior), cos2);
        phi[c] = phi21 + (base_ior < film_ior ? kPi : 0.0f);
    }
    // Airy summation: the DC term plus the interference terms m = 1, 2, each
    // of amplitude (Rs - T121) sqrt(R12 R23)^m integrated against the sensitivities.
    Rgb amp, reflectance, cm;
    for (int c = 0; c < 3; ++c) {
        const float r123 = std::clamp(r12 * r23[c], 1e-5f, 0.9999f);
        amp[c] = std::sqrt(r123);
        const float rs = t121 * t121 * r23[c] / (1.0f - r123);
        reflectance[c] = r12 + rs;
        cm[c] = rs - t121;
    }
    for (int m = 1; m <= 2; ++m) {
        cm *= amp;
        reflectance += cm * sensitivity(float(m) * opd, phi * float(m)) * 2.0f;
    }
    Rgb result;
    for (int c = 0; c < 3; ++c) result[c] = std::clamp(reflectance[c], 0.0f, 1.0f);
    return result;
}

float thin_film_reflectance_bound(float film_ior, const Rgb& base_f0, float outside_ior) {
    const float a = std::sqrt(normal_reflectance(outside_ior, film_ior));
    float bound = 0.0f;
    for (int c = 0; c < 3; ++c) {
        const float b = std::sqrt(normal_reflectance(film_ior, ior_of_reflectance(base_f0[c])));
        bound = std::max(bound, sq((a + b) / (1.0f + a * b)));
    }
    return std::min(1.0f, 1.4f * bound);
}

}  // namespace sahara
