#include "pipeline/bvh_report.h"

#include <omp.h>

#include <vector>

#include "accel/bvh_stats.h"
#include "pipeline/bench_rays.h"
#include "pipeline/mesh_input.h"
#include "scene/accelerator.h"
#include "scene/instances.h"

namespace sahara {

namespace {

/// Mean nodes visited and primitives tested per ray, counted in parallel with per-thread counters.
TraversalCounters count_work(const Accelerator& accel, const std::vector<Ray>& rays, bool occlusion = false) {
    TraversalCounters total;
#pragma omp parallel
    {
        TraversalCounters local;
#pragma omp for schedule(dynamic, 1024)
        for (size_t i = 0; i < rays.size(); ++i) {
            if (occlusion) {
                accel.occluded_counted(rays[i], local);
                continue;
            }
            Ray r = rays[i];
            Hit h;
            accel.intersect_counted(r, h, local);
        }
#pragma omp critical
        total += local;
    }
    return total;
}

nlohmann::ordered_json work_json(const TraversalCounters& c, size_t rays) {
    const double n = rays ? double(rays) : 1.0;
    return {{"count", rays},
            {"nodes_visited", double(c.nodes_visited) / n},
            {"prims_tested", double(c.prims_tested) / n}};
}

/// Bounded primitives by kind, as held by the tree.
nlohmann::ordered_json primitive_kinds_json(const Scene& scene) {
    return {{"triangles", scene.triangles.size()},
            {"spheres", scene.spheres.size()},
            {"boxes", scene.boxes.size()},
            {"quadrics", scene.quadrics.size()}};
}

/// Statistics of the wide tree, with the figures Embree's verbose build report
/// gives for its own tree.
nlohmann::ordered_json wide_tree_json(const Accelerator& accel) {
    const uint32_t block = 4;
    const WideBvhStats w = compute_wide_bvh_stats(accel.bvh8(), block);
    return {
        {"nodes", w.nodes},
        {"children_per_node", w.nodes ? double(w.children) / double(w.nodes) : 0.0},
        {"leaves", w.leaves},
        {"leaf_block_size", block},
        {"leaf_block_fill", w.leaf_blocks ? double(w.leaf_primitives) / double(w.leaf_blocks * block) : 0.0},
        {"sah_nodes", w.sah_nodes},
        {"sah_leaves", w.sah_leaves}};
}

}  // namespace

nlohmann::ordered_json bvh_report(const Scene& scene, const std::string& file, const BvhReportOptions& o) {
    const std::optional<BvhBuilder> chosen = o.builder;
    const BvhLayout layout = o.layout.value_or(AcceleratorOptions{}.layout);
    const int threads = o.threads;
    const BvhBuilder builder = chosen.value_or(scene.render.bvh_builder);
    AcceleratorOptions opt;
    opt.builder = builder;
    opt.expected_rays = scene.expected_render_rays();
    opt.layout = layout;
    opt.keep_binary_tree = true;  // for the statistics below
    omp_set_num_threads(threads);
    const Accelerator accel(scene, opt);
    // The SAH cost of the tree as built (the block layouts scale the intersection cost).
    const BvhBuildParams built = opt.build_params();
    const BvhStats s = compute_bvh_stats(accel.bvh(), built);
    const BenchRaySets rays = make_bench_rays(
        scene, accel, o.width, o.height, o.from_scene_file ? BenchAim::scene_camera : BenchAim::frame_bounds);
    const size_t prims = accel.primitive_count();
    nlohmann::ordered_json j = {
        {"mesh", file},
        {"input", o.from_scene_file ? "scene" : "mesh"},
        {"builder", bvh_builder_name(accel.builder())},
        {"primitives", prims},
        {"primitives_by_kind", primitive_kinds_json(scene)},
        {"primitive_kinds", primitive_kinds_text(scene)},
        {"planes_outside_tree", scene.planes.size()},
        {"nodes", s.nodes},
        {"leaves", s.leaves},
        {"max_depth", s.max_depth},
        {"mean_leaf_depth", s.mean_leaf_depth},
        {"leaf_size_histogram", s.leaf_size_histogram},
        {"sah_cost", s.sah_cost},
        {"traversal_cost", opt.params.traversal_cost},
        {"intersection_cost", built.intersection_cost},
        {"layout", bvh_layout_name(accel.layout())},
        {"wide_nodes", accel.bvh8().nodes.size()},
        {"build_ms", accel.build_ms()},
        {"build_cpu_ms", accel.build_cpu_ms()},
        {"build_threads", threads},
        {"mprims_s", accel.build_ms() > 0 ? double(prims) / (accel.build_ms() * 1e3) : 0.0},
        {"mprims_cpu_s", accel.build_cpu_ms() > 0 ? double(prims) / (accel.build_cpu_ms() * 1e3) : 0.0},
        {"bytes", accel.bytes()},
        {"tree_bytes", s.bytes},
        {"bytes_per_primitive", prims ? double(accel.bytes()) / double(prims) : 0.0}};
    if (layout != BvhLayout::pairs) j["wide"] = wide_tree_json(accel);
    j["rays"]["primary"] = work_json(count_work(accel, rays.primary), rays.primary.size());
    j["rays"]["diffuse"] = work_json(count_work(accel, rays.diffuse), rays.diffuse.size());
    j["rays"]["shadow"] = work_json(count_work(accel, rays.shadow, true), rays.shadow.size());
    if (scene.instances()) j["instances"] = instance_level_json(scene);
    return j;
}

nlohmann::ordered_json instance_level_json(const Scene& scene) {
    const InstanceSet* in = scene.instances();
    if (!in) return nullptr;
    const BvhStats top = compute_bvh_stats(in->top_level());
    return {{"instances", in->instance_count()},
            {"prototypes", in->prototype_count()},
            {"top_level_nodes", top.nodes},
            {"top_level_leaves", top.leaves},
            {"top_level_max_depth", top.max_depth},
            {"triangles_stored", in->unique_triangle_count()},
            {"triangles_drawn", in->instanced_triangle_count()},
            {"bytes", in->bytes()}};
}

}  // namespace sahara
