#include "app/render_args.h"

#include <CLI/CLI.hpp>

#include <cctype>

#include "accel/bvh.h"
#include "render/tonemap.h"

namespace sahara {

const char* const kRenderUsage =
    "usage: sahara render [SCENE.json] [-o OUT.png|.exr|.hdr|.pfm] [options]\n"
    "\n"
    "Renders SCENE (or the built-in default scene) to an image. Started by mpirun or srun\n"
    "(MPI builds), the ranks share the image's tiles, or whole frames with --frames.\n"
    "\n"
    "  -o, --output FILE    output image (default sahara.png); the extension picks the format\n"
    "  --spp N              samples per pixel\n"
    "  --width W, --height H  image size in pixels\n"
    "  --size WxH           both at once (N: N x N)\n"
    "  --max-depth D        rays per path, camera ray included (1..1024)\n"
    "  --seed S             random seed, 0..2^64-1 (same seed + settings = same image)\n"
    "  --integrator NAME    path | whitted | albedo | normals | depth | bvh-cost\n"
    "  --exposure STOPS     exposure for 8-bit outputs (EXR stays linear)\n"
    "  --tonemap CURVE      clamp | reinhard | aces | filmic (8-bit outputs only)\n"
    "  --sampler NAME       sobol (default: Owen-scrambled Sobol) | independent\n"
    "  --builder NAME       BVH builder: auto (default) | binned | sweep | reinsert | sbvh "
    "(render.bvh_builder)\n"
    "  --layout L           traversal structure: wide8 (default) | pairs\n"
    "                       (see sahara bench --help; pairs: a plain binary BVH, one ray at a time)\n"
    "  --threads N          worker threads (default: all)\n"
    "  --time SECONDS       stop after this long, keeping the samples done\n"
    "  --target-error E     adaptive sampling: stop when the estimated relative error is <= E\n"
    "                       (--spp is then the per-pixel maximum)\n"
    "  --reference REF.exr  also report the true error against this image\n"
    "  --checkpoint SECONDS write the partial image this often (non-EXR outputs also get\n"
    "                       OUT.partial.exr, resumable)\n"
    "  --resume FILE.exr    continue the render stored in FILE (same scene, seed, settings)\n"
    "  --preview            show the image in a window while it renders (Esc: stop and save,\n"
    "                       S: save a snapshot)\n"
    "  --preview-dump FILE  write the preview window's last frame to FILE (for tests)\n"
    "  --frames A..B        render frames A to B: OUT names the files with # (frame number,\n"
    "                       zero-padded to the run of #) or %04d; frame f shifts the camera\n"
    "                       shutter by f (moving spheres move). Under mpirun, ranks take\n"
    "                       whole frames; otherwise frames render one after another\n"
    "  --stats              print statistics at the end\n"
    "  -q, --quiet          no progress and no summary line\n"
    "  -h, --help           this text\n";

namespace {

/// "A..B" (or "A") as an inclusive frame range.
std::pair<int, int> parse_frame_range(const std::string& flag, const std::string& v) {
    const size_t dots = v.find("..");
    const int a = int(parse_int_value(flag, v.substr(0, dots), 0, 10000000));
    const int b = dots == std::string::npos ? a : int(parse_int_value(flag, v.substr(dots + 2), 0, 10000000));
    if (b < a) throw UsageError(flag + ": the range " + v + " is empty (expected A..B with A <= B)");
    return {a, b};
}

}  // namespace

std::string frame_output_name(const std::string& pattern, int frame) {
    const std::string number = std::to_string(frame);
    const size_t hash = pattern.find('#');
    if (hash != std::string::npos) {
        const size_t run = pattern.find_first_not_of('#', hash);
        const size_t width = (run == std::string::npos ? pattern.size() : run) - hash;
        const std::string padded =
            std::string(width > number.size() ? width - number.size() : 0, '0') + number;
        return pattern.substr(0, hash) + padded + pattern.substr(hash + width);
    }
    // %d or %0Nd, parsed here rather than handed to printf (a file name is no format string).
    for (size_t p = pattern.find('%'); p != std::string::npos; p = pattern.find('%', p + 1)) {
        size_t q = p + 1;
        size_t width = 0;
        if (q < pattern.size() && pattern[q] == '0') ++q;
        while (q < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[q])) && width < 100)
            width = width * 10 + size_t(pattern[q++] - '0');
        if (q < pattern.size() && pattern[q] == 'd') {
            const std::string padded =
                std::string(width > number.size() ? width - number.size() : 0, '0') + number;
            return pattern.substr(0, p) + padded + pattern.substr(q + 1);
        }
    }
    throw UsageError("--frames: the output name '" + pattern +
                     "' needs # or %04d where the frame number goes");
}

void parse_render_args(const std::vector<std::string>& args, RenderArgs& r,
                       const std::function<void(CLI::App&)>& extra) {
    CLI::App app;
    configure_app(app, r.help);
    app.add_option("-o,--output", r.output);
    add_threads_option(app, r.threads);
    app.add_flag("-q,--quiet", r.quiet);
    app.add_flag("--stats", r.stats);
    app.add_option_function<std::string>("--checkpoint", [&r](const std::string& v) {
        r.checkpoint_s = parse_real_value("--checkpoint", v, 0.1, 1e9);
    });
    app.add_option_function<std::string>("--resume", [&r](const std::string& v) { r.resume = v; });
    app.add_option_function<std::string>("--reference", [&r](const std::string& v) { r.reference = v; });
    app.add_flag("--preview", r.preview);
    app.add_option_function<std::string>("--preview-dump",
                                         [&r](const std::string& v) { r.preview_dump = v; });
    app.add_option_function<std::string>(
        "--frames", [&r](const std::string& v) { r.frames = parse_frame_range("--frames", v); });
    add_render_flags(app, r.overrides);
    if (extra) extra(app);
    const std::vector<std::string> scenes = parse_command_line(app, args);
    if (scenes.size() > 1)
        throw UsageError("more than one scene given ('" + scenes[0] + "' and '" + scenes[1] + "')");
    if (!scenes.empty()) r.scene = scenes[0];
    if (r.frames) {
        if (r.resume)
            throw UsageError("--frames and --resume cannot be combined (resume one frame at a time)");
        frame_output_name(r.output, r.frames->first);  // checks the pattern now
    }
}

RenderArgs parse_render_args(const std::vector<std::string>& args) {
    RenderArgs r;
    parse_render_args(args, r, {});
    return r;
}

}  // namespace sahara
