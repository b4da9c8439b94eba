"""What every call of a public entry point may do (issue 26), checked by the fuzz tests:

(a) return a result that passes a check of its own (an invariant, the exact solution, a
    constraint residual);
(b) raise ``ValueError`` or ``TypeError`` whose message names the argument (in backquotes,
    ```omega0[1]` must be finite``) or, for a scenario file, the file and the key;
(c) raise a documented numerical failure (:class:`poinsot.SimulationError`).

Anything else (another exception, a message that names nothing, a hang) fails the test.
"""

from __future__ import annotations

import warnings
from datetime import timedelta

import numpy as np
from hypothesis import HealthCheck, event, settings
from hypothesis import strategies as st

from bounded import deadline
from poinsot.integrate.solve import SimulationError

# Hypothesis profiles of the fuzz tests: "fuzz", a few examples per entry point (the default
# suite), and "fuzz-many", many (-m slow); both with a deadline on every example, and
# :func:`outcome` puts a hard one on every call.
_quiet = [HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large]
settings.register_profile("fuzz", max_examples=12, deadline=timedelta(seconds=30),
                          suppress_health_check=_quiet, print_blob=True)  # fmt: skip
settings.register_profile("fuzz-many", parent=settings.get_profile("fuzz"), max_examples=300)
FEW = settings(settings.get_profile("fuzz"))
MANY = settings(settings.get_profile("fuzz-many"))
#: Seconds one call may take before it counts as a hang.
HANG = 60


class Outcome:
    ACCEPTED, REFUSED, FAILED = "accepted", "refused", "failed"


def outcome(call, check, names, *, what="the call"):
    """Run ``call()`` under a deadline and judge it (see the module). ``names``: the
    arguments a refusal may name. Returns the outcome, for statistics."""
    with deadline(HANG, what), warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # rtol raised to 100 ε, and the like
        try:
            result = call()
        except (ValueError, TypeError) as exc:
            message = str(exc)
            assert any(f"`{n}" in message for n in names), (
                f"{what}: {type(exc).__name__} names no argument: {message!r}"
            )
            event(Outcome.REFUSED)
            return Outcome.REFUSED
        except SimulationError as exc:  # a documented numerical failure, with its samples
            assert str(exc), what
            event(Outcome.FAILED)
            return Outcome.FAILED
    check(result)
    event(Outcome.ACCEPTED)
    return Outcome.ACCEPTED


# ----------------------------------------------------------------- values, good and bad
finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
odd_floats = st.sampled_from([np.nan, np.inf, -np.inf, 0.0, -0.0, 1e-300, -1e-300, 1e300,
                              -1e300, 5e-324, 1.7976931348623157e308])  # fmt: skip
odd_objects = st.sampled_from([None, "1", "abc", b"1", complex(1, 1), True, [], {}, object(),
                               [1.0, "a", 2.0], [[1.0], [2.0, 3.0]]])  # fmt: skip


def sometimes(good, *odd, share=0.1):
    """``good`` values, and about ``share`` of the time one of the ``odd`` strategies."""
    odd = st.one_of(*odd)
    return st.integers(0, 999).flatmap(lambda k: odd if k < 1000 * share else good)


def number(good):
    """Mostly ``good`` numbers, sometimes extreme floats or things that are not numbers."""
    return sometimes(good, odd_floats, odd_objects)


def _array_or_list(values):
    try:
        return np.array(values, dtype=float)
    except (TypeError, ValueError):
        return list(values)


def vector3(good=finite):
    """Mostly 3-vectors of ``good`` numbers; sometimes of odd numbers, of the wrong length, or
    not vectors at all."""
    return sometimes(
        st.tuples(good, good, good).map(_array_or_list),
        st.lists(number(good), min_size=0, max_size=5),
        st.tuples(number(good), number(good), number(good)).map(list),
        odd_objects,
    )
