"""Small closed meshes for the ray caster tests, built with numpy."""
import numpy as np


def cube(half=1.0):
    """The cube [-half, half]^3: 8 vertices, 12 triangles, counter-clockwise seen from outside."""
    v = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    return v, np.array(tris, dtype=np.int64)


def icosphere(subdivisions=2, radius=1.0):
    """An icosahedron subdivided `subdivisions` times, vertices pushed onto the sphere."""
    p = (1 + 5 ** 0.5) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p), (0, 1, -p),
         (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
         (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(x, dtype=float) / np.linalg.norm(x) for x in v]
    for _ in range(subdivisions):
        mid = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                mid[key] = len(verts) - 1
            return mid[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return np.array(verts) * radius, np.array(f, dtype=np.int64)


def unwelded(vertices, triangles):
    """The same surface with three vertices of its own per triangle."""
    return vertices[triangles.reshape(-1)], np.arange(3 * len(triangles)).reshape(-1, 3)


def brute_force_nearest(vertices, triangles, rays):
    """Nearest hit per ray in float64 (Möller-Trumbore over every triangle): (t, id), inf/-1 on a miss."""
    o, d = rays[:, None, :3], rays[:, None, 3:]
    p0, p1, p2 = (vertices[triangles[:, k]][None] for k in range(3))
    e1, e2 = p1 - p0, p2 - p0
    pv = np.cross(d, e2)
    det = np.einsum("rtk,rtk->rt", e1, pv)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - p0
        u = np.einsum("rtk,rtk->rt", s, pv) * inv
        q = np.cross(s, e1)
        v = np.einsum("rtk,rtk->rt", d, q) * inv
        t = np.einsum("rtk,rtk->rt", e2, q) * inv
    ok = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    t = np.where(ok, t, np.inf)
    ids = np.argmin(t, axis=1)
    best = t[np.arange(len(rays)), ids]
    return best, np.where(np.isfinite(best), ids, -1)
