"""What a run keeps: sample times, or every k-th step (diffrax's ``SaveAt``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SaveAt"]


@dataclass(frozen=True)
class SaveAt:
    """Keep the state at the times ``t`` (increasing; fixed-step methods land on them exactly,
    adaptive ones interpolate with their dense output), or, without ``t``, at the start, every
    ``every``-th step and the end."""

    t: np.ndarray | None = None
    every: int = 1

    def __post_init__(self):
        if self.t is not None:
            object.__setattr__(self, "t", np.asarray(self.t, dtype=float))
        if not isinstance(self.every, int | np.integer) or self.every < 1:
            raise ValueError(f"`save_every` must be a positive integer, found {self.every!r}")

    @property
    def times(self) -> np.ndarray:
        """The sample times as the drivers read them (empty: every k-th step)."""
        return np.zeros(0) if self.t is None else self.t
