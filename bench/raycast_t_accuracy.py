"""Relative error of t_hit, sahara's and Open3D's, against the hit on the triangle's plane in double.

    PATH=/usr/bin:$PATH PYTHONPATH=build/python python3 bench/raycast_t_accuracy.py MESH.obj [--rays N]

Rays start at uniform random points of the mesh's box, in uniform random directions (an
interior's rays start inside it); only rays both hit on the same triangle are compared.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import raycast_vs_open3d as rv  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", help="OBJ or glTF file")
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    o3d = rv.import_open3d_unmasked()
    import sahara

    caster = sahara.RayCaster.from_file(args.mesh)
    v, f = np.array(caster.vertices), np.array(caster.triangles)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f))
    rng = np.random.default_rng(args.seed)
    origins = rng.uniform(v.min(0), v.max(0), size=(args.rays, 3))
    d = rng.normal(size=(args.rays, 3))
    rays = np.hstack([origins, d / np.linalg.norm(d, axis=1, keepdims=True)]).astype(np.float32)
    ours, theirs = caster.cast_rays(rays), scene.cast_rays(o3d.core.Tensor(rays))
    ids = ours["primitive_ids"]
    same = (ids >= 0) & (ids == theirs["primitive_ids"].numpy().astype(np.int64)) & np.isfinite(theirs["t_hit"].numpy())
    p = v[f[ids[same]]].astype(float)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    o, dd = rays[same, :3].astype(float), rays[same, 3:].astype(float)
    exact = np.einsum("ij,ij->i", n, p[:, 0] - o) / np.einsum("ij,ij->i", n, dd)
    print(f"{args.mesh}: {same.sum()} rays hit the same triangle in both")
    for name, t in (("sahara", ours["t_hit"][same]), ("open3d", theirs["t_hit"].numpy()[same])):
        err = np.abs(t - exact) / exact
        q = np.percentile(err, [50, 99, 99.99, 100])
        print(f"{name:7s} relative error of t: median {q[0]:.2g}, 99% {q[1]:.2g}, 99.99% {q[2]:.2g}, "
              f"max {q[3]:.2g}; above 1e-5: {(err > 1e-5).sum()}")


if __name__ == "__main__":
    main()
