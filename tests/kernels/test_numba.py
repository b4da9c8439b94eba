"""The kernel layer compiles with numba and gives the same numbers as plain Python.

(The integrator steps call these kernels from Python today; compiling them is the route to
speed, so the layer must stay numba-compatible.)
"""

from __future__ import annotations

import numpy as np
import pytest

numba = pytest.importorskip("numba")

from poinsot.kernels import elliptic, inertia, rigid, so3  # noqa: E402
from poinsot.kernels.jit import jit  # noqa: E402

RNG = np.random.default_rng(7)
FACES = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 3], [1, 2, 3]])

CASES = {
    "axis_rotation": (rigid.axis_rotation, (1, 0.3)),
    "euler_omega_dot": (
        rigid.euler_omega_dot,
        (np.diag([1.0, 2, 3]), np.diag([1.0, 0.5, 1 / 3]), RNG.normal(size=3), RNG.normal(size=3)),
    ),
    "free_rotor_strang": (
        rigid.free_rotor_strang,
        (np.array([1.0, 2, 3]), RNG.normal(size=3), so3.rodrigues(RNG.normal(size=3)), 0.01),
    ),
    "free_rotor_symmetric": (
        rigid.free_rotor_symmetric,
        (np.array([1.0, 1, 3]), RNG.normal(size=3), np.eye(3), 0.01, 2),
    ),
    "free_rotor_step": (
        rigid.free_rotor_step,
        (np.array([1.0, 2, 2]), RNG.normal(size=3), np.eye(3), 0.01, 1e-12),
    ),
    "pack_state": (rigid.pack_state, (np.ones(3), np.ones(3), np.eye(3), np.ones(3))),
    "rodrigues": (so3.rodrigues, (RNG.normal(size=3),)),
    "rodrigues_small": (so3.rodrigues, (np.array([1e-6, -2e-6, 3e-7]),)),
    "hat3": (so3.hat3, (RNG.normal(size=3),)),
    "particle_inertia": (inertia.particle_inertia, (RNG.uniform(1, 2, 5), RNG.normal(size=(5, 3)))),
    "parallel_axis": (inertia.parallel_axis, (np.eye(3), 2.0, RNG.normal(size=3))),
    "planar_inertia": (inertia.planar_inertia, (np.diag([1.0, 2, 3]),)),
    "principal_decomposition": (inertia.principal_decomposition, (np.diag([3.0, 1, 2]),)),
    "polyhedron_mass_properties": (
        inertia.polyhedron_mass_properties,
        (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), FACES),
    ),
    "jacobi_sn_cn_dn_am": (elliptic.jacobi_sn_cn_dn_am, (np.linspace(0, 5, 7), 0.7, 0.3)),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_kernel_compiles_and_agrees(name):
    fn, args = CASES[name]
    expected = fn(*args)
    got = jit(fn)(*args)
    if not isinstance(expected, tuple):
        expected, got = (expected,), (got,)
    for e, g in zip(expected, got, strict=True):
        np.testing.assert_allclose(g, e, rtol=1e-13, atol=1e-15)


def test_rodrigues_matches_batched_exp():
    for w in RNG.normal(size=(20, 3)) * 2:
        np.testing.assert_allclose(so3.rodrigues(w), so3.exp_so3(w), atol=1e-15)
    np.testing.assert_allclose(so3.hat3(w), so3.hat(w))
