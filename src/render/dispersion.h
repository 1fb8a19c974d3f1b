#pragma once
/// KHR_materials_dispersion: a volume's ior varies with the wavelength, by
/// the extension's Cauchy fit through the Abbe number V = 20 / dispersion,
///   n(lambda) = max(n_d + (n_d - 1) / V (523655 / lambda^2 - 1.5168), 1), lambda in nm,
/// which gives n_d at the d line (587.56 nm) and n_F - n_C = (n_d - 1) / V.
///
/// sahara renders RGB, taken as three box bands of wavelengths (red 600-700,
/// green 500-600, blue 400-500 nm). A path reaching a dispersive volume picks
/// one channel c with probability 1/3 and one wavelength uniformly in its band;
/// from there it carries channel c only, its throughput times 3 (the masked
/// channel divided by its probability), and every pbr material it meets later
/// refracts with its ior at that wavelength. The estimator's expectation in
/// channel c is then the average over c's band of the light transported with
/// n(lambda): the spectral answer for box-shaped channel responses and for
/// lights and colours constant within each band, which is what RGB assumes.
/// Paths that never meet a dispersive volume keep all three channels.
#include "desc/scene_desc.h"
#include "math/vec3.h"

namespace sahara {

/// n(lambda) above; exactly `ior` without dispersion.
float dispersed_ior(float ior, float dispersion, float wavelength_nm);

/// Whether `m` disperses: a pbr volume (not thin-walled) with dispersion > 0.
inline bool disperses(const MaterialDesc& m) {
    return m.dispersion > 0.0f && m.type == MaterialType::pbr && !m.thin_walled;
}

/// A path's colour channel and wavelength, from one uniform number u in [0, 1).
struct PathWavelength {
    int channel = 0;  ///< 0 red, 1 green, 2 blue
    float nm = 0;
    /// The throughput factor: channel `channel` times 3, the others 0.
    Rgb weight() const {
        Rgb w(0.0f);
        w[channel] = 3.0f;
        return w;
    }
};
PathWavelength sample_path_wavelength(float u);

}  // namespace sahara
