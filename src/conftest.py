"""Doctest set-up for the package's docstrings (not installed: it sits beside the package)."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def _close_figures():
    """Figures drawn by a docstring example are closed after it."""
    yield
    import sys

    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")
