"""Issue 44, messages that name the place: a Lagrangian input or an event that raises, or gives
something other than a finite real number, is named with the time t; the user's own exception
is kept as the cause. (The campaign saw "`q0`, `params`: … the mass matrix is singular" for a
NaN input, a raw NumPy message for a string, and "cannot reshape array of size 0" for a NaN
event; a complex input was silently cut to its real part.)"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from poinsot import RigidBody, simulate
from poinsot.integrate.events import EventError
from poinsot.lagrange import LagrangianSystem
from poinsot.lagrange.arguments import InputError

t = sp.Symbol("t")
x, F = sp.Function("x")(t), sp.Function("F")(t)
m = sp.Symbol("m")
#: a mass driven by an input force F(t): L = ½ m ẋ² + F x
DRIVEN = LagrangianSystem([x], sp.Rational(1, 2) * m * x.diff(t) ** 2 + F * x)


def run(force, span=(0, 1), **kw):
    return DRIVEN.simulate(span, q0={x: 0.0}, params={m: 1.0}, inputs={F: force}, **kw)


@pytest.mark.parametrize(
    ("force", "message"),
    [
        (lambda tt: float("nan"), r"`inputs\[F\]` returned nan at t = 0: an input must be finite"),
        (lambda tt: np.sqrt(complex(tt - 2)),
         r"`inputs\[F\]` returned the complex number 1.414.*j at t = 0: an input must be real"),
        (lambda tt: "a", r"`inputs\[F\]` returned 'a' at t = 0: an input must be a number"),
        (lambda tt, q, qd: np.inf, r"`inputs\[F\]` returned inf at t = 0"),
    ],
)  # fmt: skip
def test_an_input_that_is_not_a_finite_real_number_is_named(force, message):
    with pytest.raises(InputError, match=message):
        run(force)


def test_an_input_that_turns_complex_during_the_run_is_named_with_its_time():
    with pytest.raises(InputError, match=r"complex number .* at t = 0\.5000"):
        run(lambda tt: np.sqrt(complex(0.5 - tt)))


def test_an_input_expression_that_leaves_its_domain_is_named():
    """``sqrt(2 - t)``, compiled into the core, stalls the step size as t nears 2: the input
    is named as the cause, where it stops being real, not the step size."""
    with pytest.raises(InputError, match=r"`inputs\[F\]` returned nan at t = 2\.0000") as err:
        run(sp.sqrt(2 - t), span=(0, 3))
    assert "step size" in str(err.value.__cause__)  # what the run saw, kept
    assert run(sp.sqrt(2 - t), span=(0, 1.5)).t[-1] == 1.5  # within its domain it runs


def test_an_input_that_raises_is_named_with_its_time_and_the_cause_kept():
    def force(tt):
        if tt > 0.25:
            raise ZeroDivisionError("the user's input broke")
        return 1.0

    with pytest.raises(InputError, match=r"`inputs\[F\]` raised ZeroDivisionError at "
                                         r"t = 0\.2.*the user's input broke") as err:  # fmt: skip
        run(force)
    assert isinstance(err.value.__cause__, ZeroDivisionError)


BOX = RigidBody.box(1.0, (1, 2, 3))


@pytest.mark.parametrize(
    ("event", "message"),
    [
        (lambda tt, y: float("nan"), r"`events\[0\]` returned nan at t = 0: an event must"),
        (lambda tt, y: y, r"(?s)`events\[0\]` returned array\(.*at t = 0: an event must"),
        (lambda tt, y: 1 / 0, r"`events\[0\]` raised ZeroDivisionError at t = 0: division"),
    ],
)  # fmt: skip
def test_an_event_that_fails_is_named(event, message):
    with pytest.raises(EventError, match=message):
        simulate(BOX, (0, 1), omega0=(0.1, 1, 0.2), events=event)
    with pytest.raises(EventError, match=message):
        run(1.0, events=event)


def test_an_initial_state_the_run_cannot_leave_is_named():
    """``qd0 = 1e300`` was refused as "`q0`, `params`: … the mass matrix is singular"."""
    from poinsot.simulation import SimulationError

    with pytest.raises(SimulationError, match=r"could not take its first step from the initial "
                                              r"state .*largest \|qd0\| = 1e\+300"):  # fmt: skip
        DRIVEN.simulate((0, 1), q0={x: 0.0}, qd0={x: 1e300}, params={m: 1.0},
                        inputs={F: 0.0})  # fmt: skip
