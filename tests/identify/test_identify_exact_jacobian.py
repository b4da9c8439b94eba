"""The output-error fit's Jacobian is the exact derivative of its model (forward sensitivities
of the gyrostat in the core): checked against Richardson-extrapolated central differences of
the model's own prediction, with and without a rotor, with the rotor's inertia known (the
scale η fitted) or not (κ = J/I3 fitted), over several segments and at a point away from the
start (δ ≠ 0, so that the derivative of exp(δ̂) is not the identity's)."""

import numpy as np
import pytest

from poinsot.identify.output_error import (
    _default_max_step,
    _Model,
    _parameter_vector,
    _segments,
    _start_frame,
    _start_omegas,
)
from poinsot.identify.synthetic import synthetic_throw


def model_and_point(rotor, known_J, seed=3):
    throw = synthetic_throw(rotor=rotor, duration=0.4, rate=1500.0, seed=seed)
    t, omega = throw.t, throw.omega
    segments = _segments(len(t), t, 0.15)
    m0, E0, I3_0 = _start_frame(throw.inertia * 1.05)
    rot = (t.copy(), throw.rotor_speed, np.asarray(throw.rotor_axis)) if rotor else None
    J = throw.rotor_inertia if (rotor and known_J) else None
    model = _Model(t, omega, segments, rot, J, E0, I3_0, _default_max_step(t, omega))
    w0 = _start_omegas(t, omega, None, segments)
    J0 = 0.9 * throw.rotor_inertia if rotor else 0.0  # κ = J/I3 from it
    x = _parameter_vector(model.extra, w0, m0, J0, (0.01, 0, 0))
    lr = slice(3 * model.K, 3 * model.K + 2)
    x[lr] = np.log(x[lr])
    x[3 * model.K + 2 : 3 * model.K + 5] = (0.05, -0.03, 0.08)  # a turn of the frame
    if model.extra == "eta":
        x[3 * model.K + 5] = 0.02
    return model, x


@pytest.mark.parametrize(
    ("rotor", "known_J"), [(False, False), (True, True), (True, False)],
    ids=["torque-free", "rotor of known J", "rotor of unknown J"],
)  # fmt: skip
def test_the_jacobian_is_the_derivative_of_the_model(rotor, known_J):
    model, x = model_and_point(rotor, known_J)
    J = model.jacobian(x)
    assert J.shape == (3 * len(model.t), model.p)
    read = np.isfinite(model.omega).ravel()  # saturated readings are missing
    assert read.mean() > 0.5
    for j in range(model.p):
        # κ = J/I3 is small: its step is relative to itself
        h = 1e-4 * (abs(x[j]) if model.names[j] == "kappa" else max(abs(x[j]), 1.0))

        def r(s, j=j):
            xj = x.copy()
            xj[j] += s
            return model.residuals(xj)

        d1 = (r(h) - r(-h)) / (2 * h)
        d2 = (r(h / 2) - r(-h / 2)) / h
        fd = (4 * d2 - d1) / 3
        scale = max(np.abs(fd[read]).max(), 1e-12)
        err = np.abs(J[read, j] - fd[read]).max() / scale
        assert err < 1e-8, f"{model.names[j]}: {err:.2e}"
