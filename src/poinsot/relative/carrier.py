"""The carrier frame: a frame that turns (and whose origin accelerates) in a prescribed way
(``docs/relative.md``).

A :class:`Carrier` turns the user's description of the carrier's motion into what the engine
reads: the 9 numbers ``(ω_e, ε_e, a_O)`` (carrier components) at any time. It holds no formula
of the dynamics; the kinematics of a frame given by its Euler angles (paper eq. (14)) or its
attitude (``Ω_e = Q_cᵀ Q̇_c``) are derived exactly with SymPy.

How the engine evaluates it:

* constants and splines (SciPy ``PPoly`` and its subclasses ``CubicSpline``,
  ``Akima1DInterpolator``, ``PchipInterpolator``, or a ``BSpline``) become piecewise
  polynomials: data for the cached compiled engine, ``ε_e`` the exact derivative of the spline;
* SymPy expressions (or text parsed by SymPy) become machine code at run time, in a few
  milliseconds and without a C compiler (:mod:`poinsot.expressions`; ``ε_e`` by exact
  differentiation first); a carrier seen before in the process is not compiled again;
* Python callables are called back from the core at every
  evaluation: the slow path. A callable ω_e needs its ``epsilon_e`` too: poinsot does not
  differentiate a black box.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from .._validation import as_rotation_matrix, as_times, as_vector3

__all__ = ["Carrier"]


def _sympy():
    import sympy

    return sympy


def _is_sympy(value) -> bool:
    mod = type(value).__module__ or ""
    return mod.startswith("sympy")


def _is_spline(value) -> bool:
    # scipy.interpolate is imported only for a value from it (its import costs most of a
    # second of a cold start); a spline's class, or a class it derives from, lives there
    if not any(c.__module__.startswith("scipy.interpolate") for c in type(value).__mro__):
        return False
    from scipy.interpolate import BSpline, PPoly

    return isinstance(value, PPoly | BSpline)


def _has_sympy(value) -> bool:
    if isinstance(value, str) or _is_sympy(value):
        return True
    if isinstance(value, list | tuple):
        return any(_has_sympy(v) for v in value)
    return False


def _classify(value, name):
    """'constant', 'sympy', 'spline', 'compiled' or 'python' for one ω_e/ε_e/a_O argument."""
    if value is None:
        return None
    if _is_spline(value):
        return "spline"
    if callable(value) and not _is_sympy(value):
        return "python"
    if _has_sympy(value):
        return "sympy"
    if isinstance(value, numbers.Number | np.ndarray | list | tuple):
        return "constant"
    raise TypeError(
        f"`{name}` must be a 3-vector, SymPy expressions in t, a spline or a callable of t, "
        f"found {type(value).__name__}"
    )


def _parse_text(text, where, t):
    """A SymPy expression in the time ``t`` from text: numbers, ``t``, arithmetic and the
    functions of :data:`poinsot.expressions.TEXT_FUNCTIONS`, read from its syntax tree
    (:func:`poinsot.expressions.parse`; never evaluated as Python)."""
    from ..expressions import parse

    return parse(text, {"t": t}, f"`{where}`")


def _sympy_vector(value, name, t, size=3):
    """A list of ``size`` SymPy expressions in the time symbol ``t`` (text is parsed)."""
    sp = _sympy()
    if isinstance(value, str) or (_is_sympy(value) and not hasattr(value, "shape")):
        items = [value] if size == 1 else None
        if items is None:
            raise ValueError(f"`{name}` must have {size} components, found one expression")
    else:
        items = list(sp.Matrix(value)) if _is_sympy(value) else list(value)
    if len(items) != size:
        raise ValueError(f"`{name}` must have {size} components, found {len(items)}")
    out = []
    for i, item in enumerate(items):
        where = f"{name}[{i}]" if size > 1 else name
        if isinstance(item, str):
            expr = _parse_text(item, where, t)
        else:
            try:
                expr = sp.sympify(item)
            except (sp.SympifyError, SyntaxError, TypeError) as exc:
                raise ValueError(f"`{where}` is not a SymPy expression: {item!r}") from exc
        if not isinstance(expr, sp.Expr):
            raise ValueError(f"`{where}` must be a scalar expression, found {expr!r}")
        extra = expr.free_symbols - {t}
        if extra:
            names = ", ".join(sorted(str(s) for s in extra))
            raise ValueError(f"`{where}` may depend on the time {t} only; it also contains {names}")
        out.append(expr)
    return out


def _time_symbol(values, t):
    """The time symbol: ``t`` if given, else the one free symbol of the expressions (named t
    for text)."""
    sp = _sympy()
    if t is not None:
        if not isinstance(t, sp.Symbol):
            raise TypeError(f"`t` must be a SymPy Symbol, found {type(t).__name__}")
        return t
    found = set()
    for v in values:
        for item in v if isinstance(v, list | tuple) else [v]:
            if _is_sympy(item):
                found |= sp.sympify(item).free_symbols
    if len(found) > 1:
        names = ", ".join(sorted(str(s) for s in found))
        raise ValueError(f"the carrier's expressions contain several symbols ({names}): pass `t=`")
    return found.pop() if found else sp.Symbol("t", real=True)


def _constant_ppoly(v):
    """A constant 3-vector as one piece of degree 0: breaks (2,), coefficients (1, 1, 3)."""
    return np.array([0.0, 1.0]), np.asarray(v, dtype=float).reshape(1, 1, 3)


def _spline_ppoly(spline, name):
    """A SciPy spline of 3-vector values as ``(breaks, coeffs, domain)`` in ``PPoly`` layout,
    without empty pieces."""
    from scipy.interpolate import BSpline, PPoly

    if isinstance(spline, BSpline):
        c = np.asarray(spline.c)
        if c.ndim != 2 or c.shape[1] != 3:
            raise ValueError(
                f"`{name}` must be a spline of 3-vectors, found values of shape {c.shape[1:]}"
            )
        pieces = [PPoly.from_spline(BSpline(spline.t, c[:, j], spline.k)) for j in range(3)]
        x = pieces[0].x
        coeffs = np.stack([p.c for p in pieces], axis=-1)
    else:
        x = np.asarray(spline.x, dtype=float)
        coeffs = np.asarray(spline.c, dtype=float)
        if coeffs.ndim != 3 or coeffs.shape[2] != 3:
            raise ValueError(
                f"`{name}` must be a spline of 3-vectors, found values of shape {coeffs.shape[2:]}"
            )
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(coeffs))):
        raise ValueError(f"`{name}` must have finite breakpoints and coefficients")
    if x[-1] < x[0]:
        raise ValueError(f"`{name}` must have increasing breakpoints")
    keep = np.diff(x) > 0
    breaks = np.concatenate([x[:-1][keep], x[-1:]])
    return np.ascontiguousarray(breaks), np.ascontiguousarray(coeffs[:, keep, :]), (x[0], x[-1])


def zxz_matrix(psi, theta, phi):
    """``Rz(ψ) Rx(θ) Rz(φ)`` as a SymPy matrix (z-x-z Euler angles, as
    ``poinsot_core::so3::zxz_matrix``)."""
    sp = _sympy()
    c, s = sp.cos, sp.sin

    def Rz(a):
        return sp.Matrix([[c(a), -s(a), 0], [s(a), c(a), 0], [0, 0, 1]])

    def Rx(a):
        return sp.Matrix([[1, 0, 0], [0, c(a), -s(a)], [0, s(a), c(a)]])

    return Rz(psi) * Rx(theta) * Rz(phi)


def zxz_body_rates(psi, theta, phi, t):
    """The angular velocity on the rotating axes, ``(p, q, r)``, of z-x-z Euler angles given
    as SymPy functions of ``t`` (eqs. (13)–(14), as ``poinsot_core::so3::zxz_body_rates``):
    ``p = ψ̇ sin θ sin φ + θ̇ cos φ``, ``q = ψ̇ sin θ cos φ − θ̇ sin φ``, ``r = φ̇ + ψ̇ cos θ``."""
    sp = _sympy()
    dpsi, dtheta, dphi = (sp.diff(a, t) for a in (psi, theta, phi))
    return [
        dpsi * sp.sin(theta) * sp.sin(phi) + dtheta * sp.cos(phi),
        dpsi * sp.sin(theta) * sp.cos(phi) - dtheta * sp.sin(phi),
        dphi + dpsi * sp.cos(theta),
    ]


def _compile_motion(exprs, t):
    """The nine expressions ``(ω_e, ε_e, a_O)`` of t as one compiled function (machine code;
    cached by content, so equal carriers share it)."""
    from ..expressions import ExpressionError, compile_expressions

    try:
        return compile_expressions(exprs, [t])
    except ExpressionError as exc:
        raise ValueError(f"the carrier's expressions cannot be compiled: {exc}") from exc


class Carrier:
    """A carrier frame's prescribed motion: its angular velocity ``ω_e(t)`` and acceleration
    ``ε_e(t)`` in its own (carrier) components, and optionally its origin's acceleration.

    Give the rotation in exactly one way:

    Parameters
    ----------
    omega_e : array_like (3,), SymPy expressions, spline or callable, optional
        ω_e in carrier components: a constant vector (ε_e = 0); three SymPy expressions in t
        (or text such as ``"0.3*sin(t)"``; ε_e derived exactly); a SciPy spline of 3-vectors
        (ε_e its exact derivative); or a callable of t returning (3,), which needs
        ``epsilon_e``. A callable is called back from the compiled core (the slow path).
    epsilon_e : callable, optional
        ε_e = dω_e/dt (carrier components) for a callable ``omega_e``; refused otherwise
        (poinsot derives it exactly).
    euler_angles : three SymPy expressions in t, optional
        The carrier's z-x-z Euler angles ψ1(t), θ1(t), φ1(t) relative to the inertial frame:
        ω_e by eq. (14), ε_e by differentiation, and the carrier's attitude exactly.
    rotation : SymPy 3×3 matrix in t, optional
        The carrier's attitude Q_c(t) (carrier → inertial): ``Ω_e = Q_cᵀ Q̇_c``.
    quaternion : four SymPy expressions in t, optional
        The same as a unit quaternion (w, x, y, z).
    origin_acceleration : array_like (3,), SymPy expressions, spline or callable, optional
        The acceleration of the carrier's origin in carrier components (a vehicle speeding up
        along its own x axis); it adds the inertia force ``−M a_O`` at the centre of mass.
    t : sympy.Symbol, optional
        The time symbol of the expressions (found by itself when they contain one symbol).
    name : str, optional

    Examples
    --------
    A turntable spinning up about its own z axis at 0.5 rad/s²:

    >>> from poinsot.relative import Carrier
    >>> turntable = Carrier(omega_e=["0", "0", "0.5*t"])
    >>> turntable.motion(2.0).tolist()   # ω_e, ε_e, a_O
    [0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0]
    """

    def __init__(
        self,
        omega_e=None,
        epsilon_e=None,
        *,
        euler_angles=None,
        rotation=None,
        quaternion=None,
        origin_acceleration=None,
        t=None,
        name=None,
    ):
        given = [n for n, v in (("omega_e", omega_e), ("euler_angles", euler_angles),
                                ("rotation", rotation), ("quaternion", quaternion))
                 if v is not None]  # fmt: skip
        if len(given) != 1:
            raise ValueError(
                "give the carrier's rotation in exactly one way (`omega_e`, `euler_angles`, "
                f"`rotation` or `quaternion`), found {', '.join(given) or 'none'}"
            )
        self.name = str(name) if name is not None else "carrier"
        self.given = given[0]
        kind_w = _classify(omega_e, "omega_e") if omega_e is not None else "sympy"
        kind_e = _classify(epsilon_e, "epsilon_e")
        kind_a = _classify(origin_acceleration, "origin_acceleration")
        if epsilon_e is not None and kind_w != "python":
            raise ValueError(
                "`epsilon_e` is for a callable `omega_e` only: for a constant it is zero, and "
                "for SymPy expressions, Euler angles, attitudes and splines it is derived exactly"
            )
        if kind_w == "python" and epsilon_e is None:
            raise ValueError(
                "a callable `omega_e` needs `epsilon_e` (its time derivative, carrier "
                "components): poinsot cannot differentiate a black box exactly (or give SymPy "
                "expressions or a spline)"
            )
        if kind_e is not None and kind_e != "python":
            raise TypeError("`epsilon_e` must be a callable of t")
        self._attitude = None
        self.t_symbol = None
        sym = [v for v in (omega_e, euler_angles, rotation, quaternion, origin_acceleration)
               if v is not None and _classify(v, "carrier") == "sympy"]  # fmt: skip
        if self.given != "omega_e":
            if not _has_sympy(euler_angles if euler_angles is not None else
                              rotation if rotation is not None else quaternion):  # fmt: skip
                raise TypeError(
                    f"`{self.given}` must be SymPy expressions in t (or text), so that ω_e and "
                    "ε_e can be derived exactly"
                )
        self.domain = (-math.inf, math.inf)
        kinds = {kind_w, kind_a} - {None}
        if "python" in kinds or kind_e == "python":
            self.kind = "python"
        elif "sympy" in kinds:
            self.kind = "function"
            if "spline" in kinds:
                raise ValueError(
                    "combine a spline only with constants or other splines (give both "
                    "`omega_e` and `origin_acceleration` as SymPy expressions, or as splines)"
                )
        else:
            self.kind = "ppoly"
        if sym or self.given != "omega_e":
            self.t_symbol = _time_symbol(sym, t)
        self._polynomial = None
        if (
            self.kind == "function"
            and self.given == "omega_e"
            and kind_w == "sympy"
            and (kind_a in (None, "constant", "sympy"))
        ):
            self._polynomial = self._as_polynomials(omega_e, origin_acceleration, kind_a)
            if self._polynomial is not None:  # data for the cached engine, still exact
                self.kind = "ppoly"
        self._build(omega_e, epsilon_e, euler_angles, rotation, quaternion, origin_acceleration,
                    kind_w, kind_a)  # fmt: skip

    # ------------------------------------------------------------------ construction
    def _omega_expressions(self, omega_e, euler_angles, rotation, quaternion):
        """ω_e (carrier components) as SymPy expressions, and the exact attitude if known."""
        sp = _sympy()
        t = self.t_symbol
        if omega_e is not None:
            return _sympy_vector(omega_e, "omega_e", t), None
        if euler_angles is not None:
            psi, theta, phi = _sympy_vector(euler_angles, "euler_angles", t)
            # eq. (14): the carrier's angular velocity on its own axes
            return zxz_body_rates(psi, theta, phi, t), zxz_matrix(psi, theta, phi)
        if quaternion is not None:
            w, x, y, z = _sympy_vector(quaternion, "quaternion", t, 4)
            Q = sp.Matrix([
                [1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)],
            ])  # fmt: skip
        else:
            items = _sympy_vector(list(sp.Matrix(rotation)) if not isinstance(rotation, str)
                                  else rotation, "rotation", t, 9)  # fmt: skip
            Q = sp.Matrix(3, 3, items)
        W = Q.T * Q.diff(t)  # Ω_e = Q_cᵀ Q̇_c, skew for a rotation
        return [W[2, 1], W[0, 2], W[1, 0]], Q

    def _as_polynomials(self, omega_e, accel, kind_a):
        """ω_e and a_O as one polynomial piece each (exact, for the cached engine) when every
        expression is a polynomial in t; else None."""
        sp = _sympy()
        t = self.t_symbol
        w = _sympy_vector(omega_e, "omega_e", t)
        if accel is None:
            a = [sp.Integer(0)] * 3
        elif kind_a == "constant":
            a = [sp.Float(v) for v in as_vector3(accel, "origin_acceleration")]
        else:
            a = _sympy_vector(accel, "origin_acceleration", t)
        blocks = []
        for exprs in (w, a):
            try:
                polys = [sp.Poly(e, t) for e in exprs]
            except sp.PolynomialError:
                return None
            if any(not all(c.is_number for c in p.all_coeffs()) for p in polys):
                return None
            k = max(p.degree() for p in polys)
            c = np.zeros((max(k, 0) + 1, 1, 3))
            for j, p in enumerate(polys):
                coeffs = [float(x) for x in p.all_coeffs()]
                c[c.shape[0] - len(coeffs) :, 0, j] = coeffs
            blocks.append((np.array([0.0, 1.0]), c))
        self.expressions = {"omega_e": w, "epsilon_e": [sp.diff(e, t) for e in w],
                            "origin_acceleration": a}  # fmt: skip
        return blocks[0][0], blocks[0][1], blocks[1][0], blocks[1][1]

    def _build(self, omega_e, epsilon_e, euler_angles, rotation, quaternion, accel, kind_w,
               kind_a):  # fmt: skip
        sp = _sympy() if self.t_symbol is not None else None
        self._python = None
        if self.kind == "ppoly" and self._polynomial is not None:
            self.ppoly = self._polynomial
            return
        if self.kind == "ppoly":
            if kind_w == "spline":
                wb, wc, self.domain = _spline_ppoly(omega_e, "omega_e")
            else:
                wb, wc = _constant_ppoly(as_vector3(omega_e, "omega_e"))
            if kind_a == "spline":
                ab, ac, dom = _spline_ppoly(accel, "origin_acceleration")
                self.domain = (max(self.domain[0], dom[0]), min(self.domain[1], dom[1]))
            else:
                ab, ac = _constant_ppoly(np.zeros(3) if accel is None
                                         else as_vector3(accel, "origin_acceleration"))  # fmt: skip
            self.ppoly = (wb, wc, ab, ac)
            return
        if self.kind == "function" and self.t_symbol is not None:
            t = self.t_symbol
            omega, Q = self._omega_expressions(omega_e, euler_angles, rotation, quaternion)
            eps = [sp.diff(w, t) for w in omega]
            if accel is None:
                acc = [sp.Integer(0)] * 3
            elif kind_a == "constant":
                acc = [sp.Float(v) for v in as_vector3(accel, "origin_acceleration")]
            else:
                acc = _sympy_vector(accel, "origin_acceleration", t)
            self.expressions = {"omega_e": omega, "epsilon_e": eps, "origin_acceleration": acc}
            self.function = _compile_motion([*omega, *eps, *acc], t)
            if Q is not None:
                self._attitude = sp.lambdify(t, Q, modules="numpy")
            return
        # Python callables: every part as a Python function of t
        parts = []
        for value, kind, name in ((omega_e, kind_w, "omega_e"), (epsilon_e, "python", "epsilon_e"),
                                  (accel, kind_a, "origin_acceleration")):  # fmt: skip
            if value is None:
                parts.append(lambda t: np.zeros(3))
            elif kind == "constant":
                v = as_vector3(value, name)
                parts.append(lambda t, v=v: v)
            elif kind == "spline":
                parts.append(value)
            elif kind == "sympy":
                t = self.t_symbol
                exprs = _sympy_vector(value, name, t)
                parts.append(_sympy().lambdify(t, exprs, modules="numpy"))
            else:
                parts.append(value)
        self._python = tuple(parts)

    # ------------------------------------------------------------------ evaluation
    @property
    def compiled(self) -> bool:
        """True when the core evaluates the carrier without calling Python."""
        return self.kind != "python"

    @property
    def engine(self):
        """The carrier as the core's engine takes it: piecewise polynomials
        ``(w_breaks, w_coeffs, a_breaks, a_coeffs)``, compiled expressions, or (the slow
        path) the Python callable :meth:`motion_tuple`."""
        if self.kind == "ppoly":
            return self.ppoly
        if self.kind == "function":
            return self.function
        return self.motion_tuple

    @property
    def has_attitude(self) -> bool:
        """True when the carrier's attitude is known in closed form (Euler angles, rotation)."""
        return self._attitude is not None

    def attitude(self, t) -> np.ndarray:
        """The carrier's exact attitude Q_c(t) (carrier → inertial), for carriers given by Euler
        angles, a rotation or a quaternion; (3, 3), or (n, 3, 3) for times (n,)."""
        if self._attitude is None:
            raise ValueError(
                f"{self.name}: the attitude is known in closed form only for a carrier given by "
                "`euler_angles`, `rotation` or `quaternion`; see the trajectory's Q_carrier"
            )
        times = as_times(t, "t")
        out = np.array([np.array(self._attitude(float(s)), dtype=float) for s in times])
        return out.reshape(*np.shape(t), 3, 3) if np.ndim(t) == 0 else out.reshape(-1, 3, 3)

    def motion(self, t: float) -> np.ndarray:
        """``(ω_e, ε_e, a_O)`` (9,) at the time ``t``, carrier components."""
        return self.motions(np.array([float(t)]))[0]

    def motions(self, t) -> np.ndarray:
        """``(ω_e, ε_e, a_O)`` at the times ``t`` (n,) → (n, 9), carrier components."""
        from .._bindings import relative as core_relative

        t = np.ascontiguousarray(as_times(t, "t"))
        if self.kind != "python":
            return core_relative.carrier_motions(self.engine, t)
        out = np.empty((len(t), 9))
        for i, s in enumerate(t):
            out[i] = self.motion_tuple(float(s))
        return out

    def motion_tuple(self, t: float) -> tuple:
        """The 9-tuple of the engine at ``t`` (callables checked: shape (3,), finite)."""
        if self.kind != "python":
            return tuple(self.motions(float(t))[0].tolist())
        values = []
        for f, name in zip(self._python, ("omega_e", "epsilon_e", "origin_acceleration"),
                           strict=True):  # fmt: skip
            v = np.asarray(f(t), dtype=float)
            if v.shape != (3,):
                raise ValueError(f"`{name}`({t:g}) must return a 3-vector, found shape {v.shape}")
            values.extend(float(x) for x in v)
        return tuple(values)

    def omega_e(self, t) -> np.ndarray:
        """ω_e at the times ``t`` (carrier components), (n, 3)."""
        return self.motions(t)[:, 0:3]

    def epsilon_e(self, t) -> np.ndarray:
        """ε_e = dω_e/dt at the times ``t`` (carrier components), (n, 3)."""
        return self.motions(t)[:, 3:6]

    def origin_acceleration(self, t) -> np.ndarray:
        """The origin's acceleration at the times ``t`` (carrier components), (n, 3)."""
        return self.motions(t)[:, 6:9]

    def check(self, t0: float, t1: float):
        """Refuse a span outside a spline's domain, and a motion that is not finite at the
        start, naming the quantity."""
        lo, hi = self.domain
        if t0 < lo - 1e-12 * max(1.0, abs(lo)) or t1 > hi + 1e-12 * max(1.0, abs(hi)):
            raise ValueError(
                f"{self.name}: the time span [{t0:g}, {t1:g}] leaves the spline's domain "
                f"[{lo:g}, {hi:g}]"
            )
        m = np.asarray(self.motion_tuple(float(t0)), dtype=float)
        for k, name in enumerate(("omega_e", "epsilon_e", "origin_acceleration")):
            if not np.all(np.isfinite(m[3 * k : 3 * k + 3])):
                raise ValueError(
                    f"{self.name}: `{name}` is not finite at t = {t0:g}: {m[3 * k : 3 * k + 3]}"
                )

    def initial_attitude(self, t0: float, Q_carrier0=None) -> np.ndarray:
        """Q_c(t0): the exact attitude when known (then ``Q_carrier0`` must be omitted), else
        ``Q_carrier0`` (default: the identity)."""
        if self.has_attitude:
            if Q_carrier0 is not None:
                raise ValueError(
                    "`Q_carrier0` must be omitted: the carrier's attitude is given by its "
                    f"`{self.given}`"
                )
            return as_rotation_matrix(self.attitude(t0), f"{self.name} attitude at t0")
        return np.eye(3) if Q_carrier0 is None else as_rotation_matrix(Q_carrier0, "Q_carrier0")

    def __repr__(self):
        return f"Carrier({self.name!r}, given by {self.given}, {self.kind})"
