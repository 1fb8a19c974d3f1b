"""Ray sets the Python benchmarks share, so every script casts the same rays."""
import numpy as np


def random_rays(vertices, count, rng):
    """Origins uniform on a sphere around the mesh's box, aimed at random points inside it (K x 6 float32)."""
    lo, hi = vertices.min(0), vertices.max(0)
    center, radius = (lo + hi) / 2, np.linalg.norm(hi - lo)
    d = rng.normal(size=(count, 3))
    origins = center + radius * d / np.linalg.norm(d, axis=1, keepdims=True)
    targets = rng.uniform(lo, hi, size=(count, 3))
    return np.hstack([origins, targets - origins]).astype(np.float32)
