"""Several throws of one body combined into one estimate, with their spread.

Each throw's tensor (normalised to trace 1 unless every throw is absolute) is weighted by the
inverse variance of its ratios; the weighted mean tensor gives the combined principal moments
and axes. The standard error of a ratio is that of an inverse-variance weighted mean,
``1/√(Σ 1/σ_i²)``, and of an axis the same over the throws' axis errors; each is inflated by
the Birge ratio ``√(χ²/dof)`` when the throws disagree by more than their standard errors
say (a model error common to all throws, such as air drag, shows up there).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from .._bindings import inertia as core_inertia
from .result import IdentifyResult

__all__ = ["CombinedResult", "combine"]


@dataclass(frozen=True, eq=False)
class CombinedResult:
    """The combined estimate of several throws.

    Attributes
    ----------
    inertia, absolute, principal_moments, ratios, axes, ratios_stderr, axes_stderr_deg
        As in :class:`~poinsot.identify.IdentifyResult`, for the combination.
    principal_moments_stderr : ndarray (3,)
    windows : tuple of (float, float)
        Each throw's window.
    ratios_spread : ndarray (2,)
        Standard deviation of the throws' ratios (0 for one throw).
    axes_spread_deg : ndarray (3,)
        RMS angle [deg] between the throws' axes and the combined ones.
    birge : ndarray (2,)
        ``√(χ²/dof)`` of the ratios: about 1 when the throws agree within their errors.
    throws : tuple of IdentifyResult
    """

    inertia: np.ndarray
    absolute: bool
    principal_moments: np.ndarray
    ratios: np.ndarray
    axes: np.ndarray
    ratios_stderr: np.ndarray
    axes_stderr_deg: np.ndarray
    principal_moments_stderr: np.ndarray
    windows: tuple
    ratios_spread: np.ndarray
    axes_spread_deg: np.ndarray
    birge: np.ndarray
    throws: tuple

    @property
    def n_throws(self) -> int:
        return len(self.throws)

    def to_dict(self) -> dict:
        """A JSON-ready dict of the combination (without the throws' series)."""
        f = lambda a: np.asarray(a, float).tolist()  # noqa: E731
        return {
            "ratios": f(self.ratios),
            "ratios_stderr": f(self.ratios_stderr),
            "axes": f(self.axes),
            "axes_stderr_deg": f(self.axes_stderr_deg),
            "inertia": f(self.inertia),
            "absolute": bool(self.absolute),
            "principal_moments": f(self.principal_moments),
            "principal_moments_stderr": f(self.principal_moments_stderr),
            "windows": [list(map(float, w)) for w in self.windows],
            "throws": self.n_throws,
            "ratios_spread": f(self.ratios_spread),
            "axes_spread_deg": f(self.axes_spread_deg),
            "birge": f(self.birge),
        }

    def to_json(self, **kwargs) -> str:
        kwargs.setdefault("indent", 2)
        return json.dumps(self.to_dict(), **kwargs)


def combine(results) -> CombinedResult:
    """Combine the identifications of several throws of one body (same sensor frame).

    Parameters
    ----------
    results : sequence of IdentifyResult
        At least one; none flagged (a fit its model does not explain is refused).

    Returns
    -------
    CombinedResult

    Examples
    --------
    >>> from poinsot.identify import identify, synthetic_throw
    >>> throws = [synthetic_throw(rotor=False, seed=s) for s in (1, 2, 3)]
    >>> fits = [identify(th.t, th.omega) for th in throws]
    >>> both = combine(fits)
    >>> both.n_throws, bool(np.all(np.abs(both.ratios / throws[0].ratios - 1) < 0.001))
    (3, True)
    """
    if isinstance(results, IdentifyResult):
        raise TypeError("`results` must be a sequence of IdentifyResult, found one result")
    try:
        results = tuple(results)
    except TypeError:
        raise TypeError(
            f"`results` must be a sequence of IdentifyResult, found {type(results).__name__}"
        ) from None
    if not results:
        raise ValueError("`results` must hold at least one IdentifyResult")
    for i, r in enumerate(results):
        if not isinstance(r, IdentifyResult):
            raise TypeError(f"`results[{i}]` must be an IdentifyResult, found "
                            f"{type(r).__name__}")  # fmt: skip
        if r.flags:
            raise ValueError(f"`results[{i}]` is flagged and is not combined: {r.flags[0]}")
    n = len(results)
    absolute = all(r.absolute for r in results)
    tensors = np.array([r.inertia if absolute else r.inertia / np.trace(r.inertia)
                        for r in results])  # fmt: skip
    rs = np.array([r.ratios for r in results])
    sr = np.array([r.ratios_stderr for r in results])
    tiny = 1e-12
    wr = 1.0 / np.maximum(sr, tiny) ** 2  # (n, 2)
    weight = 1.0 / np.mean(np.maximum(sr, tiny) ** 2, axis=1)
    mean = np.einsum("i,ijk->jk", weight, tensors) / weight.sum()
    mean = 0.5 * (mean + mean.T)
    moments, axes = (np.asarray(x) for x in core_inertia.principal_decomposition(mean))
    ratios = moments[:2] / moments[2]
    dof = max(n - 1, 1)
    chi_r = np.sum(wr * (rs - ratios) ** 2, axis=0)
    birge = np.sqrt(chi_r / dof) if n > 1 else np.ones(2)
    ratios_stderr = np.sqrt(1.0 / wr.sum(axis=0)) * np.maximum(birge, 1.0)
    # axes: each throw's angle to the combined axis, against its own standard error
    ang = np.array([np.degrees(np.arccos(np.abs(np.sum(r.axes * axes, axis=0)).clip(max=1.0)))
                    for r in results])  # fmt: skip
    sa = np.maximum(np.array([r.axes_stderr_deg for r in results]), tiny)
    wa = 1.0 / sa**2
    chi_a = np.sum(wa * ang**2, axis=0)
    birge_a = np.sqrt(chi_a / (2 * dof)) if n > 1 else np.ones(3)
    axes_stderr = np.sqrt(1.0 / wa.sum(axis=0)) * np.maximum(birge_a, 1.0)
    sm = np.array([r.principal_moments_stderr / (1.0 if absolute else np.trace(r.inertia))
                   for r in results])  # fmt: skip
    wm = 1.0 / np.maximum(sm, tiny) ** 2
    moments_stderr = np.sqrt(1.0 / wm.sum(axis=0)) * np.max(np.maximum(birge, 1.0))
    return CombinedResult(
        inertia=mean,
        absolute=absolute,
        principal_moments=moments,
        ratios=ratios,
        axes=axes,
        ratios_stderr=ratios_stderr,
        axes_stderr_deg=axes_stderr,
        principal_moments_stderr=moments_stderr,
        windows=tuple(r.window for r in results),
        ratios_spread=rs.std(axis=0, ddof=1) if n > 1 else np.zeros(2),
        axes_spread_deg=np.sqrt(np.mean(ang**2, axis=0)),
        birge=birge,
        throws=results,
    )
