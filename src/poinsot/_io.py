"""Writing files and folders so that nothing is lost and nothing is left half-written.

* :func:`atomic_path` / :func:`atomic_write_text`: one file, through a temporary file in the
  target folder and ``os.replace``. An interrupted write leaves the old file or the new one.
* :class:`OutputFolder`: a whole output folder. The files are written into a hidden
  ``.NAME.partial-*`` folder beside the target and moved into place only when complete. A
  manifest (``.poinsot-manifest.json``) lists what poinsot wrote; ``force`` replaces only a
  folder that carries one, and in a folder that also holds the user's files it replaces only
  poinsot's. Everything is checked before the work starts: a path that is not a folder, a
  folder that is not writable, a disk without room, a folder that poinsot did not write.
* Outputs follow the user's umask (``tempfile`` alone would leave 0600 files in 0700 folders).
* :func:`critical`: the moves that complete an output (and the removal of an unfinished one)
  are not cut in half by a signal: SIGINT, SIGTERM and SIGALRM that arrive meanwhile are held
  and delivered when the moves are done. :func:`emergency_cleanup` removes what this process
  is writing, for a program that must end at once (``poinsot.app.interrupts``).
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import signal
import socket
import tempfile
import threading
import time
import warnings
from pathlib import Path

__all__ = [
    "MANIFEST",
    "OutputError",
    "OutputExistsError",
    "OutputFolder",
    "PoinsotWarning",
    "atomic_path",
    "atomic_savez",
    "atomic_write_text",
    "read_toml",
    "safe_name",
    "write_netcdf",
    "xarray_dataset",
]

#: The file that marks a folder as poinsot's output and lists what poinsot wrote in it.
MANIFEST = ".poinsot-manifest.json"
#: The file inside a ``.partial-*`` folder naming the process that writes it.
PARTIAL_MARKER = ".poinsot-partial"
#: Longest name a scenario contributes to a path.
MAX_NAME = 100


class PoinsotWarning(UserWarning):
    """Something the user should know that did not stop the run (``--quiet`` hides it)."""


class OutputError(ValueError):
    """An output path poinsot will not or cannot write to; the message says why."""


class OutputExistsError(OutputError, FileExistsError):
    """The output folder exists and ``force`` was not given."""


#: The signals :func:`critical` holds back.
HELD_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGALRM") if hasattr(signal, name)
)
#: What this process is writing now: unfinished output folders and temporary files, and the
#: folders it created for them (removed by :func:`emergency_cleanup`).
_WRITING: dict[Path, str] = {}
_critical_depth = 0


def in_critical() -> bool:
    """Whether a :func:`critical` block is running (an output being moved into place)."""
    return _critical_depth > 0


@contextlib.contextmanager
def critical():
    """Hold back SIGINT, SIGTERM and SIGALRM for the block, then deliver the first that came
    (to whatever handler was installed): the block is never cut in half by them. Elsewhere
    than in the main thread (where Python runs signal handlers) it only marks the block."""
    global _critical_depth
    held: list[int] = []
    previous = {}
    if threading.current_thread() is threading.main_thread():

        def hold(signum, frame):
            held.append(signum)

        for sig in HELD_SIGNALS:
            previous[sig] = signal.signal(sig, hold)
    _critical_depth += 1
    try:
        yield
    finally:
        _critical_depth -= 1
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if held:
            signal.raise_signal(held[0])


def emergency_cleanup() -> None:
    """Remove what this process is writing (unfinished output folders and temporary files,
    then the folders created for them, if empty): for a program about to end without
    unwinding (``os._exit``). Safe to call from any thread; errors are ignored."""
    for path, kind in list(_WRITING.items()):
        if kind == "created":
            continue
        for _ in range(3):  # a file may appear while the tree is removed
            if kind == "folder":
                shutil.rmtree(path, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    os.unlink(path)
            if not os.path.lexists(path):
                break
    created = [p for p, kind in _WRITING.items() if kind == "created"]
    for path in sorted(created, key=lambda p: len(p.parts), reverse=True):
        with contextlib.suppress(OSError):
            os.rmdir(path)


def _make_parents(folder: Path) -> list[Path]:
    """``folder.mkdir(parents=True, exist_ok=True)``; returns the folders it created,
    outermost first."""
    missing = []
    for p in (folder, *folder.parents):
        if os.path.lexists(p):
            break
        missing.append(p)
    folder.mkdir(parents=True, exist_ok=True)
    return missing[::-1]


def _remove_created(created: list[Path]) -> None:
    """Remove the folders :func:`_make_parents` created, innermost first, if still empty."""
    for p in reversed(created):
        with contextlib.suppress(OSError):
            os.rmdir(p)
        _WRITING.pop(p, None)


def _umask() -> int:
    mask = os.umask(0o022)  # read it: os.umask has no getter
    os.umask(mask)
    return mask


def _follow_umask(path: Path, folder: bool = False) -> None:
    os.chmod(path, (0o777 if folder else 0o666) & ~_umask())


def safe_name(name: str, fallback: str = "scenario") -> str:
    """``name`` as one safe path component: letters, digits, ``._-`` and ``+``; anything else
    becomes ``-``; no leading dot or dash, at most :data:`MAX_NAME` characters; ``fallback``
    when nothing is left (``""``, ``".."``, ``"/"``).

    Examples
    --------
    >>> safe_name("../../home/me/victim"), safe_name(""), safe_name("Tennis racket (1)")
    ('home-me-victim', 'scenario', 'Tennis-racket-1')
    """
    text = re.sub(r"[^A-Za-z0-9._+-]+", "-", str(name))
    text = text.strip(".-")[:MAX_NAME].strip(".-")
    return text or fallback


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically."""
    path = Path(path)
    created = _make_parents(path.parent)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.name}.", suffix=suffix or path.suffix or ".tmp", dir=path.parent
    )
    os.close(fd)
    _WRITING[Path(tmp)] = "file"
    try:
        yield Path(tmp)
        _follow_umask(Path(tmp))
        with critical():
            os.replace(tmp, path)
            _WRITING.pop(Path(tmp), None)
    except BaseException:
        with critical():
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            _WRITING.pop(Path(tmp), None)
            _remove_created(created)
        raise


def atomic_savez(path, **arrays) -> None:
    """Write ``arrays`` to a compressed ``.npz`` file at ``path`` atomically.

    NumPy's writer cut short by a signal leaves a ``ZipFile`` behind whose destructor fails
    later (``Exception ignored in: … ValueError: seek of closed file`` on stderr), so the
    archive is written in :func:`critical`: a signal lands before or after it, and the
    temporary file goes with the unwinding."""
    import numpy as np

    with atomic_path(path, suffix=".npz") as tmp, critical():
        np.savez_compressed(tmp, **arrays)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def xarray_dataset(variables: dict, attrs: dict):
    """An ``xarray.Dataset`` of ``name → (dims, values, attrs)`` (the variables a NetCDF export
    writes), those named like a dimension as its coordinates; needs the ``xarray`` extra."""
    try:
        import xarray as xr
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("to_xarray needs xarray: pip install 'poinsot[xarray]'") from exc
    coords = {n: v for n, v in variables.items() if v[0] == (n,)}
    data = {n: v for n, v in variables.items() if n not in coords}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def write_netcdf(path, variables: dict, attrs: dict | None = None) -> None:
    """Write a NetCDF-3 file (64-bit offsets) atomically, in every install (no xarray needed;
    xarray, netCDF4, ncdump and SciPy read it), streaming each variable to the file a few
    megabytes at a time: the memory it takes is that of the arrays given, not a second copy
    of the whole file (SciPy's writer holds every variable until it closes).

    ``variables``: ``name → (dims, data, attrs)``; a variable named like its dimension is that
    dimension's coordinate. NetCDF-3 has no 64-bit integers: int64 is written as int32 (refused
    if it does not fit), bool as int8, strings as characters along a ``NAME_strlen`` dimension,
    padded with NULs as NetCDF-3 pads text (xarray reads them back as the same strings; text
    holding a NUL is refused). Attribute values are numbers (integers as int32,
    others as double) or strings (UTF-8).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from scipy.io import netcdf_file
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "x.nc"
    >>> write_netcdf(path, {"time": (("time",), np.arange(3.0), {"units": "s"}),
    ...                     "E": (("time",), np.ones(3), {"units": "J"})}, {"method": "rk4"})
    >>> with netcdf_file(path, mmap=False) as f:
    ...     f.variables["E"].units, f.method, f.variables["time"][:].tolist()
    (b'J', b'rk4', [0.0, 1.0, 2.0])
    """
    import numpy as np

    sizes: dict[str, int] = {}
    prepared = []
    for name, (dims, data, var_attrs) in variables.items():
        a = np.asarray(data)
        dims = tuple(dims)
        if a.dtype.kind in "US":  # strings: UTF-8 bytes along a dimension of the longest
            raw = [x if isinstance(x, bytes) else str(x).encode() for x in a.ravel()]
            if any(b"\0" in r for r in raw):
                # NetCDF-3 pads text with NULs and readers strip them: refused, not altered
                bad = next(r for r in raw if b"\0" in r)
                raise ValueError(f"`{name}`: the text {bad!r} holds a NUL character, which "
                                 "NetCDF-3 cannot keep")  # fmt: skip
            width = max(1, max(map(len, raw), default=1))
            # padded with NULs, as NetCDF-3 pads text: readers strip them, and only them
            a = np.frombuffer(b"".join(r.ljust(width, b"\0") for r in raw) or b"\0",
                              dtype="S1")[: len(raw) * width].reshape(*a.shape, width)  # fmt: skip
            dims = (*dims, f"{name}_strlen")
            var_attrs = {**(var_attrs or {}), "_Encoding": "utf-8"}  # read back as str
        if a.dtype == bool:
            target = np.dtype(">i1")
        elif a.dtype.kind == "u" and a.dtype.itemsize < 4:  # no unsigned types: widened
            target = np.dtype(f">i{2 * a.dtype.itemsize}")
        elif a.dtype.kind in "iu" and a.dtype.itemsize >= 4 + (a.dtype.kind == "i"):
            if a.size and (a.max() > np.iinfo(np.int32).max or a.min() < np.iinfo(np.int32).min):
                raise ValueError(f"`{name}`: integers beyond 32 bits cannot go into NetCDF-3")
            target = np.dtype(">i4")
        elif a.dtype.kind == "f":
            target = np.dtype(">f8")
        elif a.dtype.kind == "S":
            target = np.dtype("S1")
        elif a.dtype.kind == "i":
            target = np.dtype(f">i{a.dtype.itemsize}")
        else:
            raise ValueError(f"`{name}`: NetCDF-3 cannot hold values of type {a.dtype}")
        if a.ndim != len(dims):
            raise ValueError(f"`{name}`: {a.ndim} axes but dimensions {dims}")
        for d, n in zip(dims, a.shape, strict=True):
            if sizes.setdefault(d, n) != n:
                raise ValueError(f"dimension `{d}` has sizes {sizes[d]} and {n}")
        prepared.append((name, dims, a, target, var_attrs or {}))
    empty = [d for d, n in sizes.items() if n == 0]  # NetCDF-3's record dimension, 0 records
    for name, dims, *_ in prepared:
        if len(empty) > 1 or any(d in empty for d in dims[1:]):
            raise ValueError(f"`{name}`: NetCDF-3 holds an empty dimension only as the first "
                             f"one, and one at most (empty: {', '.join(empty)})")  # fmt: skip
    _write_cdf2(path, sizes, prepared, attrs or {})


#: NetCDF-3's type codes (the classic format specification, "nc_type").
_NC_TYPES = {("S", 1): 2, ("i", 1): 1, ("i", 2): 3, ("i", 4): 4, ("f", 4): 5, ("f", 8): 6}
#: Bytes a variable is written in at most, per write (its rows are converted that many at once).
_NC_WRITE_BYTES = 1 << 22


def _write_cdf2(path, sizes, prepared, attrs) -> None:
    """The file of the NetCDF classic format with 64-bit offsets ("CDF-2"): the header (the
    dimensions, global attributes and variables with their offsets), then each variable's
    values, big-endian, padded to 4 bytes, written rows at a time."""
    import struct

    import numpy as np

    def name_bytes(s: str) -> bytes:
        raw = s.encode("utf-8")
        return struct.pack(">i", len(raw)) + raw + b"\0" * (-len(raw) % 4)

    def attributes(items: dict) -> bytes:
        if not items:
            return b"\0" * 8  # ABSENT
        out = [struct.pack(">ii", 12, len(items))]  # NC_ATTRIBUTE
        for key, value in items.items():
            if isinstance(value, str) and "\0" in value:
                # NetCDF-3 pads text with NULs and readers strip them: refused, not altered
                raise ValueError(f"the NetCDF attribute {key!r} is text holding a NUL character "
                                 f"({value!r}), which NetCDF-3 cannot keep")  # fmt: skip
            value = _attribute(value)
            if isinstance(value, bytes):
                kind, raw, count = 2, value, len(value)
            else:
                v = np.atleast_1d(np.asarray(value))
                integral = v.dtype.kind in "iub" and np.all(np.abs(v) < 2**31)
                v = v.astype(">i4" if integral else ">f8")
                kind, raw, count = (4 if integral else 6), v.tobytes(), v.size
            out.append(name_bytes(key) + struct.pack(">ii", kind, count) + raw
                       + b"\0" * (-len(raw) % 4))  # fmt: skip
        return b"".join(out)

    dim_ids = {d: i for i, d in enumerate(sizes)}
    head = [b"CDF\x02", struct.pack(">i", 0)]  # 64-bit offsets; no records
    if sizes:
        head.append(struct.pack(">ii", 10, len(sizes)))  # NC_DIMENSION
        head += [name_bytes(d) + struct.pack(">i", n) for d, n in sizes.items()]
    else:
        head.append(b"\0" * 8)
    head.append(attributes(attrs))
    entries, lengths = [], []
    for name, dims, a, target, var_attrs in prepared:
        nbytes = a.size * target.itemsize
        lengths.append(nbytes + (-nbytes % 4))
        if dims and sizes[dims[0]] == 0:  # a record variable (no records): one record's size
            record = int(np.prod(a.shape[1:], dtype=np.int64)) * target.itemsize
            vsize = record + (-record % 4)
        else:
            vsize = lengths[-1]
        entries.append(name_bytes(name) + struct.pack(">i", len(dims))
                       + b"".join(struct.pack(">i", dim_ids[d]) for d in dims)
                       + attributes(var_attrs)
                       + struct.pack(">iI", _NC_TYPES[target.kind, target.itemsize],
                                     min(vsize, 2**32 - 1)))  # fmt: skip
    var_list = struct.pack(">ii", 11, len(entries)) if entries else b"\0" * 8
    size = sum(map(len, head)) + len(var_list) + sum(len(e) + 8 for e in entries)
    begins = size + np.concatenate([[0], np.cumsum(lengths[:-1])]).astype(np.int64)
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        f.write(b"".join(head) + var_list)
        for entry, begin in zip(entries, begins, strict=True):
            f.write(entry + struct.pack(">q", int(begin)))
        for (_, _, a, target, _), length in zip(prepared, lengths, strict=True):
            if not a.size:
                continue
            rows = a.reshape(len(a) if a.ndim else 1, -1)
            step = max(1, _NC_WRITE_BYTES // max(1, rows.shape[1] * target.itemsize))
            for i in range(0, len(rows), step):
                f.write(np.ascontiguousarray(rows[i : i + step], dtype=target).tobytes())
            f.write(b"\0" * (length - a.size * target.itemsize))


def _read_manifest(folder: Path) -> dict | None:
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get("files"), list):
        return None
    data["files"] = [f for f in data["files"] if isinstance(f, str) and f == Path(f).name]
    return data


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    return True


def _existing_ancestor(path: Path) -> Path:
    for p in (path, *path.parents):
        if p.exists() or p.is_symlink():
            return p
    return Path(path.anchor or ".")


class OutputFolder:
    """The folder ``out`` that a command writes, checked now, written atomically later.

    Parameters
    ----------
    out : path
    force : bool
        Replace an existing output folder, which must be poinsot's (it has a manifest) or empty.
    command : str
        What writes it (recorded in the manifest).
    needs_bytes : int
        A rough size of the output, checked against the free space of the disk.

    Raises
    ------
    OutputExistsError
        ``out`` exists and ``force`` is false.
    OutputError
        ``out`` is not a folder, is a folder poinsot did not write, holds the current
        folder, is not writable or the disk has no room.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "run"
    >>> folder = OutputFolder(target, command="doctest")
    >>> with folder.writing() as work:
    ...     _ = (work / "a.txt").write_text("hello")
    >>> sorted(p.name for p in target.iterdir())
    ['.poinsot-manifest.json', 'a.txt']
    """

    def __init__(self, out, *, force: bool = False, command: str = "run", needs_bytes: int = 0):
        self.out = Path(out)
        self.force = bool(force)
        self.command = command
        self.needs_bytes = int(needs_bytes)
        self.in_place = False  # replace poinsot's files one by one instead of the whole folder
        self.check()

    # ----------------------------------------------------------------- checks before the work
    def check(self) -> None:
        """Everything that can be checked before the work starts (see the class)."""
        out = self.out
        if out.is_symlink() and not out.exists():
            raise OutputError(f"{out}: a broken symbolic link, not a folder")
        if out.exists():
            if not out.is_dir():
                raise OutputError(f"{out}: exists and is not a folder")
            if not self.force:
                raise OutputExistsError(f"{out}: output folder exists (use --force to replace it)")
            resolved, cwd = out.resolve(), Path.cwd().resolve()
            entries = [p.name for p in out.iterdir()]
            manifest = _read_manifest(out)
            if manifest is None and entries:
                raise OutputError(
                    f"{out}: not a folder that poinsot wrote (it has no {MANIFEST}), so --force "
                    "will not replace it; choose a new --out folder or empty this one yourself"
                )
            ours = set(manifest["files"]) | {MANIFEST} if manifest else set()
            self.in_place = (
                out.is_symlink()
                or resolved == cwd
                or resolved in cwd.parents
                or not set(entries) <= ours
                or not entries
            )
        parent = _existing_ancestor(out.parent if not out.exists() else out)
        if not parent.is_dir():
            raise OutputError(f"{out}: cannot create it: {parent} is not a folder")
        if not os.access(parent, os.W_OK | os.X_OK):
            raise OutputError(f"{out}: cannot write: {parent} is read-only or not yours")
        if self.needs_bytes:
            free = shutil.disk_usage(parent).free
            if free < self.needs_bytes:
                raise OutputError(
                    f"{out}: not enough disk space: the output needs about "
                    f"{self.needs_bytes / 1e6:.3g} MB and {free / 1e6:.3g} MB are free"
                )
        self.clean_stale()

    def clean_stale(self) -> list[Path]:
        """Remove the ``.*.partial-*`` folders that killed runs left beside ``out`` (a process
        of this machine that no longer exists), and warn about those that cannot be judged.
        Returns the removed paths."""
        parent = self.out.parent
        removed = []
        if not parent.is_dir():
            return removed
        host = socket.gethostname()
        for p in parent.glob(".*.partial-*"):
            if not p.is_dir() or p.is_symlink():
                continue
            try:
                pid_text, _, where = (p / PARTIAL_MARKER).read_text().partition("@")
                pid = int(pid_text)
            except (OSError, ValueError):
                warnings.warn(
                    f"{p}: an unfinished output folder, not poinsot's to remove; left alone",
                    PoinsotWarning,
                    stacklevel=2,
                )
                continue
            if where.strip() != host or _alive(pid):
                continue  # a run in progress, or on another machine
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
            warnings.warn(
                f"removed {p}: the unfinished output of an interrupted run (process {pid})",
                PoinsotWarning,
                stacklevel=2,
            )
        return removed

    # ----------------------------------------------------------------- the work
    @contextlib.contextmanager
    def writing(self):
        """Yield a fresh hidden folder to write into; on success its files become ``out``'s.
        On any exception (``KeyboardInterrupt`` included) it is removed and ``out`` is as
        it was."""
        out = self.out
        created = _make_parents(out.parent)
        _WRITING.update(dict.fromkeys(created, "created"))
        work = Path(
            tempfile.mkdtemp(prefix=f".{safe_name(out.name, 'out')}.partial-", dir=out.parent)
        )
        _WRITING[work] = "folder"
        try:
            _follow_umask(work, folder=True)
            (work / PARTIAL_MARKER).write_text(f"{os.getpid()}@{socket.gethostname()}")
            yield work
            (work / PARTIAL_MARKER).unlink()
            files = sorted(p.name for p in work.iterdir())
            manifest = {
                "written_by": "poinsot",
                "version": _version(),
                "command": self.command,
                "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                "files": files,
            }
            atomic_write_text(work / MANIFEST, json.dumps(manifest, indent=2))
            with critical():  # the folder appears whole, or not at all
                self._commit(work, files)
                _WRITING.pop(work, None)
                for p in created:
                    _WRITING.pop(p, None)
        except BaseException:
            with critical():
                shutil.rmtree(work, ignore_errors=True)
                _WRITING.pop(work, None)
                _remove_created(created)
            raise

    def _commit(self, work: Path, files: list[str]) -> None:
        out = self.out
        if not out.exists():
            work.rename(out)
            return
        if not self.force:  # it appeared while we worked
            raise OutputExistsError(f"{out}: output folder appeared meanwhile (use --force)")
        old = _read_manifest(out)
        if old is None and any(out.iterdir()):
            raise OutputError(f"{out}: not a folder that poinsot wrote; left as it was")
        ours = set(old["files"]) if old else set()
        if not self.in_place:
            aside = out.with_name(f".{safe_name(out.name, 'out')}.old-{time.time_ns()}")
            out.rename(aside)
            work.rename(out)
            shutil.rmtree(aside, ignore_errors=True)
            return
        clash = [f for f in files if (out / f).exists() and f not in ours and f != MANIFEST]
        if clash:
            raise OutputError(
                f"{out}: {clash[0]} exists and poinsot did not write it; nothing was replaced"
            )
        for f in sorted(ours - set(files)):
            with contextlib.suppress(FileNotFoundError, IsADirectoryError):
                (out / f).unlink()
        for f in files:
            if f != MANIFEST:
                os.replace(work / f, out / f)
        os.replace(work / MANIFEST, out / MANIFEST)  # last: the folder is complete
        shutil.rmtree(work, ignore_errors=True)


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("poinsot")
    except Exception:  # pragma: no cover - an uninstalled checkout
        return "unknown"


def is_disk_full(exc: BaseException) -> bool:
    """Whether ``exc`` is the operating system's "no space left" (or quota) error."""
    return isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT)


def _attribute(value):
    """A NetCDF-3 attribute: strings as UTF-8 bytes (SciPy's writer takes only ASCII text)."""
    return value.encode("utf-8") if isinstance(value, str) else value


class TOMLError(ValueError):
    """A TOML text that does not parse: the message names the file, the line and the column
    (``file:line:column: ...``, as compilers write it, so that editors can jump there)."""


def read_toml(text: str, label: str) -> dict:
    """The tables of the TOML ``text`` read from ``label`` (a file's name, for messages), or a
    :class:`TOMLError` naming ``label``, the line and the column of a syntax error (the end of
    the file included) or of the point where arrays and tables nest too deeply.

    >>> read_toml('a = 1', 'f.toml')
    {'a': 1}
    >>> read_toml('a = 1\\nb = [1, 2', 'f.toml')
    Traceback (most recent call last):
    ...
    poinsot._io.TOMLError: f.toml:2:10: TOML syntax error: Unclosed array (at the end of the file)
    """
    import re
    import tomllib

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = str(exc)
        at = re.search(r"\(at line (\d+), column (\d+)\)$", message)
        if at:
            line, column = int(at.group(1)), int(at.group(2))
            message = message[: at.start()].rstrip()
        else:  # "(at end of document)": the last line's end
            lines = text.split("\n")
            line, column = len(lines), len(lines[-1]) + 1
            message = message.replace("(at end of document)", "(at the end of the file)")
        raise TOMLError(f"{label}:{line}:{column}: TOML syntax error: {message}") from None
    except RecursionError:
        line, column = _deepest(text)
        raise TOMLError(f"{label}:{line}:{column}: arrays or tables are nested too deeply "
                        "(the parser's recursion limit)") from None  # fmt: skip


def _deepest(text: str) -> tuple[int, int]:
    """The line and column where the brackets and braces of ``text`` first nest deepest
    (strings and comments are not told apart: a message's pointer, not a parser)."""
    depth = best = 0
    where = (1, 1)
    line, column = 1, 0
    for ch in text:
        column += 1
        if ch == "\n":
            line, column = line + 1, 0
        elif ch in "[{":
            depth += 1
            if depth > best:
                best, where = depth, (line, column)
        elif ch in "]}":
            depth -= 1
    return where
