/// sahara.Scene, render and write_image: the library's render path
/// (pipeline/render_pipeline.h, the one `sahara render` takes) behind numpy.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <omp.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "base/error.h"
#include "io/image_io.h"
#include "io/scene_parser.h"
#include "pipeline/bvh_report.h"
#include "pipeline/render_pipeline.h"
#include "pipeline/scene_info.h"
#include "python/bindings.h"
#include "render/bvh_cost.h"
#include "render/renderer.h"
#include "render/tonemap.h"

namespace py = pybind11;

namespace sahara::python {

std::string type_name(const py::handle& h) { return py::str(py::type::handle_of(h).attr("__name__")); }

std::optional<int64_t> int_arg(const py::object& v, const char* name, int64_t lo, int64_t hi) {
    if (v.is_none()) return std::nullopt;
    if (py::isinstance<py::bool_>(v) || !PyIndex_Check(v.ptr()))
        throw py::type_error(std::string(name) + ": expected an integer, got " + type_name(v));
    int64_t x = 0;
    try {
        x = py::cast<int64_t>(py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr())));
    } catch (const py::cast_error&) {
        throw py::value_error(std::string(name) + ": expected an integer in [" + std::to_string(lo) + ", " +
                              std::to_string(hi) + "], got " + std::string(py::repr(v)));
    }
    if (x < lo || x > hi)
        throw py::value_error(std::string(name) + ": expected an integer in [" + std::to_string(lo) + ", " +
                              std::to_string(hi) + "], got " + std::to_string(x));
    return x;
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The name a dict scene carries in messages ("<dict>: objects[2].radius: ...");
/// its empty parent directory makes relative paths resolve against the cwd.
constexpr const char* kDictSceneName = "<dict>";

std::optional<double> real_arg(const py::object& v, const char* name, double lo, double hi) {
    if (v.is_none()) return std::nullopt;
    if (py::isinstance<py::bool_>(v) || !(py::isinstance<py::float_>(v) || PyIndex_Check(v.ptr())))
        throw py::type_error(std::string(name) + ": expected a number, got " + type_name(v));
    const double x = py::cast<double>(py::float_(v));
    if (!(x > lo && x <= hi))
        throw py::value_error(std::string(name) + ": expected a number in (" + std::to_string(lo) + ", " +
                              std::to_string(hi) + "], got " + std::string(py::repr(v)));
    return x;
}

std::optional<std::string> str_arg(const py::object& v, const char* name) {
    if (v.is_none()) return std::nullopt;
    if (!py::isinstance<py::str>(v))
        throw py::type_error(std::string(name) + ": expected a str, got " + type_name(v));
    return v.cast<std::string>();
}

IntegratorType integrator_from_name(const std::string& name) {
    static const std::pair<const char*, IntegratorType> names[] = {
        {"path", IntegratorType::path},     {"whitted", IntegratorType::whitted},
        {"albedo", IntegratorType::albedo}, {"normals", IntegratorType::normals},
        {"depth", IntegratorType::depth},   {"bvh-cost", IntegratorType::bvh_cost}};
    for (const auto& [n, t] : names)
        if (name == n) return t;
    throw py::value_error("integrator: expected path|whitted|albedo|normals|depth|bvh-cost, got '" + name +
                          "'");
}

Tonemap tonemap_arg(const std::string& name) {
    const std::optional<Tonemap> t = tonemap_from_name(name);
    if (!t) throw py::value_error("tonemap: expected clamp|reinhard|aces|filmic, got '" + name + "'");
    return *t;
}

/// The keyword arguments of render(), checked with the command line's ranges.
struct RenderKwargs {
    RenderOverrides overrides;
    int threads = 0;
    bool progress = false;
};

RenderKwargs parse_kwargs(const py::object& spp, const py::object& width, const py::object& height,
                          const py::object& seed, const py::object& max_depth, const py::object& threads,
                          const py::object& integrator, const py::object& time, bool progress) {
    RenderKwargs k;
    RenderOverrides& o = k.overrides;
    if (auto v = int_arg(spp, "spp", 1, 1 << 24)) o.spp = int(*v);
    if (auto v = int_arg(width, "width", 1, 32768)) o.width = int(*v);
    if (auto v = int_arg(height, "height", 1, 32768)) o.height = int(*v);
    if (auto v = int_arg(max_depth, "max_depth", 1, 1024)) o.max_depth = int(*v);
    if (!seed.is_none()) {
        if (py::isinstance<py::bool_>(seed) || !PyIndex_Check(seed.ptr()))
            throw py::type_error("seed: expected an integer, got " + type_name(seed));
        try {
            o.seed = py::cast<uint64_t>(py::reinterpret_steal<py::object>(PyNumber_Index(seed.ptr())));
        } catch (const py::cast_error&) {
            throw py::value_error("seed: expected an integer in [0, 2**64), got " +
                                  std::string(py::repr(seed)));
        }
    }
    if (auto v = str_arg(integrator, "integrator")) o.integrator = integrator_from_name(*v);
    if (auto v = real_arg(time, "time", 0.0, 1e9)) o.time_limit_s = *v;
    if (auto v = int_arg(threads, "threads", 0, 1 << 16)) k.threads = int(*v);
    k.progress = progress;
    return k;
}

/// A scene loaded and built once, rendered any number of times.
class PyScene {
   public:
    PyScene(const py::object& source, const py::object& variant_arg) {
        const auto t = Clock::now();
        const std::optional<std::string> variant = str_arg(variant_arg, "variant");
        SceneDesc desc;
        if (source.is_none()) {
            desc = load_scene_source(std::nullopt, variant);
        } else if (py::isinstance<py::dict>(source)) {
            if (variant)
                throw py::value_error(
                    "variant: applies to a glTF model path; a dict names its variants with the mesh "
                    "object's 'variant' key");
            const Json json = json_from_python(source, "scene");
            py::gil_scoped_release unlocked;
            desc = parse_scene_value(json, kDictSceneName);
        } else if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
            const std::string path = py::str(py::module_::import("os").attr("fspath")(source));
            py::gil_scoped_release unlocked;
            desc = load_scene_source(path, variant);
        } else {
            throw py::type_error("scene: expected a path, a dict or None, got " + type_name(source));
        }
        const double load = seconds_since(t);
        const auto t_build = Clock::now();
        {
            py::gil_scoped_release unlocked;
            scene_ = std::make_unique<Scene>(prepare_scene(desc, RenderOverrides{}));
        }
        settings_ = scene_->render;
        info_ = describe_scene(desc, *scene_).to_json();
        info_["Time"] = {{"Load", load}, {"Build", seconds_since(t_build)}};
    }

    const Scene& scene() const { return *scene_; }
    const RenderSettings& settings() const { return settings_; }
    std::mutex& busy() { return busy_; }
    Scene& scene_for_render() { return *scene_; }
    const nlohmann::json& info() const { return info_; }

   private:
    std::unique_ptr<Scene> scene_;
    RenderSettings settings_;  ///< the scene's own settings; render() overrides a copy
    std::mutex busy_;          ///< one render at a time per scene (render settings live in it)
    nlohmann::json info_;
};

/// Linear RGB as a float32 H x W x 3 array that owns the pixels (no copy).
py::array_t<float> rgb_array(std::vector<float>&& rgb, int width, int height) {
    auto* owned = new std::vector<float>(std::move(rgb));
    py::capsule free_pixels(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    return py::array_t<float>({size_t(height), size_t(width), size_t(3)}, owned->data(), free_pixels);
}

/// Renders on worker threads with the GIL released; this thread wakes every
/// tick to let Python run its signal handlers, and a KeyboardInterrupt (or any
/// exception a handler raises) stops the render at the next pixel.
RenderResult render_interruptibly(const Scene& scene, Film& film, const RenderKwargs& k) {
    std::atomic<bool> stop{false};
    bool raised = false;
    RenderOptions options;
    options.threads = k.threads;
    options.progress = k.progress;
    options.stop = &stop;
    options.tick_seconds = 0.05;
    options.on_tick = [&](RenderSession&) {
        if (raised) return;
        py::gil_scoped_acquire locked;
        if (PyErr_CheckSignals() != 0) {  // the exception stays set on this thread
            raised = true;
            stop = true;
        }
    };
    RenderResult result;
    {
        py::gil_scoped_release unlocked;
        result = render_image(scene, film, options);
    }
    if (raised) throw py::error_already_set();
    return result;
}

/// What render() returns to __init__.py: the pixels and what the Image keeps.
py::tuple render_scene(PyScene& ps, const RenderKwargs& k) {
    RenderSettings settings = ps.settings();
    k.overrides.apply(settings);
    std::unique_lock<std::mutex> lock(ps.busy(), std::defer_lock);
    {
        py::gil_scoped_release unlocked;  // another thread may hold the lock while rendering
        lock.lock();
    }
    Scene& scene = ps.scene_for_render();
    scene.render = settings;
    py::dict meta;
    meta["exposure"] = settings.exposure;
    meta["tonemap"] = std::string(tonemap_name(settings.tonemap));
    meta["spp_requested"] = settings.spp;
    meta["seed"] = settings.seed;
    if (settings.integrator == IntegratorType::bvh_cost) {
        // One primary ray per pixel and a legend, as `sahara render --integrator bvh-cost` writes it.
        BvhCostImage img;
        {
            py::gil_scoped_release unlocked;
            img = render_bvh_cost(scene, settings.width, settings.height,
                                  k.threads > 0 ? k.threads : omp_get_max_threads());
        }
        meta["mean_cost"] = img.mean_cost;
        meta["max_cost"] = img.max_cost;
        return py::make_tuple(rgb_array(std::move(img.rgb), img.width, img.height), meta);
    }
    Film film(settings.width, settings.height);
    const RenderResult r = render_interruptibly(scene, film, k);
    meta["spp"] = r.spp_done;
    meta["seconds"] = r.seconds;
    meta["samples"] = r.samples;
    meta["complete"] = r.stop == StopReason::complete || r.stop == StopReason::converged;
    return py::make_tuple(rgb_array(film.to_rgb(), film.width(), film.height()), meta);
}

/// write_image: the array as linear RGB, through the CLI's tone curve and encoder.
size_t write_array(const py::object& path_like, const py::object& array, float exposure,
                   const std::string& tonemap) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(path_like));
    check_output_path(path);  // the CLI's formats and messages, before any work
    const Tonemap curve = tonemap_arg(tonemap);
    if (!std::isfinite(exposure) || exposure < -64 || exposure > 64)
        throw py::value_error("exposure: expected a number in [-64, 64] (stops)");
    const py::array any = py::array::ensure(array);
    if (!any) throw py::type_error("array: expected a numpy array, got " + type_name(array));
    const char kind = any.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
        throw py::type_error("array: expected a float or integer array, got dtype " +
                             std::string(py::str(any.dtype())));
    if (any.ndim() != 3 || any.shape(2) != 3 || any.shape(0) < 1 || any.shape(1) < 1 ||
        any.shape(0) > 32768 || any.shape(1) > 32768)
        throw py::value_error("array: expected an H x W x 3 array, H and W in 1..32768, got shape " +
                              std::string(py::str(any.attr("shape"))));
    const auto pixels = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(any);
    const int height = int(pixels.shape(0)), width = int(pixels.shape(1));
    std::vector<float> rgb(pixels.data(), pixels.data() + pixels.size());
    py::gil_scoped_release unlocked;
    return write_rgb_image(path, width, height, rgb, exposure, curve,
                           {{"integrator", "python"}, {"version", SAHARA_VERSION}});
}

/// read_image: any image sahara reads, as linear RGB (8-bit formats sRGB-decoded).
py::array_t<float> read_array(const py::object& path_like) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(path_like));
    std::shared_ptr<const Image> img;
    {
        py::gil_scoped_release unlocked;
        img = read_image(path, !is_hdr_output(path));
    }
    std::vector<float> rgb(size_t(img->width) * size_t(img->height) * 3);
    for (size_t i = 0, n = rgb.size() / 3; i < n; ++i)
        for (size_t c = 0; c < 3; ++c) rgb[3 * i + c] = img->rgba[4 * i + c];
    return rgb_array(std::move(rgb), img->width, img->height);
}

py::object bvh_stats(const PyScene& ps, const py::object& builder, const py::object& layout,
                     const py::object& width, const py::object& height, const py::object& threads) {
    BvhReportOptions o;
    if (auto name = str_arg(builder, "builder")) {
        BvhBuilder b{};
        if (!parse_bvh_builder(*name, b))
            throw py::value_error("builder: expected binned|sweep|reinsert|sbvh|auto, got '" + *name + "'");
        o.builder = b;
    }
    if (auto name = str_arg(layout, "layout")) {
        BvhLayout l{};
        if (!parse_bvh_layout(*name, l))
            throw py::value_error("layout: expected " + std::string(kBvhLayoutChoices) + ", got '" + *name +
                                  "'");
        o.layout = l;
    }
    o.width = int(int_arg(width, "width", 1, 32768).value_or(1024));
    o.height = int(int_arg(height, "height", 1, 32768).value_or(1024));
    // 0 would change OpenMP's thread count for the rest of the process.
    o.threads = int(int_arg(threads, "threads", 0, 1 << 16).value_or(0));
    if (o.threads == 0) o.threads = omp_get_max_threads();
    o.from_scene_file = true;  // every Scene has a camera: aim the primary rays through it
    nlohmann::ordered_json report;
    {
        py::gil_scoped_release unlocked;
        report = bvh_report(ps.scene(), ps.scene().source, o);
    }
    return python_from_json(report);
}

}  // namespace

void bind_errors(py::module_& m) {
    py::register_exception<InputError>(m, "InputError", PyExc_ValueError).attr("__doc__") =
        "Bad scene input (a ValueError): the command line's message, naming the file (<dict> for a "
        "dict), the key path and what was expected, e.g. '<dict>: objects[2].radius: expected a number "
        "> 0, got -1'. Missing or unreadable files and unsupported image extensions raise it too.";
}

void bind_render(py::module_& m) {
    py::class_<PyScene>(m, "Scene",
                        "A scene loaded and built once (path, dict or None), rendered many times.")
        .def(py::init<const py::object&, const py::object&>(), py::arg("scene") = py::none(), py::kw_only(),
             py::arg("variant") = py::none(),
             "Loads and builds the scene once: a scene file (.json), a model (.obj, .gltf, .glb, framed "
             "as `sahara view` frames it), a dict in the scene format, or None for the built-in default "
             "scene. variant: the glTF model's KHR_materials_variants variant to render (None: the "
             "default materials). Raises InputError for bad scene input and for a variant the model "
             "does not have.")
        .def(
            "_render",
            [](PyScene& ps, const py::object& spp, const py::object& width, const py::object& height,
               const py::object& seed, const py::object& max_depth, const py::object& threads,
               const py::object& integrator, const py::object& time, bool progress) {
                return render_scene(ps, parse_kwargs(spp, width, height, seed, max_depth, threads, integrator,
                                                     time, progress));
            },
            py::kw_only(), py::arg("spp") = py::none(), py::arg("width") = py::none(),
            py::arg("height") = py::none(), py::arg("seed") = py::none(), py::arg("max_depth") = py::none(),
            py::arg("threads") = py::none(), py::arg("integrator") = py::none(), py::arg("time") = py::none(),
            py::arg("progress") = false)
        .def(
            "info", [](const PyScene& ps) { return python_from_json(ps.info()); },
            "What `sahara info --json` reports as a dict: Scene, Objects, Materials (counts by type and "
            "one entry per material), Textures, Lights, Bounds, Memory, Features, and Time (Load and "
            "Build seconds).")
        .def("bvh_stats", &bvh_stats, py::kw_only(), py::arg("builder") = py::none(),
             py::arg("layout") = py::none(), py::arg("width") = py::none(), py::arg("height") = py::none(),
             py::arg("threads") = py::none(),
             "The BVH report of `sahara bvh FILE --json` as a dict (nodes, leaves, SAH cost, bytes, "
             "build time, the mean work of primary, diffuse and shadow rays). builder: 'auto', "
             "'binned', 'sweep', 'reinsert' or 'sbvh'; layout: 'wide8' or 'pairs'; the primary rays are "
             "a width x height grid (default 1024 x 1024) through the scene's camera.")
        .def_property_readonly(
            "source", [](const PyScene& ps) { return ps.scene().source; },
            "The scene's file name ('<dict>' for a dict, '<default>' for the built-in scene).")
        .def_property_readonly(
            "settings",
            [](const PyScene& ps) {
                const RenderSettings& r = ps.settings();
                py::dict d;
                d["width"] = r.width;
                d["height"] = r.height;
                d["spp"] = r.spp;
                d["max_depth"] = r.max_depth;
                d["seed"] = r.seed;
                d["exposure"] = r.exposure;
                d["tonemap"] = std::string(tonemap_name(r.tonemap));
                return d;
            },
            "The scene's own render settings as a dict: what each render starts from before its "
            "keywords.");
    m.def("_read_image", &read_array, py::arg("path"));
    m.def("_write_image", &write_array, py::arg("path"), py::arg("array"), py::kw_only(),
          py::arg("exposure") = 0.0f, py::arg("tonemap") = "clamp");
}

}  // namespace sahara::python
