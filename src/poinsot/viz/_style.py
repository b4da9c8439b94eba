"""Shared placement rules of the matplotlib figures: legends outside the plotting area (a
legend never covers a curve), and the labels of principal-axis components."""

from __future__ import annotations

__all__ = ["PRINCIPAL_LABELS", "fit_titles", "legend_outside", "omega_axis_labels"]

#: Axis labels of angular-velocity components along the sorted principal axes e1, e2, e3.
PRINCIPAL_LABELS = ("ω·e₁ [rad/s]", "ω·e₂ [rad/s]", "ω·e₃ [rad/s]")


def legend_outside(ax, *, fontsize=8, **kwargs):
    """The legend of ``ax`` to the right of its plotting area (upper left corner at the axes'
    upper right), or none when nothing is labelled (no "No artists with labels" warning).
    Returns the legend or None."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    kwargs.setdefault("loc", "upper left")
    kwargs.setdefault("bbox_to_anchor", (1.02, 1.0))
    kwargs.setdefault("borderaxespad", 0.0)
    return ax.legend(handles, labels, fontsize=fontsize, **kwargs)


def legend_below(ax, *, fontsize=8, ncol=None, drop=40.0, **kwargs):
    """The legend of ``ax`` below its plotting area, ``drop`` points under the axes' bottom
    edge (clear of the tick labels and the x-axis label), in ``ncol`` columns; none when
    nothing is labelled."""
    from matplotlib.transforms import offset_copy

    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    kwargs.pop("bbox_to_anchor", None)
    return ax.legend(handles, labels, fontsize=fontsize, ncol=ncol or min(len(handles), 2),
                     loc="upper left", bbox_to_anchor=(0.0, 0.0), borderaxespad=0.0,
                     bbox_transform=offset_copy(ax.transAxes, fig=ax.figure, y=-drop,
                                                units="points"), **kwargs)  # fmt: skip


def omega_axis_labels(ax, moments=None):
    """Label the three axes of a 3D axes as ω components along e1, e2, e3 (with the moments
    I1 ≤ I2 ≤ I3 when given)."""
    labels = list(PRINCIPAL_LABELS)
    if moments is not None:
        labels = [f"ω·e{'₁₂₃'[k]} (I{'₁₂₃'[k]} = {moments[k]:.4g}) [rad/s]" for k in range(3)]
    label_3d(ax, *labels)


def fit_titles(fig) -> None:
    """Wrap each axes' title of ``fig`` onto as many lines as it needs to stay within the
    width of its axes (measured as drawn, so for any text: a long label of a tilted vertical
    no longer runs into its neighbour's title, nor off the figure), then lay the figure out
    again (``tight_layout``) with room for the extra lines. Words are never broken."""
    import textwrap

    fig.tight_layout()
    for ax in fig.axes:
        title = ax.title
        text = " ".join(title.get_text().split())
        if not text:
            continue
        width = ax.get_window_extent().width
        n = len(text)
        title.set_text(text)
        while n > 10 and title.get_window_extent().width > width:
            n = int(n * 0.9)
            title.set_text(textwrap.fill(text, n, break_long_words=False))
    fig.tight_layout()


def label_3d(ax, xlabel, ylabel, zlabel, ticks=5, pad=14):
    """Label a 3D axes with at most ``ticks`` ticks per axis, the labels ``pad`` points beyond
    the tick labels, so that neither covers the other."""
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(ticks))
    ax.set_xlabel(xlabel, labelpad=pad)
    ax.set_ylabel(ylabel, labelpad=pad)
    ax.set_zlabel(zlabel, labelpad=pad)


def png_images(figures, folder=None, dpi: int = 100) -> dict:
    """``figures`` (``(figure, file name, caption)``) rendered as PNG once and closed: written
    into ``folder`` (each file atomically) unless it is None, and returned as
    ``{caption: PNG bytes}`` for a report. The one place a report's figures become files."""
    import io
    from pathlib import Path

    import matplotlib.pyplot as plt

    from .._io import atomic_path

    images = {}
    for fig, name, caption in figures:
        buf = io.BytesIO()
        fig.savefig(buf, dpi=dpi, format="png")
        plt.close(fig)
        if folder is not None:
            with atomic_path(Path(folder) / name) as tmp:
                Path(tmp).write_bytes(buf.getvalue())
        images[caption] = buf.getvalue()
    return images
