"""Every optional extra, absent: what needs it is refused before any work, in one line naming the
extra and the pip command, with exit code 2, no traceback and no files; what only prefers it
(the interactive report) does without it and says so.

Each case runs in a fresh process whose ``sys.modules`` hides the extra's package
(``sys.modules[name] = None`` makes ``import name`` fail, as on a bare install), so the exit
code, standard error and the files left are the user's.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

HIDE = """
import sys
for name in {names!r}:
    sys.modules[name] = None
"""


def _run(tmp_path, hidden, code):
    """Run ``code`` in a fresh Python with the packages ``hidden`` missing; the process."""
    script = textwrap.dedent(HIDE.format(names=list(hidden))) + textwrap.dedent(code)
    return subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)  # fmt: skip


def _cli(tmp_path, hidden, *args):
    return _run(
        tmp_path,
        hidden,
        f"""
        from poinsot.app.cli import main
        sys.exit(main({list(args)!r}))
    """,
    )


def _one_clean_line(proc, *words):
    err = proc.stderr.strip()
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err and "Error:" not in err.split(":", 1)[0]
    for word in words:
        assert word in err, (word, err)


def _files(folder):
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


PLOTLY = ("plotly", "plotly.graph_objects", "plotly.io")


@pytest.mark.parametrize("command", [
    ("run", "--example", "heavy-top", "--plotly-js", "cdn", "--out", "o"),
    ("run", "--example", "notebook", "--plotly-js", "shared"),
    ("polhodes", "--moments", "1", "2", "3", "--plotly-js", "inline", "--out", "o"),
])  # fmt: skip
def test_report_extra_asked_for_without_plotly_is_refused_up_front(tmp_path, command):
    proc = _cli(tmp_path, PLOTLY, *command)
    _one_clean_line(proc, "--plotly-js", "pip install 'poinsot[report]'")
    assert _files(tmp_path) == []


def test_run_without_plotly_writes_a_static_report_and_says_so(tmp_path):
    proc = _cli(tmp_path, PLOTLY, "run", "--example", "heavy-top", "--out", "o")
    assert proc.returncode == 0, proc.stderr
    notes = proc.stderr.strip().splitlines()
    assert len(notes) == 1 and "static" in notes[0] and "poinsot[report]" in notes[0]
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert "Plotly.newPlot" not in page and "<script src" not in page  # no plotly figure
    assert "data:image/png;base64," in page  # the matplotlib figures, embedded
    assert "<h2>Numbers</h2>" in page and "kg·m²" in page  # the numbers, with units
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert "static" in summary["report"]
    for name in ("omega.png", "attitude.png", "trajectory.npz", "trajectory.nc"):
        assert (tmp_path / "o" / name).exists(), name


def test_lagrangian_run_without_plotly_writes_a_static_report(tmp_path):
    proc = _cli(tmp_path, PLOTLY, "run", "--example", "atwood", "--out", "o", "--quiet")
    assert proc.returncode == 0, proc.stderr
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert page.count("data:image/png;base64,") == 2 and "<h2>Numbers</h2>" in page


def test_polhodes_without_plotly_lists_what_it_wrote(tmp_path):
    proc = _cli(tmp_path, PLOTLY, "polhodes", "--moments", "1", "2", "3", "--omega0", "0.1",
                "1", "0.1", "--out", "o")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    wrote = [line for line in proc.stdout.splitlines() if "wrote" in line]
    assert wrote and "energy_ellipsoid.png" in wrote[0] and "report.html" in wrote[0]
    assert _files(tmp_path / "o") == [".poinsot-manifest.json", "energy_ellipsoid.png",
                                      "polhodes.json", "polhodes.png", "report.html"]  # fmt: skip


MESH = (
    "solid t\n"
    + "".join(
        f"facet normal 0 0 0\nouter loop\n{a}\n{b}\n{c}\nendloop\nendfacet\n"
        for a, b, c in [
            ("vertex 0 0 0", "vertex 0 1 0", "vertex 1 0 0"),
            ("vertex 0 0 0", "vertex 1 0 0", "vertex 0 0 1"),
            ("vertex 0 0 0", "vertex 0 0 1", "vertex 0 1 0"),
            ("vertex 1 0 0", "vertex 0 1 0", "vertex 0 0 1"),
        ]
    )
    + "endsolid t\n"
)


def test_mesh_extra_missing_inertia(tmp_path):
    (tmp_path / "t.stl").write_text(MESH)
    proc = _cli(tmp_path, ("trimesh",), "inertia", "t.stl", "--density", "1000")
    _one_clean_line(proc, "trimesh", "pip install 'poinsot[mesh]'")
    assert _files(tmp_path) == ["t.stl"]


def test_mesh_extra_missing_scenario(tmp_path):
    (tmp_path / "t.stl").write_text(MESH)
    (tmp_path / "s.toml").write_text(
        textwrap.dedent("""
        name = "mesh"
        [body]
        type = "mesh"
        path = "t.stl"
        density = 1000
        [initial]
        omega = [0, 1, 1]
        [time]
        span = [0, 1]
    """)
    )
    proc = _cli(tmp_path, ("trimesh",), "run", "s.toml")
    _one_clean_line(proc, "trimesh", "pip install 'poinsot[mesh]'")
    assert _files(tmp_path) == ["s.toml", "t.stl"]


def test_xarray_extra_missing(tmp_path):
    """The command line does not need xarray (NetCDF is written with SciPy); the API's
    ``to_xarray`` names the extra."""
    proc = _cli(tmp_path, ("xarray",), "run", "--out", "o", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "o" / "trajectory.nc").exists()
    proc = _run(
        tmp_path,
        ("xarray",),
        """
        import poinsot as po
        traj = po.simulate(po.RigidBody.box(1, (1, 2, 3)), (0, 1), omega0=(0, 1, 1))
        try:
            traj.to_xarray()
        except ImportError as exc:
            print(exc)
    """,
    )
    assert proc.returncode == 0 and "pip install 'poinsot[xarray]'" in proc.stdout


def test_distributed_extra_missing(tmp_path):
    proc = _run(
        tmp_path,
        ("distributed", "dask", "dask.distributed"),
        """
        import poinsot as po
        from poinsot.ensemble import simulate_ensemble
        try:
            simulate_ensemble(po.RigidBody.box(1, (1, 2, 3)), (0, 1), omega0=[[0, 1, 1]], dt=0.01,
                              client=object())
        except ValueError as exc:
            print(exc)
    """,
    )
    assert proc.returncode == 0 and "pip install 'poinsot[distributed]'" in proc.stdout


def test_progress_extra_missing(tmp_path):
    """``progress=True`` asks for tqdm's bar: refused without it; the default stays silent."""
    proc = _run(
        tmp_path,
        ("tqdm", "tqdm.auto"),
        """
        import poinsot as po
        from poinsot.ensemble import simulate_ensemble
        body = po.RigidBody.box(1, (1, 2, 3))
        res = simulate_ensemble(body, (0, 1), omega0=[[0, 1, 1]] * 4, dt=0.01)
        print("default", len(res.omega))
        try:
            simulate_ensemble(body, (0, 1), omega0=[[0, 1, 1]] * 4, dt=0.01, progress=True)
        except ValueError as exc:
            print(exc)
    """,
    )
    assert proc.returncode == 0, proc.stderr
    assert "default 4" in proc.stdout and "pip install 'poinsot[progress]'" in proc.stdout
