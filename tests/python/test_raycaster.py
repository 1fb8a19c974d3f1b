"""sahara.RayCaster against brute force, and its edge/vertex and error behaviour.

Run with PYTHONPATH=build/python (or build-dev/python) python3 -m pytest tests/python.
"""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))
import sahara  # noqa: E402
from gltf_docs import write_gltf  # noqa: E402
from raycast_meshes import brute_force_nearest, cube, icosphere, unwelded  # noqa: E402


def rays_from(origins, directions):
    origins, directions = np.broadcast_arrays(np.asarray(origins, float), np.asarray(directions, float))
    return np.hstack([origins.reshape(-1, 3), directions.reshape(-1, 3)])


def random_rays_at(vertices, count, seed):
    """Rays from a sphere around the mesh aimed at random points of its box."""
    rng = np.random.default_rng(seed)
    lo, hi = vertices.min(0), vertices.max(0)
    center, radius = (lo + hi) / 2, np.linalg.norm(hi - lo)
    d = rng.normal(size=(count, 3))
    origins = center + radius * d / np.linalg.norm(d, axis=1, keepdims=True)
    targets = rng.uniform(lo, hi, size=(count, 3))
    return rays_from(origins, targets - origins)


@pytest.fixture(scope="module")
def sphere():
    v, f = icosphere(2)
    return v, f, sahara.RayCaster(v, f)


def test_icosphere_is_wound_outward():
    v, f = icosphere(1)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    assert np.all(np.einsum("ij,ij->i", n, v[f].mean(1)) > 0)


def test_nearest_hits_match_brute_force(sphere):
    v, f, caster = sphere
    rays = random_rays_at(v, 2000, seed=1)
    got = caster.cast_rays(rays)
    t_ref, id_ref = brute_force_nearest(v, f, rays)
    hit = np.isfinite(t_ref)
    assert 0.2 < hit.mean() < 1.0
    assert np.array_equal(np.isfinite(got["t_hit"]), hit)
    np.testing.assert_allclose(got["t_hit"][hit], t_ref[hit], rtol=1e-5)
    assert np.mean(got["primitive_ids"][hit] == id_ref[hit]) > 0.999
    # Barycentrics reproduce the hit point; normals are the unit face normals.
    ids = got["primitive_ids"][hit]
    u, w = got["primitive_uvs"][hit].T
    p = (1 - u - w)[:, None] * v[f[ids, 0]] + u[:, None] * v[f[ids, 1]] + w[:, None] * v[f[ids, 2]]
    np.testing.assert_allclose(p, rays[hit, :3] + got["t_hit"][hit, None] * rays[hit, 3:], atol=1e-4)
    n = np.cross(v[f[ids, 1]] - v[f[ids, 0]], v[f[ids, 2]] - v[f[ids, 0]])
    np.testing.assert_allclose(got["normals"][hit], n / np.linalg.norm(n, axis=1, keepdims=True), atol=1e-5)


def test_coherent_rays_match_brute_force(sphere):
    # A camera's rays in image order: runs of them share direction signs, so they take
    # the packet traversal rather than the single-ray one.
    v, f, caster = sphere
    x, y = np.meshgrid(np.linspace(-1.2, 1.2, 48), np.linspace(-1.2, 1.2, 48))
    dirs = np.stack([x.ravel() * 0.3, y.ravel() * 0.3, np.ones(x.size)], axis=1)
    rays = rays_from([[0.05, -0.02, -4]], dirs)
    got = caster.cast_rays(rays)
    t_ref, id_ref = brute_force_nearest(v, f, rays)
    assert 0.3 < np.isfinite(t_ref).mean() < 1.0
    np.testing.assert_allclose(got["t_hit"], t_ref, rtol=1e-5)
    hit = np.isfinite(t_ref)
    assert np.mean(got["primitive_ids"][hit] == id_ref[hit]) > 0.999


def test_misses_report_inf_and_minus_one(sphere):
    _, _, caster = sphere
    rays = rays_from([[0, 0, 3], [5, 5, 5]], [[0, 0, 1], [1, 0, 0]])
    got = caster.cast_rays(rays)
    assert np.all(np.isinf(got["t_hit"]))
    assert got["primitive_ids"].dtype == np.int64 and np.all(got["primitive_ids"] == -1)
    assert np.all(got["normals"] == 0) and np.all(got["primitive_uvs"] == 0)
    assert not caster.occluded(rays).any()


def test_tmin_and_tmax_bound_the_hits():
    caster = sahara.RayCaster(*cube())
    rays = rays_from([[-3, 0.1, 0.2]] * 4, [[1, 0, 0]])  # enters at t = 2, leaves at t = 4
    got = caster.cast_rays(rays, tmin=np.array([0, 2.5, 0, 4.5]), tmax=np.array([10, 10, 1.5, 10]))
    np.testing.assert_allclose(got["t_hit"], [2, 4, np.inf, np.inf])
    assert list(caster.occluded(rays, tmax=1.99)) == [False] * 4
    assert list(caster.occluded(rays, tmax=2.01)) == [True] * 4
    assert list(caster.occluded(rays, tmin=3.0, tmax=np.array([3.9, 4.1, 5, 3]))) == [False, True, True, False]
    assert list(caster.count_intersections(rays, tmin=3.0)) == [1] * 4


def test_occluded_agrees_with_cast_rays(sphere):
    v, _, caster = sphere
    rays = random_rays_at(v, 3000, seed=2)
    tmax = np.random.default_rng(3).uniform(0.5, 5, len(rays))
    t = caster.cast_rays(rays)["t_hit"]
    np.testing.assert_array_equal(caster.occluded(rays, tmax=tmax), t < tmax)


def test_intersect_all_is_sorted_and_matches_the_counts(sphere):
    v, f, caster = sphere
    rays = random_rays_at(v, 3000, seed=4)
    all_hits = caster.intersect_all(rays)
    ray_ids, t = all_hits["ray_ids"], all_hits["t"]
    order = np.lexsort((t, ray_ids))
    assert np.array_equal(order, np.arange(len(t)))
    counts = caster.count_intersections(rays)
    assert np.array_equal(np.bincount(ray_ids, minlength=len(rays)), counts)
    # A closed surface seen from outside: every ray enters as often as it leaves.
    assert np.all(counts % 2 == 0) and counts.max() == 2
    first = np.searchsorted(ray_ids, np.arange(len(rays)))
    hit = counts > 0
    np.testing.assert_allclose(t[first[hit]], caster.cast_rays(rays)["t_hit"][hit], rtol=1e-6)


def cube_edge_and_vertex_points():
    """Every vertex, edge midpoint, edge quarter point and face centre (on a diagonal) of the unit cube."""
    c = [-1.0, 0.0, 1.0]
    pts = np.array([[x, y, z] for x in c for y in c for z in c])
    pts = pts[np.abs(pts).max(1) == 1]  # the surface: vertices, edge midpoints, face centres
    quarter = np.array([[1, 1, 0.5], [-1, 0.5, 1], [0.5, -1, -1], [1, -0.25, -1]])
    return np.vstack([pts, quarter])


@pytest.mark.parametrize("welded", [True, False])
def test_rays_through_cube_edges_and_vertices_cross_once(welded):
    v, f = cube()
    caster = sahara.RayCaster(*(cube() if welded else unwelded(v, f)))
    pts = cube_edge_and_vertex_points()
    inside = [[0, 0, 0], [0.1, -0.2, 0.3], [-0.5, 0.5, 0.25]]
    for o in inside:  # from inside: one crossing, never zero
        rays = rays_from(np.asarray(o, float), pts - o)
        assert list(caster.count_intersections(rays)) == [1] * len(pts)
        assert np.all(np.isfinite(caster.cast_rays(rays)["t_hit"]))
    # From outside through the surface point and the centre: in and out, two crossings.
    rays = rays_from(2.5 * pts, -pts)
    assert list(caster.count_intersections(rays)) == [2] * len(pts)


def test_rays_that_only_touch_a_cube_corner_or_edge_count_even():
    caster = sahara.RayCaster(*cube())
    # Lines through a vertex or an edge that stay outside the cube everywhere else.
    through = np.array([[1, 1, 1], [1, 1, 1], [1, 1, 0], [-1, 1, -1], [1, 0, 1]], float)
    dirs = np.array([[1, 1, -1], [1, -1, 0.5], [1, -1, 0.3], [-1, -1, 1], [1, 0.2, -1]], float)
    rays = rays_from(through - 3 * dirs, dirs)
    counts = caster.count_intersections(rays)
    assert np.all(counts % 2 == 0)


@pytest.mark.parametrize("welded", [True, False])
def test_rays_through_icosphere_vertices_and_edges_cross_once(welded):
    v, f = icosphere(2)
    caster = sahara.RayCaster(*(icosphere(2) if welded else unwelded(v, f)))
    edges = np.vstack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    v32 = v.astype(np.float32).astype(float)  # the vertices as the BVH holds them
    targets = np.vstack([v32, (v32[edges[:, 0]] + v32[edges[:, 1]]) / 2])
    rays = rays_from(np.zeros(3), targets)
    assert np.all(caster.count_intersections(rays) == 1)
    rays = rays_from(-2 * targets, 3 * targets)  # through the centre: in and out
    assert np.all(caster.count_intersections(rays) == 2)
    rays = rays_from(targets * 0.25, targets)  # from inside, off centre
    assert np.all(caster.count_intersections(rays) == 1)


@pytest.mark.parametrize("welded", [True, False])
def test_rays_exactly_through_cube_vertices_and_edges_give_the_parity(welded):
    """Corners and dyadic points of every edge (face diagonals included) as targets,
    directions with power-of-two components, origins a dyadic step back: every float
    operation of the triangle test is then exact, so each ray passes exactly through
    its target, where only the tie-break decides."""
    v, f = cube()
    caster = sahara.RayCaster(*((v, f) if welded else unwelded(v, f)))
    rng = np.random.default_rng(9)
    n = 20000
    tri, k = f[rng.integers(0, len(f), n)], rng.integers(0, 3, n)
    a, b = v[tri[np.arange(n), k]], v[tri[np.arange(n), (k + 1) % 3]]
    targets = a + (b - a) * rng.integers(0, 8, (n, 1)) / 8
    dirs = rng.choice([-4.0, -2.0, -1.0, 0.0, 1.0, 2.0, 4.0], size=(n, 3))
    origins = targets - dirs * rng.integers(1, 17, (n, 1)) / 32
    extent = np.abs(origins).max(1)
    keep = (np.abs(dirs).max(1) > 0) & (extent != 1)  # not on a face plane
    counts = caster.count_intersections(rays_from(origins[keep], dirs[keep]))
    np.testing.assert_array_equal(counts % 2 == 1, extent[keep] < 1)
    assert (extent[keep] < 1).sum() > 1000


@pytest.mark.parametrize("mesh", ["cube", "icosphere"])
def test_inside_outside_by_parity(mesh):
    v, f = cube() if mesh == "cube" else icosphere(3)
    caster = sahara.RayCaster(v, f)
    rng = np.random.default_rng(5)
    pts = rng.uniform(-1.5, 1.5, size=(20000, 3))
    if mesh == "cube":
        inside = np.abs(pts).max(1) < 1
        margin = np.abs(np.abs(pts).max(1) - 1) > 1e-6
    else:  # between the inscribed and the circumscribed sphere the answer needs the faces
        r = np.linalg.norm(pts, axis=1)
        inside = r < 0.99
        margin = (r < 0.99) | (r > 1.0)
    pts, inside = pts[margin], inside[margin]
    dirs = rng.normal(size=pts.shape)
    # Axis-aligned directions too: they run along the cube's edges and faces.
    dirs[::3] = np.eye(3)[rng.integers(0, 3, len(dirs[::3]))]
    counts = caster.count_intersections(rays_from(pts, dirs))
    np.testing.assert_array_equal(counts % 2 == 1, inside)


def test_float32_and_float64_inputs_agree(sphere):
    v, f, caster = sphere
    rays = random_rays_at(v, 500, seed=6)
    c32 = sahara.RayCaster(v.astype(np.float32), f.astype(np.uint32))
    a = caster.cast_rays(rays)
    for other in (c32.cast_rays(rays.astype(np.float32)), caster.cast_rays(np.asfortranarray(rays)),
                  caster.cast_rays(np.hstack([rays, rays])[:, :6])):
        np.testing.assert_allclose(other["t_hit"], a["t_hit"], rtol=1e-6)
    assert c32.vertices.dtype == np.float32 and c32.triangles.dtype == np.uint32
    np.testing.assert_array_equal(c32.triangles, f)
    with pytest.raises(ValueError):
        c32.vertices[0, 0] = 1  # read-only view


def test_leading_dimensions_are_kept(sphere):
    _, _, caster = sphere
    rays = np.zeros((2, 3, 6))
    rays[..., 2] = -3
    rays[..., 5] = 1
    got = caster.cast_rays(rays)
    assert got["t_hit"].shape == (2, 3) and got["normals"].shape == (2, 3, 3)
    assert caster.occluded(rays).shape == (2, 3) and caster.count_intersections(rays).shape == (2, 3)
    assert np.all(caster.count_intersections(rays) == 2)


def test_degenerate_rays_do_not_crash(sphere):
    _, _, caster = sphere
    rays = np.array([[0, 0, -3, 0, 0, 0], [np.nan, 0, 0, 0, 0, 1], [0, 0, -3, np.inf, 0, 1]], float)
    got = caster.cast_rays(rays)
    assert got["t_hit"].shape == (3,)
    caster.occluded(rays), caster.count_intersections(rays), caster.intersect_all(rays)


def test_empty_mesh_and_empty_batch():
    caster = sahara.RayCaster(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32))
    rays = rays_from([[0, 0, 0]], [[0, 0, 1]])
    assert np.isinf(caster.cast_rays(rays)["t_hit"][0]) and caster.count_intersections(rays)[0] == 0
    v, f = cube()
    assert sahara.RayCaster(v, f).cast_rays(np.zeros((0, 6)))["t_hit"].shape == (0,)
    assert len(sahara.RayCaster(v, f).intersect_all(np.zeros((0, 6)))["t"]) == 0


@pytest.mark.parametrize(
    "vertices, triangles, error, name",
    [
        (np.zeros((4, 2)), [[0, 1, 2]], ValueError, "vertices"),
        (np.zeros((4, 3), dtype=np.int32), [[0, 1, 2]], TypeError, "vertices"),
        ([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], ValueError, "vertices"),
        (np.zeros((4, 3)), np.zeros((1, 3)), TypeError, "triangles"),
        (np.zeros((4, 3)), [[0, 1]], ValueError, "triangles"),
        (np.zeros((4, 3)), [[0, 1, 4]], ValueError, "triangles"),
        (np.zeros((4, 3)), [[0, -1, 2]], ValueError, "triangles"),
        ("not an array", [[0, 1, 2]], TypeError, "vertices"),
    ],
)
def test_bad_meshes_raise_naming_the_argument(vertices, triangles, error, name):
    with pytest.raises(error, match=name):
        sahara.RayCaster(vertices, triangles)


def test_bad_rays_raise_naming_the_argument(sphere):
    _, _, caster = sphere
    with pytest.raises(ValueError, match="rays"):
        caster.cast_rays(np.zeros((3, 5)))
    with pytest.raises(TypeError, match="rays"):
        caster.cast_rays(np.zeros((3, 6), dtype=np.int64))
    with pytest.raises(ValueError, match="tmin"):
        caster.cast_rays(np.zeros((3, 6)), tmin=np.zeros(4))
    with pytest.raises(ValueError, match="tmax"):
        caster.occluded(np.zeros((3, 6)), tmax=np.zeros(2))
    with pytest.raises(TypeError, match="tmax"):
        caster.intersect_all(np.zeros((3, 6)), tmax="far")


def test_from_file_reads_triangles_in_file_order(tmp_path):
    obj = tmp_path / "two.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n")
    caster = sahara.RayCaster.from_file(str(obj))
    # The loader may give each triangle corners of its own: compare positions.
    corners = caster.vertices[caster.triangles]
    assert corners.tolist() == [[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [1, 0, 0], [0, 0, 1]]]
    rays = rays_from([[0.2, 0.2, 1], [0.2, -1, 0.2]], [[0, 0, -1], [0, 1, 0]])
    assert caster.cast_rays(rays)["primitive_ids"].tolist() == [0, 1]
    with pytest.raises(Exception, match="missing.obj"):
        sahara.RayCaster.from_file(tmp_path / "missing.obj")


def test_from_file_bakes_gltf_gpu_instances(tmp_path):
    """EXT_mesh_gpu_instancing: every instance's triangle is a primitive, in instance order."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    moves = np.array([[0, 0, 0], [5, 0, 0]], np.float32)
    path = write_gltf(tmp_path / "instanced.gltf", [positions, moves], {
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "extensionsRequired": ["EXT_mesh_gpu_instancing"],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1}}}}],
        "scenes": [{"nodes": [0]}],
    })
    caster = sahara.RayCaster.from_file(path)
    assert len(caster.triangles) == 2
    rays = rays_from([[0.2, 0.2, 1], [5.2, 0.2, 1]], [[0, 0, -1], [0, 0, -1]])
    assert caster.cast_rays(rays)["primitive_ids"].tolist() == [0, 1]


def exact_plane_hits(v, f, rays, ids):
    """t and barycentrics of each ray on its triangle's plane, in double."""
    p0, p1, p2 = (v[f[ids, k]].astype(float) for k in range(3))
    e1, e2 = p1 - p0, p2 - p0
    n = np.cross(e1, e2)
    o, d = rays[:, :3].astype(float), rays[:, 3:].astype(float)
    t = np.einsum("ij,ij->i", n, p0 - o) / np.einsum("ij,ij->i", n, d)
    q = o + d * t[:, None] - p0
    nn = np.einsum("ij,ij->i", n, n)
    u = np.einsum("ij,ij->i", n, np.cross(q, e2)) / nn
    w = np.einsum("ij,ij->i", n, np.cross(e1, q)) / nn
    return t, u, w


@pytest.mark.parametrize("coherent", [False, True])
def test_near_hits_on_long_slivers_have_float_accurate_t_and_barycentrics(coherent):
    # Strips 6 units long and 1.5 cm wide, like a room's skirting boards, hit from a few
    # cm away: the watertight test's own t is off by up to 1e-3 relative there; the
    # caster reports the plane intersection, within a float rounding or two.
    v = np.array([[0, 0, 0.1], [0.015, 6, 0.1], [0, 6, 0.1], [0.015, 0, 0.1],
                  [0, -1, 0.1], [8, -0.985, 0.1], [0, -0.985, 0.1]], np.float32)
    f = np.array([[0, 1, 2], [0, 3, 1], [4, 5, 6]], np.int32)
    caster = sahara.RayCaster(v, f)
    rng = np.random.default_rng(7)
    n = 4096
    if coherent:  # one origin, a narrow cone: the packet traversal
        origins = np.tile([[0.005, 3.0, 0.13]], (n, 1))
        d = np.array([0.0, 0.0, -1.0]) + 0.02 * rng.uniform(-1, 1, size=(n, 3))
    else:
        origins = np.column_stack([rng.uniform(0, 0.015, n), rng.uniform(0, 6, n), rng.uniform(0.1001, 0.2, n)])
        d = rng.normal(size=(n, 3))
        d[:, 2] = -np.abs(d[:, 2])
    rays = np.hstack([origins, d]).astype(np.float32)
    got = caster.cast_rays(rays)
    hit = got["primitive_ids"] >= 0
    assert hit.mean() > 0.1
    ids = got["primitive_ids"][hit]
    t, u, w = exact_plane_hits(v, f, rays[hit], ids)
    np.testing.assert_allclose(got["t_hit"][hit], t, rtol=4e-7)
    scale = np.linalg.norm(rays[hit, 3:], axis=1) * t  # distance along the ray
    np.testing.assert_allclose(got["primitive_uvs"][hit, 0], u, atol=1e-6 + 1e-7 * scale.max())
    np.testing.assert_allclose(got["primitive_uvs"][hit, 1], w, atol=1e-6 + 1e-7 * scale.max())
    # intersect_all reports the same nearest crossing.
    all_hits = caster.intersect_all(rays)
    first = np.unique(all_hits["ray_ids"], return_index=True)[1]
    np.testing.assert_allclose(all_hits["t"][first], got["t_hit"][hit], rtol=1e-7)



def test_no_hits_on_a_strip_just_behind_the_origin():
    # A skirting-board strip (6 x 0.015) in a random orientation, rays through random
    # points of it in random directions, their origins 1e-7 to 1e-5 of its length off its
    # plane: where the plane lies behind the origin (double plane t < 0) nothing may be
    # hit; on the other side the float test still hits (all but rays whose float t comes
    # out <= 0, a few percent on this sliver).
    rng = np.random.default_rng(5)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    strip = np.array([[0, 0, 0], [0.015, 6, 0], [0, 6, 0], [0.015, 0, 0]])
    v = (strip @ q.T + [0.3, -0.2, 0.1]).astype(np.float32)
    f = np.array([[0, 1, 2], [0, 3, 1]], np.int32)
    caster = sahara.RayCaster(v, f)
    p = v.astype(np.float64)
    normal = np.cross(p[1] - p[0], p[2] - p[0])
    normal /= np.linalg.norm(normal)
    n = 20000
    tri = rng.integers(0, 2, n)
    b = rng.uniform(0.1, 0.45, size=(n, 2))
    corner = p[f[tri, 0]]
    target = corner + b[:, :1] * (p[f[tri, 1]] - corner) + b[:, 1:] * (p[f[tri, 2]] - corner)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    cos = d @ normal
    keep = np.abs(cos) > 0.05
    d, target, cos = d[keep], target[keep], cos[keep]
    offset = 6.0 * 10.0 ** rng.uniform(-7, -5, len(d))
    side = np.where(rng.uniform(size=len(d)) < 0.5, -1.0, 1.0)  # -1: the plane behind the origin
    rays = np.hstack([target - d * (side * offset / np.abs(cos))[:, None], d]).astype(np.float32)
    r = rays.astype(np.float64)
    behind = ((p[0] - r[:, :3]) @ normal) / (r[:, 3:] @ normal) < 0
    assert behind.sum() > 5000 and (~behind).sum() > 5000
    got = caster.cast_rays(rays)
    assert (got["primitive_ids"][behind] == -1).all()
    assert not caster.occluded(rays)[behind].any()
    assert (got["primitive_ids"][~behind] >= 0).mean() > 0.9
    assert (got["t_hit"][~behind][got["primitive_ids"][~behind] >= 0] > 0).all()
