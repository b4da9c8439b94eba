"""Issue 43: every export format carries the same fields, and each vector names its frame and,
for a moment, its reference point. The values are checked for their meaning: the angular
momentum about the centre of mass of a body thrown under gravity is conserved (gravity has no
moment about G), the one about the pivot of a top keeps its vertical component (gravity's
moment about the pivot is horizontal), and the one about the origin is ``L_G + M R × V``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.io import netcdf_file

from poinsot import Gravity, RigidBody, simulate

TOP = RigidBody.cylinder(1.0, 0.3, 0.2)


def _top():
    return simulate(TOP, (0, 1), omega0=(0, 1.5, 100), forces=[Gravity((0, 0, -9.81))],
                    pivot=(0, 0, -0.5), t_eval=np.linspace(0, 1, 21))  # fmt: skip


def _throw():
    body = RigidBody.box(10.0, (1, 2, 3))
    return simulate(body, (0, 20), omega0=(0, 1, 1), V0=(1, 2, 3),
                    forces=[Gravity((0, 0, -9.8))], t_eval=np.linspace(0, 20, 41))  # fmt: skip


def _written(traj, tmp_path):
    traj.to_npz(tmp_path / "a.npz")
    traj.to_csv(tmp_path / "a.csv")
    traj.to_netcdf(tmp_path / "a.nc")
    npz = np.load(tmp_path / "a.npz")
    header = (tmp_path / "a.csv").read_text().splitlines()[0].split(",")
    csv = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)
    with netcdf_file(tmp_path / "a.nc", mmap=False) as f:
        nc = {n: (v.data.copy(), dict(v._attributes)) for n, v in f.variables.items()}
    return npz, header, csv, nc


@pytest.mark.parametrize("make", [_top, _throw])
def test_every_format_carries_the_same_fields_with_the_same_values(make, tmp_path):
    traj = make()
    npz, header, csv, nc = _written(traj, tmp_path)
    fields = set(npz.files) - {"attributes", "summary", "t"}
    assert fields == set(nc) - {"time", "axis", "component", "axis_strlen", "component_strlen"}
    assert "potential_energy" in nc  # the .nc had lost it
    names = [h.split(" [")[0] for h in header]
    for name in fields:
        cols = [i for i, h in enumerate(names) if h == name or (h.startswith(name + "_")
                and h[len(name) + 1:] in {"x", "y", "z", "w"} | {f"{i}{j}" for i in "123"
                                                                  for j in "123"})]  # fmt: skip
        value = npz[name].reshape(len(traj.t), -1)
        assert len(cols) == value.shape[1], name
        np.testing.assert_array_equal(csv[:, cols], value)
        np.testing.assert_array_equal(nc[name][0].reshape(value.shape), value)
    attrs = json.loads(str(npz["attributes"]))
    for name, a in attrs.items():
        assert a["units"], name
        if name.startswith("angular_momentum"):
            assert a["frame"] == "space" and a["about"] and a["symbol"].startswith("L_")
            assert nc[name][1]["about"] == a["about"].encode()
    assert attrs["omega"]["frame"] == "body" and attrs["omega_space"]["frame"] == "space"


def test_a_thrown_body_exports_its_conserved_momentum_about_the_centre_of_mass(tmp_path):
    traj = _throw()
    npz = _written(traj, tmp_path)[0]
    L_G = npz["angular_momentum_com"]
    np.testing.assert_allclose(L_G - L_G[0], 0, atol=1e-8 * np.abs(L_G[0]).max())
    L_O = npz["angular_momentum_origin"]  # changes as the centre of mass moves
    assert np.abs(L_O - L_O[0]).max() > 1.0
    np.testing.assert_allclose(L_O, L_G + 10.0 * np.cross(npz["R"], npz["V"]), atol=1e-9)
    assert "angular_momentum_pivot" not in npz.files


def test_a_top_exports_its_momentum_about_the_pivot(tmp_path):
    traj = _top()
    npz, header, _, nc = _written(traj, tmp_path)
    L_P = npz["angular_momentum_pivot"]
    report = {i.symbol: i for i in traj.invariants}
    np.testing.assert_allclose(L_P[:, 2], report["L_P·ĝ"].values * -1, atol=1e-12)
    np.testing.assert_allclose(L_P[:, 2], L_P[0, 2], rtol=1e-9)  # gravity's moment: horizontal
    P = np.array([0.0, 0.0, -0.5])
    np.testing.assert_allclose(L_P, npz["angular_momentum_com"]
                               + np.cross(npz["R"] - P, npz["V"]), atol=1e-12)  # fmt: skip
    assert json.loads(str(npz["attributes"]))["angular_momentum_pivot"]["pivot_position"] == [
        0.0, 0.0, -0.5]  # fmt: skip
    assert "angular_momentum_pivot_z [kg m2/s]" in header
    np.testing.assert_array_equal(nc["angular_momentum_pivot"][1]["pivot_position"], P)
