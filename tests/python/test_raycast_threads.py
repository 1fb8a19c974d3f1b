"""sahara.RayCaster on large batches: sorted tracing, threads= arguments and Ctrl-C."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))
import sahara  # noqa: E402
from raycast_meshes import icosphere  # noqa: E402


def random_rays(count, seed):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(count, 3))
    origins = 3 * d / np.linalg.norm(d, axis=1, keepdims=True)
    return np.hstack([origins, rng.uniform(-1, 1, size=(count, 3)) - origins]).astype(np.float32)


@pytest.fixture(scope="module")
def sphere():
    return icosphere(3)


def test_thread_counts_give_the_same_hits(sphere):
    v, f = sphere
    # More rays than one slice between signal checks, so several slices run.
    rays = random_rays(150_000, seed=3)
    reference = sahara.RayCaster(v, f, threads=1).cast_rays(rays)
    assert 0.3 < np.isfinite(reference["t_hit"]).mean() < 1.0
    caster = sahara.RayCaster(v, f)
    for threads in (None, 0, 1, 2, 3):
        got = caster.cast_rays(rays, threads=threads)
        for key in reference:
            np.testing.assert_array_equal(got[key], reference[key], err_msg=f"{key}, threads={threads}")
        np.testing.assert_array_equal(caster.occluded(rays, threads=threads), np.isfinite(reference["t_hit"]))


def test_a_large_batch_gives_what_small_batches_give():
    # Large incoherent batches are traced in a sorted order, small ones (and coherent
    # ones) in their own: the results must not depend on it, per-ray limits included.
    v, f = icosphere(6)  # a tree larger than the caster's threshold for sorting
    caster = sahara.RayCaster(v, f)
    assert caster.bvh_bytes > 2 << 20
    rays = random_rays(100_000, seed=5)
    tmax = np.random.default_rng(6).uniform(1, 4, len(rays)).astype(np.float32)
    whole = caster.cast_rays(rays, tmax=tmax)
    parts = [caster.cast_rays(rays[i:i + 5000], tmax=tmax[i:i + 5000]) for i in range(0, len(rays), 5000)]
    assert 0.2 < np.isfinite(whole["t_hit"]).mean() < 0.9
    for key in whole:
        np.testing.assert_array_equal(whole[key], np.concatenate([p[key] for p in parts]), err_msg=key)
    occluded = np.concatenate([caster.occluded(rays[i:i + 5000], tmax=tmax[i:i + 5000])
                               for i in range(0, len(rays), 5000)])
    np.testing.assert_array_equal(caster.occluded(rays, tmax=tmax), occluded)
    np.testing.assert_array_equal(occluded, np.isfinite(whole["t_hit"]))


def awkward_rays(count, seed):
    """Random rays mixed with the ones a sort key must not trip over: origins inside the
    box and exactly on its planes with zero direction components, zero, NaN and infinite
    rays, and per-ray limits including empty intervals; shuffled, so the batch is sorted."""
    rng = np.random.default_rng(seed)
    rays = random_rays(count, seed)
    n = count // 10
    inside = rays[:n]
    inside[:, :3] = rng.uniform(-0.9, 0.9, size=(n, 3))
    axis = rays[n:2 * n]
    # On the box's planes, or anywhere (not at 0: the sphere's vertices on the axes would
    # make ties between triangles, which the packet path may break the other way).
    on_plane = rng.random((n, 3)) < 0.5
    axis[:, :3] = np.where(on_plane, rng.choice([-1.0, 1.0], (n, 3)), rng.uniform(-0.9, 0.9, (n, 3)))
    axis[:, 3:] = 0
    axis[np.arange(n), 3 + rng.integers(0, 3, n)] = rng.choice([-1.0, 1.0], n)
    rays[2 * n:2 * n + 50, 3:] = 0
    rays[2 * n + 50:2 * n + 100, 0] = np.nan
    rays[2 * n + 100:2 * n + 150, 4] = np.inf
    rays[2 * n + 150:2 * n + 200, 1] = -np.inf
    tmin = rng.choice([0.0, 0.5, 3.0], count).astype(np.float32)
    tmax = rng.choice([np.inf, 2.0, 0.25], count).astype(np.float32)
    order = rng.permutation(count)
    return rays[order], tmin[order], tmax[order]


def test_sorted_tracing_of_awkward_rays_matches_tracing_in_batch_order():
    # Chunks below the sorting threshold trace in batch order; the whole batch is sorted
    # by where its rays cross the mesh's box. Same hits, every field, any thread count.
    v, f = icosphere(6)
    caster = sahara.RayCaster(v, f)
    rays, tmin, tmax = awkward_rays(60_000, seed=11)
    step = 5000
    parts = [caster.cast_rays(rays[i:i + step], tmin=tmin[i:i + step], tmax=tmax[i:i + step], threads=1)
             for i in range(0, len(rays), step)]
    reference = {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}
    assert 0.1 < np.isfinite(reference["t_hit"]).mean() < 0.9
    for threads in (1, 2, 3):
        whole = caster.cast_rays(rays, tmin=tmin, tmax=tmax, threads=threads)
        for key in whole:
            np.testing.assert_array_equal(whole[key], reference[key], err_msg=f"{key}, threads={threads}")
        np.testing.assert_array_equal(caster.occluded(rays, tmin=tmin, tmax=tmax, threads=threads),
                                      np.isfinite(reference["t_hit"]))


def test_batches_of_changing_sizes_on_one_caster_match_batch_order():
    # A caster keeps its sort buffers for the next batch: later batches, larger or
    # smaller, and occlusion queries in between, must not see what an earlier one left.
    v, f = icosphere(6)
    caster = sahara.RayCaster(v, f)
    for count, seed in ((60_000, 21), (20_000, 22), (90_000, 23), (30_000, 24)):
        rays, tmin, tmax = awkward_rays(count, seed)
        step = 5000
        parts = [caster.cast_rays(rays[i:i + step], tmin=tmin[i:i + step], tmax=tmax[i:i + step])
                 for i in range(0, count, step)]
        whole = caster.cast_rays(rays, tmin=tmin, tmax=tmax)
        for key in whole:
            np.testing.assert_array_equal(whole[key], np.concatenate([p[key] for p in parts]),
                                          err_msg=f"{key}, {count} rays")
        np.testing.assert_array_equal(caster.occluded(rays, tmin=tmin, tmax=tmax), np.isfinite(whole["t_hit"]))


def test_concurrent_casts_on_one_caster_match_casts_one_after_another():
    # Casts from several Python threads share the caster's kept sort buffers: each
    # must get buffers of its own.
    import concurrent.futures
    v, f = icosphere(6)
    caster = sahara.RayCaster(v, f, threads=1)
    batches = [awkward_rays(40_000 + 10_000 * i, seed=30 + i) for i in range(4)]
    expected = [caster.cast_rays(r, tmin=lo, tmax=hi) for r, lo, hi in batches]
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        for _ in range(2):
            got = list(pool.map(lambda b: caster.cast_rays(b[0], tmin=b[1], tmax=b[2]), batches))
            for g, e in zip(got, expected):
                for key in e:
                    np.testing.assert_array_equal(g[key], e[key], err_msg=key)


def test_sorted_casts_on_the_sse2_path_match(tmp_path):
    # The sort key has a baseline and an AVX2 build (SAHARA_SIMD picks the path, the
    # traversal's too): the hits must not depend on it.
    rays, tmin, tmax = awkward_rays(40_000, seed=41)
    np.savez(tmp_path / "rays.npz", rays=rays, tmin=tmin, tmax=tmax)
    child = textwrap.dedent(f"""
        import sys
        import numpy as np
        sys.path.insert(0, {os.path.dirname(__file__)!r})
        import sahara
        from raycast_meshes import icosphere
        v, f = icosphere(6)
        a = np.load({str(tmp_path / "rays.npz")!r})
        r = sahara.RayCaster(v, f).cast_rays(a["rays"], tmin=a["tmin"], tmax=a["tmax"])
        np.savez({str(tmp_path / "hits.npz")!r}, **r)
    """)
    subprocess.run([sys.executable, "-c", child], check=True, timeout=300,
                   env=dict(os.environ, SAHARA_SIMD="sse2"))
    got = np.load(tmp_path / "hits.npz")
    v, f = icosphere(6)
    expected = sahara.RayCaster(v, f).cast_rays(rays, tmin=tmin, tmax=tmax)
    assert 0.1 < np.isfinite(expected["t_hit"]).mean() < 0.9
    for key in expected:
        np.testing.assert_array_equal(got[key], expected[key], err_msg=key)


def test_threads_property_and_from_file(tmp_path, sphere):
    v, f = sphere
    assert sahara.RayCaster(v, f).threads is None
    assert sahara.RayCaster(v, f, threads=0).threads is None
    assert sahara.RayCaster(v, f, threads=2).threads == 2
    path = tmp_path / "sphere.obj"
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in v) + "".join(f"f {a + 1} {b + 1} {c + 1}\n"
                                                                           for a, b, c in f))
    assert sahara.RayCaster.from_file(path, threads=1).threads == 1


@pytest.mark.parametrize("threads, error", [(-1, ValueError), (1 << 20, ValueError), ("2", TypeError),
                                            (2.0, TypeError), (True, TypeError)])
def test_bad_thread_counts_raise_naming_the_argument(sphere, threads, error):
    v, f = sphere
    caster = sahara.RayCaster(v, f)
    rays = random_rays(4, seed=1)
    for call in (lambda: sahara.RayCaster(v, f, threads=threads), lambda: caster.cast_rays(rays, threads=threads),
                 lambda: caster.occluded(rays, threads=threads)):
        with pytest.raises(error, match="threads"):
            call()


# A cast that takes many seconds on one thread (every ray misses a stack of triangles but
# passes through all their boxes), interrupted by SIGINT shortly after it starts. The cast's
# full length is estimated from a short one first: a KeyboardInterrupt that only came after
# the cast had finished would arrive after that time, not within half of it.
CHILD = textwrap.dedent("""
    import os, signal, sys, threading, time
    import numpy as np
    import sahara
    n = 20000
    v = np.tile(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), (n, 1))
    v[:, 2] = np.repeat(np.arange(n, dtype=np.float32), 3)
    caster = sahara.RayCaster(v, np.arange(3 * n).reshape(n, 3), threads=1)
    ray = np.array([0.9, 0.9, -1, 0, 0, 1], np.float32)
    caster.cast_rays(np.broadcast_to(ray, (500, 6)))  # warm-up
    start = time.monotonic()
    probe = caster.cast_rays(np.broadcast_to(ray, (5000, 6)))
    per_ray = (time.monotonic() - start) / 5000
    assert not np.isfinite(probe["t_hit"]).any()
    count = int(min(4e6, max(1e5, 30 / per_ray)))
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    try:
        caster.cast_rays(np.broadcast_to(ray, (count, 6)))
    except KeyboardInterrupt:
        print("interrupted", time.monotonic() - start, count * per_ray, flush=True)
        sys.exit(42)
    sys.exit(1)
""")


def test_sigint_stops_a_long_cast_with_keyboard_interrupt():
    proc = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ))
    assert proc.returncode == 42, proc.stdout + proc.stderr
    _, elapsed, full = proc.stdout.split()
    assert float(elapsed) < float(full) / 2, proc.stdout
