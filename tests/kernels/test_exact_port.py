"""The exact torque-free solution in the Rust core (``poinsot._core``) against the numba kernels
it was ported from (:mod:`poinsot.kernels.elliptic`, :mod:`~poinsot.kernels.torque_free`,
:mod:`~poinsot.kernels.freebody`).

The port keeps every formula and its order of operations, and calls the same C library
functions, so the two agree to round-off; the tests ask for 1e-14 relative (in practice they
are bit-for-bit equal). Inputs: random moments and ω, every symmetry class, ω near the
separatrix and near the axes, ``m`` near 0 and near 1 on both sides of the branch points, and
ω scaled over the whole floating-point range.
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from poinsot import _core
from poinsot.kernels import elliptic as ke
from poinsot.kernels import freebody as kf
from poinsot.kernels import inertia as ki
from poinsot.kernels import torque_free as kt

RTOL = 1e-14
RNG = np.random.default_rng(20240611)


def assert_agree(rust, numba, scale=None):
    """Equal to ``RTOL`` relative (each value, or of ``scale`` where given); NaN and inf in the
    same places."""
    rust = np.asarray(rust, dtype=float)
    numba = np.asarray(numba, dtype=float)
    assert rust.shape == numba.shape
    assert np.array_equal(np.isnan(rust), np.isnan(numba))
    assert np.array_equal(np.isinf(rust), np.isinf(numba))
    both = np.isfinite(numba)
    np.testing.assert_array_equal(rust[~both & ~np.isnan(numba)], numba[~both & ~np.isnan(numba)])
    ref = np.abs(numba) if scale is None else np.broadcast_to(scale, numba.shape)
    err = np.abs(rust[both] - numba[both])
    tol = RTOL * ref[both] + 1e-300
    assert np.all(err <= tol), f"max relative difference {np.max(err / (ref[both] + 1e-300)):.3g}"


# --------------------------------------------------------------------------- elliptic
#: complements across the branch points: 0 (separatrix), below TINY_M1, around NEAR_ONE, to 1
M1S = [
    0.0,
    1e-300,
    1e-40,
    1e-33,
    1e-31,
    1e-20,
    1e-14,
    1e-9,
    0.99e-5,
    1.01e-5,
    1e-3,
    0.1,
    0.5,
    0.9,
    1.0 - 1e-9,
    1.0,
]


@pytest.mark.parametrize("m1", M1S)
def test_jacobi_functions(m1):
    m = 1.0 - m1
    K = ke.ellipk_m1(m1)
    assert _core.ellipk_m1(m1) == K or (math.isinf(K) and math.isinf(_core.ellipk_m1(m1)))
    span = 40.0 if math.isinf(K) else 7.0 * K
    u = np.concatenate([RNG.uniform(-span, span, 300), [0.0, 1e-300, -1e-12]])
    if math.isfinite(K):  # the quarter periods, where cn and dn are small
        u = np.concatenate([u, K * np.arange(-5, 6), K * np.arange(-5, 6) + 1e-9])
    for rust, numba in zip(
        _core.jacobi_reduced(u, m, m1, K), ke.jacobi_reduced(u, m, m1, K), strict=True
    ):
        assert_agree(rust, numba)
    for rust, numba in zip(
        _core.jacobi_sn_cn_dn_am(u, m, m1), ke.jacobi_sn_cn_dn_am(u, m, m1), strict=True
    ):
        assert_agree(rust, numba)


@pytest.mark.parametrize("m1", M1S)
def test_integrals(m1):
    m = 1.0 - m1
    phi = np.concatenate([RNG.uniform(-12, 12, 60), [0.0, math.pi / 2, -math.pi, 3 * math.pi]])
    assert_agree(_core.ellipf(phi, m, m1), [ke.ellipf_scalar(p, m, m1) for p in phi])
    for n in (-50.0, -3.0, -0.4, 0.0, 0.3, 0.9):
        if m1 > 0:
            assert_agree(_core.ellippi_complete(n, m, m1), ke.ellippi_complete(n, m, m1))
            assert_agree(
                _core.ellippi(n, phi, m, m1), [ke.ellippi_scalar(n, p, m, m1) for p in phi]
            )
        K = ke.ellipk_m1(m1)
        u = RNG.uniform(-30, 30, 60) if math.isinf(K) else RNG.uniform(-6 * K, 6 * K, 60)
        assert_agree(_core.third_kind_u(n, u, m, m1), ke.third_kind_u(n, u, m, m1))
    for a in RNG.uniform(-math.pi, math.pi, 40):
        s, c = math.sin(a), math.cos(a)
        assert_agree(
            _core.first_kind_from_sn_cn(s, c, m, m1), ke.first_kind_from_sn_cn(s, c, m, m1)
        )


def test_carlson_forms():
    for _ in range(300):
        x, y, z, p = RNG.uniform(0, 10, 4) * 10.0 ** RNG.integers(-8, 8, 4)
        if RNG.random() < 0.3:
            x = 0.0
        assert_agree(_core.carlson_rf(x, y, z), ke.carlson_rf(x, y, z))
        assert_agree(_core.carlson_rj(x, y, z, p), ke.carlson_rj(x, y, z, p))


# --------------------------------------------------------------------------- torque-free
def _rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 2] = -q[:, 2]
    return np.ascontiguousarray(q)


def _separatrix_omegas(I, rng, n):
    """ω on the separatrix (a² = 2k I2: I1(I2 − I1) ω1² = I3(I3 − I2) ω3²), then nudged off it
    by relative 1e-16 … 1e-6."""
    I1, I2, I3 = I
    w3 = rng.uniform(0.1, 1, n) * rng.choice([-1, 1], n)
    w1 = np.sqrt(I3 * (I3 - I2) / (I1 * (I2 - I1))) * w3 * rng.choice([-1, 1], n)
    w2 = rng.uniform(-2, 2, n)
    W = np.column_stack([w1, w2, w3])
    nudge = 10.0 ** rng.uniform(-16, -6, (n, 1)) * rng.choice([-1, 1], (n, 3))
    return np.vstack([W, W * (1 + nudge)])


def _cases(rng):
    """(sorted moments scaled to I3 ~ 1, symmetry code, body-frame ω (N, 3))."""
    out = []
    for _ in range(6):
        I = np.sort(rng.uniform(0.2, 3, 3))
        out.append(I)
    out += [np.array([1.0, 2.0, 3.0]), np.array([1.0, 1.0, 2.0]), np.array([1.0, 2.0, 2.0])]
    out += [np.array([2.0, 2.0, 2.0]), np.array([1.0, 1.0 + 1e-9, 3.0])]
    for I in out:
        In = np.ldexp(I, -int(np.frexp(I[2])[1]))
        code = int(ki.symmetry_code(In, ki.SYMMETRY_RTOL))
        W = [rng.normal(size=(40, 3))]
        W.append(np.array([[1e-3, 1.0, 1e-3], [0, 1.0, 0], [0, 0, 0], [1.0, 0, 0], [0, 0, 2.0]]))
        W.append(np.array([[1e-150, 1.0, -1e-150], [1e-3, 1e-200, 0.0], [5e-200, 1e-300, 2e-200]]))
        W.append(rng.normal(size=(10, 3)) * 10.0 ** rng.uniform(-150, 150, (10, 1)))
        if code == 0:
            W.append(_separatrix_omegas(In, rng, 20))
        yield In, code, np.ascontiguousarray(np.vstack(W))


def test_regimes_periods_and_flips():
    for I, code, W in _cases(RNG):
        S = _rotation(RNG)
        rust = _core.torque_free_regimes(I, S, code, W)
        numba = kt.regimes(I, S, code, W)
        assert_agree(rust, numba)
        assert_agree(_core.torque_free_periods(I, S, code, W), kt.periods(numba))
        assert_agree(_core.torque_free_flip_intervals(I, S, code, W), kt.flip_intervals(numba))
    assert tuple(_core.TORQUE_FREE_CASE_NAMES) == kt.CASE_NAMES
    offsets = {name: getattr(kt, name.upper()) for name in _core.REGIME_OFFSETS if name != "size"}
    assert _core.REGIME_OFFSETS == {**offsets, "size": kt.REGIME_SIZE}


def test_exact_omegas_and_attitudes():
    T = np.concatenate([[0.0], np.sort(RNG.uniform(-30, 300, 40))])
    for I, code, W in _cases(RNG):
        S = _rotation(RNG)
        rust = _core.torque_free_omegas(I, S, code, W, T)
        numba = kt.exact_omegas(I, S, code, W, T)
        scale = np.linalg.norm(W, axis=1)[:, None, None]  # |ω| is the scale of each member
        assert_agree(rust, numba, scale=scale)
        keep = np.abs(W).max(axis=1) < 1e100  # Q(t) of ω ~ 1e150 turns 1e150 radians: noise
        Wq = np.ascontiguousarray(W[keep])
        Q0 = np.ascontiguousarray(np.array([_rotation(RNG) for _ in Wq]))
        for q in (Q0, Q0[:1]):
            rust = _core.torque_free_attitudes(I, S, code, Wq, q, T)
            numba = kt.exact_attitudes(I, S, code, Wq, q, T)
            assert_agree(rust, numba, scale=1.0)


def test_the_readme_flip_interval():
    I = np.array([0.25, 0.5, 0.75])  # (1, 2, 3) scaled to I3 ~ 1 as FreeRigidBody does
    w = np.array([[1e-3, 1.0, 1e-3]])
    value = _core.torque_free_flip_intervals(I, np.eye(3), 0, w)[0]
    assert value == kt.flip_intervals(kt.regimes(I, np.eye(3), 0, w))[0]
    assert value == pytest.approx(27.5308405537, rel=1e-11)


# --------------------------------------------------------------------------- the free body
def test_free_body_formulas():
    for _ in range(50):
        I = np.sort(RNG.uniform(0.2, 3, 3))
        W = RNG.normal(size=(20, 3))
        for rust, numba in zip(_core.principal_invariants(I, W), kf.invariants(I, W), strict=True):
            assert_agree(rust, numba)
        k, a = kf.invariants(I, W[:1])
        k, a = float(k[0]), float(a[0])
        assert_agree(_core.energy_ellipsoid_semi_axes(I, k), kf.energy_ellipsoid_semi_axes(I, k))
        assert_agree(
            _core.momentum_ellipsoid_semi_axes(I, a), kf.momentum_ellipsoid_semi_axes(I, a)
        )
        b = kf.cone_coefficients(I, k, a)
        assert_agree(_core.cone_coefficients(I, k, a), b, scale=np.abs(b).max())
        R = _rotation(RNG)
        A = np.ascontiguousarray(R @ np.diag(I) @ R.T)
        J = kf.euler_jacobian(A, W[0])
        # LU by LAPACK against ours: the same algorithm, not always the same rounding
        assert_agree(_core.euler_jacobian(A, W[0]), J, scale=10 * np.abs(J).max())
        assert _core.symmetry_code(I, _core.SYMMETRY_RTOL) == ki.symmetry_code(I, ki.SYMMETRY_RTOL)
    assert _core.SYMMETRY_RTOL == ki.SYMMETRY_RTOL
    assert tuple(_core.SYMMETRY_CLASSES) == ki.SYMMETRY_CLASSES
    for I in ([1.0, 1.0, 2.0], [1.0, 2.0, 2.0], [2.0, 2.0, 2.0], [1.0, 1.0 + 1e-13, 2.0]):
        I = np.array(I)
        assert _core.symmetry_code(I, _core.SYMMETRY_RTOL) == ki.symmetry_code(I, ki.SYMMETRY_RTOL)


# --------------------------------------------------------------------------- the boundary
def test_bad_shapes_are_value_errors_not_panics():
    I, S = np.array([1.0, 2.0, 3.0]), np.eye(3)
    with pytest.raises(ValueError, match=r"`w` must have shape \(N, 3\)"):
        _core.torque_free_omegas(I, S, 0, np.zeros((2, 4)), np.zeros(3))
    with pytest.raises(ValueError, match="`symmetry` must be a code"):
        _core.torque_free_regimes(I, S, 7, np.zeros((1, 3)))
    with pytest.raises(ValueError, match="`q0` must hold one rotation or one per member"):
        _core.torque_free_attitudes(I, S, 0, np.ones((3, 3)), np.ones((2, 3, 3)), np.zeros(2))
    with pytest.raises(ValueError, match="singular"):
        _core.euler_jacobian(np.zeros((3, 3)), np.ones(3))
    assert _core.torque_free_omegas(I, S, 0, np.zeros((0, 3)), np.zeros(4)).shape == (0, 4, 3)
    assert _core.torque_free_omegas(I, S, 0, np.ones((2, 3)), np.zeros(0)).shape == (2, 0, 3)


def test_free_rigid_body_never_imports_numba():
    code = textwrap.dedent(
        """
        import sys
        import numpy as np
        from poinsot.torquefree import FreeRigidBody
        for moments in ((1, 2, 3), (1, 1, 2), (1, 2, 2), (2, 2, 2)):
            body = FreeRigidBody(moments)
            w = (0.1, 1.0, 0.2)
            t = np.linspace(0, 20, 101)
            body.exact_omega(w, t)
            body.exact_omega(np.array([w, (0.3, -0.2, 1.0)]), t)
            body.exact_attitude(w, t)
            body.period(np.array([w, w]))
            body.flip_interval(np.array([w, w]))
            body.classify(w)
            body.invariants(w)
            body.describe(w)
            body.polhode(w, n=50)
            body.herpolhode(w, t)
            body.euler_rhs(w)
            body.fixed_points()
            body.cone_matrix(*body.invariants(w))
        body = FreeRigidBody((1, 2, 3))
        body.polhode_family(levels=3, n=20)
        body.stability((0.0, 1.0, 0.0))
        body.fixed_point_attitude((0.0, 1.0, 0.0), [0.0, 1.0])
        from poinsot import elliptic
        elliptic.jacobi(np.linspace(0, 3, 5), 0.5, 0.5)
        elliptic.third_kind_u(-0.5, 1.0, 0.5, 0.5)
        print("numba" in sys.modules)
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False", done.stdout + done.stderr
