"""What a physicist sees (issue 27): axes labelled by what they are, stable fixed points where
the labels say, legends that cover nothing, numbers rounded to their uncertainty with units,
the heavy top's nutation and precession, and the notebook displays of every result."""

from __future__ import annotations

import re
from html.parser import HTMLParser

import matplotlib
import numpy as np
import pytest

from poinsot import Gravity, RigidBody, models, simulate
from poinsot.torquefree import FreeRigidBody
from poinsot.viz.numbers import format_value

matplotlib.use("Agg")
import matplotlib.pyplot as plt

NOTEBOOK = models.notebook_body()  # its smallest moment's axis e1 is its own z axis


def _axis_of(label: str) -> int:
    """The principal axis (0, 1, 2) an axis label names: 'ω·e₁ …' → 0."""
    found = re.search(r"e([₁₂₃])", label)
    assert found, f"the axis label {label!r} names no principal axis"
    return "₁₂₃".index(found.group(1))


def _components(points, labels):
    """Drawn points (n, 3) as the components along e1, e2, e3 that the axis labels claim."""
    order = [_axis_of(label) for label in labels]
    assert sorted(order) == [0, 1, 2], labels
    out = np.empty_like(np.asarray(points, float))
    for j, k in enumerate(order):
        out[:, k] = np.asarray(points, float)[:, j]
    return out


def _assert_stable_on_extreme_axes(points, labels, free, energy=0.5):
    """The stable points, read through the labels, lie on the energy ellipsoid Σ I_k c_k² = 2k
    (so each sits on the axis its label names, at that axis's semi-axis √(2k/I_k)), and on the
    axes of the smallest and the largest moment."""
    I = free.principal_moments
    c = _components(points, labels)
    assert len(c) == 4
    np.testing.assert_allclose((I * c * c).sum(axis=1), 2 * energy, rtol=1e-12)
    on = np.abs(c) > 1e-9 * np.abs(c).max()
    assert (on.sum(axis=1) == 1).all()  # each on one principal axis
    assert sorted(np.nonzero(on)[1].tolist()) == [0, 0, 2, 2]  # ±e1 and ±e3


def test_stable_fixed_points_lie_on_the_axes_of_smallest_and_largest_moment():
    free = FreeRigidBody.from_body(NOTEBOOK)
    fig = __import__("poinsot.viz", fromlist=["x"]).plot_polhode_family(free, 0.5, levels=3)
    ax = fig.axes[0]
    labels = [ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()]
    stable = next(c for c in ax.collections if c.get_label() == "stable")
    _assert_stable_on_extreme_axes(np.array(stable._offsets3d).T, labels, free)
    for line in ax.get_lines():  # every polhode drawn lies on the ellipsoid as labelled
        if line.get_label() in ("around e1", "around e3", "separatrix"):
            c = _components(np.array(line.get_data_3d()).T, labels)
            np.testing.assert_allclose((free.principal_moments * c * c).sum(1), 1.0, rtol=1e-9)
    plt.close(fig)


def test_stable_fixed_points_in_the_interactive_figure():
    pytest.importorskip("plotly")
    from poinsot.viz.interactive import polhode_family_figure

    free = FreeRigidBody.from_body(NOTEBOOK)
    fig = polhode_family_figure(free, 0.5, levels=3)
    scene = fig.layout.scene
    labels = [scene.xaxis.title.text, scene.yaxis.title.text, scene.zaxis.title.text]
    stable = next(t for t in fig.data if t.name == "stable fixed points")
    _assert_stable_on_extreme_axes(np.column_stack([stable.x, stable.y, stable.z]), labels, free)


def test_omega_series_is_drawn_along_the_principal_axes():
    from poinsot.viz import plot_omega_series

    traj = simulate(NOTEBOOK, (0, 2), omega0=(0.0, 0.2, 1.0))
    fig = plot_omega_series(traj)
    lines = fig.axes[0].get_lines()
    for k in range(3):  # the curve labelled e_k is ω·e_k
        label = lines[k].get_label()
        assert f"I{'₁₂₃'[k]}" in label
        np.testing.assert_allclose(lines[k].get_ydata(), traj.omega @ NOTEBOOK.principal_axes[:, k])
    np.testing.assert_allclose(lines[0].get_ydata(), traj.omega[:, 2], atol=1e-15)  # e1 = z
    plt.close(fig)


# --------------------------------------------------------------------------- legends
def _figures():
    from poinsot.app.runs.rigid import compare_methods
    from poinsot.app.scenario import load_example
    from poinsot.tops import heavy_top, top_motion
    from poinsot.viz import (
        plot_center_of_mass_path,
        plot_conservation,
        plot_energy_ellipsoid,
        plot_method_comparison,
        plot_omega,
        plot_omega_series,
        plot_polhode_family,
    )
    from poinsot.viz.ensemble import plot_ensemble_histograms, plot_flip_intervals
    from poinsot.viz.lagrange import plot_lagrangian_solution, plot_mechanism_frames
    from poinsot.viz.relative import plot_hodograph, plot_relative_motion
    from poinsot.viz.trajectory import plot_attitude, plot_axis_trace

    nb = load_example("notebook")
    traj = nb.simulate()
    free = FreeRigidBody.from_body(nb.body)
    errors, _ = compare_methods(nb, traj, free)
    yield "omega", plot_omega_series(traj)
    yield "conservation", plot_conservation(traj)
    yield "methods", plot_method_comparison(traj.t, errors)
    yield "polhodes", plot_polhode_family(free, 12.5, levels=5, omega=traj.omega)
    yield "ellipsoid", plot_energy_ellipsoid(free, 0.5, 14.0**0.5)
    yield "omega(t)", plot_omega(traj.t, traj.omega)
    yield "centre of mass", plot_center_of_mass_path(traj)
    ht = load_example("heavy-top")
    ht.t_span = (0.0, 1.0)
    top_traj = ht.simulate()
    motion = top_motion(top_traj, heavy_top(ht.body, ht.pivot, ht.forces))
    yield "attitude", plot_attitude(motion)
    yield "axis trace", plot_axis_trace(top_traj.axis_trace())
    for name in ("sliding-ladder", "double-pendulum", "pendulum-on-cart"):
        model = models.MODELS[name]()
        sol = model.simulate((0, 0.8))
        yield name, plot_lagrangian_solution(sol, model=model)
        yield f"{name} mechanism", plot_mechanism_frames(model, sol)
    rel = load_example("hodograph-bound")
    rel.t_span = (0.0, 2.0)
    rsol = rel.simulate()
    yield "relative", plot_relative_motion(rsol)
    yield "hodograph", plot_hodograph(rsol)
    ens = load_example("tennis-racket-ensemble")
    ens.ensemble["members"] = 50
    res = ens.simulate_ensemble()
    yield "histograms", plot_ensemble_histograms(res)
    exact = FreeRigidBody.from_body(ens.body).flip_interval(res.initial_omega)
    yield "flips", plot_flip_intervals(res, exact)


def _overlap(a, b):
    return max(min(a.x1, b.x1) - max(a.x0, b.x0), 0) * max(min(a.y1, b.y1) - max(a.y0, b.y0), 0)


def test_matplotlib_legends_are_outside_the_plotting_area():
    seen = 0
    for name, fig in _figures():
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        page = fig.bbox
        for ax in fig.axes:
            legend = ax.get_legend()
            if legend is None:
                continue
            seen += 1
            box, area = legend.get_window_extent(renderer), ax.get_window_extent(renderer)
            assert _overlap(box, area) == 0, f"{name}: the legend covers the plotting area"
            assert box.x0 >= page.x0 - 1 and box.x1 <= page.x1 + 1, f"{name}: legend cut off"
            assert box.y0 >= page.y0 - 1 and box.y1 <= page.y1 + 1, f"{name}: legend cut off"
        plt.close(fig)
    assert seen >= 20


# --------------------------------------------------------------------------- numbers
def test_table_values_are_rounded_to_their_uncertainty():
    noise = -5.551115123125783e-17
    inertia = [[21.666666666666668, noise, -0.0], [noise, 16.666666666666668, -0.0],
               [-0.0, -0.0, 8.333333333333334]]  # fmt: skip
    shown = format_value(inertia)
    assert "e-17" not in shown and "-0" not in shown and "-5.5" not in shown
    assert shown == "(21.6667, 0, 0)<br>(0, 16.6667, 0)<br>(0, 0, 8.33333)"
    assert format_value(-0.0) == "0" and format_value(-1e-20, 1e-10) == "0"
    assert format_value(0.98730845, uncertainty=2.3e-4) == "0.9873"
    assert format_value(123456.789, uncertainty=10.0) == "1.2346e+05"


def test_the_report_rounds_and_the_json_keeps_the_raw_values(tmp_path):
    from poinsot.app.job import run_scenario
    from poinsot.app.scenario import load_example

    scenario = load_example("notebook")
    scenario.outputs["figures"] = False
    summary = run_scenario(scenario, tmp_path / "o", plotlyjs="cdn")
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    numbers = page.split("<h2>Numbers</h2>")[1].split("<h3>Torque-free motion</h3>")[0]
    assert "inertia tensor" in numbers  # the body, its initial state and invariants
    assert not re.search(r"e-1[5-9]|(?<![\w.])-0(?![.\d])", numbers), "noise in the tables"
    assert any(abs(x) < 1e-15 and x != 0 for row in summary["body"]["inertia"] for x in row)


def test_lagrangian_parameters_have_units(tmp_path):
    from poinsot.app.runs.lagrangian import summarize_lagrangian
    from poinsot.app.scenario import load_example
    from poinsot.viz.numbers import rows_of

    for name in ("double-pendulum", "atwood", "rolling-coin"):
        scenario = load_example(name)
        scenario.t_span = (0.0, 0.1)
        summary = summarize_lagrangian(scenario, scenario.simulate())
        params = [r for r in rows_of(summary) if r[1].startswith("parameter ")]
        assert params and all(r[3] for r in params), params
    for name, make in models.MODELS.items():
        model = make()
        missing = [p for p in model.system.parameters if not model.unit_of_parameter(p)]
        assert not missing, f"{name}: no unit for {missing}"


def test_compile_time_is_not_reported_as_run_time():
    from poinsot.viz.numbers import LAGRANGIAN, RIGID

    labels = {path: name for _, name, path, _ in RIGID + LAGRANGIAN}
    assert "nothing is compiled" in labels["integration.wall_time_s"]
    assert "derivation" in labels["timings.derivation_s"]


# --------------------------------------------------------------------------- the heavy top
def test_heavy_top_report_shows_nutation_and_precession(tmp_path):
    from poinsot.app.job import run_scenario
    from poinsot.app.scenario import load_example

    scenario = load_example("heavy-top")
    summary = run_scenario(scenario, tmp_path / "o", plotlyjs="cdn")
    top = summary["top"]
    assert top["theta_min"] < top["theta_max"] <= 0.6 + 1e-9  # it rises from 0.6 rad and back
    assert top["gyroscopic_precession_rate"] == pytest.approx(4.905 / (0.045 * 100), rel=1e-12)
    assert top["mean_precession_rate"] == pytest.approx(top["steady_precession_rate_slow"],
                                                        rel=0.01)  # fmt: skip
    assert summary["units"]["top.mean_precession_rate"] == "rad/s"
    assert "gyroscopic estimate" in summary["lead"] and "steady precession" in summary["lead"]
    for png in ("attitude.png", "axis_trace.png"):
        assert (tmp_path / "o" / png).is_file()
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert "Nutation" in page and "Precession" in page and "unit sphere" in page


# --------------------------------------------------------------------------- notebook displays
class _Checker(HTMLParser):
    """Well-formed HTML: every opened element closed, in order (void elements aside)."""

    VOID = frozenset({"br", "hr", "img", "meta", "link", "input", "col"})

    def __init__(self):
        super().__init__()
        self.stack = []

    def handle_starttag(self, tag, attrs):
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        assert self.stack and self.stack[-1] == tag, f"</{tag}> closes {self.stack[-1:]}"
        self.stack.pop()


def _valid_html(text):
    checker = _Checker()
    checker.feed(text)
    checker.close()
    assert not checker.stack, f"unclosed: {checker.stack}"
    return text


def _units_on_axes(fig):
    """Every axis label that names a quantity carries its unit: [unit] or (dimensionless)."""
    labelled = 0
    for ax in fig.axes:
        texts = [ax.get_xlabel(), ax.get_ylabel()]
        if hasattr(ax, "get_zlabel"):
            texts.append(ax.get_zlabel())
        for text in filter(None, texts):
            labelled += 1
            assert re.search(r"\[.+\]|dimensionless|members|number of", text), text
    assert labelled


@pytest.fixture(scope="module")
def results():
    from poinsot.ensemble import simulate_ensemble
    from poinsot.relative import Carrier, simulate_relative

    traj = simulate(NOTEBOOK, (0, 5), omega0=(0, 1, 1), forces=[Gravity((0, 0, -9.8))])
    model = models.double_pendulum()
    sol = model.simulate((0, 1))
    box = RigidBody.box(1.0, (1, 2, 3))
    ens = simulate_ensemble(box, (0, 5), omega0=np.tile([0.01, 1.0, 0.01], (20, 1)), method="rk4",
                            dt=0.01, t_eval=np.linspace(0, 5, 11))  # fmt: skip
    rel = simulate_relative(box, (0, 1), omega_r0=(0, 1, 0), carrier=Carrier(omega_e=(0, 0, 1)),
                            hold_com=True)  # fmt: skip
    return {"trajectory": traj, "free": FreeRigidBody.from_body(NOTEBOOK), "solution": sol,
            "system": model.system, "model": model, "ensemble": ens, "relative": rel}  # fmt: skip


@pytest.mark.parametrize("name", ["trajectory", "free", "solution", "system", "model",
                                  "ensemble", "relative"])  # fmt: skip
def test_every_result_and_model_has_an_html_table_with_units(results, name):
    text = _valid_html(results[name]._repr_html_())
    assert "<table>" in text and "unit" in text
    units = re.findall(r"color:#666'>([^<]*)</td>", text)
    assert any(u.strip() for u in units), "no unit in the table"


def test_html_tables_say_what_matters(results):
    t = results["trajectory"]._repr_html_()
    assert "time span" in t and ">s<" in t and "max relative change of E" in t
    assert "kg·m²" in t
    free = results["free"]._repr_html_()
    assert "stable" in free and "kg·m²" in free
    sol = results["solution"]._repr_html_()
    assert "rod 1 tension T1: range" in sol and ">N<" in sol
    assert "finished" in results["ensemble"]._repr_html_()
    assert "max |ω| absolute" in results["relative"]._repr_html_()


def test_the_system_shows_its_equations_in_latex(results):
    latex = results["system"]._repr_latex_()
    assert latex.startswith("$") and latex.endswith("$") and r"\ddot{\theta}_{1}" in latex


@pytest.mark.parametrize("name", ["trajectory", "free", "solution", "ensemble", "relative"])
def test_plot_returns_the_reports_figure_with_units(results, name):
    fig = results[name].plot()
    assert isinstance(fig, matplotlib.figure.Figure)
    _units_on_axes(fig)
    plt.close(fig)


def test_plot_kinds_of_a_trajectory(results):
    traj = results["trajectory"]
    for kind in ("omega", "conservation", "polhodes", "center_of_mass"):
        _units_on_axes(traj.plot(kind))
        plt.close("all")
    with pytest.raises(ValueError, match="not a heavy symmetric top"):
        traj.plot("attitude")
    with pytest.raises(ValueError, match="`kind` must be"):
        traj.plot("colours")


@pytest.mark.parametrize("name", ["trajectory", "free", "solution", "ensemble", "relative"])
def test_show_displays_the_interactive_figure(results, name, monkeypatch):
    go = pytest.importorskip("plotly.graph_objects")
    shown = []
    monkeypatch.setattr(go.Figure, "show", lambda self, *a, **k: shown.append(self))
    assert results[name].show() is None
    assert len(shown) == 1 and len(shown[0].data) > 0


def test_displays_are_registered_by_the_presentation_not_imported_by_the_library():
    import ast
    from pathlib import Path

    import poinsot
    import poinsot.display as display

    library = Path(poinsot.__file__).parent
    for path in [library / "display.py", library / "trajectory.py", library / "models.py"]:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                assert "viz" not in (node.module or ""), f"{path.name} imports the presentation"
    assert display.backend == "poinsot.viz.display"
    assert ("poinsot.trajectory.Trajectory", "html") in display._RENDERERS


# --------------------------------------------------------------------------- Euler angles
def test_euler_angles_of_a_trajectory():
    top = RigidBody.cylinder(1.0, 0.3, 0.2)
    Q0 = np.array([[1, 0, 0], [0, np.cos(0.6), -np.sin(0.6)], [0, np.sin(0.6), np.cos(0.6)]])
    grid = np.linspace(0, 2, 801)
    traj = simulate(top, (0, 2), omega0=(0.3, 1.5, 40.0), Q0=Q0, forces=[Gravity()],
                    pivot=(0, 0, -0.5), t_eval=grid, rtol=1e-12, atol=1e-12)  # fmt: skip
    angles, rates = traj.euler_angles(), traj.euler_rates()
    np.testing.assert_allclose(angles[:, 1], traj.axis_tilt("z"), atol=1e-12)  # θ is the tilt
    from poinsot.rotation import matrix_from_euler

    np.testing.assert_allclose(matrix_from_euler(angles), traj.Q, atol=1e-12)  # unwrapped, same Q
    assert np.ptp(angles[:, 2]) > 70  # φ unwrapped through many turns
    h = traj.t[1] - traj.t[0]
    fd = (angles[2:] - angles[:-2]) / (2 * h)  # finite differences of the unwrapped angles
    np.testing.assert_allclose(fd, rates[1:-1], rtol=0, atol=2e-3 * np.abs(rates).max())
    assert not traj.euler_singular().any()
    trace = traj.axis_trace()
    np.testing.assert_allclose(np.linalg.norm(trace, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(trace, traj.axis_trace("z"), atol=1e-15)  # oblate: e3 = z


def test_euler_angles_coarse_sampling_and_the_singular_pose():
    body = RigidBody.box(1.0, (1, 2, 3))
    coarse = simulate(body, (0, 1), omega0=(0, 0, 40.0), Q0=np.eye(3), t_eval=np.linspace(0, 1, 11))
    assert coarse.euler_singular().all()  # θ = 0: ψ and φ not separately defined
    assert np.isnan(coarse.euler_rates()).all(axis=1).any()
    tilted = simulate(body, (0, 1), omega0=(0, 0, 40.0), t_eval=np.linspace(0, 1, 11),
                      Q0=[[1, 0, 0], [0, 0, -1], [0, 1, 0]])  # fmt: skip
    # 4 rad per sample, beyond π: the rates still unwrap φ to 40 t
    phi = tilted.euler_angles()[:, 2]
    np.testing.assert_allclose(phi, 40 * tilted.t + phi[0], atol=1e-9)
    with pytest.raises(ValueError, match="no single symmetry axis"):
        tilted.axis_trace()
    with pytest.raises(ValueError, match="`frame` must be"):
        tilted.euler_angles("space")
