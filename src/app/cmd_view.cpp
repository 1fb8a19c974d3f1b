#include <cstdio>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/render_args.h"
#include "app/tool_args.h"
#include "io/model_loader.h"
#include "io/view_scene.h"

namespace sahara {

namespace {

const char* const kViewUsage =
    "usage: sahara view MODEL [-o OUT.png] [--spp N] [--size WxH] [--up y|z] [--gltf-camera N] [render "
    "options]\n"
    "\n"
    "Renders a downloaded model (.obj with its .mtl, .gltf, .glb) with no scene file: a camera\n"
    "framing it from a three-quarter view, a ground plane under it, the sky and a sun.\n"
    "\n"
    "  -o, --output FILE   output image (default view.png)\n"
    "  --size WxH          image size (default 800x600)\n"
    "  --up y|z            the model's up axis (default: y for glTF, guessed for OBJ)\n"
    "  --gltf-camera N     look through the model's glTF camera N instead\n"
    "  --no-ground         no ground plane\n"
    "  every `sahara render` option (--spp, --threads, --preview, --integrator, ...) works too\n";

struct ViewArgs {
    RenderArgs render;
    ViewOptions view;
};

ViewArgs parse_view_args(const std::vector<std::string>& args) {
    ViewArgs v;
    std::vector<std::string> rest;
    bool output_given = false;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size()) throw UsageError(a + ": missing value");
            return args[++i];
        };
        if (a == "--size") {
            const std::string& s = value();
            const size_t x = s.find('x');
            if (x == std::string::npos) throw UsageError("--size: expected WxH, got '" + s + "'");
            v.render.overrides.width = int(parse_int_value("--size", s.substr(0, x), 1, 32768));
            v.render.overrides.height = int(parse_int_value("--size", s.substr(x + 1), 1, 32768));
        } else if (a == "--up") {
            const std::string& s = value();
            if (s != "y" && s != "z") throw UsageError("--up: expected y or z, got '" + s + "'");
            v.view.up = s == "y" ? UpAxis::y : UpAxis::z;
        } else if (a == "--gltf-camera") {
            v.view.gltf_camera = int(parse_int_value(a, value(), 0, 1 << 20));
        } else if (a == "--no-ground") {
            v.view.ground = false;
        } else {
            output_given |= a == "-o" || a == "--output";
            rest.push_back(a);
        }
    }
    const RenderOverrides size = v.render.overrides;
    v.render = parse_render_args(rest);
    if (size.width) v.render.overrides.width = size.width;
    if (size.height) v.render.overrides.height = size.height;
    if (!output_given) v.render.output = "view.png";
    v.render.auto_exposure = true;
    if (!v.render.help && !v.render.scene) throw UsageError("no MODEL given");
    return v;
}

bool is_gltf_file(const std::string& file) {
    const std::string ext = std::filesystem::path(file).extension().string();
    return ext == ".gltf" || ext == ".glb" || ext == ".GLTF" || ext == ".GLB";
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
    return run_render(v.render,
                      [&] { return make_view_scene(load_model(model), is_gltf_file(model), v.view, model); });
}

}  // namespace sahara
