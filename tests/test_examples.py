"""The examples run (smoke tests) and reproduce the numbers they claim."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_notebook_reproduction(tmp_path, capsys):
    result = _load("notebook").main(tmp_path)
    printed = capsys.readouterr().out
    assert "infeasible invariants" in printed and "erratum" in printed
    traj = result["trajectory"]
    np.testing.assert_allclose(traj.R[-1, 2] - traj.R[0, 2], -1960.0, atol=1e-9)
    assert result["sweep_error"] < 1e-5  # RK4 dt = 0.4 against the exact polhodes
    assert result["flip_interval"] == pytest.approx(
        result["free"].flip_interval(result["free"]._from_sorted([1e-3, 1.0, 1e-3]))
    )
    for name in (
        "omega_gravity.png",
        "polhode_family.png",
        "cone_reference_body.png",
        "cone_two_equal_plane.png",
        "cone_two_equal.png",
        "cone_all_equal.png",
        "tumbling_frames.png",
        "tumbling.gif",
    ):
        assert (tmp_path / name).stat().st_size > 5000, name


def test_events_example(capsys):
    result = _load("events").main()
    measured, exact = result["flips"]
    np.testing.assert_allclose(measured, 2 * exact, rtol=1e-7)  # two flips per ω₂ period
    ((_, _, state),) = result["ladder"].releases
    assert np.cos(state[2]) == pytest.approx(2 / 3 * np.cos(0.3), rel=1e-8)
    assert "lets go" in capsys.readouterr().out
