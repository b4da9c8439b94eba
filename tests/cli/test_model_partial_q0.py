"""[model] q0 may give any subset of the coordinates: the rest keep the model's values (without
holonomic constraints) or are solved for from the constraints, starting from them."""

from __future__ import annotations

import pytest

from poinsot.app.scenario import load_scenario

TAIL = "[time]\nspan = [0, 1]\n[output]\nreport = false\n"


def _start(name, q0):
    s = load_scenario(f'[model]\nname = "{name}"\nq0 = {q0}\n' + TAIL)
    return {str(q).replace("(t)", ""): v for q, v in s.consistent[0].items()}


def test_a_partial_q0_keeps_the_models_values_for_the_rest():
    assert _start("spherical-pendulum", "{ theta = 0.5 }") == {"theta": 0.5, "phi": 0.0}
    assert _start("double-pendulum", "{ theta1 = 0.5 }") == {"theta1": 0.5, "theta2": 1.0}


def test_with_constraints_the_rest_is_solved_for_from_the_models_values():
    q = _start("pendulum-cartesian", "{ x = 0.6 }")
    assert q["x"] == 0.6 and q["y"] == pytest.approx(-0.8, abs=1e-12)  # the lower branch
    full = "{ x_c = 0.29552020666133955, y_c = 0.955336489125606, theta = 0.3 }"
    assert _start("sliding-ladder", full)["theta"] == 0.3  # the model's guess is not in the way
