#pragma once
/// Subcommands of the BVH tools. argv[0] is the subcommand name; each returns
/// the process exit code (0 ok, 2 bad usage or bad input) and prints its usage on --help.
namespace sahara {

/// `sahara bvh FILE [--builder binned|sweep] [--json]`: tree statistics.
int run_bvh_command(int argc, char** argv);
/// `sahara bench MESH [--threads N] [--rays primary|diffuse|shadow|all] [--json]`: throughput vs Embree.
int run_bench_command(int argc, char** argv);
/// `sahara trace MESH --rays IN.rays --hits OUT.hits [--occlusion OUT.occl]`: trace a ray file.
int run_trace_command(int argc, char** argv);

}  // namespace sahara
