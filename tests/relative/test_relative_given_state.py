"""``PreparedRelativeRun.run(y0=...)`` checks the whole relative state it is given, as
``PreparedRun.run(y0=...)`` does a rigid body's: a state that is not one (a Q_r of det 2, a
NaN, a carrier attitude other than the carrier's own) is refused naming its slice, and the
state ``initial_state`` returns runs as the keyword arguments do, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from poinsot import RigidBody
from poinsot.relative import Carrier, prepare_relative

T = sp.Symbol("t", real=True)
BODY = RigidBody.box(3.0, (0.4, 0.7, 1.2))
SPIN = Carrier(omega_e=(0, 0, 1), name="turntable")
NODDING = Carrier(euler_angles=[0.3 * T, 0.2 * sp.sin(T), 0], t=T, name="nodding")


def _prepared(carrier, **kw):
    return prepare_relative(BODY, (0, 1), carrier=carrier, t_eval=[0, 0.5, 1], **kw)


@pytest.mark.parametrize("carrier", [SPIN, NODDING], ids=["omega_e", "euler_angles"])
def test_the_state_initial_state_returns_runs_as_the_arguments(carrier):
    p = _prepared(carrier)
    y0 = p.initial_state(omega_r0=(1, 2, 3), r0=(0.1, 0.2, 0.3))
    a = p.run(omega_r0=(1, 2, 3), r0=(0.1, 0.2, 0.3))
    b = p.run(y0=y0)
    np.testing.assert_array_equal(a.y, b.y)
    c = p.run(y0=list(y0))  # any array NumPy can hand over
    np.testing.assert_array_equal(a.y, c.y)


def _with(y0, index, value):
    y = np.array(y0, dtype=float)
    y[index] = value
    return y


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda y: y[:30], r"`y0` must have shape \(33,\), found shape \(30,\)"),
        (lambda y: y.reshape(3, 11), r"`y0` must have shape \(33,\)"),
        (lambda y: _with(y, 6, 2.0), r"`y0\[6:15\] \(Q_r, row by row\)` is not a rotation"),
        (lambda y: _with(y, 18, -1.0), r"`y0\[18:27\] \(Q_carrier, row by row\)` is not a rot"),
        (lambda y: _with(y, 0, np.nan), r"`y0\[0\]` must be finite"),
    ],
)
def test_a_state_that_is_not_one_is_refused(change, match):
    p = _prepared(SPIN)
    y0 = p.initial_state(omega_r0=(1, 2, 3))
    with pytest.raises(ValueError, match=match):
        p.run(y0=change(y0))


def test_the_carriers_own_attitude_and_a_held_centre_of_mass():
    p = _prepared(NODDING)
    y0 = p.initial_state(omega_r0=(1, 2, 3))
    turned = _with(y0, slice(18, 27), np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]]).ravel())
    with pytest.raises(ValueError, match=r"Q_carrier\) must be the carrier's attitude at t0"):
        p.run(y0=turned)
    held = _prepared(SPIN, hold_com=True)
    y0 = held.initial_state(omega_r0=(1, 2, 3))
    with pytest.raises(ValueError, match=r"\(v_r\) must be zero with `hold_com`"):
        held.run(y0=_with(y0, 4, 0.5))
