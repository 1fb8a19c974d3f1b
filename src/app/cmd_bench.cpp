/// `sahara bench`: builds the BVH over a mesh or a scene file, traces fixed seeded
/// ray sets and reports throughput, with Embree 3 on the same rays as the
/// yardstick (triangles only: skipped for scenes with other primitives).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>

#include "scene/accelerator.h"
#include "pipeline/bench_rays.h"
#include "app/commands.h"
#include "pipeline/bvh_report.h"
#include "pipeline/mesh_input.h"
#include "io/generated_mesh.h"
#include "app/ray_batch.h"
#include "app/cli_args.h"
#include "accel/packet.h"
#include "base/error.h"
#include "base/process_usage.h"

namespace sahara {

namespace {

constexpr const char* kBenchUsage =
    "usage: sahara bench FILE [--threads N] [--ray-set primary|primary_packet|diffuse|shadow|all]\n"
    "                         [--json]\n"
    "                         [--builder binned|sweep|reinsert|sbvh|auto] [--layout L] [--size WxH|N] "
    "[--repeat K]\n"
    "                         [--no-embree] [--embree-robust] [--embree-isa ISA]\n"
    "                         [--embree-quality low|medium|high]\n"
    "       sahara bench --generated-mesh N [options above]\n"
    "       sahara bench --small-scenes   (flat loop vs tree for scenes of 1..32 primitives)\n"
    "  FILE        a mesh (.obj, .gltf, .glb) or a scene file (.json); for a scene the tree holds\n"
    "              its triangles, spheres, boxes and quadrics (planes are unbounded: not in the\n"
    "              tree, not traced), primary rays come from the scene's camera (lens centre), and\n"
    "              the Embree comparison runs only if every bounded primitive is a triangle\n"
    "  --generated-mesh N\n"
    "              instead of FILE, a displaced sphere of exactly N triangles made in memory\n"
    "              (N even, at least 6); the report adds the process's resident memory\n"
    "  --threads   threads for building and tracing (default: all cores)\n"
    "  --ray-set S ray set to trace (default all): primary = W x H camera rays framing the mesh\n"
    "              (a scene: its camera), primary_packet = the primary rays as 16-ray packets of\n"
    "              4x4 pixel tiles (Embree: rtcIntersect16 on the same tiles; also compared with\n"
    "              sahara's single rays),\n"
    "              diffuse = cosine-distributed bounces from the primary hits, shadow = occlusion\n"
    "              rays from the primary hits to a square light above the geometry (a scene: along\n"
    "              the camera's up axis, or towards its first directional light, a sun)\n"
    "              (shadow rays are also traced with a per-thread shadow cache, which tests the\n"
    "              block that stopped the thread's last ray first: figures marked cached,\n"
    "              beside, never in place of, the traversal's own)\n"
    "  --layout L  traversal structure: wide8 (default: 8-wide BVH, leaf triangles tested 4 at a\n"
    "              time, 8 with AVX2) or pairs (binary BVH, the reference); wide8 uses the widest\n"
    "              of AVX-512, AVX2 and SSE2 the CPU has (SAHARA_SIMD=avx2 or sse2 asks for a\n"
    "              narrower one)\n"
    "  --size WxH  primary image size, N x N for one number (default 1024: 1M rays per set)\n"
    "  --repeat K  time each pass K times and report the median (default 3)\n"
    "  --no-embree skip the Embree comparison\n"
    "  --embree-robust\n"
    "              build Embree's scene with RTC_SCENE_FLAG_ROBUST: robust traversal and no\n"
    "              accuracy-reducing optimisations (meant to stop rays slipping through shared\n"
    "              edges), the nearest Embree comes to sahara's guarantees (default: Embree's\n"
    "              default mode, faster and not watertight)\n"
    "  --embree-isa ISA\n"
    "              cap Embree's kernels at sse2, avx, avx2 or avx512 (default best: the widest the\n"
    "              CPU has); with SAHARA_SIMD=avx2 and --embree-isa avx2 an AVX-512 machine\n"
    "              compares both tracers as an AVX2-only machine would\n"
    "  --embree-quality Q\n"
    "              Embree's build quality: low (Morton build), medium (default: binned SAH) or\n"
    "              high (SAH with spatial splits, Embree's best tree for long thin triangles)\n"
    "  --json      print one JSON object\n"
    "Both tracers run with flush-to-zero and denormals-are-zero (Embree's recommendation) on the\n"
    "same rays. Disagreements: hit/miss differ, t differs beyond 1e-4 relative, or a different\n"
    "triangle at a t that differs beyond 1e-6 relative (closer ones are ties, listed apart).\n"
    "MRays/s is per second of elapsed time; (CPU) per second of CPU time summed over the tracing\n"
    "threads, which is steadier when other processes share the cores.\n"
    "Build: sahara's whole acceleration structure (primitive boxes, binned SAH BVH, wide tree,\n"
    "leaf blocks), Mprims/s per elapsed second (also per thread) and per CPU second; Embree's is\n"
    "rtcCommitScene alone (its primitive boxes, BVH and leaf triangles) on a device with --threads\n"
    "build threads, timed the same ways (JSON: embree_build_ms, embree_build_cpu_ms, embree_mtris_s,\n"
    "build_ratio, build_ratio_cpu; embree_setup_ms adds the device start and the buffer copies).\n"
    "confirmed: the answers differ and a double-precision brute-force test sides with sahara\n"
    "(Embree's default triangle test is not watertight: rays slip through shared edges); these\n"
    "are not counted as disagreements.\n";

struct BenchOptions {
    std::string mesh;
    size_t generated_triangles = 0;  ///< > 0: --generated-mesh instead of a file
    int threads = 1;
    std::vector<std::string> sets;
    BvhBuilder builder = BvhBuilder::binned;
    BvhLayout layout = AcceleratorOptions{}.layout;
    int width = 1024, height = 1024;
    int repeat = 3;
    bool embree = true;
    bool embree_robust = false;
    std::string embree_isa = "best";
    EmbreeQuality embree_quality = EmbreeQuality::medium;
    bool json = false;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// Wall and CPU seconds of the repeated passes over one ray set.
struct PassTimes {
    std::vector<double> wall, cpu;
    void add(const PassTime& t) {
        wall.push_back(t.wall_s);
        cpu.push_back(t.cpu_s);
    }
};

/// Median throughput and hit rate of sahara's passes over `count` rays.
nlohmann::ordered_json throughput_json(double count, const PassTimes& ours, const RayAnswers& a) {
    return {{"count", size_t(count)},
            {"mrays_s", count / median(ours.wall) * 1e-6},
            {"mrays_cpu_s", count / median(ours.cpu) * 1e-6},
            {"hit_rate", count == 0.0 ? 0.0 : double(a.hits()) / count}};
}

/// a / b, or null when there is no ratio to give (an empty ray set: no rays, no rate).
nlohmann::ordered_json ratio_or_null(double a, double b) {
    const double r = a / b;
    return std::isfinite(r) && b > 0.0 ? nlohmann::ordered_json(r) : nlohmann::ordered_json(nullptr);
}

/// Adds Embree's median throughput, the ratios and the disagreements to `j`.
void add_embree_json(nlohmann::ordered_json& j, double count, const PassTimes& theirs,
                     const Disagreements& d) {
    j["embree_mrays_s"] = count / median(theirs.wall) * 1e-6;
    j["embree_mrays_cpu_s"] = count / median(theirs.cpu) * 1e-6;
    j["ratio"] = ratio_or_null(j["mrays_s"].get<double>(), j["embree_mrays_s"].get<double>());
    j["ratio_cpu"] = ratio_or_null(j["mrays_cpu_s"].get<double>(), j["embree_mrays_cpu_s"].get<double>());
    j["disagreements"] = d.total;
    j["ties"] = d.ties;
    j["confirmed_for_sahara"] = d.confirmed_for_a;
}

/// The occlusion pass with the shadow cache (OcclusionCache), apart from the plain
/// traversal's figures: "cached" ones, and how many answers differ from the plain pass
/// (none should).
void add_cached_json(nlohmann::ordered_json& j, double count, const PassTimes& cached,
                     const PassTimes& theirs, const RayAnswers& plain, const RayAnswers& with_cache,
                     bool embree) {
    j["cached_mrays_s"] = count / median(cached.wall) * 1e-6;
    j["cached_mrays_cpu_s"] = count / median(cached.cpu) * 1e-6;
    size_t differ = 0;
    for (size_t i = 0; i < plain.prim.size(); ++i) differ += plain.prim[i] != with_cache.prim[i];
    j["cached_answers_differ"] = differ;
    if (!embree) return;
    j["cached_ratio"] = ratio_or_null(j["cached_mrays_s"].get<double>(), count / median(theirs.wall) * 1e-6);
    j["cached_ratio_cpu"] =
        ratio_or_null(j["cached_mrays_cpu_s"].get<double>(), count / median(theirs.cpu) * 1e-6);
}

nlohmann::ordered_json bench_set(const TriangleMesh& mesh, const Accelerator& accel,
                                 const EmbreeReference* embree, const std::vector<Ray>& rays, bool occlusion,
                                 const BenchOptions& opt) {
    PassTimes ours, cached, theirs;
    RayAnswers a, b, c;
    for (int k = 0; k < opt.repeat; ++k) {
        ours.add(trace_sahara(accel, rays, occlusion, opt.threads, true, a));
        if (occlusion) cached.add(trace_sahara_cached(accel, rays, opt.threads, true, c));
        if (embree) theirs.add(trace_embree(*embree, rays, occlusion, opt.threads, true, b));
    }
    const double count = double(rays.size());
    nlohmann::ordered_json j = throughput_json(count, ours, a);
    if (embree) add_embree_json(j, count, theirs, compare_answers(a, b, rays, mesh));
    if (occlusion) add_cached_json(j, count, cached, theirs, a, c, embree != nullptr);
    return j;
}

/// The primary rays as 16-ray packets of 4x4 pixel tiles, against Embree's
/// rtcIntersect16 on the same tiles; also compared with sahara's single rays.
nlohmann::ordered_json bench_packet_set(const TriangleMesh& mesh, const Accelerator& accel,
                                        const EmbreeReference* embree, const std::vector<Ray>& rays,
                                        const BenchOptions& opt) {
    PassTimes ours, theirs;
    RayAnswers a, b, single;
    for (int k = 0; k < opt.repeat; ++k) {
        ours.add(trace_sahara_packets(accel, rays, opt.width, opt.height, opt.threads, true, a));
        if (embree)
            theirs.add(trace_embree_packets(*embree, rays, opt.width, opt.height, opt.threads, true, b));
    }
    trace_sahara(accel, rays, false, opt.threads, true, single);
    const Disagreements ds = compare_answers(a, single, rays, mesh);
    const double count = double(rays.size());
    nlohmann::ordered_json j = throughput_json(count, ours, a);
    j["packet_simd"] = simd_path_name(active_simd_path());
    j["disagreements_single_ray"] = ds.total + ds.confirmed_for_a;
    j["ties_single_ray"] = ds.ties;
    if (embree) add_embree_json(j, count, theirs, compare_answers(a, b, rays, mesh));
    return j;
}

/// "compared" when Embree will run on the same triangles, else why not. Embree
/// (accel/embree_reference.h) holds triangles only, so a scene with spheres,
/// boxes or quadrics would compare different geometry.
std::string embree_plan(const BenchOptions& opt, const Scene& scene) {
    if (!opt.embree) return "skipped: --no-embree";
    if (!EmbreeReference::available()) return "skipped: sahara was built without Embree 3";
    if (scene.spheres.size() + scene.boxes.size() + scene.quadrics.size() > 0)
        return "skipped: scene has " + primitive_kinds_text(scene, false) +
               " (Embree reference holds triangles only)";
    if (scene.accelerator() && scene.accelerator()->has_cutouts())
        return "skipped: scene has cut-out triangles (the Embree reference has no alpha test)";
    if (scene.accelerator() && scene.accelerator()->one_sided_count())
        return "skipped: scene has one-sided triangles (the Embree reference culls no back faces)";
    return "compared";
}

/// The process's resident memory (MiB) by stage: a stage's peak is the high-water
/// mark while it ran (reset_peak_rss before it), its rss what it left resident.
struct MemoryStages {
    double input_rss = 0, input_peak = 0;    ///< the input read (or generated)
    double sahara_rss = 0, sahara_peak = 0;  ///< sahara's build
    double embree_rss = 0, embree_peak = 0;  ///< Embree's build (if it ran)
};

nlohmann::ordered_json memory_json(const MemoryStages& m, bool embree) {
    nlohmann::ordered_json j = {{"input_rss_mib", m.input_rss},
                                {"input_peak_rss_mib", m.input_peak},
                                {"sahara_build_rss_mib", m.sahara_rss},
                                {"sahara_build_peak_rss_mib", m.sahara_peak}};
    if (embree) {
        j["embree_build_rss_mib"] = m.embree_rss;
        j["embree_build_peak_rss_mib"] = m.embree_peak;
    }
    return j;
}

nlohmann::ordered_json run_bench(const BenchOptions& opt) {
    omp_set_num_threads(opt.threads);
    const ToolInput input =
        opt.generated_triangles ? generated_tool_input(opt.generated_triangles) : read_tool_input(opt.mesh);
    const Scene& scene = input.scene;
    const TriangleMesh& mesh = input.triangles;
    MemoryStages memory{current_rss_mib(), peak_rss_mib()};
    reset_peak_rss();
    AcceleratorOptions aopt;
    aopt.builder = opt.builder;
    aopt.layout = opt.layout;
    const Accelerator accel(scene, aopt);
    memory.sahara_rss = current_rss_mib();
    memory.sahara_peak = peak_rss_mib();
    std::unique_ptr<EmbreeReference> embree;
    const std::string embree_status = embree_plan(opt, scene);
    if (embree_status == "compared") {
        reset_peak_rss();
        embree = std::make_unique<EmbreeReference>(mesh.positions, mesh.indices, opt.embree_robust,
                                                   opt.threads, opt.embree_isa, opt.embree_quality);
        memory.embree_rss = current_rss_mib();
        memory.embree_peak = peak_rss_mib();
    }
    const BenchRaySets rays =
        make_bench_rays(scene, accel, opt.width, opt.height,
                        input.from_scene_file ? BenchAim::scene_camera : BenchAim::frame_bounds);
    nlohmann::ordered_json j = {
        {"mesh", opt.generated_triangles ? mesh.name : opt.mesh},
        {"input", input.from_scene_file ? "scene" : "mesh"},
        {"primitives", accel.primitive_count()},
        {"primitive_kinds", primitive_kinds_text(scene)},
        {"planes_outside_tree", scene.planes.size()},
        {"embree", embree_status},
        {"embree_mode", opt.embree_robust ? "robust" : "default"},
        {"embree_isa", opt.embree_isa},
        {"embree_quality", kEmbreeQualityNames[size_t(opt.embree_quality)]},
        {"threads", opt.threads},
        {"builder", bvh_builder_name(accel.builder())},
        {"references", accel.reference_count()},
        {"layout", bvh_layout_name(opt.layout)},
        {"simd", simd_path_name(active_simd_path())},
        {"node_pairing", accel.pairs_nodes() && active_simd_path() != SimdPath::sse2},
        {"occlusion_order", accel.occlusion_far_first() ? "far_first" : "slot"},
        {"tree_bytes_per_primitive",
         double(accel.bytes()) / double(std::max<size_t>(accel.primitive_count(), 1))},
        {"build_ms", accel.build_ms()},
        {"build_cpu_ms", accel.build_cpu_ms()},
        {"build_threads", opt.threads},
        {"mprims_s", double(accel.primitive_count()) / std::max(accel.build_ms() * 1e3, 1e-9)},
        {"mprims_cpu_s", double(accel.primitive_count()) / std::max(accel.build_cpu_ms() * 1e3, 1e-9)}};
    j["mprims_s_per_thread"] = j["mprims_s"].get<double>() / opt.threads;
    if (scene.instances()) j["instances"] = instance_level_json(scene);
    if (embree) {
        // rtcCommitScene alone: Embree's build from the triangle buffers (its device, started
        // before, and the buffer copies are in embree_setup_ms).
        j["embree_build_ms"] = embree->build_ms();
        j["embree_mtris_s"] = double(mesh.triangle_count()) / std::max(embree->build_ms() * 1e3, 1e-9);
        j["embree_build_cpu_ms"] = embree->build_cpu_ms();
        j["embree_mtris_cpu_s"] =
            double(mesh.triangle_count()) / std::max(embree->build_cpu_ms() * 1e3, 1e-9);
        j["embree_mtris_s_per_thread"] = j["embree_mtris_s"].get<double>() / opt.threads;
        // Build speed against Embree's: primitives per elapsed second, and per CPU second.
        j["build_ratio"] = j["mprims_s"].get<double>() / j["embree_mtris_s"].get<double>();
        j["build_ratio_cpu"] = j["mprims_cpu_s"].get<double>() / j["embree_mtris_cpu_s"].get<double>();
        j["embree_setup_ms"] = embree->setup_ms();
        j["embree_bvh_bytes_per_primitive"] =
            double(embree->bvh_bytes()) / double(std::max<size_t>(accel.primitive_count(), 1));
    }
    if (opt.generated_triangles) j["memory"] = memory_json(memory, embree != nullptr);
    for (const std::string& set : opt.sets) {
        if (set == "primary_packet") {
            j["rays"][set] = bench_packet_set(mesh, accel, embree.get(), rays.primary, opt);
            continue;
        }
        const std::vector<Ray>& r = set == "primary"   ? rays.primary
                                    : set == "diffuse" ? rays.diffuse
                                                       : rays.shadow;
        j["rays"][set] = bench_set(mesh, accel, embree.get(), r, set == "shadow", opt);
    }
    return j;
}

/// The process's resident memory by stage: what it left, and its peak while it ran.
/// A ratio for the text table: two decimals, or "-" where the JSON has null.
std::string ratio_text(const nlohmann::ordered_json& r) {
    if (!r.is_number()) return "-";
    char text[32];
    std::snprintf(text, sizeof text, "%.2f", r.get<double>());
    return text;
}

void print_memory(const nlohmann::ordered_json& m) {
    std::printf("memory      resident MiB after (peak during): input %.0f (%.0f), sahara's build %.0f (%.0f)",
                m["input_rss_mib"].get<double>(), m["input_peak_rss_mib"].get<double>(),
                m["sahara_build_rss_mib"].get<double>(), m["sahara_build_peak_rss_mib"].get<double>());
    if (m.contains("embree_build_rss_mib"))
        std::printf(", Embree's build %.0f (%.0f)", m["embree_build_rss_mib"].get<double>(),
                    m["embree_build_peak_rss_mib"].get<double>());
    std::printf("\n");
}

void print_text(const nlohmann::ordered_json& j) {
    std::printf("%-11s %s\nprimitives  %zu (%s)\n", j["input"].get<std::string>().c_str(),
                j["mesh"].get<std::string>().c_str(), j["primitives"].get<size_t>(),
                j["primitive_kinds"].get<std::string>().c_str());
    if (const auto planes = j["planes_outside_tree"].get<size_t>())
        std::printf("planes      %zu, unbounded: not in the tree, not traced here\n", planes);
    if (j.contains("instances")) {
        const auto& in = j["instances"];
        std::printf(
            "instances   %zu of %zu prototypes, top-level tree %zu nodes; %zu triangles stored, %zu drawn\n"
            "            (not traced here: the rays below see the scene's own tree only)\n",
            in["instances"].get<size_t>(), in["prototypes"].get<size_t>(),
            in["top_level_nodes"].get<size_t>(), in["triangles_stored"].get<size_t>(),
            in["triangles_drawn"].get<size_t>());
    }
    std::printf("threads     %d\n", j["threads"].get<int>());
    std::printf(
        "build       %.1f ms (%.2f Mprims/s, %.2f per thread), CPU %.1f ms (%.2f Mprims/s) (%s SAH, %s "
        "layout, %s%s%s)",
        j["build_ms"].get<double>(), j["mprims_s"].get<double>(), j["mprims_s_per_thread"].get<double>(),
        j["build_cpu_ms"].get<double>(), j["mprims_cpu_s"].get<double>(),
        j["builder"].get<std::string>().c_str(), j["layout"].get<std::string>().c_str(),
        j["simd"].get<std::string>().c_str(), j["node_pairing"].get<bool>() ? ", node pairing" : "",
        j["occlusion_order"] == "far_first" ? ", occlusion rays farthest child first" : "");
    if (j.contains("embree_build_ms"))
        std::printf(
            "\nEmbree      build %.1f ms (%.2f Mtris/s, %.2f per thread), CPU %.1f ms (%.2f Mtris/s) "
            "(rtcCommitScene, %d threads), %s quality, %s mode, %s%s\nbuild ratio %.2f, CPU %.2f (sahara / "
            "Embree)",
            j["embree_build_ms"].get<double>(), j["embree_mtris_s"].get<double>(),
            j["embree_mtris_s_per_thread"].get<double>(), j["embree_build_cpu_ms"].get<double>(),
            j["embree_mtris_cpu_s"].get<double>(), j["threads"].get<int>(),
            j["embree_quality"].get<std::string>().c_str(), j["embree_mode"].get<std::string>().c_str(),
            j["embree_isa"] == "best" ? "" : "ISA up to ", j["embree_isa"].get<std::string>().c_str(),
            j["build_ratio"].get<double>(), j["build_ratio_cpu"].get<double>());
    std::printf("\nbytes/prim  %.1f (tree + leaf-ordered primitive data)",
                j["tree_bytes_per_primitive"].get<double>());
    if (j.contains("embree_bvh_bytes_per_primitive"))
        std::printf(", Embree %.1f (what its build allocated)",
                    j["embree_bvh_bytes_per_primitive"].get<double>());
    std::printf("\n");
    if (j.contains("memory")) print_memory(j["memory"]);
    const bool embree = j.contains("embree_build_ms");
    if (!embree) std::printf("Embree      %s\n", j["embree"].get<std::string>().c_str());
    std::printf("%-14s %9s %8s %8s %8s", "rays", "count", "hit rate", "MRays/s", "(CPU)");
    if (embree)
        std::printf(" %8s %8s %6s %6s %6s %5s %9s", "Embree", "(CPU)", "ratio", "(CPU)", "disagr", "ties",
                    "confirmed");
    std::printf("\n");
    for (const auto& [name, r] : j["rays"].items()) {
        std::printf("%-14s %9zu %8.3f %8.2f %8.2f", name.c_str(), r["count"].get<size_t>(),
                    r["hit_rate"].get<double>(), r["mrays_s"].get<double>(), r["mrays_cpu_s"].get<double>());
        if (embree)
            std::printf(" %8.2f %8.2f %6s %6s %6zu %5zu %9zu", r["embree_mrays_s"].get<double>(),
                        r["embree_mrays_cpu_s"].get<double>(), ratio_text(r["ratio"]).c_str(),
                        ratio_text(r["ratio_cpu"]).c_str(), r["disagreements"].get<size_t>(),
                        r["ties"].get<size_t>(), r["confirmed_for_sahara"].get<size_t>());
        std::printf("\n");
    }
    if (j["rays"].contains("shadow") && j["rays"]["shadow"].contains("cached_mrays_s")) {
        const auto& r = j["rays"]["shadow"];
        std::printf("shadow, cached: %.2f MRays/s, CPU %.2f", r["cached_mrays_s"].get<double>(),
                    r["cached_mrays_cpu_s"].get<double>());
        if (r.contains("cached_ratio"))
            std::printf(", ratio %s, CPU %s", ratio_text(r["cached_ratio"]).c_str(),
                        ratio_text(r["cached_ratio_cpu"]).c_str());
        std::printf(" (per-thread shadow cache; %zu answers differ from the plain traversal)\n",
                    r["cached_answers_differ"].get<size_t>());
    }
    if (j["rays"].contains("primary_packet")) {
        const auto& r = j["rays"]["primary_packet"];
        std::printf("primary_packet: %s kernel; against sahara's single rays %zu disagreements, %zu ties\n",
                    r["packet_simd"].get<std::string>().c_str(), r["disagreements_single_ray"].get<size_t>(),
                    r["ties_single_ray"].get<size_t>());
    }
}

/// Times the flat loop against the tree on scenes of n random spheres and n random
/// triangles in a unit cube (200k random rays, one thread, median of 5); this
/// measurement sets kFlatLoopMaxPrims.
int run_small_scenes() {
    std::printf("%-6s %-9s %12s %12s %8s\n", "prims", "kind", "flat ns/ray", "tree ns/ray", "flat/tree");
    for (uint32_t n : {1u, 2u, 3u, 4u, 6u, 8u, 12u, 16u, 24u, 32u}) {
        for (int kind = 0; kind < 2; ++kind) {
            Scene scene;
            uint64_t state = 12345 + n;
            auto rnd = [&state] {
                state = state * 6364136223846793005ull + 1442695040888963407ull;
                return float(state >> 40) * 0x1p-24f;
            };
            for (uint32_t i = 0; i < n; ++i) {
                const Vec3 c(rnd(), rnd(), rnd());
                if (kind == 0) {
                    scene.spheres.push_back(Sphere{c, 0.05f + 0.1f * rnd()});
                } else {
                    for (int k = 0; k < 3; ++k)
                        scene.triangles.positions.push_back(c + Vec3(rnd(), rnd(), rnd()) * 0.2f);
                    for (uint32_t k = 0; k < 3; ++k) scene.triangles.indices.push_back(3 * i + k);
                }
            }
            std::vector<Ray> rays(200000);
            for (Ray& r : rays)
                r = Ray{Vec3(rnd(), rnd(), rnd()) * 3.0f - Vec3(1.0f),
                        Vec3(rnd(), rnd(), rnd()) - Vec3(0.5f)};
            AcceleratorOptions flat, tree;
            flat.flat_loop_max_prims = 1000;
            tree.flat_loop_max_prims = 0;
            const Accelerator a(scene, flat), b(scene, tree);
            std::vector<double> ta, tb;
            RayAnswers answers;
            for (int k = 0; k < 5; ++k) {
                ta.push_back(trace_sahara(a, rays, false, 1, true, answers).cpu_s);
                tb.push_back(trace_sahara(b, rays, false, 1, true, answers).cpu_s);
            }
            const double fa = median(ta) / double(rays.size()) * 1e9,
                         fb = median(tb) / double(rays.size()) * 1e9;
            // (CPU time of the single tracing thread: steady on shared cores.)
            std::printf("%-6u %-9s %12.1f %12.1f %8.2f\n", n, kind ? "triangles" : "spheres", fa, fb,
                        fa / fb);
        }
    }
    return 0;
}

/// The ray sets --ray-set names ("all": every one).
std::vector<std::string> parse_ray_sets(const std::string& flag, const std::string& v) {
    if (v == "all") return {"primary", "primary_packet", "diffuse", "shadow"};
    if (v == "primary" || v == "primary_packet" || v == "diffuse" || v == "shadow") return {v};
    throw UsageError(flag + ": expected primary|primary_packet|diffuse|shadow|all, got '" + v + "'");
}

/// Adds bench's options to `app`, filling `opt`; `small_scenes` and `help` are the two modes without a file.
void add_bench_options(CLI::App& app, BenchOptions& opt, bool& small_scenes) {
    add_threads_option(app, opt.threads);
    app.add_option_function<std::string>(
        "--ray-set", [&opt](const std::string& v) { opt.sets = parse_ray_sets("--ray-set", v); });
    // --rays names a ray file in `sahara trace`; here it was the set, renamed so one name means one thing.
    app.add_option_function<std::string>("--rays", [](const std::string&) {
        throw UsageError("--rays is now --ray-set (--rays names a ray file)");
    });
    app.add_option_function<std::string>(
        "--builder", [&opt](const std::string& v) { opt.builder = parse_builder_name("--builder", v); });
    app.add_option_function<std::string>(
        "--layout", [&opt](const std::string& v) { opt.layout = parse_layout_name("--layout", v); });
    app.add_option_function<std::string>("--size", [&opt](const std::string& v) {
        std::tie(opt.width, opt.height) = parse_size_value("--size", v);
    });
    app.add_option_function<std::string>("--repeat", [&opt](const std::string& v) {
        opt.repeat = int(parse_int_value("--repeat", v, 1, 1 << 20));
    });
    app.add_option_function<std::string>("--embree-isa", [&opt](const std::string& v) {
        if (std::find(std::begin(kEmbreeIsas), std::end(kEmbreeIsas), v) == std::end(kEmbreeIsas))
            throw UsageError("--embree-isa: expected best|sse2|avx|avx2|avx512, got '" + v + "'");
        opt.embree_isa = v;
    });
    app.add_option_function<std::string>("--embree-quality", [&opt](const std::string& v) {
        const auto* q = std::find(std::begin(kEmbreeQualityNames), std::end(kEmbreeQualityNames), v);
        if (q == std::end(kEmbreeQualityNames))
            throw UsageError("--embree-quality: expected low|medium|high, got '" + v + "'");
        opt.embree_quality = EmbreeQuality(q - std::begin(kEmbreeQualityNames));
    });
    app.add_flag("--json", opt.json);
    app.add_flag_callback("--no-embree", [&opt] { opt.embree = false; });
    app.add_flag("--embree-robust", opt.embree_robust);
    app.add_flag("--small-scenes", small_scenes);
    app.add_option_function<std::string>("--generated-mesh", [&opt](const std::string& v) {
        opt.generated_triangles = size_t(parse_int_value("--generated-mesh", v, 6, 1ll << 32));
        try {
            sphere_grid_for(opt.generated_triangles);
        } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--generated-mesh: ") + e.what());
        }
    });
}

}  // namespace

int run_bench_command(int argc, char** argv) {
    BenchOptions opt;
    opt.threads = omp_get_num_procs();
    opt.sets = parse_ray_sets("--ray-set", "all");
    bool small_scenes = false, help = false;
    try {
        CLI::App app;
        configure_app(app, help);
        add_bench_options(app, opt, small_scenes);
        const std::vector<std::string> files =
            parse_command_line(app, std::vector<std::string>(argv + 1, argv + argc));
        const size_t inputs = files.size() + (opt.generated_triangles ? 1 : 0);
        if (!help && !small_scenes && inputs != 1)
            throw UsageError("expected one mesh or scene file, or --generated-mesh N");
        if (files.size() == 1) opt.mesh = files[0];
    } catch (const UsageError& e) {
        return usage_error("bench", e.what());
    }
    if (help) {
        std::fputs(kBenchUsage, stdout);
        return 0;
    }
    if (small_scenes) return run_small_scenes();
    try {
        const nlohmann::ordered_json j = run_bench(opt);
        if (opt.json)
            std::printf("%s\n", j.dump().c_str());
        else
            print_text(j);
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara bench: %s\n", e.what());
        return 2;
    }
    return 0;
}

}  // namespace sahara
