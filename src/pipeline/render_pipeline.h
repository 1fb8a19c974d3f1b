#pragma once
/// The steps from a scene source to pixels and image files that the command
/// line (app) and the Python module share, so both render the same image for
/// the same scene and settings: load, apply the caller's settings, build,
/// render (render/renderer.h), tone-map and write.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "desc/scene_desc.h"
#include "io/image_io.h"
#include "scene/scene.h"

namespace sahara {

/// Render settings given by the caller (flags, keyword arguments); each
/// overrides the scene's value.
struct RenderOverrides {
    std::optional<int> width, height, spp, max_depth;
    std::optional<uint64_t> seed;
    std::optional<IntegratorType> integrator;
    std::optional<double> time_limit_s, target_error;
    std::optional<float> exposure;
    std::optional<Tonemap> tonemap;
    std::optional<SamplerType> sampler;
    std::optional<BvhBuilder> bvh_builder;
    std::optional<BvhLayout> bvh_layout;
    std::optional<bool> packets;

    void apply(RenderSettings& r) const;
};

/// A scene file (.json), a model (.obj, .gltf, .glb: framed as `sahara view`
/// frames it; a glTF model in material variant `variant`, if given) or, for
/// nullopt, the built-in default scene. Throws InputError.
SceneDesc load_scene_source(const std::optional<std::string>& source,
                            const std::optional<std::string>& variant = std::nullopt);

/// Applies `overrides` to `desc` (and, for an animation frame, shifts the
/// shutter by `frame`: moving objects move on), then builds the runtime scene
/// and its BVH.
Scene prepare_scene(SceneDesc& desc, const RenderOverrides& overrides,
                    std::optional<int> frame = std::nullopt);

/// Writes linear RGB pixels (row 0 at the top) to `file`: 8-bit formats get
/// `exposure` (stops) and the tone curve, then sRGB encoding; HDR formats stay
/// linear, with `extra` channels. Returns how many pixels the curve clipped.
size_t write_rgb_image(const std::filesystem::path& file, int width, int height,
                       const std::vector<float>& rgb, float exposure, Tonemap tonemap,
                       const ImageMetadata& metadata = {}, const std::vector<ExtraChannel>& extra = {});

}  // namespace sahara
