"""Figures and the report of ``poinsot grade``: what :class:`poinsot.grade.Grade` holds, drawn
(the errors against time; ω with its exact polhode) under the library's names."""

from __future__ import annotations

import html

import numpy as np

from ._style import label_3d, legend_outside, png_images

__all__ = ["plot_grade_errors", "plot_grade_polhode", "write_grade_report_folder"]

#: Report figures: (file, caption).
FIGURES = (
    ("errors.png", "Errors against the exact motion from the first sample"),
    ("polhode.png", "ω(t) and its exact polhode, body frame"),
)


def _plt():
    import matplotlib.pyplot as plt

    return plt


def plot_grade_errors(grade):
    """The grade's errors against time, on log scales: ``|ω − ω_exact|`` [rad/s] and the
    distance of ω from its exact polhode; ``max |Q − Q_exact|`` and ``max |QᵀQ − I|``; the
    relative drift of ``k`` and ``|L|`` (free body) or the errors of θ, ψ, φ [rad] (top)."""
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    t = grade.t
    floor = {}  # per axes: the smallest positive value drawn

    def draw(ax, y, label, **style):
        if y is None:
            return
        y = np.asarray(y, dtype=float)
        positive = y[y > 0]
        if positive.size:
            floor[ax] = min(floor.get(ax, np.inf), float(positive.min()))
        # a zero (the first sample, where the exact motion starts) is left out of a log axis
        ax.semilogy(t, np.where(y > 0, y, np.nan), lw=1.1, label=label, **style)

    draw(axes[0], grade.omega_error, "|ω − ω_exact|")
    draw(axes[0], grade.polhode_distance, "distance of ω from its exact polhode", ls="--")
    axes[0].set_ylabel("[rad/s]")
    axes[0].set_title("Angular velocity (body frame)", fontsize=10)
    draw(axes[1], grade.attitude_error, "max |Q − Q_exact|")
    draw(axes[1], grade.orthogonality_error, "max |QᵀQ − I|", ls="--")
    axes[1].set_ylabel("dimensionless")
    axes[1].set_title("Attitude" if grade.attitude_error is not None
                      else "Attitude (none in the file)", fontsize=10)  # fmt: skip
    if grade.kind == "free body":
        draw(axes[2], grade.energy_error, "|k/k₀ − 1| (energy)")
        draw(axes[2], grade.momentum_error, "||L|/|L₀| − 1|", ls="--")
        axes[2].set_ylabel("relative change (dimensionless)")
        axes[2].set_title("Invariants (conserved exactly)", fontsize=10)
    else:
        for name, symbol in (("theta", "θ"), ("psi", "ψ"), ("phi", "φ")):
            draw(axes[2], grade.angle_errors[name], f"|{symbol} − {symbol}_exact|")
        axes[2].set_ylabel("[rad]")
        axes[2].set_title("Euler angles of the top's axis (z-x-z)", fontsize=10)
    for ax, lowest in floor.items():
        ax.set_ylim(bottom=max(lowest / 3, 1e-18))
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.grid(alpha=0.3, which="both")
        if ax.get_lines():
            legend_outside(ax, loc="upper center", bbox_to_anchor=(0.5, -0.18))
    fig.tight_layout()
    return fig


def plot_grade_polhode(grade):
    """ω(t) of the graded trajectory and the exact polhode through its first sample, in the
    body frame's components [rad/s] (free body)."""
    plt = _plt()
    fig = plt.figure(figsize=(8, 6.5))
    ax = fig.add_subplot(projection="3d")
    if grade.polhode is not None:
        ax.plot(*grade.polhode.T, color="black", lw=2.0, alpha=0.6, label="exact polhode")
    ax.plot(*grade.omega.T, color="tab:red", lw=0.9, label="ω(t) of the file")
    ax.scatter(*grade.omega[0], color="green", depthshade=False, label="first sample")
    label_3d(ax, *(f"ω_{c} (body) [rad/s]" for c in "xyz"))
    ax.set_box_aspect((1, 1, 1), zoom=0.8)
    ax.set_title(f"ω(t) against the exact polhode ({grade.family})", fontsize=10)
    legend_outside(ax, bbox_to_anchor=(1.02, 0.95))
    fig.subplots_adjust(left=0.0, right=0.72)
    return fig


def write_grade_report_folder(folder, grade, summary: dict) -> list[str]:
    """Write ``errors.png``, ``polhode.png`` (free body) and ``report.html`` into the existing
    ``folder`` (each atomically). Returns the file names written."""
    from pathlib import Path

    from .report import _image_page

    folder = Path(folder)
    drawn = [(plot_grade_errors(grade), *FIGURES[0])]
    if grade.kind == "free body":
        drawn.append((plot_grade_polhode(grade), *FIGURES[1]))
    images = png_images(drawn, folder)
    s = summary["grade"]
    units = s.get("units", {})
    cells = "".join(
        f"<tr><th>{html.escape(NAMES.get(k, k))}</th><td>{html.escape(_shown(v))}</td>"
        f"<td class='unit'>{html.escape(units.get(k, ''))}</td></tr>"
        for k, v in s.items()
        if k != "units"
    )
    table = ("<h2>Grade</h2><table class='numbers'><tr><th>quantity</th><th>value</th>"
             "<th>unit</th></tr>" + cells + "</table>")  # fmt: skip
    _image_page(folder / "report.html", summary, summary.get("lead", ""), table, images,
                ("grade.json",))  # fmt: skip
    return [file for _, file, _ in drawn] + ["report.html"]


#: The report's name of each number of :meth:`poinsot.grade.Grade.summary`.
NAMES = {
    "kind": "graded as",
    "samples": "samples",
    "t_start": "first sample",
    "t_end": "last sample",
    "max_omega_error": "max |ω − ω_exact|",
    "max_attitude_error": "max |Q − Q_exact| (largest entry)",
    "max_orthogonality_error": "max |QᵀQ − I| (distance from a rotation)",
    "family": "polhode family of ω₀",
    "family_kept": "ω stays in that family at every sample",
    "family_left_at": "first sample in another family",
    "wrong_family_fraction": "fraction of the samples in another family",
    "max_energy_error": "max |k/k₀ − 1| (energy, conserved exactly)",
    "max_momentum_error": "max ||L|/|L₀| − 1| (conserved exactly)",
    "max_polhode_distance": "max distance of ω from its exact polhode",
    "flips": "flips measured (sign changes of ω·e₂)",
    "exact_flips": "flips of the exact motion over the same span",
    "flip_interval": "exact time between flips, 2K(m)/λ",
    "max_flip_time_error": "max |t_flip − t_flip,exact|",
    "max_theta_error": "max |θ − θ_exact| (nutation)",
    "max_psi_error": "max |ψ − ψ_exact| (precession)",
    "max_phi_error": "max |φ − φ_exact| (spin)",
}


def _shown(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return "—" if value is None else str(value)
