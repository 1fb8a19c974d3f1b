#pragma once
/// Thin-film interference for KHR_materials_iridescence: the reflectance of a
/// dielectric film of ior `film_ior` and thickness `thickness_nm` lying on a
/// base, seen from a medium of ior `outside_ior` (1: air), after Belcour and
/// Barla 2017 ("A Practical Extension to Microfacet Theory for the Modeling of
/// Varying Iridescence") in the extension's simplified form: Schlick Fresnel
/// at both interfaces, the base's ior inferred from its reflectance at normal
/// incidence (no extinction, so metals are approximated), the Airy series cut
/// after its first two interference terms, and the spectral integration to
/// Rec.709 RGB done analytically with Gaussian fits of the CIE XYZ curves.
#include "math/vec3.h"

namespace sahara {

/// Reflectance per channel at cos_theta (the angle to the microfacet normal)
/// of the film over a base whose reflectance at normal incidence from air is
/// base_f0 (per channel, below 1). Clamped to [0, 1]: the truncated series and
/// the colour matrix's negative lobes can leave that range slightly.
Rgb thin_film_reflectance(float cos_theta, float film_ior, float thickness_nm, const Rgb& base_f0,
                          float outside_ior = 1.0f);

/// A bound, at normal incidence and for any thickness, of the film's
/// reflectance over the dielectric base of reflectance base_f0 (largest
/// channel): the largest reflectance of the inner-reflection sum over the
/// phase, per wavelength, times 1.4, the most the conversion of the film's
/// spectrum to RGB adds to one channel (1.27-1.35 for film iors 1.3-3 over
/// glass, 10-1500 nm). The pbr layering takes it as the layer's F0 so that
/// the base below is scaled by what the film leaves (render/bsdf_pbr.cpp).
float thin_film_reflectance_bound(float film_ior, const Rgb& base_f0, float outside_ior = 1.0f);

}  // namespace sahara
