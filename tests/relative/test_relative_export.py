"""The export of a relative motion (``RelativeTrajectory.to_npz``, ``to_csv``, ``to_netcdf``,
``to_xarray``): every format carries the same fields with their frames and units, and the
fields read back mean what their labels say. The decisive checks are relations between
fields that the file must satisfy if each is labelled right: the absolute motion equals the
carrier's motion composed with the relative one (``R = X_O + Q_c r``, ``Q = Q_c Q_r``,
``ω = ω_r + ω_e`` on the body axes), and it equals the absolute export of ``to_trajectory``
(tested against poinsot's absolute ``simulate`` in ``test_relative.py``).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp
from scipy.io import netcdf_file

from poinsot import RigidBody
from poinsot.forces import Gravity
from poinsot.relative import Carrier, simulate_relative

T = sp.Symbol("t", real=True)
CARRIER = Carrier(omega_e=[0.2 * sp.sin(0.7 * T), 0.1 * T, 0.8], origin_acceleration=[0.5, 0, 0],
                  t=T, name="turning vehicle")  # fmt: skip
BODY = RigidBody.box(3.0, (0.4, 0.7, 1.2))


@pytest.fixture(scope="module")
def sol():
    return simulate_relative(BODY, (0, 2), omega_r0=(0.5, -1.0, 2.0), carrier=CARRIER,
                             forces=[Gravity((0, 0, -9.8))], r0=(1.0, 0.5, -0.2),
                             v_r0=(0.1, 0.0, 0.3), Q_carrier0=[0.9, 0.1, -0.3, 0.3],
                             t_eval=np.linspace(0, 2, 9), rtol=1e-11, atol=1e-13)  # fmt: skip


def test_the_fields_are_related_as_their_labels_say(sol, tmp_path):
    sol.to_npz(tmp_path / "rel.npz")
    f = np.load(tmp_path / "rel.npz")
    attrs = json.loads(str(f["attributes"]))
    Qc, Qr = f["Q_carrier"], f["Q_r"]
    np.testing.assert_allclose(f["R_absolute"], f["origin"] + np.einsum("nij,nj->ni", Qc, f["r"]),
                               rtol=0, atol=1e-13)  # fmt: skip
    np.testing.assert_allclose(f["Q_absolute"], Qc @ Qr, rtol=0, atol=1e-14)
    np.testing.assert_allclose(f["omega_absolute"], f["omega_r"] + f["omega_e"], rtol=0, atol=1e-14)
    # ω_e on the body axes is the carrier's own ω_e, Q_rᵀ ω_e(t) carrier components
    w_e = np.stack([[0.2 * np.sin(0.7 * t), 0.1 * t, 0.8] for t in f["t"]])
    np.testing.assert_allclose(np.einsum("nij,nj->ni", Qr, f["omega_e"]), w_e, atol=1e-14)
    # the absolute motion is the one to_trajectory() exports
    ab = sol.to_trajectory()
    for mine, theirs in (("R_absolute", "R"), ("V_absolute", "V"), ("Q_absolute", "Q"),
                         ("omega_absolute", "omega")):  # fmt: skip
        np.testing.assert_array_equal(f[mine], getattr(ab, theirs))
    assert attrs["r"]["frame"] == "carrier" and attrs["omega_r"]["frame"] == "body"
    assert attrs["R_absolute"]["frame"] == "space" and attrs["coriolis_moment"]["units"] == "N m"
    assert json.loads(str(f["summary"]))["carrier"] == repr(CARRIER)


def test_every_format_carries_the_same_numbers(sol, tmp_path):
    sol.to_npz(tmp_path / "rel.npz")
    sol.to_csv(tmp_path / "rel.csv")
    sol.to_netcdf(tmp_path / "rel.nc")
    npz = np.load(tmp_path / "rel.npz")
    header = (tmp_path / "rel.csv").read_text().splitlines()[0].split(",")
    assert header == sol.csv_columns()
    assert header[:4] == ["t [s]", "r_x [m]", "r_y [m]", "r_z [m]"]
    assert "Q_r_23 [1]" in header and "epsilon_e_z [rad/s2]" in header
    table = np.loadtxt(tmp_path / "rel.csv", delimiter=",", skiprows=1)
    column = {name: table[:, i] for i, name in enumerate(header)}
    np.testing.assert_array_equal(column["Q_r_23 [1]"], sol.Q_r[:, 1, 2])
    np.testing.assert_array_equal(column["relative_energy [J]"], sol.relative_energy)
    with netcdf_file(tmp_path / "rel.nc", "r", mmap=False) as nc:
        for name in ("r", "v_r", "Q_r", "omega_r", "Q_carrier", "transport_moment",
                     "coriolis_moment", "omega_absolute"):  # fmt: skip
            np.testing.assert_array_equal(nc.variables[name].data, npz[name])
            np.testing.assert_array_equal(npz[name], getattr(sol, name))
        assert nc.variables["v_r"].frame == b"carrier"
        assert nc.variables["Q_r"].dimensions == ("time", "row", "col")


def test_sensitivities_come_with_their_labels(tmp_path):
    s = simulate_relative(BODY, (0, 1), omega_r0=(0.5, -1.0, 2.0), carrier=CARRIER,
                          t_eval=[0, 0.5, 1], sensitivities=("omega_r0", "inertia"),
                          rtol=1e-10, atol=1e-12)  # fmt: skip
    s.to_npz(tmp_path / "s.npz")
    f = np.load(tmp_path / "s.npz")
    labels = list(f["state_component"])
    assert len(labels) == 33 and labels[15:18] == ["omega_r_x", "omega_r_y", "omega_r_z"]
    assert labels[6] == "Q_r_11" and labels[-1] == "origin_velocity_z"
    cols = list(f["parameter"])
    i = cols.index("omega_r0[1]")
    np.testing.assert_array_equal(f["sensitivity"][:, 15:18, i],
                                  s.sensitivity("omega_r", "omega_r0")[:, :, 1])  # fmt: skip
    np.testing.assert_array_equal(f["sensitivity"][:, 0:3, cols.index("inertia[2]")],
                                  s.sensitivity("r", "inertia")[:, :, 2])  # fmt: skip
    attrs = json.loads(str(f["attributes"]))["sensitivity"]
    assert "Q_r body to carrier" in attrs["frames"] and "omega0_frame" not in attrs
    assert "sensitivity" not in "".join(s.csv_columns())


def test_xarray_selects_by_label(sol, tmp_path):
    xr = pytest.importorskip("xarray")
    ds = sol.to_xarray()
    np.testing.assert_array_equal(ds["omega_r"].sel(axis="y").values, sol.omega_r[:, 1])
    assert ds["r"].attrs["frame"] == "carrier" and ds.attrs["method"] == sol.method
    sol.to_netcdf(tmp_path / "rel.nc")
    with xr.open_dataset(tmp_path / "rel.nc") as back:
        np.testing.assert_array_equal(back["Q_carrier"].values, sol.Q_carrier)
