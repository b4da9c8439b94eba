"""Forward sensitivities of motions relative to a carrier against Richardson-extrapolated
central differences of plain relative runs: the initial relative state, the inertia and the
forces' parameters, under a time-varying carrier (turning, nodding, accelerating)."""

import numpy as np
import pytest
import sympy as sp
from scipy.spatial.transform import Rotation

from poinsot import RigidBody
from poinsot.forces import CentralGravity, Gravity, Spring
from poinsot.relative import Carrier, simulate_relative

T = sp.Symbol("t", real=True)
CARRIER = Carrier(
    omega_e=[0.2 * sp.sin(0.7 * T), 0.1 * T, 0.8 + 0.3 * sp.cos(1.3 * T)],
    origin_acceleration=[0.5 + 0.2 * T, 0, 0],
    t=T,
    name="turning vehicle",
)
INERTIA = np.array([[2.0, 0.3, -0.1], [0.3, 3.0, 0.2], [-0.1, 0.2, 4.5]])
Q_R0 = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
START = {"omega_r0": np.array([0.4, -1.1, 0.7]), "Q_r0": Q_R0,
         "r0": np.array([1.0, 0.5, -0.2]), "v_r0": np.array([0.1, 0.0, 0.3])}  # fmt: skip
CASES = {
    "gravity": (Gravity((0.1, -0.2, -9.8)),),
    "central gravity": (CentralGravity(20.0, (0.5, 0.2, -3.0)),),
    "spring": (Spring((0.2, 0.1, -0.3), (1.0, 0.5, 2.5), 7.0, 0.5, damping=0.3),),
}


def final(forces, method, inertia=INERTIA, **moved):
    kw = START | moved
    opts = {"dt": 1e-2} if method == "rk4" else {"rtol": 1e-13, "atol": 1e-15}
    sol = simulate_relative(RigidBody(2.0, inertia, (0.1, -0.2, 0.3)), (0, 1), carrier=CARRIER,
                            forces=forces, method=method, **opts, **kw)  # fmt: skip
    return np.concatenate([sol.r[-1], sol.v_r[-1], sol.Q_r[-1].ravel(), sol.omega_r[-1]])


def richardson(f, h):
    d1 = (f(h) - f(-h)) / (2 * h)
    d2 = (f(h / 2) - f(-h / 2)) / h
    return (4 * d2 - d1) / 3


@pytest.mark.parametrize("method", ["rk4", "dop853"])
@pytest.mark.parametrize("case", list(CASES))
def test_relative_sensitivities_agree_with_differences(case, method):
    forces = CASES[case]
    opts = {"dt": 1e-2} if method == "rk4" else {"rtol": 1e-13, "atol": 1e-15}
    wrt = ("omega_r0", "Q_r0", "r0", "v_r0", "inertia", "forces[0]")
    sol = simulate_relative(RigidBody(2.0, INERTIA, (0.1, -0.2, 0.3)), (0, 1), carrier=CARRIER,
                            forces=forces, method=method, sensitivities=wrt, **opts,
                            **START)  # fmt: skip
    S = sol.sensitivity("state")[-1][:18]
    E = sol.system.principal_axes
    moves = []
    for name in ("omega_r0", "r0", "v_r0"):
        moves += [lambda h, n=name, k=k: {n: START[n] + h * np.eye(3)[k]} for k in range(3)]
    moves[3:3] = [lambda h, k=k: {"Q_r0": Rotation.from_rotvec(h * np.eye(3)[k]).as_matrix()
                                  @ Q_R0} for k in range(3)]  # fmt: skip
    moves += [lambda h, k=k: {"inertia": INERTIA + h * np.outer(E[:, k], E[:, k])}
              for k in range(3)]  # fmt: skip
    force = forces[0]
    for pname, _, size, _ in force.sensitive_parameters():
        for c in range(size):

            def moved(h, pname=pname, c=c, size=size):
                kw = {k: getattr(force, k) for k in ("g", "mu", "center", "point", "anchor",
                                                    "stiffness", "rest_length", "damping")
                      if hasattr(force, k)}  # fmt: skip
                kw[pname] = np.array(kw[pname], float) + h * (np.eye(size)[c] if size > 1 else 1)
                if isinstance(force, Gravity):
                    return {"forces": (Gravity(kw["g"]),)}
                if isinstance(force, CentralGravity):
                    return {"forces": (CentralGravity(kw["mu"], kw["center"]),)}
                return {"forces": (Spring(kw["point"], kw["anchor"], kw["stiffness"],
                                          kw["rest_length"], damping=kw["damping"]),)}  # fmt: skip

            moves.append(moved)
    assert S.shape[1] == len(moves)
    for c, move in enumerate(moves):

        def f(h, move=move):
            kw = move(h)
            return final(kw.pop("forces", forces), method, **kw)

        fd = richardson(f, 1e-3)
        err = np.abs(S[:, c] - fd[:18]).max() / max(np.abs(fd).max(), 1.0)
        assert err <= 1e-9, f"{case} {method}: column {sol.sensitivities.directions.labels[c]}"


def test_the_carrier_part_does_not_move_and_the_refusals():
    sol = simulate_relative(RigidBody(2.0, INERTIA), (0, 1), carrier=CARRIER, method="rk4",
                            dt=1e-2, sensitivities=("omega_r0", "inertia"),
                            omega_r0=(0.4, -1.1, 0.7))  # fmt: skip
    assert not sol.sensitivity("state")[:, 18:].any()
    assert sol.lyapunov_exponents().shape == (len(sol.t), 3)
    with pytest.raises(ValueError, match="'v_r0' has no effect"):
        simulate_relative(RigidBody(2.0, INERTIA), (0, 1), carrier=CARRIER, hold_com=True,
                          sensitivities="v_r0", omega_r0=(0, 0, 1))  # fmt: skip
    with pytest.raises(ValueError, match="unknown parameter 'omega0'"):
        simulate_relative(RigidBody(2.0, INERTIA), (0, 1), carrier=CARRIER,
                          sensitivities="omega0", omega_r0=(0, 0, 1))  # fmt: skip
