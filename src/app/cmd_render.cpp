#include <cstdio>
#include <string>

#include "app/commands.h"
#include "app/render_args.h"
#include "base/error.h"
#include "base/log.h"
#include "io/image_io.h"
#include "render/progress.h"
#include "render/renderer.h"
#include "render/tonemap.h"
#include "scene/scene_parser.h"

namespace sahara {

namespace {

/// Integrators that are parsed from scene files but not implemented yet are
/// refused up front rather than silently replaced by another.
void check_integrator(IntegratorType t) {
    if (t == IntegratorType::bvh_cost) throw InputError("integrator 'bvh-cost' is not supported yet");
}

}  // namespace

/// Renders an already loaded scene description and writes the image.
int render_scene_to_file(SceneDesc desc, const std::string& output, int threads, bool quiet) {
    check_integrator(desc.render.integrator);
    const Scene scene = build_scene(desc);
    Film film(scene.render.width, scene.render.height);
    RenderOptions options;
    options.threads = threads;
    options.progress = !quiet && Progress::stderr_is_tty();
    const RenderResult result = render_image(scene, film, options);

    std::vector<float> rgb = film.to_rgb();
    if (!is_hdr_output(output)) rgb = tonemap_image(rgb, scene.render.exposure, scene.render.tonemap);
    const ImageMetadata meta = {{"scene", scene.source},
                                {"spp", std::to_string(result.spp_done)},
                                {"seed", std::to_string(scene.render.seed)},
                                {"render_seconds", std::to_string(result.seconds)},
                                {"version", SAHARA_VERSION}};
    write_image(output, film.width(), film.height(), rgb, meta);
    if (!quiet)
        std::fprintf(stderr, "sahara: %dx%d, %d spp, %.2f s, %.2f Msamples/s -> %s\n", film.width(), film.height(),
                     result.spp_done, result.seconds, double(result.samples) / result.seconds / 1e6, output.c_str());
    if (result.nonfinite > 0) log_warning(std::to_string(result.nonfinite) + " non-finite samples were discarded");
    return 0;
}

int run_render_command(const std::vector<std::string>& args) {
    RenderArgs a;
    try {
        a = parse_render_args(args);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "sahara render: %s\n\n%s", e.what(), kRenderUsage);
        return 2;
    }
    if (a.help) {
        std::fputs(kRenderUsage, stdout);
        return 0;
    }
    try {
        set_log_quiet(a.quiet);
        check_output_path(a.output);
        SceneDesc desc = a.scene ? parse_scene_file(*a.scene) : default_scene();
        a.overrides.apply(desc.render);
        return render_scene_to_file(std::move(desc), a.output, a.threads, a.quiet);
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara: error: %s\n", e.what());
        return 2;
    }
}

}  // namespace sahara
