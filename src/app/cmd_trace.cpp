/// `sahara trace`: traces a raw ray file against a mesh and writes raw hit
/// (and optionally occlusion) files, for checking sahara against other tracers.
#include <CLI/CLI.hpp>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "scene/accelerator.h"
#include "app/commands.h"
#include "pipeline/mesh_input.h"
#include "app/cli_args.h"
#include "base/error.h"
#include "io/files.h"

namespace sahara {

namespace {

static_assert(std::endian::native == std::endian::little, "ray and hit files are little-endian");

constexpr const char* kTraceUsage =
    "usage: sahara trace MESH --rays IN.rays --hits OUT.hits [--occlusion OUT.occl]\n"
    "  MESH         a mesh (.obj); not a scene file: ray files index OBJ triangles only (use\n"
    "               `sahara bvh` / `sahara bench` for scene files)\n"
    "  --rays       raw little-endian float32 x 8 per ray: ox oy oz dx dy dz tmin tmax (32 bytes)\n"
    "  --hits       written: per ray float32 t and uint32 primitive index (miss: +inf, 0xFFFFFFFF)\n"
    "  --occlusion  written: one byte per ray, 1 = something blocks (tmin, tmax)\n"
    "Primitive indices are triangle indices in file order; a polygon v0 v1 .. vk is fan-split\n"
    "into (v0,v1,v2), (v0,v2,v3), ..., (v0,vk-1,vk). Concave polygons are fan-split the same way\n"
    "(no ear clipping, so the fan may cover area outside the polygon). Degenerate triangles keep\n"
    "their index and are never hit. Outputs are written to a temporary file and renamed.\n";

std::vector<Ray> read_ray_file(const std::string& path) {
    const std::string bytes = read_file(path, "ray file");
    if (bytes.size() % 32 != 0)
        throw input_error(
            path, "",
            "size " + std::to_string(bytes.size()) + " is not a multiple of 32 bytes (8 float32 per ray)");
    std::vector<Ray> rays(bytes.size() / 32);
    for (size_t i = 0; i < rays.size(); ++i) {
        float f[8];
        std::memcpy(f, bytes.data() + 32 * i, 32);
        for (float x : f)
            if (std::isnan(x)) throw input_error(path, "ray " + std::to_string(i), "NaN component");
        rays[i] = Ray{{f[0], f[1], f[2]}, {f[3], f[4], f[5]}, f[6], f[7]};
        if (!is_finite(rays[i].origin) || !is_finite(rays[i].dir))
            throw input_error(path, "ray " + std::to_string(i), "infinite origin or direction");
    }
    return rays;
}

/// Writes `bytes` to `path` through a temporary: an interrupted or failed trace leaves no half file.
void write_output(const std::string& path, const std::vector<char>& bytes) {
    write_via_temporary(
        path,
        [&](const std::filesystem::path& tmp) {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            out.write(bytes.data(), std::streamsize(bytes.size()));
            return out.flush() ? std::string() : std::string("cannot write the file");
        },
        "output");
}

struct TraceArgs {
    std::string mesh, rays, hits, occlusion;  ///< occlusion empty: not written
    bool help = false;
};

/// An output that names an input (or the other output) would replace the very file
/// being read: refused before anything is traced. Outputs that do not exist yet are
/// new files, so only existing ones are compared.
void check_outputs_are_new_files(const TraceArgs& args) {
    const std::pair<const std::string*, const char*> inputs[] = {
        {&args.mesh, "the mesh"}, {&args.rays, "--rays"}, {&args.hits, "--hits"}};
    const std::pair<const std::string*, const char*> outputs[] = {{&args.hits, "--hits"},
                                                                  {&args.occlusion, "--occlusion"}};
    std::error_code ec, ec2;
    if (!args.occlusion.empty()) {
        const auto hits = std::filesystem::weakly_canonical(args.hits, ec);
        const auto occl = std::filesystem::weakly_canonical(args.occlusion, ec2);
        if (!ec && !ec2 && hits == occl)
            throw input_error(args.occlusion, "", "--occlusion names the same file as --hits");
    }
    for (const auto& [out, out_name] : outputs) {
        if (out->empty() || !std::filesystem::exists(*out, ec)) continue;
        for (const auto& [in, in_name] : inputs) {
            if (in == out || in->empty()) continue;
            if (std::filesystem::equivalent(*out, *in, ec))
                throw input_error(*out, "",
                                  std::string(out_name) + " names the same file as " + in_name +
                                      "; refusing to overwrite it");
        }
    }
}

int trace(const TraceArgs& args) {
    check_outputs_are_new_files(args);
    if (const FileKind kind = file_kind(args.mesh); kind == FileKind::scene || kind == FileKind::gltf)
        throw input_error(args.mesh, "",
                          "trace reads OBJ meshes only (primitive indices are OBJ triangle indices)");
    const std::vector<Ray> rays = read_ray_file(args.rays);
    const Scene scene = scene_from_mesh(read_obj_triangles(args.mesh));
    const Accelerator accel(scene);
    const bool want_occl = !args.occlusion.empty();
    std::vector<char> hits(rays.size() * 8), occl(want_occl ? rays.size() : 0);
#pragma omp parallel for schedule(dynamic, 1024)
    for (size_t i = 0; i < rays.size(); ++i) {
        Ray r = rays[i];
        Hit h;
        float t = kInfinity;
        uint32_t prim = kNoPrim;
        if (accel.intersect(r, h)) t = h.t, prim = prim_index(h.prim);
        std::memcpy(&hits[8 * i], &t, 4);
        std::memcpy(&hits[8 * i + 4], &prim, 4);
        if (want_occl) occl[i] = accel.occluded(rays[i]) ? 1 : 0;
    }
    write_output(args.hits, hits);
    if (want_occl) write_output(args.occlusion, occl);
    return 0;
}

TraceArgs parse_trace_args(const std::vector<std::string>& words) {
    TraceArgs a;
    CLI::App app;
    configure_app(app, a.help);
    app.add_option("--rays", a.rays);
    app.add_option("--hits", a.hits);
    app.add_option("--occlusion", a.occlusion);
    const std::vector<std::string> meshes = parse_command_line(app, words);
    if (a.help) return a;
    if (meshes.size() != 1) throw UsageError("expected one mesh file");
    if (a.rays.empty() || a.hits.empty()) throw UsageError("--rays and --hits are required");
    a.mesh = meshes[0];
    return a;
}

}  // namespace

int run_trace_command(int argc, char** argv) {
    TraceArgs args;
    try {
        args = parse_trace_args(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const UsageError& e) {
        return usage_error("trace", e.what());
    }
    if (args.help) {
        std::fputs(kTraceUsage, stdout);
        return 0;
    }
    try {
        return trace(args);
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara trace: %s\n", e.what());
        return 2;
    }
}

}  // namespace sahara
