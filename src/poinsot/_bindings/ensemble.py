"""Ensembles: the members' bodies and the batched run (``crates/core/src/ensemble/``)."""

from .._core import (
    member_bodies,
    run_ensemble,
)

__all__ = [
    "member_bodies",
    "run_ensemble",
]
