#pragma once
/// Directional albedo of the anisotropic GGX reflection lobe
/// (KHR_materials_anisotropy), for the multiple-scattering compensation of
/// render/ggx_albedo.h. With two alphas the albedo depends on the azimuth of
/// the outgoing direction as well as on its cosine, and no single isotropic
/// alpha reproduces it at every angle; so it is tabulated over (cosine,
/// azimuth, alpha_y, stretch towards alpha_x) once per process, by the same
/// numerical integration as the isotropic table, and read multilinearly.
#include <vector>

#include "math/vec3.h"
#include "render/ggx_albedo.h"

namespace sahara {

class GgxAnisoAlbedoTable {
   public:
    static constexpr int kMuSteps = 12, kPhiSteps = 6, kRoughnessSteps = 12, kStretchSteps = 8;

    /// The process-wide table, built on first use (thread-safe).
    static const GgxAnisoAlbedoTable& get();

    /// Albedo towards the local direction wo (wo.z >= 0) of GGX with alpha_x along
    /// local x and alpha_y along y, each in [kMinPbrAlpha, 1].
    GgxAlbedo at(const Vec3& wo, float alpha_x, float alpha_y) const;
    /// Cosine-weighted hemispherical average of the function at() interpolates,
    /// so that a compensation lobe built from both integrates to what is missing.
    GgxAlbedo average(float alpha_x, float alpha_y) const;

    /// Built by numerical integration with `strata` x `strata` visible-normal samples per entry.
    explicit GgxAnisoAlbedoTable(int strata);

   private:
    struct Cell {
        int i[4];
        float t[4];
    };
    /// The table coordinates of (alpha_x, alpha_y): alpha_y's roughness and the stretch.
    static void material_cell(float alpha_x, float alpha_y, Cell* c);
    size_t index(int r, int s, int m, int p) const {
        return ((size_t(r) * kStretchSteps + size_t(s)) * kMuSteps + size_t(m)) * kPhiSteps + size_t(p);
    }

    std::vector<GgxAlbedo> table_;  ///< [roughness][stretch][mu][phi]
    std::vector<GgxAlbedo> avg_;    ///< [roughness][stretch]
};

}  // namespace sahara
