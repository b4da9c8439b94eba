"""Standard errors of a fit with a robust loss, and the residual numbers the result prints.

* The influence ``ψ`` and its slope ``ψ'`` of each robust loss are the first and second
  derivatives of the objective SciPy itself minimises with that loss (its ``cost`` read back
  from :func:`scipy.optimize.least_squares`, differentiated by central differences).
* Least squares is unchanged: the variance is ``s² = Σ r²/(N − p)`` bit for bit and the
  covariance ``s² (JᵀJ)⁻¹`` (an independent inverse of the normal matrix).
* A robust loss gives Huber's M-estimator covariance ``σ² (JᵀJ)⁻¹``, ``σ²`` assembled here from
  SciPy's loss.
* Over synthetic throws with Gaussian noise (and with 3 % outliers) the standard errors of a
  robust fit cover the truth at their nominal rate: the z-scores' RMS is near 1. (The
  reweighting's ``s² (Jᵀ W J)⁻¹`` they replace gave an RMS of 1.9–2.4 on such throws.)
* The summary and the mismatch flag print each number under its own name: the residuals' RMS
  beside the RMS ratio, the robust scale (1.4826 MAD) beside the robust ratio, and the scale
  the standard errors are calibrated to.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from identify_throws import throw
from scipy.optimize import least_squares
from scipy.stats import median_abs_deviation

from poinsot import RigidBody
from poinsot.identify import ModelMismatchWarning, NotIdentifiableError, identify, synthetic_throw
from poinsot.identify import output_error as oe_mod

ROBUST = ("soft_l1", "huber", "cauchy", "arctan")
PHONE = RigidBody.box(0.19, (0.0715, 0.147, 0.0078))


def _phone_throw(seed, duration=0.5):
    return synthetic_throw(rotor=False, body=PHONE, rate=200.0, duration=duration, noise=0.005,
                           saturation=None, seed=seed)  # fmt: skip


def _with_outliers(th, fraction, seed):
    """The readings with ``fraction`` of the samples thrown off by ±0.3 rad/s (60 σ) per axis."""
    rng = np.random.default_rng(seed)
    w = th.omega.copy()
    hit = rng.random(len(w)) < fraction
    w[hit] += rng.choice([-0.3, 0.3], (int(hit.sum()), 3))
    return w


@pytest.fixture
def spy(monkeypatch):
    """What the final fit's covariance was computed from: the model, the parameters, the loss,
    the residual scale and the returned ``(covariance, condition, σ²)``."""
    seen = {}
    real = oe_mod._uncertainty

    def wrapper(model, x, loss, scale, moments):
        out = real(model, x, loss, scale, moments)
        seen.update(model=model, x=x.copy(), loss=loss, scale=scale, out=out)
        return out

    monkeypatch.setattr(oe_mod, "_uncertainty", wrapper)
    return seen


def _scipy_cost(loss, r, f):
    """SciPy's objective ``½ f² ρ(r²/f²)`` of one residual ``r``: the ``cost`` that
    :func:`~scipy.optimize.least_squares` reports for a residual that no parameter moves."""
    sol = least_squares(lambda x: np.array([r]) + 0.0 * x, [0.0], jac=lambda x: np.zeros((1, 1)),
                        loss=loss, f_scale=f, method="trf")  # fmt: skip
    return sol.cost


@pytest.mark.parametrize("loss", ROBUST)
def test_the_influence_is_the_derivative_of_scipys_loss(loss):
    f = 0.02
    r = np.array([-3.1, -1.7, -0.6, -0.05, 0.0, 0.3, 0.8, 1.3, 2.2, 7.0]) * f  # not at ±f
    psi, dpsi = oe_mod._influence(loss, r, f)
    h = 1e-4 * f
    cost = lambda x: _scipy_cost(loss, x, f)  # noqa: E731
    fd_psi = np.array([(cost(x + h) - cost(x - h)) / (2 * h) for x in r])
    fd_dpsi = np.array([(cost(x + h) - 2 * cost(x) + cost(x - h)) / h**2 for x in r])
    np.testing.assert_allclose(psi, fd_psi, rtol=1e-6, atol=1e-9 * f)
    np.testing.assert_allclose(dpsi, fd_dpsi, rtol=1e-4, atol=1e-4)


def test_least_squares_is_unchanged_exactly(spy):
    """``loss="linear"``: ``ψ = r``, ``ψ' = 1`` and ``σ² = Σ r²/(N − p)`` bit for bit, the
    covariance ``s² (JᵀJ)⁻¹`` (here by a Cholesky solve), the result's standard errors its."""
    th = _phone_throw(3)
    res = identify(th.t, th.omega)
    model, x = spy["model"], spy["x"]
    cov, _, s2 = spy["out"]
    r = model.residuals(x)
    J = model.jacobian(x)
    n, p = J.shape
    psi, dpsi = oe_mod._influence("linear", r, spy["scale"])
    assert np.array_equal(psi, r) and np.array_equal(dpsi, np.ones(n))
    assert s2 == float(r @ r) / (n - p)
    assert oe_mod._m_estimator_variance(r, np.ones(n), p) == float(r @ r) / (n - p)
    L = np.linalg.cholesky(J.T @ J)
    inv = np.linalg.solve(L.T, np.linalg.solve(L, np.eye(p)))
    np.testing.assert_allclose(cov, s2 * inv, rtol=1e-8, atol=0)
    k = [model.names.index("rho1"), model.names.index("rho2")]
    np.testing.assert_allclose(res.ratios_stderr, np.sqrt(s2 * np.diag(inv)[k]), rtol=1e-8)


@pytest.mark.parametrize("loss", ROBUST)
def test_a_robust_loss_gives_hubers_covariance(spy, loss):
    """``σ² (JᵀJ)⁻¹`` with ``σ² = K² [Σ ψ²/(N − p)] / [Σ ψ'/N]²``,
    ``K = 1 + (p/N) var ψ'/(mean ψ')²``, ψ and ψ' from SciPy's loss (central differences)."""
    th = _phone_throw(4, duration=0.3)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelMismatchWarning)
        identify(th.t, _with_outliers(th, 0.03, 4), loss=loss)
    model, x, f = spy["model"], spy["x"], spy["scale"]
    cov, _, s2 = spy["out"]
    r = model.residuals(x)
    J = model.jacobian(x)
    n, p = J.shape
    h = 1e-4 * f
    cost = np.vectorize(lambda v: _scipy_cost(loss, v, f))
    psi = (cost(r + h) - cost(r - h)) / (2 * h)
    dpsi = (cost(r + h) - 2 * cost(r) + cost(r - h)) / h**2
    K = 1 + p / n * np.var(dpsi) / np.mean(dpsi) ** 2
    want = K**2 * (psi @ psi / (n - p)) / np.mean(dpsi) ** 2
    assert abs(s2 / want - 1) < 1e-5
    np.testing.assert_allclose(cov, s2 * np.linalg.inv(J.T @ J), rtol=1e-7, atol=0)
    # the reweighting's covariance it replaces is not this one
    w = oe_mod._loss_weight(loss, (r / f) ** 2)
    old = (w * r * r).sum() / (n - p) * np.linalg.inv(J.T @ (w[:, None] * J))
    assert not np.allclose(np.diag(cov), np.diag(old), rtol=0.05)


@pytest.mark.parametrize("fraction", [0.0, 0.03])
def test_robust_standard_errors_cover_the_truth_40_throws(fraction):
    """40 phone throws (0.5 s at 200 Hz, noise 0.005 rad/s), fitted with the arctan loss (the
    one whose reweighted covariance was furthest off), clean or with 3 % outliers: the RMS of
    the ratios' z-scores is 1 within 0.35 (over five such sets of 40 throws it ran from 0.88 to
    1.10), and 2 standard errors hold more than 85 % of them (nominal 95.4 %; 91–100 % over
    those sets). The reweighted covariance it replaces gave an RMS of 2.4 (clean) and 1.9
    (outliers) over 120 throws, 58 % and 73 % within 2 standard errors."""
    z = []
    for seed in range(100, 140):
        th = _phone_throw(seed)
        w = _with_outliers(th, fraction, seed) if fraction else th.omega
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", ModelMismatchWarning)
                res = identify(th.t, w, loss="arctan")
        except (NotIdentifiableError, ModelMismatchWarning):
            continue  # refused or flagged: no claim to check
        z.append((res.ratios - th.ratios) / res.ratios_stderr)
    z = np.array(z)
    assert len(z) >= 38
    rms = float(np.sqrt(np.mean(z**2)))
    assert abs(rms - 1) < 0.35, rms
    assert np.mean(np.abs(z) < 2) > 0.85, np.mean(np.abs(z) < 2)


def _numbers(text):
    return [float(v) for v in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", text)]


def _close(a, b, digits):
    """``a`` printed to ``digits`` significant figures is ``b``."""
    return abs(a - b) <= 0.51 * 10.0 ** (np.floor(np.log10(abs(b))) - digits + 1)


def test_the_summary_prints_the_rms_and_the_robust_scale_each_by_name():
    """With outliers the residuals' RMS is far above the noise and their robust scale near it:
    each is printed with its own ratio to the noise, recomputed here from the residuals (the
    scale by SciPy's MAD)."""
    th = _phone_throw(2000)
    w = th.omega.copy()
    w[::30] += 0.3
    res = identify(th.t, w, loss="huber")
    noise = np.sqrt(np.mean(res.noise_std**2))
    rms = np.sqrt(np.mean(res.residuals**2))
    scale = np.sqrt(np.mean(median_abs_deviation(res.residuals, axis=0, scale="normal") ** 2))
    lines = res.summary()
    (line,) = [s for s in lines if s.startswith("residuals")]
    (robust,) = [s for s in lines if s.startswith("robust scale")]
    assert re.fullmatch(r"residuals +\S+ rad/s RMS, \S+× the gyro noise; condition \S+", line)
    assert re.fullmatch(r"robust scale +\S+ rad/s \(1\.4826 MAD of the residuals\), \S+× the gyro "
                        r"noise; loss huber", robust)  # fmt: skip
    a, b, _ = _numbers(line)
    assert _close(a, rms, 4) and _close(b, rms / noise, 3) and b > 5
    c, _, d = _numbers(robust)
    assert _close(c, scale, 4) and _close(d, scale / noise, 3) and d < 1.5
    assert _close(d, res.residual_ratio, 3)
    assert res.loss == "huber" and res.to_dict()["loss"] == "huber"
    np.testing.assert_allclose(res.residual_scale,
                               median_abs_deviation(res.residuals, axis=0, scale="normal"),
                               rtol=1e-12)  # fmt: skip
    # least squares prints its RMS ratio, which is its residual_ratio, and no robust scale
    plain = identify(th.t, th.omega)
    (line,) = [s for s in plain.summary() if s.startswith("residuals")]
    assert not any(s.startswith("robust scale") for s in plain.summary())
    rms = np.sqrt(np.mean(plain.residuals**2))
    a, b, _ = _numbers(line)
    assert _close(a, rms, 4) and _close(b, plain.residual_ratio, 3)
    assert _close(b, rms / np.sqrt(np.mean(plain.noise_std**2)), 3)
    # the fit figure's title names the ratio it shows (it had said "RMS" of the robust one)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from poinsot.viz.identify import plot_identified_fit

    for r, size in ((res, "robust scale, 1.4826 MAD"), (plain, "RMS")):
        fig = plot_identified_fit(r)
        titles = [ax.get_title() for ax in fig.axes]
        ratio = f"{r.residual_ratio:.3g}× the gyro noise ({size})"
        assert any(ratio in title for title in titles), titles
        plt.close(fig)


@pytest.mark.parametrize("loss", ["linear", "huber"])
def test_the_mismatch_flag_names_its_numbers(spy, loss):
    """A rotor throw fitted torque-free is flagged: the flag's sizes are the residuals' RMS
    (least squares) or their robust scale with their RMS beside it (robust), against the
    noise; the standard errors' scale it names is the fit's ``σ``."""
    th = throw(seed=11, duration=0.25)
    with pytest.warns(ModelMismatchWarning):
        res = identify(th.t, th.omega, loss=loss)
    (flag,) = [f for f in res.flags if "does not explain" in f]
    noise = np.sqrt(np.mean(res.noise_std**2))
    rms = np.sqrt(np.mean(res.residuals**2))
    sigma = float(np.sqrt(spy["out"][2]))
    if loss == "linear":
        m = re.match(r"the residuals are (\S+)× the gyro noise \((\S+) against (\S+) rad/s RMS\)",
                     flag)  # fmt: skip
        ratio, size, n = map(float, m.groups())
        assert _close(size, rms, 3) and _close(ratio, rms / noise, 3)
        named = r"\((\S+) rad/s, their standard deviation;"
        r = spy["model"].residuals(spy["x"])
        assert sigma == pytest.approx(np.sqrt(r @ r / (r.size - spy["model"].p)), rel=1e-12)
    else:
        m = re.match(r"the residuals' robust scale \(1\.4826 MAD\) is (\S+)× the gyro noise "
                     r"\((\S+) rad/s against (\S+) rad/s RMS; their RMS is (\S+) rad/s\)",
                     flag)  # fmt: skip
        ratio, size, n, size_rms = map(float, m.groups())
        scale = np.sqrt(np.mean(median_abs_deviation(res.residuals, axis=0, scale="normal") ** 2))
        assert _close(size, scale, 3) and _close(ratio, scale / noise, 3)
        assert _close(size_rms, rms, 3) and not _close(size_rms, scale, 3)
        named = r"\((\S+) rad/s, the huber loss's M-estimator scale;"
    assert _close(n, noise, 3)
    (printed,) = re.findall(r"calibrated to the residuals " + named, flag)
    assert _close(float(printed), sigma, 3)
