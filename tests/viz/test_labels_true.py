"""Issue 43, "every label true": each case was wrong on the landed main without any error. Each
test reads what was written (the summary's rows as the report shows them, a figure's legend and
axis labels) and checks what it means, not only that it is there."""

from __future__ import annotations

import json

import matplotlib
import numpy as np
import pytest

from poinsot import Gravity, RigidBody, simulate
from poinsot.app.cli import main
from poinsot.viz.numbers import rows_of

matplotlib.use("Agg")
import matplotlib.pyplot as plt

TOP = RigidBody.cylinder(1.0, 0.3, 0.2)


@pytest.fixture(scope="module")
def heavy_top(tmp_path_factory):
    out = tmp_path_factory.mktemp("top") / "h"
    assert main(["run", "--example", "heavy-top", "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "summary.json").read_text()), out


def test_heavy_top_moments_are_named_by_their_point(heavy_top):
    summary, _ = heavy_top
    rows = {name: value for _, name, value, _ in rows_of(summary)}
    body = next(v for n, v in rows.items() if n.startswith("principal moments"))
    tip = next(v for n, v in rows.items() if n.startswith("A_P"))
    assert "A_G" in next(n for n in rows if n.startswith("principal moments"))
    assert body[0] == pytest.approx(0.025833333, rel=1e-6)  # about G
    assert tip == pytest.approx(0.3**2 / 4 + 0.2**2 / 12 + 1.0 * 0.5**2, rel=1e-12)  # parallel axes
    assert not any(n == "A: moment about the tip, across the axis" for n in rows)


def test_heavy_top_initial_energy_is_the_tops_kinetic_energy_and_no_polhode_row(heavy_top):
    summary, out = heavy_top
    rows = {name: value for _, name, value, _ in rows_of(summary)}
    energy = next(v for n, v in rows.items() if "½ ω·A" in n)
    kinetic = np.load(out / "trajectory.npz")["kinetic_energy"][0]
    assert energy == pytest.approx(kinetic, rel=1e-12)  # 225.31 J, not 225.029 about G
    assert not any("polhode" in n for n in rows), "a top has no polhodes"
    assert "a2_over_2k" not in summary["initial"]


def test_omega_legend_gives_the_moments_about_the_pivot_for_a_pivoted_top():
    from poinsot.viz import plot_omega_series

    traj = simulate(TOP, (0, 0.2), omega0=(0, 1.5, 100), forces=[Gravity((0, 0, -9.81))],
                    pivot=(0, 0, -0.5))  # fmt: skip
    fig = plot_omega_series(traj)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    plt.close(fig)
    # ascending; the axes about the pivot are e₁ᴾ, e₂ᴾ, e₃ᴾ (e₁, e₂, e₃ are those about G)
    assert labels[0] == "ω·e₁ᴾ (I₁ᴾ = 0.045 kg·m² about the pivot)"
    assert labels[2] == "ω·e₃ᴾ (I₃ᴾ = 0.2758 kg·m² about the pivot)"  # not 0.02583 about G
    free = simulate(TOP, (0, 0.2), omega0=(0, 1.5, 100))
    fig = plot_omega_series(free)
    assert fig.axes[0].get_legend().get_texts()[0].get_text().endswith("kg·m² about G)")
    plt.close(fig)


def test_a_zero_reference_gives_an_absolute_change_with_its_unit(tmp_path):
    assert main(["run", "--example", "atwood", "--out", str(tmp_path / "a"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    h = summary["conserved"]["energy (Jacobi integral h = Σ q̇ ∂L/∂q̇ − L)"]
    assert h["initial"] == 0.0 and h["max_relative_change"] is None
    accuracy = [(n, v, u) for g, n, v, u in rows_of(summary) if g == "Accuracy"]
    about_h = [r for r in accuracy if r[0].startswith("h")]
    assert len(about_h) == 1, "one number for the change of h, not two"
    name, value, unit = about_h[0]
    assert unit == "J" and "relative" not in name and value == h["max_change"] > 0
    assert not any("relative change of h" in r[0] for r in accuracy)


def test_a_nonzero_reference_keeps_its_relative_change():
    traj = simulate(TOP, (0, 0.5), omega0=(0, 1.5, 100), forces=[Gravity((0, 0, -9.81))],
                    pivot=(0, 0, -0.5), method="rk4", dt=1e-3)  # fmt: skip
    E = next(i for i in traj.invariants if i.symbol == "E").describe()
    values = traj.total_energy
    assert E["max_change"] == pytest.approx(np.abs(values - values[0]).max(), rel=1e-9)
    assert E["max_relative_change"] == pytest.approx(E["max_change"] / abs(values[0]), rel=1e-9)


def test_the_identify_ellipsoid_uses_the_tables_normalisation():
    from poinsot.identify import identify, synthetic_throw
    from poinsot.viz.identify import plot_identified_polhode

    result = identify(*(lambda th: (th.t, th.omega))(synthetic_throw(rotor=False, seed=1)))
    fig = plot_identified_polhode(result)
    ax = fig.axes[0]
    shown = [float(lbl.split("= ")[1].split(")")[0])
             for lbl in (ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel())]  # fmt: skip
    plt.close(fig)
    np.testing.assert_allclose(shown, result.principal_moments, rtol=1e-3)
    assert sum(result.principal_moments) == pytest.approx(1.0)  # trace 1, as the table says
    assert "trace 1" in ax.get_title()
