#!/usr/bin/env python3
"""MRays/s of sahara.RayCaster.count_intersections and intersect_all.

    PYTHONPATH=build/python python3 bench/crossings_speed.py MESH [--rays N] [--repeats R]

Random rays (origins on a sphere around the mesh, aimed at random points inside its
box, as bench/raycast_vs_open3d.py casts), one warm-up call, then the median of
--repeats runs of each query. Threads: OMP_NUM_THREADS (default: all cores). Also
prints the total crossing count, which must not change between two builds.
"""
import argparse
import os
import statistics
import time

import numpy as np

from ray_sets import random_rays

import sahara


def median_seconds(fn, repeats):
    fn()  # warm-up: page faults, thread pool
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", help="OBJ or glTF file")
    ap.add_argument("--rays", type=int, default=200_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    caster = sahara.RayCaster.from_file(args.mesh)
    rays = random_rays(np.array(caster.vertices), args.rays, np.random.default_rng(args.seed))
    counts = caster.count_intersections(rays)
    n = len(rays)
    count_s = median_seconds(lambda: caster.count_intersections(rays), args.repeats)
    all_s = median_seconds(lambda: caster.intersect_all(rays), args.repeats)
    print(f"{os.path.basename(args.mesh)}: {len(caster.triangles)} triangles, {n} rays, "
          f"{int(counts.sum())} crossings, threads {os.environ.get('OMP_NUM_THREADS', os.cpu_count())} | "
          f"count_intersections {n / count_s / 1e6:.3f} MRays/s | intersect_all {n / all_s / 1e6:.3f} MRays/s")


if __name__ == "__main__":
    main()
