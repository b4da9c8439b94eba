"""The in-place solver of the compiled right-hand sides against LAPACK (numpy.linalg.solve),
with the invariances every linear solve has."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poinsot.kernels.linalg import solve_augmented, solve_spd_augmented


def _system(seed, n):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n)) + n * np.eye(n) * rng.choice([-1, 1], size=n)  # well conditioned
    return A[rng.permutation(n)], rng.normal(size=n)  # permuted rows: pivoting is needed


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 14))
def test_equals_lapack(seed, n):
    A, b = _system(seed, n)
    K = np.column_stack([A, b])
    assert solve_augmented(K, n)
    np.testing.assert_allclose(K[:, n], np.linalg.solve(A, b), rtol=1e-11, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 10), st.sampled_from([1e-150, 1e-8, 1e8, 1e150]))
def test_scale_invariance(seed, n, s):
    """(sA) x = s b has the same x: with partial pivoting, to round-off at any scale."""
    A, b = _system(seed, n)
    K1, K2 = np.column_stack([A, b]), np.column_stack([s * A, s * b])
    assert solve_augmented(K1, n) and solve_augmented(K2, n)
    np.testing.assert_allclose(K2[:, n], K1[:, n], rtol=1e-12, atol=1e-14)


def test_kkt_system_of_a_constrained_pendulum():
    """The Cartesian pendulum (m = l = 1, g = 9.81) at rest at θ = 90°: the KKT matrix has a
    zero diagonal block, so the first pivot must come from below. ẍ = 0, ÿ = −g, λ = 0 — and
    at θ = 0 (hanging) the rod tension −2λl = m g gives λ = −g/2 (docs/theory.md, [L] (6.60))."""
    # unknowns (ẍ, ÿ, λ); G = [2x, 2y]; row 3: G q̈ = −γ = −2|q̇|² = 0
    K = np.array([[1.0, 0.0, -2.0, 0.0], [0.0, 1.0, 0.0, -9.81], [2.0, 0.0, 0.0, 0.0]])
    assert solve_augmented(K, 3)
    np.testing.assert_allclose(K[:, 3], [0.0, -9.81, 0.0], atol=1e-15)
    K = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 2.0, -9.81], [0.0, -2.0, 0.0, 0.0]])
    assert solve_augmented(K, 3)
    np.testing.assert_allclose(K[:, 3], [0.0, 0.0, -9.81 / 2], atol=1e-15)


@pytest.mark.parametrize("bad", [0.0, np.nan, np.inf])
def test_singular_or_non_finite_is_reported(bad):
    K = np.array([[1.0, 2.0, 1.0], [2.0, 4.0, 2.0]])  # rank 1
    assert not solve_augmented(K, 2)
    K = np.array([[bad, 0.0, 1.0], [0.0, bad, 1.0]])
    assert not solve_augmented(K, 2)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 14), st.sampled_from([1e-150, 1.0, 1e150]))
def test_cholesky_equals_lapack_on_mass_matrices(seed, n, s):
    """A mass matrix is symmetric positive definite: Cholesky gives LAPACK's solution, at any
    scale, reading only the lower triangle."""
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(n, n))
    M = s * (B @ B.T + n * np.eye(n))
    b = s * rng.normal(size=n)
    K = np.column_stack([np.tril(M), b])  # the upper triangle is never read
    assert solve_spd_augmented(K, n)
    np.testing.assert_allclose(K[:, n], np.linalg.solve(M, b), rtol=1e-10, atol=1e-12)


def test_cholesky_refuses_an_indefinite_matrix():
    K = np.array([[1.0, 2.0, 1.0], [2.0, 1.0, 1.0]])  # eigenvalues 3 and −1
    assert not solve_spd_augmented(K, 2)
