#!/usr/bin/env python3
"""Which points lie inside a closed mesh: count crossings along a ray (odd: inside).

    PYTHONPATH=build/python python3 examples/cast_rays_inside_outside.py [MESH.obj|.gltf] [--points N]

count_intersections counts a ray through a shared edge or vertex once, so the
parity is exact even for rays aimed along the mesh's own grid. Without a mesh
argument it uses an octahedron (|x| + |y| + |z| <= 1), whose answer is known, and
checks it; with a mesh, it estimates the mesh's volume by Monte Carlo.
"""
import argparse

import numpy as np

import sahara


def octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    f = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    return v, np.array(f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh", nargs="?")
    ap.add_argument("--points", type=int, default=1_000_000)
    args = ap.parse_args()
    caster = sahara.RayCaster.from_file(args.mesh) if args.mesh else sahara.RayCaster(*octahedron())
    v = np.asarray(caster.vertices, float)
    lo, hi = v.min(0), v.max(0)
    rng = np.random.default_rng(0)
    points = rng.uniform(lo, hi, size=(args.points, 3))
    # Any direction works on a closed mesh; +x hits the octahedron's edges and vertices head on.
    rays = np.hstack([points, np.broadcast_to([1.0, 0.0, 0.0], points.shape)])
    inside = caster.count_intersections(rays) % 2 == 1
    volume = inside.mean() * np.prod(hi - lo)
    print(f"{caster}: {inside.sum()} of {len(points)} points inside, volume ~ {volume:.4f}")
    if not args.mesh:
        truth = np.abs(points).sum(axis=1) < 1
        print(f"octahedron: {np.mean(inside == truth) * 100:.4f}% agree with |x|+|y|+|z| < 1 "
              f"(exact volume {4 / 3:.4f})")


if __name__ == "__main__":
    main()
