"""Synthetic throws shared by the identification tests (made once per session)."""

from __future__ import annotations

import functools

import pytest


@functools.cache
def throw(**kwargs):
    """A cached :func:`poinsot.identify.synthetic_throw` (keyword arguments hashable)."""
    from poinsot.identify import synthetic_throw

    return synthetic_throw(**kwargs)


@pytest.fixture(scope="session")
def cached_throw():
    return throw
