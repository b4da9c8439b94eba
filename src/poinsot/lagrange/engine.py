"""The compiled engine of a Lagrangian system: its expressions as machine code in the core.

:func:`compile_system` lowers, once per system, the model's own expressions — the mass matrix
``M``, the forcing ``f``, the constraint Jacobian ``G``, its right-hand side ``b``, the
velocity-product terms ``γ``, the holonomic residuals ``g`` and the energy ``h``, all sharing
one set of common subexpressions (``sympy.cse``) — to one postfix program of
``[q, q̇, t, p, u]`` (:mod:`poinsot.expressions`), which the core compiles to machine code with
``symjit`` in milliseconds, without a C compiler (``poinsot._core.LagrangianModel``). The
parameters ``p`` and inputs ``u`` are runtime arguments, so a parameter sweep reuses the one
compiled model.

Nothing of the engine's mathematics is generated: the KKT system, Baumgarte's terms, the
projection, the multipliers and reactions are the core's (``crates/core/src/lagrange.rs``),
the same for every model. Only how the model's numbers are computed is generated.

A run with forward sensitivities needs the model's Jacobian too: :func:`compile_tangent`
lowers the same expressions and their derivatives along ``[q, q̇, p, u]`` (SymPy's ``diff``) to
one program sharing their subexpressions (``poinsot._core.LagrangianTangent``), once per model
and only when a run asks for it.

A model seen before is found by its hash: the program is kept on disk
(``$POINSOT_CACHE_DIR/lagrange``, default ``~/.cache/poinsot/lagrange``) and in the process,
so its equations are not derived again.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np

__all__ = ["CompiledSystem", "cache_dir", "compile_system", "compile_tangent"]

_ATTR = "_poinsot_compiled"
#: Models compiled in this process, by their hash.
_MODELS: dict[str, object] = {}
#: The version of the program's layout; a change makes old cache entries unused.
_LAYOUT = "core-1"


def cache_dir() -> Path:
    """Where the models' programs are kept."""
    root = os.environ.get("POINSOT_CACHE_DIR") or os.path.join(
        os.path.expanduser("~"), ".cache", "poinsot"
    )
    return Path(root) / "lagrange"


class CompiledSystem:
    """The compiled model of one system, with the order of its parameters and inputs.

    Attributes
    ----------
    model : poinsot._core.LagrangianModel
        The machine code of ``[M, f, G, b, γ, g, h]`` in ``[q, q̇, t, p, u]``.
    parameters : list of SymPy symbols, the order of the vector ``p``
    inputs : list of SymPy functions, the order of the vector ``u``
    key : str, the model's hash
    """

    def __init__(self, model, parameters, inputs, key):
        self.model = model
        self.parameters = list(parameters)
        self.inputs = list(inputs)
        self.key = key
        self.n, self.m, self.nh, self.np, self.nu = model.sizes

    def parameter_vector(self, params: dict) -> np.ndarray:
        """``p`` (k,) from ``{symbol: value}`` (every parameter of the system)."""
        missing = [str(s) for s in self.parameters if s not in params]
        if missing:
            raise ValueError(
                f"`params` must give a number for every parameter: missing {', '.join(missing)}"
            )
        return np.array([float(params[s]) for s in self.parameters])

    def samples(self, t, y, p, u, active=None) -> dict:
        """Accelerations ``qdd``, physical multipliers ``lam`` (NaN for a constraint not in
        ``active``), generalized constraint forces ``constraint_forces`` (``Gᵀλ``), residuals
        ``g`` and ``velocity_residual`` (``Gq̇ + b``) and the Jacobi integral ``energy`` at
        samples ``t`` (S,), ``y`` (S, 2n), inputs ``u`` (S, j): one call into the core."""
        t = _floats(t)
        y = _floats(y).reshape(len(t), 2 * self.n)
        u = _floats(u).reshape(len(t), self.nu)
        act = None if active is None else np.ascontiguousarray(active, dtype=bool)
        qdd, lam, forces, g, vel, h = self.model.samples(t, y, _floats(p), u, act)
        return {"qdd": qdd, "lam": lam, "constraint_forces": forces, "g": g,
                "velocity_residual": vel, "energy": h}  # fmt: skip


def _floats(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def _program(system, tangent=False):
    """The postfix program of ``[M, f, G, b, γ, g, h]`` in ``[q, q̇, t, p, u]``; with
    ``tangent``, followed by the Jacobian of ``[M, f, G, b, γ, g]`` along ``[q, q̇, p, u]``
    (row-major: one row per output)."""
    import sympy as sp

    from ..expressions import lower

    names = system.plain
    m = system.n_constraints
    blocks = [
        list(system.mass_matrix),
        list(system.forcing),
        list(system.constraint_jacobian) if m else [],
        list(system.constraint_rhs) if m else [],
        list(system.constraint_gamma) if m else [],
        list(system.holonomic),
        [system.energy_function],
    ]
    exprs = [sp.sympify(names.of(e)) for block in blocks for e in block]
    if tangent:
        along = [*names.q, *names.v, *system.parameters, *names.u]
        exprs += [e.diff(x) for e in exprs[:-1] for x in along]
    inputs = [*names.q, *names.v, system.t, *system.parameters, *names.u]
    codes, values = lower(exprs, inputs)
    return codes, values


def _model_key(system) -> str:
    """A hash of everything the program depends on: the model as given (coordinates,
    Lagrangian, constraints, generalized forces, parameters, inputs, by ``srepr``), this
    module's code and SymPy's version. It finds a model's program without deriving its
    equations again."""
    import sympy as sp

    digest = hashlib.sha256(Path(__file__).read_bytes())
    digest.update(f"{_LAYOUT} {sp.__version__}".encode())
    model = (system.coordinates, system.lagrangian, system.holonomic, system.nonholonomic,
             list(system.generalized_forces), system.parameters, system.inputs)  # fmt: skip
    digest.update(sp.srepr(model).encode())
    return digest.hexdigest()[:24]


class _no_cyclic_gc:
    """Python's cycle collector paused while SymPy derives and lowers a model: the
    derivation makes millions of short-lived, acyclic objects (freed by their reference
    counts), and each of the collector's passes would walk every object alive in the process
    (a large model, or another library's expressions, can double the derivation's time)."""

    def __enter__(self):
        import gc

        self.was = gc.isenabled()
        gc.disable()

    def __exit__(self, *exc):
        import gc

        if self.was:
            gc.enable()
        return False


def _load(path: Path, sizes):
    try:
        with np.load(path, allow_pickle=False) as data:
            if tuple(int(x) for x in data["sizes"]) != sizes:
                return None
            return np.asarray(data["codes"], np.int64), np.asarray(data["values"], float)
    except (OSError, ValueError, KeyError):
        return None  # absent, unreadable or from another layout: derive again


def _save(path: Path, codes, values, sizes) -> None:
    """Write atomically: a concurrent process reads a whole file or none."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        with open(tmp, "wb") as fh:
            np.savez(fh, codes=codes, values=values, sizes=np.array(sizes))
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only or full cache only costs the next process a derivation


def _compiled(key, sizes, derive, make):
    """The core's object of the program ``key``: from this process, from the disk, or derived
    (``derive()``) and kept in both; ``make(codes, values)`` builds it."""
    out = _MODELS.get(key)
    if out is None:
        path = cache_dir() / f"model_{key}.npz"
        program = _load(path, sizes)
        if program is None:
            with _no_cyclic_gc():
                program = derive()
            _save(path, *program, sizes)
        out = make(*program)
        _MODELS[key] = out
    return out


def compile_tangent(system):
    """The model of ``system`` with its Jacobian along ``[q, q̇, p, u]``, compiled
    (``poinsot._core.LagrangianTangent``): derived once per model (this process, and the
    program on disk in :func:`cache_dir`), when a run first asks for sensitivities."""
    from .._bindings import lagrange as core_lagrange

    sizes = _sizes(system)
    return _compiled(_model_key(system) + "-tangent", sizes,
                     lambda: _program(system, tangent=True),
                     lambda codes, values: core_lagrange.LagrangianTangent(codes, values,
                                                                           *sizes))  # fmt: skip


def _sizes(system) -> tuple:
    return (system.n_coordinates, system.n_constraints, system.n_holonomic,
            len(system.parameters), len(system.inputs))  # fmt: skip


def compile_system(system) -> CompiledSystem:
    """The :class:`CompiledSystem` of ``system``: compiled once per system object (kept on it)
    and per model (this process, and the program on disk in :func:`cache_dir`)."""
    done = system.__dict__.get(_ATTR)
    if done is not None:
        return done
    from .._bindings import lagrange as core_lagrange

    key = _model_key(system)
    sizes = _sizes(system)
    model = _compiled(key, sizes, lambda: _program(system),
                      lambda codes, values: core_lagrange.LagrangianModel(codes, values,
                                                                          *sizes))  # fmt: skip
    out = CompiledSystem(model, system.parameters, system.inputs, key)
    system.__dict__[_ATTR] = out
    return out
