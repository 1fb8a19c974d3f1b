#include <omp.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include "app/commands.h"
#include "pipeline/mesh_input.h"
#include "app/mpi_render.h"
#include "app/preview.h"
#include "app/render_args.h"
#include "app/render_file.h"
#include "app/signals.h"
#include "base/counters.h"
#include "base/error.h"
#include "base/log.h"
#include "io/files.h"
#include "io/image_io.h"
#include "pipeline/render_pipeline.h"
#include "render/progress.h"
#include "render/renderer.h"
#include "render/bvh_cost.h"
#include "render/features.h"
#include "render/stats.h"
#include "render/tonemap.h"
#include "io/scene_parser.h"

namespace sahara {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Wall time of each phase, for --stats.
struct PhaseTimes {
    double load = 0, build = 0, render = 0, write = 0;
};

/// Where a non-EXR output keeps its resumable state.
fs::path partial_path(const fs::path& output) { return fs::path(output.string() + ".partial.exr"); }

/// Everything one `sahara render` run needs besides the scene.
struct RenderJob {
    RenderJob(const RenderArgs& a, const Scene& s, Film& f) : args(a), scene(s), film(f) {}
    const RenderArgs& args;
    const Scene& scene;
    Film& film;
    double previous_seconds = 0;  ///< render time recorded in a resumed file
    PhaseTimes times;
    std::unique_ptr<Preview> preview;
    int snapshots = 0;
    Clock::time_point last_checkpoint = Clock::now();
    MpiSession* mpi = nullptr;  ///< set when the render is split across MPI ranks
};

/// Copies a consistent film out of a running render.
using SnapshotFn = std::function<void(Film&)>;

/// Writes a consistent copy of the film while the render runs.
void write_snapshot(RenderJob& job, const SnapshotFn& snapshot, double elapsed, const fs::path& file) {
    Film copy(job.film.width(), job.film.height());
    snapshot(copy);
    RenderResult partial;
    partial.spp_done = int(min_sample_count(copy));
    partial.stop = StopReason::interrupted;
    write_render(file, job.scene, copy,
                 render_metadata(job.scene, copy, partial, job.previous_seconds + elapsed));
}

void write_snapshot(RenderJob& job, RenderSession& session, const fs::path& file) {
    write_snapshot(
        job, [&session](Film& f) { session.snapshot(f); }, session.elapsed_seconds(), file);
}

/// --checkpoint: the output (and the resumable OUT.partial.exr) every so often.
void maybe_checkpoint(RenderJob& job, const SnapshotFn& snapshot, double elapsed) {
    if (!job.args.checkpoint_s || seconds_since(job.last_checkpoint) < *job.args.checkpoint_s) return;
    const fs::path out(job.args.output);
    write_snapshot(job, snapshot, elapsed, out);
    if (file_kind(out) != FileKind::exr) write_snapshot(job, snapshot, elapsed, partial_path(out));
    job.last_checkpoint = Clock::now();
}

void on_tick(RenderJob& job, RenderSession& session) {
    if (job.preview) {
        job.preview->update(session);
        if (job.preview->take_stop_request()) session.request_stop(StopReason::interrupted);
        if (job.preview->take_snapshot_request()) {
            const fs::path out(job.args.output);
            const fs::path snap =
                out.parent_path() / (out.stem().string() + ".snapshot-" + std::to_string(++job.snapshots) +
                                     out.extension().string());
            write_snapshot(job, session, snap);
            log_info("snapshot written to " + snap.string());
        }
    }
    maybe_checkpoint(
        job, [&session](Film& f) { session.snapshot(f); }, session.elapsed_seconds());
}

// --- MPI: one image across ranks (see app/mpi_render.h) ----------------------

/// Rank 0's render of a distributed job: every rank renders tiles, rank 0
/// checkpoints. Ranks lost on the way are reported and end the job after writing.
RenderResult render_distributed(RenderJob& job, const RenderOptions& local) {
    if (job.preview) log_warning("--preview is not available when rendering across MPI ranks");
    job.preview.reset();
    DistributedOptions options;
    options.threads = local.threads;
    options.progress = local.progress;
    options.stop = local.stop;
    options.on_tick = [&job](DistributedRender& d) {
        maybe_checkpoint(
            job, [&d](Film& f) { d.snapshot(f); }, d.elapsed_seconds());
    };
    DistributedRender render(*job.mpi, job.scene, job.film, options);
    const RenderResult r = render.run();
    if (render.lost_ranks() > 0) job.mpi->abort_at_exit(kExitInterrupted);
    if (job.args.stats)
        std::fprintf(stderr, "Ranks (%d):\n%s", job.mpi->size(), render.rank_report().c_str());
    return r;
}

/// The scene must be the same on every rank: rank 0 compares the others'
/// identity (scene file hash, seed, size, spp...) with its own. Collective.
bool ranks_agree(const MpiSession& mpi, const Scene& scene) {
    std::string id;
    for (const auto& [k, v] : render_identity(scene)) id += k + "=" + v + ";";
    id += "spp=" + std::to_string(scene.render.spp) + ";sampler=" + std::to_string(int(scene.render.sampler));
    const bool same = mpi.broadcast(id) == id;
    if (!same)
        std::fprintf(stderr, "sahara: rank %d: the scene or settings differ from rank 0's\n", mpi.rank());
    return mpi.all_ok(same);
}

std::string final_line(const RenderJob& job, const RenderResult& r, double est_error, double true_error) {
    const Film& f = job.film;
    char buf[512];
    std::string spp = std::to_string(r.spp_done);
    if (r.spp_max != r.spp_done) {
        std::snprintf(buf, sizeof buf, "%d-%d spp (mean %.1f)", r.spp_done, r.spp_max, r.spp_mean);
        spp = buf;
    } else {
        spp += " spp";
    }
    if (r.stop != StopReason::complete && r.stop != StopReason::converged)
        spp += " (" + std::string(stop_reason_name(r.stop)) + "; " + std::to_string(job.scene.render.spp) +
               " requested)";
    std::string error;
    if (job.scene.render.target_error) {
        std::snprintf(buf, sizeof buf, ", est. error %.4g (target %.4g%s)", est_error,
                      *job.scene.render.target_error,
                      r.stop == StopReason::converged ? ", reached" : ", not reached");
        error = buf;
    }
    if (true_error >= 0) {
        std::snprintf(buf, sizeof buf, ", true error %.4g", true_error);
        error += buf;
    }
    const double rate = r.seconds > 0 ? double(r.samples) / r.seconds / 1e6 : 0.0;
    std::snprintf(buf, sizeof buf, "sahara: %dx%d, %s%s, %.2f s, %.2f Msamples/s -> %s", f.width(),
                  f.height(), spp.c_str(), error.c_str(), r.seconds, rate, job.args.output.c_str());
    return buf;
}

void print_stats(const RenderJob& job, const RenderResult& r) {
    const Counters c = counter_totals();
    StatsReport s;
    const std::string features = describe_features(job.scene);
    s.add("Features", "Enabled", features, features);
    s.add_count("Render", "Camera rays", c.rays[int(RayKind::camera)]);
    s.add_count("Render", "Closest-hit rays (camera + bounce)", c.rays[int(RayKind::closest_hit)]);
    s.add_count("Render", "Shadow rays", c.rays[int(RayKind::shadow)]);
    s.add_count("Render", "Samples taken", r.samples);
    s.add_count("Render", "Non-finite samples discarded", r.nonfinite);
    s.add_ratio("Render", "Mean samples per pixel", r.spp_mean, "spp");
    s.add_count("BVH", "Nodes visited", c.bvh_nodes_visited);
    s.add_count("BVH", "Leaves visited", c.bvh_leaves_visited);
    s.add_count("BVH", "Primitive tests", c.bvh_primitive_tests);
    const SceneMemory m = estimate_scene_memory(job.scene);
    s.add_bytes("Memory", "Spheres", m.spheres);
    s.add_bytes("Memory", "Triangles", m.triangles);
    s.add_bytes("Memory", "Planes and boxes", m.other_geometry);
    s.add_bytes("Memory", "Textures", m.textures);
    s.add_bytes("Memory", "BVH (estimate)", m.bvh_estimate);
    s.add_bytes("Memory", "Film", uint64_t(job.film.width()) * uint64_t(job.film.height()) * 36);
    s.add_seconds("Time", "Load", job.times.load);
    s.add_seconds("Time", "Build", job.times.build);
    s.add_seconds("Time", "Render", job.times.render);
    s.add_seconds("Time", "Write", job.times.write);
    s.print(stderr);
}

/// The bvh-cost inspection image: one primary ray per pixel, no sampling.
int write_bvh_cost(const RenderArgs& a, const Scene& scene) {
    BvhCostImage img = render_bvh_cost(scene, scene.render.width, scene.render.height,
                                       a.threads > 0 ? a.threads : omp_get_max_threads());
    if (const std::string warning = draw_bvh_cost_legend(img, a.output); !warning.empty())
        log_warning(a.output + ": " + warning);
    write_image(a.output, img.width, img.height, img.rgb,
                {{"integrator", "bvh-cost"}, {"version", SAHARA_VERSION}});
    if (!a.quiet)
        std::fprintf(stderr,
                     "sahara: bvh-cost %dx%d: mean %.1f, max %.0f nodes + primitives per primary ray -> %s\n",
                     scene.render.width, scene.render.height, img.mean_cost, img.max_cost, a.output.c_str());
    return 0;
}

/// The --reference image as RGB floats (empty without one); its size must be the film's.
std::vector<float> read_reference(const RenderArgs& a, const Film& film) {
    std::vector<float> reference;
    if (!a.reference) return reference;
    const auto img = read_image(*a.reference, false);
    if (img->width != film.width() || img->height != film.height())
        throw input_error(*a.reference, "", "reference size differs from the render");
    for (size_t i = 0; i < img->rgba.size(); i += 4)
        reference.insert(reference.end(), &img->rgba[i], &img->rgba[i + 3]);
    return reference;
}

/// The lines after a render: the summary `line`, the automatic exposure, the
/// clipped pixels and, for an unfinished render, how to resume it.
void print_job_summary(const RenderJob& job, const std::string& line, std::optional<float> exposure,
                       size_t clipped, bool unfinished) {
    const fs::path out(job.args.output);
    std::fprintf(stderr, "%s\n", line.c_str());
    if (exposure)
        std::fprintf(stderr, "sahara: automatic exposure %+.2f stops (set one with --exposure)\n",
                     double(*exposure));
    if (clipped > 0)
        std::fprintf(stderr, "sahara: %zu pixels (%.2f%%) clipped by the '%s' tone curve\n", clipped,
                     100.0 * double(clipped) / (double(job.film.width()) * double(job.film.height())),
                     std::string(tonemap_name(job.scene.render.tonemap)).c_str());
    if (unfinished)
        std::fprintf(stderr, "sahara: resume with --resume %s\n",
                     (file_kind(out) == FileKind::exr ? out : partial_path(out)).string().c_str());
}

/// Renders, writes the output (and the resumable partial file if needed), reports.
int run_job(RenderJob& job, const std::atomic<bool>& signal_stop) {
    const RenderArgs& a = job.args;
    const std::vector<float> reference = read_reference(a, job.film);
    if (a.preview)
        job.preview = Preview::open(job.film.width(), job.film.height(), job.scene.render.exposure,
                                    job.scene.render.tonemap);
    RenderOptions options;
    options.threads = a.threads;
    options.progress = !a.quiet && Progress::stderr_is_tty();
    options.stop = &signal_stop;
    options.on_tick = [&job](RenderSession& s) { on_tick(job, s); };
    reset_counters();
    const RenderResult result =
        job.mpi ? render_distributed(job, options) : render_image(job.scene, job.film, options);
    job.times.render = result.seconds;

    const double est_error = estimated_relative_error(job.film);
    const double true_error = reference.empty() ? -1.0 : relative_error_to(job.film, reference);
    ImageMetadata meta = render_metadata(job.scene, job.film, result, job.previous_seconds + result.seconds);
    if (job.scene.render.target_error) meta.emplace_back("estimated_error", std::to_string(est_error));
    const auto t_write = Clock::now();
    const fs::path out(a.output);
    std::optional<float> exposure;
    if (a.auto_exposure && !a.overrides.exposure) {
        exposure = auto_exposure_stops(job.film.to_rgb());
        meta.emplace_back("exposure", std::to_string(*exposure));
    }
    const size_t clipped = write_render(out, job.scene, job.film, meta, exposure);
    const bool unfinished = result.stop == StopReason::interrupted || result.stop == StopReason::time_limit;
    std::error_code ec;
    if (file_kind(out) != FileKind::exr) {
        if (unfinished)
            write_render(partial_path(out), job.scene, job.film, meta);
        else if (a.checkpoint_s)
            fs::remove(partial_path(out), ec);
    }
    job.times.write = seconds_since(t_write);
    const std::string line = final_line(job, result, est_error, true_error);
    if (job.preview) {
        job.preview->show_final(job.film, line.substr(8));
        if (a.preview_dump) job.preview->dump(*a.preview_dump);
    }
    if (!a.quiet) print_job_summary(job, line, exposure, clipped, unfinished);
    if (result.nonfinite > 0)
        log_warning(std::to_string(result.nonfinite) + " non-finite samples were discarded");
    if (a.stats) print_stats(job, result);
    return signal_stop.load() ? kExitInterrupted : 0;
}

}  // namespace

int run_render_command(const std::vector<std::string>& args) {
    RenderArgs a;
    try {
        a = parse_render_args(args);
    } catch (const UsageError& e) {
        return usage_error("render", e.what());
    }
    if (a.help) {
        std::fputs(kRenderUsage, stdout);
        return 0;
    }
    return run_render(a, [&a] { return read_scene_argument(a.scene); });
}

namespace {

/// Loads, builds and renders one image: the whole job in one process, or
/// rank `mpi.rank()`'s part of it when `distributed`.
int render_one(const RenderArgs& a, const std::function<SceneDesc()>& load_scene, MpiSession& mpi,
               bool distributed, const std::atomic<bool>& signal_stop) {
    const bool root = !distributed || mpi.rank() == 0;
    bool agreed = false;
    try {
        set_log_quiet(a.quiet || !root);
        if (root) check_output_path(a.output);
        if (root && a.preview_dump) check_output_path(fs::path(*a.preview_dump).replace_extension(".png"));
        PhaseTimes times;
        auto t = Clock::now();
        SceneDesc desc = load_scene();
        times.load = seconds_since(t);
        t = Clock::now();
        const Scene scene = prepare_scene(desc, a.overrides, a.frame);
        times.build = seconds_since(t);
        // One primary ray per pixel: rank 0 alone draws it.
        if (scene.render.integrator == IntegratorType::bvh_cost) return root ? write_bvh_cost(a, scene) : 0;
        Film film(scene.render.width, scene.render.height);
        RenderJob job(a, scene, film);
        job.times = times;
        if (root && a.resume) job.previous_seconds = resume_film(*a.resume, scene, film);
        if (distributed) {
            agreed = true;
            if (!mpi.all_ok(true) || !ranks_agree(mpi, scene)) return 2;
            if (!root) {
                serve_distributed_render(mpi, scene, a.threads, signal_stop);
                return signal_stop.load() ? kExitInterrupted : 0;
            }
            job.mpi = &mpi;
        }
        return run_job(job, signal_stop);
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara: error: %s\n", e.what());
        // Before the agreement the other ranks learn of it there; after it they
        // would wait for tiles forever.
        if (distributed && !agreed) mpi.all_ok(false);
        if (distributed && agreed) mpi.abort(2);
        return 2;
    }
}

/// --frames A..B: whole frames, one after another; under MPI rank r takes
/// frames A+r, A+r+N, ... (static interleaving: neighbouring frames cost about
/// the same, and no rank has to coordinate).
int render_frames(const RenderArgs& a, const std::function<SceneDesc()>& load_scene, MpiSession& mpi,
                  const std::atomic<bool>& signal_stop) {
    const auto [first, last] = *a.frames;
    int worst = 0;
    for (int f = first + mpi.rank(); f <= last && !signal_stop.load(); f += mpi.size()) {
        RenderArgs frame_args = a;
        frame_args.frame = f;
        frame_args.output = frame_output_name(a.output, f);
        if (!a.quiet) log_info("frame " + std::to_string(f) + " -> " + frame_args.output);
        const int code = render_one(frame_args, load_scene, mpi, false, signal_stop);
        if (code == 2) return code;
        worst = std::max(worst, code);
    }
    return worst;
}

}  // namespace

int run_render(const RenderArgs& a, const std::function<SceneDesc()>& load_scene) {
    const std::atomic<bool>& signal_stop = install_stop_signals();
    MpiSession mpi;
    if (a.frames) return render_frames(a, load_scene, mpi, signal_stop);
    return render_one(a, load_scene, mpi, mpi.distributed(), signal_stop);
}

}  // namespace sahara
