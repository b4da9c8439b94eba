"""``examples/identify_throw.py`` runs and shows what it says."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "identify_throw.py"


def test_the_example_identifies_its_throw(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("identify_throw", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    out = module.main(tmp_path)
    th, known, fitted, blind = out["throw"], out["known"], out["fitted"], out["blind"]
    assert np.all(np.abs(known.ratios / th.ratios - 1) < 0.005)
    assert np.all(th.axis_errors_deg(known.axes) < 1.0)
    assert abs(out["trace_error"]) < 0.02 and known.absolute and not fitted.absolute
    assert known.found_by == "accelerometer" and known.ok and fitted.ok
    assert not blind.ok and "does not explain" in blind.flags[0]
    printed = capsys.readouterr().out
    assert "ignoring the flywheel" in printed and "wrote" in printed
    for name in ("report.html", "fit.png", "polhode.png", "axes.png"):
        assert (tmp_path / name).stat().st_size > 2000
