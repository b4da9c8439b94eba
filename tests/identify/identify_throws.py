"""Synthetic throws shared by the identification tests, made once per session (a helper
module, not a conftest: ``tests/conftest.py`` is imported by name elsewhere)."""

from __future__ import annotations

import functools


@functools.cache
def throw(**kwargs):
    """A cached :func:`poinsot.identify.synthetic_throw` (keyword arguments hashable)."""
    from poinsot.identify import synthetic_throw

    return synthetic_throw(**kwargs)
