"""Ensembles: many motions of one body at once, in compiled chunks (``docs/ensembles.md``).

>>> from poinsot.ensemble import simulate_ensemble     # doctest: +SKIP
"""

from __future__ import annotations

from .result import STATISTICS, EnsembleResult
from .run import PreparedEnsemble, prepare_ensemble, simulate_ensemble
from .tasks import ChunkSamples

__all__ = [
    "STATISTICS",
    "ChunkSamples",
    "EnsembleResult",
    "PreparedEnsemble",
    "prepare_ensemble",
    "simulate_ensemble",
]
