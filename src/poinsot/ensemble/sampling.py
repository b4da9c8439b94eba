"""Distributions of initial spins for ensembles (the scenario's ``[ensemble]`` table).

Both draw from NumPy's ``Generator`` with a stated seed, so a scenario is reproducible.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DISTRIBUTIONS", "gaussian", "uniform_on_sphere"]


def uniform_on_sphere(n: int, speed: float, seed: int) -> np.ndarray:
    """``n`` angular velocities (n, 3) uniformly distributed over the directions, all of
    magnitude ``speed``: normalised standard normal vectors (Muller, *Comm. ACM* 2, 1959)."""
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, 3))
    norms = np.linalg.norm(v, axis=1, keepdims=True)
    while np.any(norms == 0):  # probability zero, but never divide by it
        bad = norms[:, 0] == 0
        v[bad] = rng.standard_normal((int(bad.sum()), 3))
        norms = np.linalg.norm(v, axis=1, keepdims=True)
    return speed * v / norms


def gaussian(n: int, mean, std, seed: int) -> np.ndarray:
    """``n`` angular velocities (n, 3) with independent normal components ``N(mean_k, std_k²)``
    (``std_k = 0`` holds a component at its mean)."""
    rng = np.random.default_rng(seed)
    return np.asarray(mean, dtype=float) + np.asarray(std, dtype=float) * rng.standard_normal(
        (n, 3)
    )


DISTRIBUTIONS = ("sphere", "gaussian")
