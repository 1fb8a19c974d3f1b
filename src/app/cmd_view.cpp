#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/render_args.h"
#include "io/files.h"
#include "io/model_loader.h"
#include "io/view_scene.h"

namespace sahara {

namespace {

const char* const kViewUsage =
    "usage: sahara view MODEL [-o OUT.png] [--spp N] [--size WxH] [--up AXIS] [--env FILE.exr] [render "
    "options]\n"
    "\n"
    "Renders a downloaded model (.obj with its .mtl, .gltf, .glb) with no scene file: a camera\n"
    "framing it from a three-quarter view, a ground plane under it, a studio environment and a sun.\n"
    "\n"
    "  -o, --output FILE   output image (default view.png)\n"
    "  --size WxH          image size (default 800x600; N: N x N)\n"
    "  --up AXIS           the model's up axis: x, y, z, -x, -y or -z (default: +y for glTF;\n"
    "                      for OBJ the rule of docs/view.md, said on stderr)\n"
    "  --env FILE          light with this lat-long environment image (.exr, .hdr, ...)\n"
    "                      instead of the built-in studio\n"
    "  --env-strength S    multiplies the environment's radiance (default 1)\n"
    "  --gltf-camera N     look through the model's glTF camera N instead\n"
    "  --no-ground         no ground plane\n"
    "  --variant NAME      render the glTF file's material variant NAME (KHR_materials_variants;\n"
    "                      `sahara info MODEL` lists them)\n"
    "  every `sahara render` option (--spp, --threads, --preview, --integrator, ...) works too\n";

struct ViewArgs {
    RenderArgs render;
    ViewOptions view;
    std::optional<std::string> variant;
};

ViewArgs parse_view_args(const std::vector<std::string>& args) {
    ViewArgs v;
    v.render.output = "view.png";
    v.render.auto_exposure = true;
    parse_render_args(args, v.render, [&v](CLI::App& app) {
        app.add_option_function<std::string>("--up", [&v](const std::string& s) {
            v.view.up = parse_up_axis(s);
            if (!v.view.up) throw UsageError("--up: expected x, y, z, -x, -y or -z, got '" + s + "'");
        });
        app.add_option_function<std::string>("--env", [&v](const std::string& s) { v.view.env_file = s; });
        app.add_option_function<std::string>("--env-strength", [&v](const std::string& s) {
            v.view.env_strength = float(parse_real_value("--env-strength", s, 0.0, 1e6));
        });
        app.add_option_function<std::string>("--gltf-camera", [&v](const std::string& s) {
            v.view.gltf_camera = int(parse_int_value("--gltf-camera", s, 0, 1 << 20));
        });
        app.add_flag_callback("--no-ground", [&v] { v.view.ground = false; });
        app.add_option_function<std::string>("--variant", [&v](const std::string& s) { v.variant = s; });
    });
    if (!v.render.help && !v.render.scene) throw UsageError("no MODEL given");
    return v;
}

}  // namespace

int run_view_command(const std::vector<std::string>& args) {
    ViewArgs v;
    try {
        v = parse_view_args(args);
    } catch (const UsageError& e) {
        return usage_error("view", e.what());
    }
    if (v.render.help) {
        std::fputs(kViewUsage, stdout);
        return 0;
    }
    const std::string model = *v.render.scene;
    return run_render(v.render, [&] {
        return make_view_scene(load_model(model, Mat4::identity(), SharedMeshes::copy, v.variant),
                               file_kind(model) == FileKind::gltf, v.view, model);
    });
}

}  // namespace sahara
