"""The report's plotly figures: one legend per subplot, powers of ten (never SI prefixes) on
numbers, units on the axes, and the run's own energy on the polhode figure."""

from __future__ import annotations

import numpy as np
import pytest

go = pytest.importorskip("plotly.graph_objects")

from poinsot import models  # noqa: E402
from poinsot.app.scenario import load_example  # noqa: E402
from poinsot.torquefree import FreeRigidBody  # noqa: E402
from poinsot.viz.lagrange import lagrangian_panels  # noqa: E402
from poinsot.viz.report import _panels_figure, _polhode_figure, _series_figure  # noqa: E402


def _legends(fig):
    """{legend name: set of (xaxis, yaxis)} of the traces."""
    out = {}
    for trace in fig.data:
        out.setdefault(trace.legend or "legend", set()).add((trace.xaxis, trace.yaxis))
    return out


@pytest.fixture(scope="module")
def notebook():
    return load_example("notebook").simulate()


def test_series_figure_has_one_legend_per_subplot_and_units(notebook):
    fig = _series_figure(notebook, go)
    legends = _legends(fig)
    assert len(legends) == 3 and all(len(axes) == 1 for axes in legends.values())
    for name in legends:  # each below its own subplot, clear of its plotting area
        legend = fig.layout[name]
        ((xa, ya),) = legends[name]
        assert legend.y < fig.layout[f"yaxis{ya[1:]}"].domain[0]
        assert legend.x == fig.layout[f"xaxis{xa[1:]}"].domain[0]
    assert fig.layout.yaxis.title.text == "ω along e₁, e₂, e₃ [rad/s]"
    assert "dimensionless" in fig.layout.yaxis3.title.text


def test_lagrangian_panels_one_legend_each():
    model = models.pendulum_on_cart()
    sol = model.simulate((0, 1))
    panels = lagrangian_panels(sol, model)
    fig = _panels_figure(panels, go)
    assert len(_legends(fig)) == len(panels)


def test_report_pages_use_powers_of_ten(tmp_path, notebook):
    from poinsot.viz.report import write_report

    summary = {"scenario": {"name": "t", "description": ""}}
    write_report(tmp_path / "r.html", notebook, summary, plotlyjs="cdn")
    page = (tmp_path / "r.html").read_text()
    assert '"exponentformat":"power"' in page.replace(" ", "")
    assert len(page) < 3_000_000  # cdn: plotly.js is not embedded


def test_polhode_figure_is_at_the_runs_own_energy(notebook):
    free = FreeRigidBody.from_body(notebook.body)
    fig = _polhode_figure(notebook, go, free, levels=5)
    k = free.invariants(notebook.omega[0])[0]
    assert f"k = {k:.4g} J" in fig.layout.title.text
    run = fig.data[-1]
    # drawn by components along the principal axes, the notebook body's e1 being its z axis
    drawn = np.column_stack([run.x, run.y, run.z])
    np.testing.assert_allclose(drawn, notebook.omega @ free.principal_axes, atol=1e-15)
    np.testing.assert_allclose(drawn[:, 0], notebook.omega[:, 2], atol=1e-15)
    assert fig.layout.scene.xaxis.title.text.startswith("ω·e₁ (I₁ = 8.333)")
