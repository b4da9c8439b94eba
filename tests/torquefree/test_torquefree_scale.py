"""The torque-free analysis is scale-free (issue 12, §3): under ω → sω and I → s'I, for s, s'
from 1e-150 to 1e150, the family is the same, times scale as 1/s, ω(t/s) as s and Q(t/s) not at
all. Reference: Euler's equation A ω̇ = Aω × ω is homogeneous of degree 1 in A and 2 in ω."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poinsot import FreeRigidBody

exponents = st.integers(-150, 150)
# components 0 or ≥ 1e-6 in size, so that s·ω stays a normal number (the kernels flush
# subnormals to zero) over the whole range of s
component = st.one_of(st.just(0.0), st.floats(1e-6, 1.0), st.floats(-1.0, -1e-6))
directions = st.tuples(component, component, component).filter(lambda v: np.linalg.norm(v) > 0.1)
shapes = st.sampled_from([(1.0, 2.0, 3.0), (1.0, 1.0, 2.0), (2.0, 2.0, 1.0), (1.3, 1.7, 2.9)])


@settings(max_examples=60, deadline=None)
@given(shapes, directions, exponents, exponents)
def test_covariant_under_scaling_of_omega_and_moments(moments, direction, e_omega, e_moments):
    s, sI = 10.0**e_omega, 10.0**e_moments
    w = np.array(direction)
    ref = FreeRigidBody(moments)
    body = FreeRigidBody(np.array(moments) * sI)
    family = ref.classify(w)
    assert body.classify(w * s) == family
    t = np.array([0.0, 0.7, 3.1])
    np.testing.assert_allclose(body.exact_omega(w * s, t / s) / s, ref.exact_omega(w, t),
                               rtol=1e-9, atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(body.exact_attitude(w * s, t / s), ref.exact_attitude(w, t),
                               atol=1e-9)  # fmt: skip
    if family not in ("fixed point", "spherical", "separatrix"):
        assert body.period(w * s) * s == pytest.approx(ref.period(w), rel=1e-12)


@pytest.mark.parametrize("speed", [1e-12, 1e-9, 1e-8, 1e-7, 1.0])
def test_a_slow_symmetric_spin_is_not_a_fixed_point(speed):
    """A symmetric body spinning at 1e-9 rad/s precesses like one at 1 rad/s, slowed down."""
    body = FreeRigidBody((1.0, 1.0, 2.0))
    w = np.array([0.3, 0.0, 1.0]) * speed
    assert body.classify(w) == "symmetric"
    t = np.array([0.0, 2.0]) / speed
    np.testing.assert_allclose(body.exact_attitude(w, t), body.exact_attitude(w / speed,
                               t * speed), atol=1e-12)  # fmt: skip


def test_energy_out_of_the_double_range_is_refused_with_the_range():
    body = FreeRigidBody((1.0, 2.0, 3.0))
    with pytest.raises(ValueError, match=r"out of range: 2k·I3 and 2k/I1 must lie within"):
        body.polhode_family(1e308)
    assert len(body.polhode_family(1e300)) > 0


@settings(max_examples=200, deadline=None)
@given(st.integers(-300, 300), st.integers(-300, 300), st.integers(-100, 100), st.floats(1.0, 9.99))
def test_the_feasibility_check_is_exact_over_the_whole_double_range(e_k, e_a, e_I, mant):
    """Condition (33) ``I1 ≤ a²/(2k) ≤ I3`` judged against exact rational arithmetic
    (``fractions.Fraction`` of the very floats given): every verdict agrees, and no input
    raises anything but a ValueError (``momentum = 1e300`` raised OverflowError)."""
    from fractions import Fraction

    body = FreeRigidBody(np.array([1.0, 2.0, 3.0]) * 10.0**e_I)
    k, a = 10.0**e_k, mant * 10.0**e_a
    I1, _, I3 = (Fraction(x) for x in body.principal_moments)
    try:
        body.check_energy_range(k)
    except ValueError:
        with pytest.raises(ValueError, match="out of range"):
            body.check_feasible(k, a)
        return
    D = Fraction(a) ** 2 / (2 * Fraction(k))
    tol = Fraction(1, 10**12)
    if I1 * (1 - tol) <= D <= I3 * (1 + tol):
        assert body.check_feasible(k, a) == pytest.approx(float(min(max(D, I1), I3)), rel=1e-12)
    else:
        with pytest.raises(ValueError, match="infeasible invariants"):
            body.check_feasible(k, a)


@pytest.mark.parametrize("bad", [("x", 1.0), (1.0, "x"), (1.0, complex(1, 1)), (None, 1.0)])
def test_the_invariants_given_to_check_feasible_are_named(bad):
    with pytest.raises(TypeError, match=r"`(energy|momentum)` must be a real number"):
        FreeRigidBody((1.0, 2.0, 3.0)).check_feasible(*bad)
