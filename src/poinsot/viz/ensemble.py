"""Figures of an ensemble: histograms of per-member statistics, measured flips against exact."""

from __future__ import annotations

import numpy as np

from ._style import legend_outside

__all__ = ["plot_ensemble_histograms", "plot_flip_intervals"]

#: How each statistic is drawn: (axis label, logarithmic).
LABELS = {
    "energy_error": ("relative energy error max|ΔE|/|E₀| (dimensionless)", True),
    "momentum_error": ("relative momentum error max|ΔL|/|L₀| (dimensionless)", True),
    "orthogonality_error": ("orthogonality error max|QᵀQ − I| (dimensionless)", True),
    "first_flip": ("time of the first flip [s]", False),
    "flip_interval": ("mean time between flips [s]", False),
    "flip_count": ("number of flips", False),
}


def plot_ensemble_histograms(result, names=None, *, bins=40, fig=None):
    """One histogram per statistic over the members that finished (``names``: default every
    statistic with something to show). Errors are drawn on logarithmic bins; members with no
    value (no flip, an exact zero error) are counted in the title."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    if names is None:
        names = [n for n in LABELS if _values(result, n)[0].size]
        names += [n for n, v in result.reductions.items() if np.ndim(v) == 1]
    if not names:
        raise ValueError("the ensemble has no statistic with a finite value to draw")
    cols = min(3, len(names))
    rows = -(-len(names) // cols)
    if fig is None:
        fig = plt.figure(figsize=(4.6 * cols, 3.4 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, name in zip(axes, names, strict=False):
        values, missing = _values(result, name)
        label, log = LABELS.get(name, (f"{name} (user reduction)", False))
        if log:
            positive = values[values > 0]
            missing += len(values) - len(positive)
            values = positive
        if values.size:
            if log:
                lo, hi = np.log10(values.min()), np.log10(values.max())
                edges = np.logspace(lo - 0.05, hi + 0.05, bins + 1)
                ax.set_xscale("log")
                if hi - lo > 1.0:  # label the decades only (minor labels would overlap)
                    ax.xaxis.set_minor_formatter(NullFormatter())
            elif name == "flip_count":
                edges = np.arange(values.min() - 0.5, values.max() + 1.5)
            else:
                edges = bins
            ax.hist(values, bins=edges, color="#4477aa", edgecolor="white", linewidth=0.4)
        ax.set_xlabel(label)
        ax.set_ylabel("members")
        title = f"{name} ({values.size} members)"
        if missing:
            title += f"; {missing} without a value"
        ax.set_title(title, fontsize=9)
    for ax in axes[len(names) :]:
        ax.set_visible(False)
    fig.suptitle(f"{len(result)} members, {result.method}")
    return fig


def _values(result, name):
    values = np.asarray(result.statistic(name), dtype=float)[result.success]
    finite = values[np.isfinite(values)]
    return finite, len(values) - len(finite)


def plot_flip_intervals(result, exact, *, fig=None):
    """Measured mean time between flips (:attr:`EnsembleResult.flip_interval`) against the exact
    interval ``2K(m)/λ`` of each member (``exact`` (N,), from
    :meth:`~poinsot.torquefree.FreeRigidBody.flip_interval`): both distributions, and the
    relative difference per member."""
    import matplotlib.pyplot as plt

    measured = np.asarray(result.flip_interval, dtype=float)
    exact = np.asarray(exact, dtype=float)
    ok = np.isfinite(measured) & np.isfinite(exact) & result.success
    if fig is None:
        fig = plt.figure(figsize=(10, 3.8), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    if ok.any():
        lo = min(measured[ok].min(), exact[ok].min())
        hi = max(measured[ok].max(), exact[ok].max())
        edges = np.linspace(lo, hi, 41)
        ax1.hist(exact[ok], bins=edges, color="#bbbbbb", label="exact 2K(m)/λ")
        ax1.hist(measured[ok], bins=edges, histtype="step", color="crimson", lw=1.8,
                 label=f"measured ({result.method})")  # fmt: skip
        legend_outside(ax1)
        rel = measured[ok] / exact[ok] - 1
        ax2.plot(exact[ok], rel, ".", ms=3, color="#4477aa")
        ax2.axhline(0.0, color="#888", lw=0.8)
    ax1.set_xlabel("time between flips [s]")
    ax1.set_ylabel("members")
    ax1.set_title(f"flip intervals, {int(ok.sum())} members with ≥ 2 flips", fontsize=9)
    ax2.set_xlabel("exact time between flips [s]")
    ax2.set_ylabel("measured / exact − 1 (dimensionless)")
    ax2.set_title("relative error of the measured interval", fontsize=9)
    ax2.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    return fig
