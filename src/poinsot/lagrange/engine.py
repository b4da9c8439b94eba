"""A compiled engine for a Lagrangian system: one generated, numba-compiled module.

:func:`compile_system` writes, once per system, a Python module whose functions numba
compiles and caches on disk:

* ``evaluate(q, qd, t, p, u, M, f, G, b, gamma, g) → h``: the mass matrix ``M``, the forcing
  ``f``, the constraint Jacobian ``G``, its rhs ``b``, the velocity-product terms ``γ``, the
  holonomic residuals ``g`` and the energy ``h``, every expression sharing one set of common
  subexpressions (``sympy.cse``). The parameters ``p`` and the inputs ``u`` are runtime
  arguments, so a parameter sweep reuses the one compiled function.
* ``rhs(t, y, p, u, alpha, beta, out)``: ``ẏ = [q̇, q̈]`` from the index-1 system
  ``[[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; −γ − 2α(Gq̇ + b) − β² g]`` (Baumgarte's terms with
  ``alpha``, ``beta``; zero for none), G evaluated once, solved without Python.
* ``accelerations(t, q, qd, p, u) → (q̈, λ)``: the physical multipliers (no stabilisation).

It is the same mathematics as the NumPy path of :mod:`poinsot.lagrange.numeric` (tested to
agree), generated from the same SymPy matrices of :class:`~poinsot.lagrange.LagrangianSystem`:
only how the numbers are computed changes. The first call of a new system compiles it (a few
seconds); later calls, in this process or the next, load it from the cache folder
(``$POINSOT_CACHE_DIR/lagrange``, default ``~/.cache/poinsot/lagrange``).
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from pathlib import Path

import numpy as np

__all__ = ["CompiledSystem", "cache_dir", "compile_system"]

_ATTR = "_poinsot_compiled"


def cache_dir() -> Path:
    """Where the generated modules (and numba's cache of them) are kept."""
    root = os.environ.get("POINSOT_CACHE_DIR") or os.path.join(
        os.path.expanduser("~"), ".cache", "poinsot"
    )
    return Path(root) / "lagrange"


class CompiledSystem:
    """The compiled functions of one system, with the order of its parameters and inputs.

    Attributes
    ----------
    module : the generated module (``evaluate``, ``rhs``, ``accelerations``)
    parameters : list of SymPy symbols, the order of the vector ``p``
    inputs : list of SymPy functions, the order of the vector ``u``
    path : pathlib.Path of the generated source
    """

    def __init__(self, module, parameters, inputs, path):
        self.module = module
        self.parameters = list(parameters)
        self.inputs = list(inputs)
        self.path = path

    def parameter_vector(self, params: dict) -> np.ndarray:
        """``p`` (k,) from ``{symbol: value}`` (every parameter of the system)."""
        missing = [str(s) for s in self.parameters if s not in params]
        if missing:
            raise ValueError(
                f"`params` must give a number for every parameter: missing {', '.join(missing)}"
            )
        return np.array([float(params[s]) for s in self.parameters])

    def native_system(self, p, u, gains=(0.0, 0.0), projection=False):
        """The :data:`~poinsot.kernels.systems.NativeSystem` the compiled drivers step: this
        module's entry points by address, the parameters ``p`` (k,), the inputs ``u`` (j,)
        (constants), the Baumgarte ``gains`` (α, β) and, with ``projection``, the projection
        onto the constraints after every step."""
        from ..kernels.systems import NativeSystem

        m = self.module
        return NativeSystem(m.rhs_c.address, m.project_c.address if projection else 0,
                            _floats(p), _floats(u), _floats(gains))  # fmt: skip

    def native_lanes(self, P, U, gains=(0.0, 0.0), projection=False):
        """The ensemble template (:data:`~poinsot.kernels.systems.NativeLanes`) of members
        with the parameters ``P`` (m, k) and the inputs ``U`` (m, j)."""
        from ..kernels.systems import NativeLanes

        m = self.module
        return NativeLanes(m.rhs_c.address, m.project_c.address if projection else 0,
                           _floats(P), _floats(U), _floats(gains))  # fmt: skip

    def samples(self, t, y, p, u) -> dict:
        """Accelerations ``qdd``, physical multipliers ``lam``, generalized constraint forces
        ``constraint_forces`` (``Gᵀλ``), residuals ``g`` and ``velocity_residual`` (``Gq̇ + b``)
        and the Jacobi integral ``energy`` at samples ``t`` (S,), ``y`` (S, 2n), inputs ``u``
        (S, j): one compiled loop."""
        mod = self.module
        S, n, m, nh = len(t), mod.N, mod.MC, mod.NH
        out = {"qdd": np.empty((S, n)), "lam": np.empty((S, m)),
               "constraint_forces": np.empty((S, n)), "g": np.empty((S, nh)),
               "velocity_residual": np.empty((S, m)), "energy": np.empty(S)}  # fmt: skip
        mod.samples(_floats(t), _floats(y), _floats(p), _floats(u), *out.values())
        return out


def _floats(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def _source(system) -> str:
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter

    from ..kernels.jit import kernel_layer_stamp

    n, m, nh = system.n_coordinates, system.n_constraints, system.n_holonomic
    params, inputs = system.parameters, system.inputs
    to_p = dict(zip(params, sp.symbols(f"p0:{len(params)}"), strict=True))

    def plain(e):
        return system.plain.of(e).xreplace(to_p)

    blocks = [
        ("M", [(i, j) for i in range(n) for j in range(n)], list(system.mass_matrix)),
        ("f", [(i,) for i in range(n)], list(system.forcing)),
        ("G", [(i, j) for i in range(m) for j in range(n)],
         list(system.constraint_jacobian) if m else []),
        ("b", [(i,) for i in range(m)], list(system.constraint_rhs) if m else []),
        ("gamma", [(i,) for i in range(m)], list(system.constraint_gamma) if m else []),
        ("g", [(i,) for i in range(nh)], list(system.holonomic)),
    ]  # fmt: skip
    exprs = [plain(e) for _, _, es in blocks for e in es] + [plain(system.energy_function)]
    shared, reduced = sp.cse(exprs)
    pr = PythonCodePrinter({"fully_qualified_modules": True})
    lines = [
        '"""Generated by poinsot.lagrange.engine: do not edit (regenerated when stale)."""',
        # the kernel layer's hash: numba does not see that this module's cache depends on
        # the kernels it calls, so a change to them makes a new module (a new file name)
        f"# kernel layer {kernel_layer_stamp()[:16]}",
        "import math",
        "",
        "import numpy as np",
        "from numba import carray, cfunc, njit, types",
        "",
        "from poinsot.kernels.linalg import solve_augmented, solve_spd_augmented",
        "",
        f"N, MC, NH, NP, NU = {n}, {m}, {nh}, {len(params)}, {len(inputs)}",
        "D = N + MC",
        "",
        "",
        "@njit(cache=True)",
        "def evaluate(q, qd, t, p, u, M, f, G, b, gamma, g):",
    ]
    lines += [f"    q{i} = q[{i}]" for i in range(n)] + [f"    v{i} = qd[{i}]" for i in range(n)]
    lines += [f"    p{i} = p[{i}]" for i in range(len(params))]
    lines += [f"    u{i} = u[{i}]" for i in range(len(inputs))]
    lines += [f"    {symbol} = {pr.doprint(e)}" for symbol, e in shared]
    k = 0
    for name, places, es in blocks:
        for place in places[: len(es)]:
            index = ", ".join(map(str, place))
            lines.append(f"    {name}[{index}] = {pr.doprint(reduced[k])}")
            k += 1
    lines.append(f"    return {pr.doprint(reduced[k])}")
    lines += [
        "",
        "",
        "@njit(cache=True)",
        "def _parts(q, qd, t, p, u):",
        "    M = np.empty((N, N))",
        "    f = np.empty(N)",
        "    G = np.empty((MC, N))",
        "    b = np.empty(MC)",
        "    gamma = np.empty(MC)",
        "    g = np.empty(NH)",
        "    h = evaluate(q, qd, t, p, u, M, f, G, b, gamma, g)",
        "    return M, f, G, b, gamma, g, h",
        "",
        "",
        "@njit(cache=True)",
        "def _kkt(q, qd, t, p, u, alpha, beta):",
        "    # [[M, -G^T], [G, 0]] [qdd; lam] = [f; -gamma - 2 alpha (G qd + b) - beta^2 g]",
        "    # filled in one augmented matrix K (D, D + 1) and solved in place: the solution is",
        "    # K[:, D]; False when the system is singular",
        "    K = np.zeros((D, D + 1))",
        "    e = np.empty(2 * MC + NH)",
        "    b = e[:MC]",
        "    gamma = e[MC:2 * MC]",
        "    g = e[2 * MC:]",
        "    evaluate(q, qd, t, p, u, K[:N, :N], K[:N, D], K[N:, :N], b, gamma, g)",
        "    for i in range(MC):",
        "        vel = b[i]",
        "        for j in range(N):",
        "            vel += K[N + i, j] * qd[j]",
        "            K[j, N + i] = -K[N + i, j]",
        "        r = -gamma[i] - 2.0 * alpha * vel",
        "        if i < NH:",
        "            r -= beta * beta * g[i]",
        "        K[N + i, D] = r",
        "    if MC == 0:  # M alone: symmetric positive definite, Cholesky (LU if it is not)",
        "        if solve_spd_augmented(K, D):",
        "            return True, K",
        "        evaluate(q, qd, t, p, u, K[:N, :N], K[:N, D], K[N:, :N], b, gamma, g)",
        "    return solve_augmented(K, D), K",
        "",
        "",
        "@njit(cache=True)",
        "def rhs(t, y, p, u, alpha, beta, out):",
        "    q = y[:N]",
        "    qd = y[N:]",
        "    ok, K = _kkt(q, qd, t, p, u, alpha, beta)",
        "    for j in range(N):",
        "        out[j] = qd[j]",
        "        out[N + j] = K[j, D] if ok else np.nan  # NaN: the driver names it",
        "",
        "",
        "@njit(cache=True)",
        "def accelerations(t, q, qd, p, u):",
        "    # (qdd, lam) with the physical multipliers (no stabilisation)",
        "    ok, K = _kkt(q, qd, t, p, u, 0.0, 0.0)",
        "    x = K[:, D].copy() if ok else np.full(D, np.nan)",
        "    return x[:N], x[N:]",
        "",
        "",
        "@njit(cache=True)",
        "def project(t, y, p, u):",
        "    # the nearest consistent state: Gauss-Newton on g(q) = 0 (minimum-norm corrections),",
        "    # then qd <- qd - pinv(G) (G qd + b); as _Numeric.project of the NumPy path",
        "    if MC == 0:",
        "        return 0",
        "    q = y[:N]",
        "    qd = y[N:]",
        "    for _ in range(20 if NH else 0):",
        "        M, f, G, b, gamma, g, h = _parts(q, qd, t, p, u)",
        "        if np.max(np.abs(g)) <= 1e-13 * (1.0 + np.max(np.abs(q))):",
        "            break",
        "        q -= np.linalg.lstsq(G[:NH], g)[0]",
        "    M, f, G, b, gamma, g, h = _parts(q, qd, t, p, u)",
        "    qd -= np.linalg.lstsq(G, G @ qd + b)[0]",
        "    return 1",
        "",
        "",
        "@njit(cache=True)",
        "def samples(T, Y, p, U, qdd, lam, cf, res, vres, energy):",
        "    # every sample's accelerations, physical multipliers, generalized constraint forces,",
        "    # residuals and energy, in one compiled loop",
        "    for i in range(T.shape[0]):",
        "        q = Y[i, :N]",
        "        qd = Y[i, N:]",
        "        M, f, G, b, gamma, g, h = _parts(q, qd, T[i], p, U[i])",
        "        a, lm = accelerations(T[i], q, qd, p, U[i])",
        "        qdd[i] = a",
        "        lam[i] = lm",
        "        if MC:",
        "            cf[i] = G.T @ lm",
        "            vres[i] = G @ qd + b",
        "        else:",
        "            cf[i] = 0.0",
        "        res[i] = g",
        "        energy[i] = h",
        "",
        "",
        "@njit(cache=True)",
        "def starts(t, Z, P, U, pos, vel, solvable):",
        "    # every ensemble member's constraint residuals at its initial state, and whether",
        "    # its equations can be solved there",
        "    for i in range(Z.shape[0]):",
        "        q = Z[i, :N]",
        "        qd = Z[i, N:]",
        "        M, f, G, b, gamma, g, h = _parts(q, qd, t, P[i], U[i])",
        "        pos[i] = np.max(np.abs(g)) if NH else 0.0",
        "        vel[i] = np.max(np.abs(G @ qd + b)) if MC else 0.0",
        "        a, lm = accelerations(t, q, qd, P[i], U[i])",
        "        solvable[i] = np.all(np.isfinite(a))",
        "",
        "",
        "_F8 = types.float64",
        "_P8 = types.CPointer(types.float64)",
        "",
        "",
        "@cfunc(types.void(_F8, _P8, _P8, _P8, _F8, _F8, _P8), cache=True)",
        "def rhs_c(t, y, p, u, alpha, beta, out):",
        "    rhs(t, carray(y, (2 * N,)), carray(p, (NP,)), carray(u, (NU,)), alpha, beta,",
        "        carray(out, (2 * N,)))",
        "",
        "",
        "@cfunc(types.int64(_F8, _P8, _P8, _P8), cache=True)",
        "def project_c(t, y, p, u):",
        "    return project(t, carray(y, (2 * N,)), carray(p, (NP,)), carray(u, (NU,)))",
        "",
    ]
    return "\n".join(lines)


def _model_key(system) -> str:
    """A hash of everything the generated source depends on: the model as given (coordinates,
    Lagrangian, constraints, generalized forces, parameters, inputs, by ``srepr``), this
    module's own code, the kernel layer and SymPy's version. It finds a model's generated
    module without deriving its equations again."""
    import sympy as sp

    from ..kernels.jit import kernel_layer_stamp

    digest = hashlib.sha256(Path(__file__).read_bytes())
    digest.update(f"{kernel_layer_stamp()} {sp.__version__}".encode())
    model = (system.coordinates, system.lagrangian, system.holonomic, system.nonholonomic,
             list(system.generalized_forces), system.parameters, system.inputs)  # fmt: skip
    digest.update(sp.srepr(model).encode())
    return digest.hexdigest()[:20]


def _write_atomically(path: Path, text: str) -> None:
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)  # atomic: a concurrent process reads a whole file or none


def compile_system(system) -> CompiledSystem:
    """The :class:`CompiledSystem` of ``system``: generated once per system object (kept on
    it) and once per machine (the cache folder). A model seen before is found by
    :func:`_model_key` — its equations are then not derived again — and its module by the
    hash of its source."""
    done = system.__dict__.get(_ATTR)
    if done is not None:
        return done
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    index = folder / f"model_{_model_key(system)}.txt"
    key = index.read_text(encoding="utf-8").strip() if index.exists() else ""
    path = folder / f"lagrange_{key}.py"
    if not key or not path.exists():
        source = _source(system)
        key = hashlib.sha256(source.encode()).hexdigest()[:20]
        path = folder / f"lagrange_{key}.py"
        if not path.exists() or path.read_text(encoding="utf-8") != source:
            _write_atomically(path, source)
        _write_atomically(index, key)
    name = f"poinsot_lagrange_{key}"
    module = sys.modules.get(name)
    if module is None:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        # registered before it runs: numba's disk cache finds its functions' module by name
        sys.modules[name] = module
        spec.loader.exec_module(module)
    out = CompiledSystem(module, system.parameters, system.inputs, path)
    system.__dict__[_ATTR] = out
    return out
