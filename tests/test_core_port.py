"""The Rust core against the numba engine it replaces: every built-in force, every method,
free and about a pivot, must give the same trajectory to round-off (bit for bit where the
order of operations is the same) with the same counts of steps and evaluations. The numba
engine stays reachable (``backend="numba"``) only for this cross-check, until it is removed."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import simulate
from poinsot.rotation import matrix_from_euler
from test_compiled_core import BODY, FORCES, METHODS, PIVOT


@pytest.mark.parametrize("pivot", [None, PIVOT], ids=["free", "pivot"])
@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("kind", sorted(FORCES))
def test_core_equals_the_numba_engine(kind, method, pivot):
    force = FORCES[kind]
    if method == "splitting" and not force.position_only:
        pytest.skip("the splitting method takes position-only forces")
    kw = dict(
        omega0=(0.3, 1.2, -0.5),
        Q0=matrix_from_euler([0.1, 0.6, -0.3], "ZXZ"),
        forces=[force],
        pivot=pivot,
        method=method,
        dt=METHODS[method],
        rtol=1e-9,
        atol=1e-11,
    )
    for sampling in ({"t_eval": np.linspace(0, 0.4, 5)}, {"save_every": 3}):
        core = simulate(BODY, (0, 0.4), backend="compiled", **kw, **sampling)
        old = simulate(BODY, (0, 0.4), backend="numba", **kw, **sampling)
        scale = np.abs(old.state).max()
        np.testing.assert_allclose(core.t, old.t, rtol=0, atol=1e-15)
        np.testing.assert_allclose(core.state, old.state, rtol=0, atol=1e-14 * scale)
        assert (core.nfev, core.nsteps) == (old.nfev, old.nsteps)


def test_torque_free_notebook_body_equals_the_numba_engine():
    from poinsot import RigidBody

    grid = [(i, 2 * j, 3 * k) for i in (0, 0.5, 1) for j in (0, 0.5, 1) for k in (0, 0.5, 1)]
    body = RigidBody.from_particles(np.full(27, 10 / 27), grid)
    for method, dt in (("rk4", 1e-2), ("dop853", None), ("rkmk4", 1e-2), ("splitting", 1e-2)):
        a = simulate(body, (0, 20), omega0=(0, 1, 1), method=method, dt=dt, backend="compiled")
        b = simulate(body, (0, 20), omega0=(0, 1, 1), method=method, dt=dt, backend="numba")
        np.testing.assert_allclose(a.state, b.state, rtol=0, atol=1e-13)
