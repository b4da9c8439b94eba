"""Several throws of one body combined: the estimate, its standard errors and the spread."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot.identify import CombinedResult, combine, identify


@pytest.fixture(scope="module")
def fits():
    from poinsot.identify import synthetic_throw

    throws = [synthetic_throw(seed=s) for s in (51, 52, 53, 54)]
    return throws, [identify(th.t, th.omega, **th.kwargs()) for th in throws]


def test_combining_throws(fits):
    throws, results = fits
    both = combine(results)
    assert isinstance(both, CombinedResult) and both.n_throws == 4 and both.absolute
    truth = throws[0]
    assert np.all(np.abs(both.ratios / truth.ratios - 1) < 0.003)
    assert np.all(truth.axis_errors_deg(both.axes) < 0.5)
    # a weighted mean: its standard error is that of the inverse-variance mean, inflated by
    # the Birge ratio when the throws disagree
    sr = np.array([r.ratios_stderr for r in results])
    base = 1 / np.sqrt(np.sum(1 / sr**2, axis=0))
    np.testing.assert_allclose(both.ratios_stderr, base * np.maximum(both.birge, 1.0))
    assert np.all(both.ratios_stderr < sr.max(axis=0))
    np.testing.assert_allclose(both.ratios_spread, np.std([r.ratios for r in results], 0,
                                                          ddof=1))  # fmt: skip
    assert np.all(both.birge < 3)  # the throws agree within their errors
    d = both.to_dict()
    assert d["throws"] == 4 and len(d["windows"]) == 4 and "ratios_stderr" in d
    assert both.to_json().startswith("{")


def test_one_throw_combines_to_itself(fits):
    _, results = fits
    one = combine(results[:1])
    np.testing.assert_allclose(one.ratios, results[0].ratios, rtol=1e-12)
    np.testing.assert_allclose(one.ratios_stderr, results[0].ratios_stderr, rtol=1e-12)
    np.testing.assert_array_equal(one.ratios_spread, 0.0)


def test_up_to_scale_throws_combine_on_trace_one(fits):
    throws, _ = fits
    free = [identify(th.t, th.omega, **th.kwargs(rotor_inertia_known=False)) for th in throws[:2]]
    both = combine(free)
    assert not both.absolute and abs(np.trace(both.inertia) - 1) < 1e-12


def test_bad_input_is_refused(fits):
    _, results = fits
    with pytest.raises(ValueError, match="at least one"):
        combine([])
    with pytest.raises(TypeError, match=r"`results\[1\]` must be an IdentifyResult"):
        combine([results[0], "x"])
    with pytest.raises(TypeError, match="found one result"):
        combine(results[0])
    from dataclasses import replace

    flagged = replace(results[1], flags=("the residuals are 50× the gyro noise",))
    with pytest.raises(ValueError, match=r"`results\[1\]` is flagged"):
        combine([results[0], flagged])
