"""Shared fixtures and hypothesis strategies."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
positive_mass = st.floats(0.1, 10, allow_nan=False, allow_infinity=False)


@st.composite
def point_clouds(draw, min_size=1, max_size=12):
    """(masses (N,), positions (N, 3)) with well-scaled values."""
    n = draw(st.integers(min_size, max_size))
    masses = draw(hnp.arrays(float, n, elements=positive_mass))
    positions = draw(hnp.arrays(float, (n, 3), elements=finite))
    return masses, positions


@st.composite
def rotations(draw):
    """Uniformly spread rotation matrices from a random unit quaternion."""
    q = draw(hnp.arrays(float, 4, elements=st.floats(-1, 1)))
    n = np.linalg.norm(q)
    if n < 1e-3:
        q, n = np.array([1.0, 0, 0, 0]), 1.0
    from poinsot.rotation import matrix_from_quat

    return matrix_from_quat(q / n)


@pytest.fixture
def notebook_body():
    """The notebook's reference body: 27 equal particles on a 1×2×3 grid, total mass 10."""
    from poinsot.models import notebook_body as build

    return build()


# Hypothesis runs without a per-example deadline: the machines that run the suite are shared,
# and a deadline would measure them, not poinsot (a hang is caught by the tests' own limits).
from hypothesis import settings  # noqa: E402

settings.register_profile("poinsot", deadline=None)
settings.load_profile("poinsot")


@pytest.fixture(autouse=True)
def _close_figures():
    """Every test's matplotlib figures are closed after it (figures are tested, then freed)."""
    yield
    import sys

    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")
