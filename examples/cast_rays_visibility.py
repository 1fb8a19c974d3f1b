#!/usr/bin/env python3
"""How much of a mesh can be seen from outside: ambient visibility per triangle.

    PYTHONPATH=build/python python3 examples/cast_rays_visibility.py [MESH.obj|.gltf] [--rays N]

From a point just off each sampled triangle, rays go out into random directions of
the outer hemisphere; a ray that escapes (occluded() is False) sees the sky. Without
a mesh argument it uses two boxes with a narrow gap, whose facing walls see little sky.
"""
import argparse

import numpy as np

import sahara


def two_boxes():
    """Two closed boxes side by side, 0.1 apart."""
    def box(lo, hi):
        v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        q = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        return v, np.array([t for a, b, c, d in q for t in ((a, b, c), (a, c, d))])
    (v1, f1), (v2, f2) = box((-1, -1, 0), (-0.05, 1, 1)), box((0.05, -1, 0), (1, 1, 1))
    return np.vstack([v1, v2]), np.vstack([f1, f2 + len(v1)])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh", nargs="?")
    ap.add_argument("--rays", type=int, default=256, help="rays per triangle")
    ap.add_argument("--triangles", type=int, default=2000, help="triangles sampled")
    args = ap.parse_args()
    caster = sahara.RayCaster.from_file(args.mesh) if args.mesh else sahara.RayCaster(*two_boxes())
    v, f = np.asarray(caster.vertices, float), np.asarray(caster.triangles)
    rng = np.random.default_rng(0)
    tri = rng.choice(len(f), size=min(args.triangles, len(f)), replace=False)
    p0, p1, p2 = v[f[tri, 0]], v[f[tri, 1]], v[f[tri, 2]]
    n = np.cross(p1 - p0, p2 - p0)
    area = np.linalg.norm(n, axis=1)
    tri, p0, p1, p2, n = tri[area > 0], p0[area > 0], p1[area > 0], p2[area > 0], n[area > 0]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    # Rays start at the centroid, nudged along the normal, into the outer hemisphere.
    scale = np.abs(v).max()
    origins = (p0 + p1 + p2) / 3 + 1e-4 * scale * n
    d = rng.normal(size=(len(tri), args.rays, 3))
    d *= np.sign(np.einsum("trk,tk->tr", d, n))[..., None]
    rays = np.concatenate([np.broadcast_to(origins[:, None], d.shape), d], axis=-1)
    visible = 1 - caster.occluded(rays).mean(axis=1)
    print(f"{caster}: {len(tri)} triangles x {args.rays} rays")
    print(f"sky visibility: mean {visible.mean():.3f}, min {visible.min():.3f}, max {visible.max():.3f}")
    for q in (0.1, 0.5, 0.9):
        print(f"  {int(q * 100)}th percentile {np.quantile(visible, q):.3f}")


if __name__ == "__main__":
    main()
