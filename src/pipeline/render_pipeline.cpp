#include "pipeline/render_pipeline.h"

#include <algorithm>

#include "base/error.h"
#include "io/files.h"
#include "io/model_loader.h"
#include "io/scene_parser.h"
#include "io/view_scene.h"
#include "render/tonemap.h"

namespace sahara {

void RenderOverrides::apply(RenderSettings& r) const {
    if (width) r.width = *width;
    if (height) r.height = *height;
    if (spp) r.spp = *spp;
    if (max_depth) r.max_depth = *max_depth;
    if (seed) r.seed = *seed;
    if (integrator) r.integrator = *integrator;
    if (time_limit_s) r.time_limit_s = *time_limit_s;
    if (target_error) r.target_error = *target_error;
    if (exposure) r.exposure = *exposure;
    if (tonemap) r.tonemap = *tonemap;
    if (sampler) r.sampler = *sampler;
    if (bvh_builder) r.bvh_builder = *bvh_builder;
    if (bvh_layout) r.bvh_layout = *bvh_layout;
    if (packets) r.packets = *packets;
}

SceneDesc load_scene_source(const std::optional<std::string>& source,
                            const std::optional<std::string>& variant) {
    const FileKind kind = source ? file_kind(*source) : FileKind::scene;
    if (variant && !is_model_kind(kind))
        throw input_error(source.value_or("the default scene"), "",
                          "a material variant applies to a glTF model; a scene names its variants with "
                          "the mesh object's \"variant\" key");
    if (!source) return default_scene();
    if (is_model_kind(kind))
        return make_view_scene(load_model(*source, Mat4::identity(), SharedMeshes::copy, variant),
                               kind == FileKind::gltf, ViewOptions{}, *source);
    return parse_scene_file(*source);
}

Scene prepare_scene(SceneDesc& desc, const RenderOverrides& overrides, std::optional<int> frame) {
    overrides.apply(desc.render);
    if (frame) {
        desc.camera.shutter_open += float(*frame);
        desc.camera.shutter_close += float(*frame);
    }
    return build_scene(desc);
}

size_t write_rgb_image(const std::filesystem::path& file, int width, int height,
                       const std::vector<float>& rgb, float exposure, Tonemap tonemap,
                       const ImageMetadata& metadata, const std::vector<ExtraChannel>& extra) {
    if (is_hdr_output(file)) {
        write_image(file, width, height, rgb, metadata, extra);
        return 0;
    }
    size_t clipped = 0;
    write_image(file, width, height, tonemap_image(rgb, exposure, tonemap, &clipped), metadata);
    return clipped;
}

}  // namespace sahara
