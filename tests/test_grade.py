"""``poinsot grade`` (issue 43): trajectories from any engine graded against the exact motion.
Each measure is checked against an independent route: the exact motion grades at round-off; a
known offset gives the polhode distance computed by brute force; the flip instants agree with
SciPy's event location on DOP853; a family change is found where it was made; the heavy top
graded on poinsot's own tight run is at its tolerance."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from poinsot import FreeRigidBody, Gravity, RigidBody, simulate
from poinsot.app.cli import main
from poinsot.grade import grade_free, grade_top, read_motion
from poinsot.identify.log import LogMapError
from poinsot.tops import heavy_top

ROOT = Path(__file__).resolve().parents[1]
MOMENTS = (1.0, 2.0, 3.0)
W0 = (0.05, 2.0, 0.05)
FREE = FreeRigidBody(MOMENTS)


def _exact(t, w0=W0):
    return FREE.exact_omega(w0, t), FREE.exact_attitude(w0, t)


def test_the_exact_motion_grades_at_round_off():
    t = np.linspace(0.0, 30.0, 3001)
    w, Q = _exact(t)
    g = grade_free(t, w, MOMENTS, Q)
    s = g.summary()
    assert s["max_omega_error"] < 1e-13 and s["max_attitude_error"] < 1e-13
    assert s["max_polhode_distance"] < 1e-13 and s["max_energy_error"] < 1e-14
    assert s["family"] == "around e3" and s["family_kept"]
    assert s["flips"] == s["exact_flips"] == 4
    assert s["max_flip_time_error"] < 1e-6  # linear between samples 10 ms apart


def test_the_flip_instants_agree_with_scipys_events():
    from scipy.integrate import solve_ivp

    I = np.array(MOMENTS)

    def euler(_, w):
        return np.cross(I * w, w) / I

    def flip(_, w):
        return w[1]

    done = solve_ivp(euler, (0, 30), W0, method="DOP853", rtol=1e-13, atol=1e-14, events=flip)
    t = np.linspace(0.0, 30.0, 301)
    g = grade_free(t, _exact(t)[0], MOMENTS)
    np.testing.assert_allclose(g.exact_flips, done.t_events[0], atol=1e-9)
    assert g.flip_interval == pytest.approx(np.diff(done.t_events[0]).mean(), rel=1e-9)


def test_the_polhode_distance_is_the_distance_to_the_curve_itself():
    """ω on a neighbouring polhode: the distance found by the golden-section search along the
    closed form equals the minimum SciPy's Brent method finds around the nearest of 2·10⁵
    points of the exact curve."""
    t = np.linspace(0.0, 20.0, 41)
    other = FREE.exact_omega((0.05, 2.0, 0.06), t)  # another polhode, same flavour
    g = grade_free(np.linspace(0, 1, 41), np.vstack([_exact(t)[0][:1], other[1:]]), MOMENTS)
    from scipy.optimize import minimize_scalar

    s = np.linspace(0.0, FREE.period(W0), 200_001)
    dense = FREE.exact_omega(W0, s)
    brute = []
    for w in other[1:]:  # the nearest of 2·10⁵ points, then SciPy's Brent search around it
        k = int(np.argmin(((dense - w) ** 2).sum(1)))

        def dist(x, w=w):
            return float(np.linalg.norm(FREE.exact_omega(W0, [x])[0] - w))

        best = minimize_scalar(dist, bounds=(s[max(k - 1, 0)], s[min(k + 1, len(s) - 1)]),
                               method="bounded", options={"xatol": 1e-14})  # fmt: skip
        brute.append(best.fun)
    # the same minimum; Brent's bounded search stops at √ε relative in the time, so its
    # distance is at most ~1e-10 above the true one, and never below ours
    assert np.all(g.polhode_distance[1:] <= np.array(brute) + 1e-15)
    np.testing.assert_allclose(g.polhode_distance[1:], brute, atol=1e-9)
    assert g.polhode_distance[0] < 1e-14


def test_a_change_of_family_is_found_where_it_was_made():
    t = np.linspace(0.0, 10.0, 101)
    w = _exact(t)[0]
    w[60:] = FREE.exact_omega((2.0, 0.05, 0.05), t[60:])  # around e1 from t = 6 s
    s = grade_free(t, w, MOMENTS).summary()
    assert s["family"] == "around e3" and not s["family_kept"]
    assert s["family_left_at"] == pytest.approx(6.0) and s["wrong_family_fraction"] == 41 / 101


def test_a_heavy_top_graded_against_lagranges_top():
    body = RigidBody.cylinder(1.0, 0.3, 0.2)
    forces, pivot = [Gravity((0, 0, -9.81))], (0, 0, -0.5)
    top = heavy_top(body, np.array(pivot), forces)
    from poinsot.rotation import matrix_from_euler

    Q0 = matrix_from_euler([0.3, 0.6, 0.0])
    tight = simulate(body, (0, 2), omega0=(0, 1.5, 100), Q0=Q0, forces=forces, pivot=pivot,
                     rtol=1e-12, atol=1e-12, t_eval=np.linspace(0, 2, 201))  # fmt: skip
    coarse = simulate(body, (0, 2), omega0=(0, 1.5, 100), Q0=Q0, forces=forces, pivot=pivot,
                      method="rk4", dt=2e-3, t_eval=np.linspace(0, 2, 201))  # fmt: skip
    good = grade_top(tight.t, tight.omega, tight.Q, top).summary()
    bad = grade_top(coarse.t, coarse.omega, coarse.Q, top).summary()
    assert good["max_omega_error"] < 1e-7 and good["max_theta_error"] < 1e-9
    assert bad["max_omega_error"] > 100 * good["max_omega_error"]
    assert bad["max_theta_error"] > 100 * good["max_theta_error"]


def _cylinder_top():
    body = RigidBody.cylinder(1.0, 0.3, 0.2)
    forces, pivot = [Gravity((0, 0, -9.81))], (0, 0, -0.5)
    return body, forces, pivot, heavy_top(body, np.array(pivot), forces)


def test_a_swing_through_the_vertical_grades_its_angles_modulo_a_turn():
    """Released from rest with no spin, the top swings in one plane through the vertical,
    where ψ and φ step by ±π, the side a matter of round-off: the closed form's own motion
    had graded at 4π in ψ and φ with ω and Q exact, and a tight run at 12.6 rad."""
    from poinsot.rotation import matrix_from_euler
    from poinsot.tops import exact_motion

    body, forces, pivot, top = _cylinder_top()
    t = np.linspace(0, 5, 501)
    Q0 = matrix_from_euler([0.0, 0.6, 0.0])
    exact = exact_motion(top, (0.0, 0.0, 0.0), Q0, t)
    assert exact.theta_band[1] == np.pi  # through the hanging vertical
    perfect = grade_top(t, exact.omega, exact.Q, top).summary()
    assert perfect["max_psi_error"] < 1e-12 and perfect["max_phi_error"] < 1e-12
    run = simulate(body, (0, 5), omega0=(0, 0, 0), Q0=Q0, forces=forces, pivot=pivot,
                   rtol=1e-12, atol=1e-12, t_eval=t)  # fmt: skip
    g = grade_top(run.t, run.omega, run.Q, top).summary()
    assert g["max_attitude_error"] < 1e-8 and g["max_psi_error"] < 1e-6
    # the report's summary says the same
    from poinsot.tops import top_motion

    assert top_motion(run, top).summary()["exact"]["max_psi_error"] < 1e-6
    # off the vertical ψ is continuous: a whole turn off is an error, not wrapped away
    import dataclasses

    run = simulate(body, (0, 1), omega0=(0, 0, 50.0), Q0=Q0, forces=forces, pivot=pivot,
                   rtol=1e-12, atol=1e-12, t_eval=t[:101])  # fmt: skip
    spun = top_motion(run, top)
    assert spun.exact.theta_band[1] < 3.0
    turned = dataclasses.replace(spun, psi=spun.psi + 2 * np.pi)
    assert turned.angle_errors()["psi"].min() == pytest.approx(2 * np.pi, abs=1e-6)


def test_a_first_attitude_that_is_not_a_rotation_is_named_as_such():
    """It had been refused as "the top starts with its axis on the vertical"."""
    from poinsot.rotation import matrix_from_euler
    from poinsot.tops import exact_motion

    _, _, _, top = _cylinder_top()
    t = np.linspace(0, 1, 11)
    m = exact_motion(top, (0.0, 1.0, 50.0), matrix_from_euler([0.0, 0.6, 0.0]), t)
    with pytest.raises(ValueError, match="the closed form from the first sample: `Q0` is not a "
                                         "rotation"):  # fmt: skip
        grade_top(t, m.omega, m.Q * 1.0001, top)
    vertical = exact_motion(top, (0.0, 1.0, 50.0), matrix_from_euler([0.0, 0.3, 0.0]), t)
    Q = vertical.Q.copy()
    Q[0] = np.eye(3)
    with pytest.raises(ValueError, match="starts with its axis on the vertical"):
        grade_top(t, vertical.omega, Q, top)


def test_the_integrated_matrix_is_graded_not_the_quaternion(tmp_path):
    """A run's Q drifts off SO(3) (RK4 on the matrix); the export's quaternion is its
    normalised rotation. Grading the file had read the quaternion, and found no drift."""
    tr = simulate(RigidBody(1.0, np.diag(MOMENTS)), (0, 5), omega0=W0, method="rk4", dt=0.05,
                  t_eval=np.linspace(0, 5, 51))  # fmt: skip
    drift = float(np.abs(np.einsum("nji,njk->nik", tr.Q, tr.Q) - np.eye(3)).max())
    assert drift > 1e-8
    tr.to_npz(tmp_path / "t.npz")
    tr.to_csv(tmp_path / "t.csv")
    for name in ("t.npz", "t.csv"):
        m = read_motion(tmp_path / name)
        np.testing.assert_allclose(m.Q, tr.Q, rtol=0, atol=1e-15)
        graded = grade_free(m.t, m.omega, MOMENTS, m.Q).summary()
        assert graded["max_orthogonality_error"] == pytest.approx(drift, rel=1e-6)


def test_an_attitude_that_does_not_follow_the_gyro_is_named_with_its_likely_cause(tmp_path):
    """Mislabelled columns grade as large errors; the grade also says the attitude's steps
    ``Q_kᵀQ_k+1`` do not follow ω Δt and what they follow instead. The exact motion (the
    closed form, sampled every 10 ms) follows it to the trapezoid's O(Δt²)."""
    from poinsot.app.grade import gyro_note
    from poinsot.grade import FOLLOW_RTOL
    from poinsot.rotation import matrix_from_quat, quat_from_matrix

    t = np.linspace(0.0, 10.0, 1001)
    w, Q = _exact(t)
    good = grade_free(t, w, MOMENTS, Q)
    assert good.gyro_mismatch < 1e-3 and good.gyro_verdict == "" and gyro_note(good.summary()) == ""
    space = np.einsum("nij,nj->ni", Q, w)  # ω in the space frame, labelled as the body's
    q = quat_from_matrix(Q)
    cases = {
        "space": (space, Q),
        "transposed": (w, np.swapaxes(Q, 1, 2)),
        "degrees": (np.degrees(w), Q),
        "": (w, matrix_from_quat(np.roll(q, -1, axis=1))),  # x, y, z, w read as w, x, y, z
    }
    for verdict, (omega, attitude) in cases.items():
        g = grade_free(t, omega, MOMENTS, attitude)
        assert g.gyro_mismatch > FOLLOW_RTOL and g.gyro_verdict == verdict, verdict
        assert gyro_note(g.summary()).startswith("the attitude does not follow the gyro")
    coarse = grade_free(t[::100], w[::100], MOMENTS, Q[::100])  # 2 rad a step: cannot tell
    assert coarse.gyro_mismatch is None


def _write_csv(path, t, w, Q=None, quaternion=True):
    from poinsot.rotation import quat_from_matrix

    cols, head = [t[:, None], w], ["time", "wx", "wy", "wz"]
    if Q is not None and quaternion:
        cols.append(quat_from_matrix(Q))
        head += ["qw", "qx", "qy", "qz"]
    elif Q is not None:
        cols.append(Q.reshape(len(t), 9))
        head += [f"Q{i}{j}" for i in range(3) for j in range(3)]
    np.savetxt(path, np.hstack(cols), delimiter=",", header=",".join(head), comments="")


def test_csv_with_quaternion_or_matrix_columns_and_npz_read_the_same(tmp_path):
    t = np.linspace(0.0, 5.0, 51)
    w, Q = _exact(t)
    _write_csv(tmp_path / "q.csv", t, w, Q)
    _write_csv(tmp_path / "m.csv", t, w, Q, quaternion=False)
    np.savez(tmp_path / "a.npz", t=t, omega=w, Q=Q)
    a = read_motion(tmp_path / "q.csv", gyro=("wx", "wy", "wz"), attitude=("qw", "qx", "qy",
                                                                            "qz"))  # fmt: skip
    b = read_motion(tmp_path / "m.csv", gyro=("wx", "wy", "wz"),
                    attitude=tuple(f"Q{i}{j}" for i in range(3) for j in range(3)))  # fmt: skip
    c = read_motion(tmp_path / "a.npz")
    for m in (a, b, c):
        np.testing.assert_allclose(m.Q, Q, atol=1e-15)
        np.testing.assert_array_equal(m.omega, w)


@pytest.mark.parametrize("count", [1, 3, 5, 8])
def test_attitude_columns_given_as_options_are_checked_as_a_maps(tmp_path, count):
    """``attitude=`` (``--attitude``) of neither four nor nine columns is refused by name, as
    ``columns.attitude`` of a map file is (it had reached NumPy's reshape)."""
    t = np.linspace(0.0, 1.0, 11)
    w, Q = _exact(t)
    _write_csv(tmp_path / "q.csv", t, w, Q)
    with pytest.raises(LogMapError, match=r"`attitude` must list four quaternion columns"):
        read_motion(tmp_path / "q.csv", gyro=("wx", "wy", "wz"),
                    attitude=("qw", "qx", "qy", "qz", "qw", "qx", "qy", "qz")[:count])  # fmt: skip
    with pytest.raises(LogMapError, match=r"`gyro` must list three columns"):
        read_motion(tmp_path / "q.csv", gyro=("wx", "wy"))


def test_poinsots_own_csv_export_needs_no_options(tmp_path):
    tr = simulate(RigidBody(1.0, np.diag(MOMENTS)), (0, 5), omega0=W0, method="rkmk4", dt=1e-3,
                  t_eval=np.linspace(0, 5, 51))  # fmt: skip
    tr.to_csv(tmp_path / "trajectory.csv")
    m = read_motion(tmp_path / "trajectory.csv")
    np.testing.assert_allclose(m.Q, tr.Q, atol=1e-15)
    assert grade_free(m.t, m.omega, MOMENTS, m.Q).summary()["max_omega_error"] < 1e-9


def test_the_cli_prints_a_grade_a_table_and_writes_a_report(tmp_path, capsys):
    t = np.linspace(0.0, 10.0, 201)
    w, Q = _exact(t)
    _write_csv(tmp_path / "exact.csv", t, w, Q)
    _write_csv(tmp_path / "noisy.csv", t, w + 1e-4, Q)
    opts = ["--inertia", "1", "2", "3", "--gyro", "wx", "wy", "wz", "--attitude", "qw", "qx",
            "qy", "qz"]  # fmt: skip
    assert main(["grade", str(tmp_path / "noisy.csv"), *opts, "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "family        around e3 (every sample)" in out and "polhode" in out
    assert {p.name for p in (tmp_path / "o").iterdir()} >= {
        "report.html",
        "grade.json",
        "errors.png",
        "polhode.png",
    }
    saved = json.loads((tmp_path / "o" / "grade.json").read_text())
    assert saved["grade"]["units"]["max_omega_error"] == "rad/s"
    assert main(["grade", str(tmp_path / "exact.csv"), str(tmp_path / "noisy.csv"), *opts]) == 0
    rows = capsys.readouterr().out.strip().splitlines()
    assert rows[3].startswith("exact.csv") and rows[4].startswith("noisy.csv")
    assert main(["grade", str(tmp_path / "exact.csv"), *opts, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[str(tmp_path / "exact.csv")]["family_kept"]


@pytest.mark.parametrize(("args", "words"), [
    (["--inertia", "1", "2", "3", "--top", "1", "1", "1"], "exactly one of --inertia"),
    (["--inertia", "1", "2"], "three principal moments"),
    (["--inertia", "1", "1", "5"], "inertia"),
    (["--top", "0.3", "0.05", "4.9"], "needs its attitude"),
])  # fmt: skip
def test_the_cli_refuses_bad_input_by_name(tmp_path, capsys, args, words):
    t = np.linspace(0.0, 1.0, 11)
    np.savez(tmp_path / "a.npz", t=t, omega=_exact(t)[0])
    assert main(["grade", str(tmp_path / "a.npz"), *args]) == 2
    assert words in capsys.readouterr().err


def test_a_file_without_omega_is_refused(tmp_path, capsys):
    np.savez(tmp_path / "a.npz", t=np.arange(3.0))
    assert main(["grade", str(tmp_path / "a.npz"), "--inertia", "1", "2", "3"]) == 2
    assert "no array `omega`" in capsys.readouterr().err


def test_the_mujoco_recipe_prints_the_pages_table(tmp_path, monkeypatch, capsys):
    """docs/grade.md: the recipe's files, graded by the page's command, give the page's table:
    the same files, families and flips, and each error within a factor 2 of the page's (MuJoCo
    versions and BLAS round differently at the round-off end)."""
    pytest.importorskip("mujoco")
    page = (ROOT / "docs" / "grade.md").read_text(encoding="utf-8")
    recipe = re.findall(r"<!-- needs: mujoco -->\n```python\n(.*?)```", page, re.S)[0]
    command = re.findall(r"```bash\n(poinsot grade mujoco.*?)\n```", page, re.S)[0]
    shown = re.findall(r"```text\n(\d+ free body trajectories.*?)\n```", page, re.S)[0]
    monkeypatch.chdir(tmp_path)
    exec(compile(recipe, "docs/grade.md", "exec"), {"__name__": "__main__"})
    files = sorted(str(p.name) for p in tmp_path.glob("*.csv"))
    options = [a for a in command.split()[2:] if "*" not in a]  # the globs are the files
    assert main(["grade", *files, *options]) == 0
    printed = capsys.readouterr().out.strip().splitlines()
    want = shown.strip().splitlines()
    assert printed[:3] == want[:3]
    for got, expected in zip(printed[3:], want[3:], strict=True):
        g, e = got.split(), expected.split()
        assert g[0] == e[0] and g[-2:] == e[-2:]
        for a, b in zip(g[1:-2], e[1:-2], strict=True):
            x, y = float(a), float(b)
            assert y / 2 <= x <= 2 * y or max(x, y) < 1e-13, (got, expected)
