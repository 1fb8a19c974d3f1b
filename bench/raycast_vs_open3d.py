#!/usr/bin/env python3
"""Casts the same rays through sahara.RayCaster and Open3D's RaycastingScene.

    PYTHONPATH=build/python python3 bench/raycast_vs_open3d.py MESH [--rays N] [--embree]

Two ray sets: N random rays (origins on a sphere around the mesh, aimed at random
points inside its box) and a pinhole camera's rays (sqrt(N) x sqrt(N) pixels).
Prints hit/miss agreement, t agreement and MRays/s of both engines with all
threads (one warm-up call, then the best of --repeats). Rays on which the two
disagree are re-tested in double precision against every triangle, which says
which engine was right. --markdown prints the table row docs/performance.md uses.
--threads N runs both engines on N threads (default: all).

Open3D's ray masks: Open3D 0.16 (Debian bookworm's python3-open3d) leaves each
ray's `mask` field at 0, and Debian's Embree 3 is built with ray masks
(EMBREE_RAY_MASK), so every ray misses every geometry (whose mask is all ones).
Before importing open3d the script therefore compiles a tiny interposer with `cc`
into a temporary directory and loads it with RTLD_GLOBAL: it defines the two
Embree entry points Open3D casts with, rtcIntersect1M and rtcOccluded1M (see
`nm -D --undefined-only libOpen3D.so`), sets every ray's mask to 0xFFFFFFFF and
calls Embree's own function. Symbols of the global scope come before a library's
own dependencies, so Open3D binds to the interposer while everything else of
Open3D and Embree runs unchanged. A probe ray checks that it took effect.
--embree adds Embree 3 called directly through ctypes (the same rtcIntersect1M,
on a Python thread pool) as a third column.
"""
import argparse
import ctypes
import os
import subprocess
import tempfile
import time

import numpy as np

from ray_sets import random_rays

import sahara

# The interposer. RTCRay keeps `mask` at byte 36 in Embree 3 (RTCRayHit starts with an RTCRay).
UNMASK_C = r"""
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stddef.h>
#include <stdint.h>
typedef void (*stream_fn)(void*, void*, void*, unsigned, size_t);
static stream_fn embree(const char* name) {
    void* lib = dlopen("libembree3.so.3", RTLD_NOW | RTLD_NOLOAD);
    if (!lib) lib = dlopen("libembree3.so.3", RTLD_NOW);
    return lib ? (stream_fn)dlsym(lib, name) : 0;
}
static void unmask(void* rays, unsigned n, size_t stride) {
    for (unsigned i = 0; i < n; ++i) *(uint32_t*)((char*)rays + i * stride + 36) = 0xFFFFFFFFu;
}
void rtcIntersect1M(void* scene, void* context, void* rays, unsigned n, size_t stride) {
    static stream_fn real;
    if (!real) real = embree("rtcIntersect1M");
    unmask(rays, n, stride);
    real(scene, context, rays, n, stride);
}
void rtcOccluded1M(void* scene, void* context, void* rays, unsigned n, size_t stride) {
    static stream_fn real;
    if (!real) real = embree("rtcOccluded1M");
    unmask(rays, n, stride);
    real(scene, context, rays, n, stride);
}
"""


def import_open3d_unmasked():
    """open3d, with the ray-mask interposer loaded first (see the module docstring)."""
    with tempfile.TemporaryDirectory(prefix="sahara-o3d-") as tmp:
        src, lib = os.path.join(tmp, "unmask.c"), os.path.join(tmp, "unmask.so")
        with open(src, "w") as f:
            f.write(UNMASK_C)
        subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", lib, src, "-ldl"], check=True)
        ctypes.CDLL(lib, mode=ctypes.RTLD_GLOBAL)  # stays loaded after the file is gone
    try:
        import open3d as o3d
    except ImportError:  # pragma: no cover
        raise SystemExit("needs Open3D (Debian: apt-get install python3-open3d)")
    probe = o3d.t.geometry.RaycastingScene()
    probe.add_triangles(o3d.core.Tensor(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)),
                        o3d.core.Tensor(np.array([[0, 1, 2]], np.uint32)))
    t = probe.cast_rays(o3d.core.Tensor(np.array([[0.25, 0.25, -1, 0, 0, 1]], np.float32)))["t_hit"].numpy()
    if not t[0] == 1.0:
        raise SystemExit(f"Open3D still misses a ray straight at a triangle (t_hit {t[0]}): the interposer "
                         "did not take effect")
    return o3d


def camera_rays(vertices, count):
    """A 40-degree pinhole camera looking at the box centre from a diagonal."""
    side = max(1, int(round(count ** 0.5)))
    lo, hi = vertices.min(0), vertices.max(0)
    center, size = (lo + hi) / 2, np.linalg.norm(hi - lo)
    eye = center + size * np.array([0.6, 0.45, 0.9])
    forward = (center - eye) / np.linalg.norm(center - eye)
    right = np.cross(forward, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half = np.tan(np.radians(20))
    s = (np.arange(side) + 0.5) / side * 2 - 1
    x, y = np.meshgrid(s * half, -s * half)
    dirs = forward + x[..., None] * right + y[..., None] * up
    return np.hstack([np.broadcast_to(eye, (side * side, 3)), dirs.reshape(-1, 3)]).astype(np.float32)


def best_of(fns, repeats):
    """Best time of each function; the runs alternate between the functions, so a burst of
    load on a shared machine does not fall on one engine only."""
    for fn in fns.values():
        fn()  # warm-up: page faults, thread pools, lazy builds
    best = {name: float("inf") for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            start = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - start)
    return best


def double_check(vertices, triangles, ray):
    """Nearest hit of one ray in double (Möller-Trumbore over all triangles), and whether the
    answer is within float32 rounding of a triangle edge: the distance of the crossing (for
    a miss, of the nearest near-miss) from the triangle's boundary against a few float ulps
    of the coordinates involved (the engines compute relative to the ray origin in float)."""
    o, d = ray[:3].astype(float), ray[3:].astype(float)
    p0, p1, p2 = (vertices[triangles[:, k]].astype(float) for k in range(3))
    e1, e2 = p1 - p0, p2 - p0
    pv = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, pv)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1 / det
        s = o - p0
        u = np.einsum("ij,ij->i", s, pv) * inv
        q = np.cross(s, e1)
        v = q @ d * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
    margin = np.minimum(np.minimum(u, v), 1 - u - v)
    front = (det != 0) & (t > 0)
    ok = front & (margin >= 0)
    if ok.any():
        i = np.argmin(np.where(ok, t, np.inf))
    elif front.any():
        i = np.argmax(np.where(front, margin, -np.inf))
    else:
        return np.inf, False
    size = np.sqrt(np.linalg.norm(np.cross(e1[i], e2[i])))  # ~ the triangle's width
    scale = np.abs(o).max() + np.abs(t[i] * d).max() + np.abs(p0[i]).max()
    on_edge = abs(margin[i]) * size < 8 * 2.0 ** -24 * scale
    return (t[i] if ok.any() else np.inf), bool(on_edge)


class EmbreeDirect:
    """Embree 3 called through ctypes as Open3D's RaycastingScene calls it (default scene
    flags, rtcIntersect1M on float32 rays) from a thread pool (ctypes releases the GIL):
    Embree's speed without Open3D's tensor conversions around it."""

    RAYHIT = np.dtype({"names": ["org", "tnear", "dir", "time", "tfar", "mask", "id", "flags",
                                 "ng", "u", "v", "prim", "geom", "inst"],
                       "formats": [("<f4", 3), "<f4", ("<f4", 3), "<f4", "<f4", "<u4", "<u4", "<u4",
                                   ("<f4", 3), "<f4", "<f4", "<u4", "<u4", "<u4"],
                       "offsets": [0, 12, 16, 28, 32, 36, 40, 44, 48, 60, 64, 68, 72, 76], "itemsize": 80})

    def __init__(self, vertices, triangles, threads):
        import ctypes
        self.ct = ctypes
        lib = self.lib = ctypes.CDLL("libembree3.so.3")
        for name in ("rtcNewDevice", "rtcNewScene", "rtcNewGeometry"):
            getattr(lib, name).restype = ctypes.c_void_p
        vp = ctypes.c_void_p
        self.device = vp(lib.rtcNewDevice(None))
        self.scene = vp(lib.rtcNewScene(self.device))
        geom = vp(lib.rtcNewGeometry(self.device, 0))  # RTC_GEOMETRY_TYPE_TRIANGLE
        # Embree reads 16 bytes per vertex: one padding row.
        self.vertices = np.zeros((len(vertices) + 1, 3), np.float32)
        self.vertices[:-1] = vertices
        self.triangles = np.ascontiguousarray(triangles, np.uint32)
        lib.rtcSetSharedGeometryBuffer(geom, 1, 0, 0x9003, self.vertices.ctypes.data_as(vp), ctypes.c_size_t(0),
                                       ctypes.c_size_t(12), ctypes.c_size_t(len(vertices)))
        lib.rtcSetSharedGeometryBuffer(geom, 0, 0, 0x5003, self.triangles.ctypes.data_as(vp), ctypes.c_size_t(0),
                                       ctypes.c_size_t(12), ctypes.c_size_t(len(triangles)))
        lib.rtcCommitGeometry(geom)
        lib.rtcAttachGeometry(self.scene, geom)
        lib.rtcReleaseGeometry(geom)
        lib.rtcCommitScene(self.scene)
        # RTCIntersectContext: flags 0 (incoherent), no filter, instID[0] invalid.
        self.context = (ctypes.c_uint32 * 6)(0, 0, 0, 0, 0xFFFFFFFF, 0)
        self.pool = __import__("concurrent.futures").futures.ThreadPoolExecutor(threads)

    def cast_rays(self, rays):
        rh = np.zeros(len(rays), self.RAYHIT)
        rh["org"], rh["dir"] = rays[:, :3], rays[:, 3:]
        rh["tfar"], rh["mask"], rh["geom"] = np.inf, 0xFFFFFFFF, 0xFFFFFFFF
        chunk = 1 << 14
        def run(start):
            n = min(chunk, len(rays) - start)
            self.lib.rtcIntersect1M(self.scene, self.context, self.ct.c_void_p(rh.ctypes.data + 80 * start),
                                    self.ct.c_uint(n), self.ct.c_size_t(80))
        list(self.pool.map(run, range(0, len(rays), chunk)))
        return np.where(rh["geom"] != 0xFFFFFFFF, rh["tfar"], np.inf)


def compare(name, rays, engines, repeats, vertices, triangles):
    """engines: name -> function(rays) -> t_hit (inf on a miss); the first is sahara."""
    t = {e: np.asarray(fn(rays)) for e, fn in engines.items()}
    secs = best_of({e: (lambda fn=fn: fn(rays)) for e, fn in engines.items()}, repeats)
    n = len(rays)
    s_t = t["sahara"]
    s_hit = np.isfinite(s_t)
    rows = []
    for other in [e for e in engines if e != "sahara"]:
        o_t = t[other]
        o_hit = np.isfinite(o_t)
        agree = s_hit == o_hit
        both = s_hit & o_hit
        rel = np.abs(s_t[both] - o_t[both]) / np.maximum(np.abs(o_t[both]), 1e-30)
        verdict = {"sahara": 0, other: 0, "edge": 0}
        for i in np.flatnonzero(~agree)[:200]:
            t_ref, on_edge = double_check(vertices, triangles, rays[i])
            if on_edge:
                verdict["edge"] += 1  # within float rounding of an edge: both answers defensible
            elif np.isfinite(t_ref) == s_hit[i]:
                verdict["sahara"] += 1
            else:
                verdict[other] += 1
        row = {"set": name, "other": other, "rays": n, "hit_rate": s_hit.mean(), "agree": agree.mean(),
               "disagree": int((~agree).sum()), "verdict": verdict,
               "t_within_1e-5": float(np.mean(rel <= 1e-5)) if len(rel) else 1.0,
               "t_max_rel": float(rel.max()) if len(rel) else 0.0,
               "sahara_mrays": n / secs["sahara"] / 1e6, "other_mrays": n / secs[other] / 1e6}
        print(f"{name:7s} vs {other:7s} {n} rays, sahara {100 * row['hit_rate']:.1f}% hit, {other} "
              f"{100 * o_hit.mean():.1f}% | hit/miss agree {100 * row['agree']:.4f}% ({row['disagree']} differ; "
              f"double check of up to 200: {verdict}) | t within 1e-5 rel {100 * row['t_within_1e-5']:.3f}%, "
              f"max {row['t_max_rel']:.2e} | MRays/s sahara {row['sahara_mrays']:.2f}, {other} "
              f"{row['other_mrays']:.2f} ({row['sahara_mrays'] / row['other_mrays']:.2f}x)")
        rows.append(row)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", help="OBJ or glTF file")
    ap.add_argument("--rays", type=int, default=1_000_000, help="rays per set (default 1M)")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs per engine; the best counts")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=0, help="threads per engine (default 0: all)")
    ap.add_argument("--embree", action="store_true", help="add Embree called directly through ctypes")
    ap.add_argument("--markdown", action="store_true", help="also print docs/performance.md table rows")
    args = ap.parse_args()
    o3d = import_open3d_unmasked()

    start = time.perf_counter()
    caster = sahara.RayCaster.from_file(args.mesh)
    sahara_build = time.perf_counter() - start
    vertices, triangles = np.array(caster.vertices), np.array(caster.triangles)
    start = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices), o3d.core.Tensor(triangles))
    scene.cast_rays(o3d.core.Tensor(np.zeros((1, 6), np.float32)))  # Embree commits the scene lazily
    open3d_build = time.perf_counter() - start
    print(f"{os.path.basename(args.mesh)}: {len(triangles)} triangles, {args.threads or os.cpu_count()} threads; "
          f"build sahara {1e3 * sahara_build:.0f} ms (load included), open3d {1e3 * open3d_build:.0f} ms")
    threads = args.threads or None
    engines = {"sahara": lambda r: caster.cast_rays(r, threads=threads)["t_hit"],
               "open3d": lambda r: scene.cast_rays(o3d.core.Tensor(r), nthreads=args.threads)["t_hit"].numpy()}
    if args.embree:
        engines["embree"] = EmbreeDirect(vertices, triangles, args.threads or os.cpu_count()).cast_rays
    rng = np.random.default_rng(args.seed)
    rows = (compare("random", random_rays(vertices, args.rays, rng), engines, args.repeats, vertices, triangles)
            + compare("camera", camera_rays(vertices, args.rays), engines, args.repeats, vertices, triangles))
    if args.markdown:
        for r in rows:
            v = r["verdict"]
            print(f"| {os.path.basename(args.mesh)} | {len(triangles)} | {r['set']} | {r['other']} | "
                  f"{100 * r['agree']:.4f}% | {r['disagree']} ({', '.join(f'{k} {x}' for k, x in v.items())}) | "
                  f"{100 * r['t_within_1e-5']:.3f}% | {r['sahara_mrays']:.2f} | {r['other_mrays']:.2f} | "
                  f"{r['sahara_mrays'] / r['other_mrays']:.2f}x |")


if __name__ == "__main__":
    main()
