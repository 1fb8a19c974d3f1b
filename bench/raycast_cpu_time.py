#!/usr/bin/env python3
"""CPU seconds per million rays of sahara.RayCaster.cast_rays alone, one thread.

    PYTHONPATH=build-dev/python python3 bench/raycast_cpu_time.py MESH [--rays N] [--repeats N] [--camera]

Process CPU time (time.process_time) rather than wall time: on a shared, loaded
machine it moves far less between runs, so two builds run alternately compare
fairly. The same random rays as bench/raycast_vs_open3d.py (bench/ray_sets.py),
or with --camera its pinhole camera's rays. Prints the median and the best of
--repeats casts after one warm-up cast.
"""
import argparse
import statistics
import time

import numpy as np

from ray_sets import random_rays

import sahara


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", help="OBJ or glTF file")
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--camera", action="store_true", help="camera rays instead of random ones")
    args = ap.parse_args()
    caster = sahara.RayCaster.from_file(args.mesh)
    vertices = np.array(caster.vertices)
    if args.camera:
        from raycast_vs_open3d import camera_rays
        rays = camera_rays(vertices, args.rays)
    else:
        rays = random_rays(vertices, args.rays, np.random.default_rng(args.seed))
    caster.cast_rays(rays, threads=1)  # warm-up: page faults, thread pool
    seconds = []
    for _ in range(args.repeats):
        start = time.process_time()
        caster.cast_rays(rays, threads=1)
        seconds.append(time.process_time() - start)
    per_mray = [s / len(rays) * 1e6 for s in seconds]
    print(f"{args.mesh}: {len(rays)} {'camera' if args.camera else 'random'} rays, CPU s per million rays: "
          f"median {statistics.median(per_mray):.3f}, best {min(per_mray):.3f}")


if __name__ == "__main__":
    main()
