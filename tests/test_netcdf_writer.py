"""The NetCDF-3 writer (``poinsot._io.write_netcdf``) streams each variable to the file instead
of holding a second copy of them all (issue 44: an ensemble's memory was its results, twice,
while it wrote them). Its files are checked by two readers it does not share code with:
SciPy's ``netcdf_file`` and, where installed, xarray."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.io import netcdf_file

from poinsot._io import write_netcdf

DTYPES = ["float64", "float32", "int64", "int32", "int16", "int8", "uint8", "uint32", "bool", "str"]


def values(dtype, shape, rng):
    if dtype == "str":
        words = np.array(["", "a", "ω₀", "flip", "long name", "trailing "])
        return words[rng.integers(0, len(words), shape)]
    if dtype == "bool":
        return rng.integers(0, 2, shape).astype(bool)
    if "int" in dtype:  # within 32 bits (NetCDF-3's widest integer)
        info = np.iinfo(dtype if dtype not in ("int64", "uint32") else "int32")
        info = np.iinfo("uint16") if dtype == "uint32" else info
        return rng.integers(info.min, info.max, shape, endpoint=True).astype(dtype)
    return rng.normal(0, 1e3, shape).astype(dtype)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    dtypes=st.lists(st.sampled_from(DTYPES), min_size=1, max_size=5),
    n=st.integers(1, 7),
    k=st.integers(1, 3),
    seed=st.integers(0, 2**32 - 1),
    attr=st.one_of(st.floats(allow_nan=False, allow_infinity=False), st.integers(-2**31, 2**31 - 1),
                   st.text(max_size=8)),
)  # fmt: skip
def test_scipy_reads_back_what_was_written(tmp_path, dtypes, n, k, seed, attr):
    rng = np.random.default_rng(seed)
    variables = {"member": (("member",), np.arange(n, dtype=float), {"units": "1"})}
    for i, dtype in enumerate(dtypes):
        dims = ("member", "component") if i % 2 else ("member",)
        shape = (n, k) if i % 2 else (n,)
        variables[f"v{i}"] = (dims, values(dtype, shape, rng), {"long_name": f"v {i}", "x": attr})
    path = tmp_path / "x.nc"
    if isinstance(attr, str) and "\0" in attr:
        # NetCDF-3 pads text with NULs, and readers strip them: refused, naming the attribute
        with pytest.raises(ValueError, match="is text holding a NUL character"):
            write_netcdf(path, variables, {"method": "rk4", "number": attr})
        assert not path.exists()
        return
    write_netcdf(path, variables, {"method": "rk4", "number": attr})
    with netcdf_file(path, mmap=False) as f:
        assert f.dimensions["member"] == n
        got = f.method, f.number
        assert got[0] == b"rk4"
        for name, (_, data, attrs) in variables.items():
            v = f.variables[name]
            read = v[:]
            if data.dtype.kind == "U":
                # NUL-padded, as NetCDF-3 pads text: the labels come back exactly
                read = np.array([b"".join(row).decode() for row in
                                 read.reshape(-1, read.shape[-1])]).reshape(data.shape)  # fmt: skip
                assert np.array_equal(read, data)
            else:
                assert np.array_equal(read, data.astype(read.dtype))
            assert name == "member" or v.long_name == attrs["long_name"].encode()
    if isinstance(attr, str):
        assert got[1] == attr.encode()
    else:
        assert got[1] == attr  # integers as int32, other numbers as double: exact


def test_xarray_reads_back_what_was_written(tmp_path):
    xr = pytest.importorskip("xarray")
    rng = np.random.default_rng(1)
    n = 10_000
    omega = rng.normal(size=(n, 3))
    status = np.ones(n, dtype=np.int64)
    path = tmp_path / "e.nc"
    write_netcdf(path, {"omega0": (("member", "component"), omega, {"units": "rad/s"}),
                        "status": (("member",), status, {"long_name": "1: finished"}),
                        "name": (("member",), np.array(["a"] * n), {})},
                 {"method": "rk4"})  # fmt: skip
    with xr.open_dataset(path) as ds:
        np.testing.assert_array_equal(ds["omega0"].values, omega)
        assert ds["omega0"].attrs["units"] == "rad/s" and ds.attrs["method"] == "rk4"
        np.testing.assert_array_equal(ds["status"].values, status)
        assert (ds["name"].values == "a").all()


def test_labels_come_back_exactly_and_select_by_name(tmp_path):
    """Text was padded with spaces, which readers keep: ``'omega0[0] '`` read back, and
    ``.sel(parameter="omega0[0]")`` on the file raised KeyError where it worked in memory.
    NetCDF-3 pads with NULs, which readers strip; a NUL inside a label is refused."""
    xr = pytest.importorskip("xarray")
    labels = np.array(["omega0[0]", "inertia[10]", "q0[y1]", "a b "])
    path = tmp_path / "l.nc"
    write_netcdf(path, {"parameter": (("parameter",), labels, {}),
                        "x": (("parameter",), np.arange(4.0), {})})  # fmt: skip
    with xr.open_dataset(path) as ds:
        assert ds["parameter"].values.tolist() == labels.tolist()
        assert float(ds["x"].sel(parameter="inertia[10]")) == 1.0
    with pytest.raises(ValueError, match=r"`parameter`: the text b'a\\x00b' holds a NUL"):
        write_netcdf(tmp_path / "n.nc", {"parameter": (("parameter",), np.array(["a\0b"]), {})})
    assert not (tmp_path / "n.nc").exists()


def test_integers_beyond_32_bits_and_a_second_empty_dimension_are_refused(tmp_path):
    with pytest.raises(ValueError, match="`n`: integers beyond 32 bits"):
        write_netcdf(tmp_path / "a.nc", {"n": (("m",), np.array([2**40]), {})})
    with pytest.raises(ValueError, match="an empty dimension only as the first one"):
        write_netcdf(tmp_path / "b.nc", {"y": (("m", "t"), np.zeros((2, 0)), {})})
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_a_variable_is_written_a_few_megabytes_at_a_time(tmp_path, monkeypatch):
    """Rows are converted and written in pieces: a big variable takes several writes, and the
    file is the same whatever their size."""
    import poinsot._io as io

    a = np.arange(300_000, dtype=float).reshape(100_000, 3)
    write_netcdf(tmp_path / "big.nc", {"a": (("m", "c"), a, {})})
    monkeypatch.setattr(io, "_NC_WRITE_BYTES", 1000)
    write_netcdf(tmp_path / "small.nc", {"a": (("m", "c"), a, {})})
    assert (tmp_path / "big.nc").read_bytes() == (tmp_path / "small.nc").read_bytes()
    with netcdf_file(tmp_path / "small.nc", mmap=False) as f:
        np.testing.assert_array_equal(f.variables["a"][:], a)
