#include "app/render_args.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

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
    "  --max-depth D        rays per path, camera ray included\n"
    "  --seed S             random seed (same seed + settings = same image)\n"
    "  --integrator NAME    path | whitted | albedo | normals | depth | bvh-cost\n"
    "  --exposure STOPS     exposure for 8-bit outputs (EXR stays linear)\n"
    "  --tonemap CURVE      clamp | reinhard | aces | filmic (8-bit outputs only)\n"
    "  --sampler NAME       sobol (default: Owen-scrambled Sobol) | independent\n"
    "  --builder NAME       BVH builder: binned (default) | sweep | reinsert (render.bvh_builder)\n"
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
    "  --quiet              no progress and no summary line\n"
    "  -h, --help           this text\n";

long long parse_int_value(const std::string& flag, const std::string& value, long long lo, long long hi) {
    char* end = nullptr;
    errno = 0;
    long long v = std::strtoll(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
        throw UsageError(flag + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                         ", got '" + value + "'");
    return v;
}

double parse_real_value(const std::string& flag, const std::string& value, double lo, double hi) {
    char* end = nullptr;
    double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
        throw UsageError(flag + ": expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "], got '" + value + "'");
    return v;
}

IntegratorType parse_integrator_name(const std::string& flag, const std::string& v) {
    if (v == "path") return IntegratorType::path;
    if (v == "whitted") return IntegratorType::whitted;
    if (v == "albedo") return IntegratorType::albedo;
    if (v == "normals") return IntegratorType::normals;
    if (v == "depth") return IntegratorType::depth;
    if (v == "bvh-cost") return IntegratorType::bvh_cost;
    throw UsageError(flag + ": expected path|whitted|albedo|normals|depth|bvh-cost, got '" + v + "'");
}

SamplerType parse_sampler_name(const std::string& flag, const std::string& v) {
    if (v == "sobol") return SamplerType::sobol;
    if (v == "independent") return SamplerType::independent;
    throw UsageError(flag + ": expected sobol|independent, got '" + v + "'");
}

namespace {

const std::string& flag_value(const std::vector<std::string>& args, size_t& i) {
    if (i + 1 >= args.size()) throw UsageError(args[i] + ": missing value");
    return args[++i];
}

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

bool parse_override_flag(const std::vector<std::string>& args, size_t& i, RenderOverrides& o) {
    const std::string& a = args[i];
    if (a == "--spp")
        o.spp = int(parse_int_value(a, flag_value(args, i), 1, 1 << 24));
    else if (a == "--width")
        o.width = int(parse_int_value(a, flag_value(args, i), 1, 32768));
    else if (a == "--height")
        o.height = int(parse_int_value(a, flag_value(args, i), 1, 32768));
    else if (a == "--max-depth")
        o.max_depth = int(parse_int_value(a, flag_value(args, i), 0, 100000));
    else if (a == "--seed")
        o.seed = uint64_t(parse_int_value(a, flag_value(args, i), 0, (1LL << 62)));
    else if (a == "--integrator")
        o.integrator = parse_integrator_name(a, flag_value(args, i));
    else if (a == "--time")
        o.time_limit_s = parse_real_value(a, flag_value(args, i), 0.0, 1e9);
    else if (a == "--target-error")
        o.target_error = parse_real_value(a, flag_value(args, i), 1e-6, 1e3);
    else if (a == "--builder") {
        const std::string& v = flag_value(args, i);
        BvhBuilder b{};
        if (!parse_bvh_builder(v, b))
            throw UsageError(a + ": expected binned|sweep|reinsert, got '" + v + "'");
        o.bvh_builder = b;
    } else if (a == "--layout") {
        const std::string& v = flag_value(args, i);
        BvhLayout l{};
        if (!parse_bvh_layout(v, l))
            throw UsageError(a + ": expected " + kBvhLayoutChoices + ", got '" + v + "'");
        o.bvh_layout = l;
    } else if (a == "--sampler")
        o.sampler = parse_sampler_name(a, flag_value(args, i));
    else if (a == "--exposure")
        o.exposure = float(parse_real_value(a, flag_value(args, i), -64.0, 64.0));
    else if (a == "--tonemap") {
        const std::string& v = flag_value(args, i);
        const std::optional<Tonemap> t = tonemap_from_name(v);
        if (!t) throw UsageError(a + ": expected clamp|reinhard|aces|filmic, got '" + v + "'");
        o.tonemap = *t;
    } else
        return false;
    return true;
}

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
}

RenderArgs parse_render_args(const std::vector<std::string>& args) {
    RenderArgs r;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "-h" || a == "--help")
            r.help = true;
        else if (a == "-o" || a == "--output")
            r.output = flag_value(args, i);
        else if (a == "--threads")
            r.threads = int(parse_int_value(a, flag_value(args, i), 1, 1024));
        else if (a == "--quiet" || a == "-q")
            r.quiet = true;
        else if (a == "--stats")
            r.stats = true;
        else if (a == "--checkpoint")
            r.checkpoint_s = parse_real_value(a, flag_value(args, i), 0.1, 1e9);
        else if (a == "--resume")
            r.resume = flag_value(args, i);
        else if (a == "--reference")
            r.reference = flag_value(args, i);
        else if (a == "--preview")
            r.preview = true;
        else if (a == "--preview-dump")
            r.preview_dump = flag_value(args, i);
        else if (a == "--frames")
            r.frames = parse_frame_range(a, flag_value(args, i));
        else if (parse_override_flag(args, i, r.overrides))
            continue;
        else if (!a.empty() && a[0] == '-')
            throw UsageError("unknown option '" + a + "'");
        else if (r.scene)
            throw UsageError("more than one scene given ('" + *r.scene + "' and '" + a + "')");
        else
            r.scene = a;
    }
    if (r.frames) {
        if (r.resume)
            throw UsageError("--frames and --resume cannot be combined (resume one frame at a time)");
        frame_output_name(r.output, r.frames->first);  // checks the pattern now
    }
    return r;
}

}  // namespace sahara
