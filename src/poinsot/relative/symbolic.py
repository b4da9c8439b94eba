"""The relative equations in Euler angles as SymPy expressions (paper eqs (12)–(15)), for
users who want them on paper (``docs/relative.md``).

The body's attitude relative to the carrier is given by z-x-z Euler angles ψ(t), θ(t), φ(t);
``(p, q, r)`` are the relative angular velocity's body components (13), ``(p_e, q_e, r_e)``
the carrier's ω_e projected on the body axes (15), and eqs (12) are three second-order
equations in the angles. The numeric engine integrates the same physics with rotation matrices
(no gimbal lock); :meth:`RelativeEquations.mass_matrix` and :meth:`RelativeEquations.forcing`
give the angles' accelerations ``M ẍ = f`` for an independent check, away from θ = 0, π.
"""

from __future__ import annotations

from dataclasses import dataclass

from .carrier import zxz_body_rates, zxz_matrix

__all__ = ["RelativeEquations", "relative_equations"]


@dataclass(frozen=True)
class RelativeEquations:
    """Eqs (12) in Euler angles. ``equations`` are SymPy ``Eq`` (one per principal axis);
    ``coordinates`` the angles ψ(t), θ(t), φ(t); ``omega_r`` (13) and ``omega_e`` (15) the body
    components; ``t`` the time symbol; ``moments`` (A, B, C)."""

    equations: tuple
    coordinates: tuple
    omega_r: tuple
    omega_e: tuple
    epsilon_e: tuple
    t: object
    moments: tuple

    def latex(self) -> str:
        """The three equations as a LaTeX ``align`` environment."""
        import sympy as sp

        rows = [f"{sp.latex(e.lhs)} &= {sp.latex(e.rhs)}" for e in self.equations]
        return "\\begin{align}\n" + " \\\\\n".join(rows) + "\n\\end{align}"

    def _linear(self):
        import sympy as sp

        acc = [sp.diff(c, self.t, 2) for c in self.coordinates]
        exprs = [e.lhs - e.rhs for e in self.equations]
        M, f = sp.linear_eq_to_matrix(exprs, acc)
        return M, f

    def mass_matrix(self):
        """``M`` (3×3) of ``M (ψ̈, θ̈, φ̈) = f`` (SymPy ``LagrangesMethod`` vocabulary)."""
        return self._linear()[0]

    def forcing(self):
        """``f`` (3×1) of ``M (ψ̈, θ̈, φ̈) = f``."""
        return self._linear()[1]


def _vector(carrier, key, t):
    import sympy as sp

    expressions = getattr(carrier, "expressions", None)
    if expressions is None and carrier.kind == "ppoly" and carrier.ppoly[1].shape[:2] == (1, 1):
        index = {"omega_e": slice(0, 3), "epsilon_e": slice(3, 6)}[key]  # a constant
        return [sp.Float(v) for v in carrier.motion(0.0)[index]]
    if expressions is None:
        raise ValueError(
            "`carrier` must be given by constants, SymPy expressions, Euler angles or an attitude "
            "to write its equations symbolically"
        )
    return [sp.sympify(e).subs(carrier.t_symbol, t) for e in expressions[key]]


def relative_equations(moments=None, *, carrier=None, torque=None, balance_transport=False):
    """The compact relative Euler equations in principal axes (12), with the relative angular
    velocity from the Euler angles (13) and ω_e projected on the body axes (15)::

        A ṗ = (B − C) q r − A ε_ex + (B − C) q_e r_e + 2 (C' q r_e − B' r q_e) + M_x(F)

    and cyclically, ``A' = (B + C − A)/2``, … .

    Parameters
    ----------
    moments : (A, B, C), optional
        Principal moments (numbers or SymPy expressions); symbols ``A, B, C`` by default.
    carrier : Carrier, optional
        The carrier; by default its ω_e has the unknown components ``p_1(t), q_1(t), r_1(t)``
        (carrier axes), projected by (15).
    torque : three SymPy expressions, optional
        The physical moment ``M(F)`` in body components; ``M_x(t), M_y(t), M_z(t)`` by default.
    balance_transport : bool
        Case (16): the physical moment cancels the transport moment (``torque`` then omitted).

    Returns
    -------
    RelativeEquations

    Examples
    --------
    >>> eqs = relative_equations()
    >>> eqs.coordinates
    (psi(t), theta(t), phi(t))
    >>> print(eqs.omega_r[2])
    cos(theta(t))*Derivative(psi(t), t) + Derivative(phi(t), t)
    """
    import sympy as sp

    t = carrier.t_symbol if carrier is not None and carrier.t_symbol is not None else sp.Symbol("t")
    psi, theta, phi = (sp.Function(n)(t) for n in ("psi", "theta", "phi"))
    if moments is None:
        A, B, C = sp.symbols("A B C", positive=True)
    else:
        if len(moments) != 3:
            raise ValueError(f"`moments` must be three principal moments, found {len(moments)}")
        A, B, C = (sp.sympify(m) for m in moments)
    p, q, r = zxz_body_rates(psi, theta, phi, t)  # eq. (13)
    if carrier is None:
        w_c = [sp.Function(n)(t) for n in ("p_1", "q_1", "r_1")]
        e_c = [sp.diff(w, t) for w in w_c]
    else:
        w_c = _vector(carrier, "omega_e", t)
        e_c = _vector(carrier, "epsilon_e", t)
    Qr = zxz_matrix(psi, theta, phi)  # body → carrier
    pe, qe, re = list(Qr.T * sp.Matrix(w_c))  # eq. (15)
    ex, ey, ez = list(Qr.T * sp.Matrix(e_c))
    Ap, Bp, Cp = (B + C - A) / 2, (C + A - B) / 2, (A + B - C) / 2
    if balance_transport:
        if torque is not None:
            raise ValueError("give `torque` or `balance_transport`, not both")
        Mx = A * ex - (B - C) * qe * re
        My = B * ey - (C - A) * re * pe
        Mz = C * ez - (A - B) * pe * qe
    elif torque is None:
        Mx, My, Mz = (sp.Function(n)(t) for n in ("M_x", "M_y", "M_z"))
    else:
        if len(torque) != 3:
            raise ValueError(f"`torque` must have three components, found {len(torque)}")
        Mx, My, Mz = (sp.sympify(m) for m in torque)
    equations = (  # eq. (12)
        sp.Eq(A * sp.diff(p, t), (B - C) * q * r - A * ex + (B - C) * qe * re
              + 2 * (Cp * q * re - Bp * r * qe) + Mx),
        sp.Eq(B * sp.diff(q, t), (C - A) * r * p - B * ey + (C - A) * re * pe
              + 2 * (Ap * r * pe - Cp * p * re) + My),
        sp.Eq(C * sp.diff(r, t), (A - B) * p * q - C * ez + (A - B) * pe * qe
              + 2 * (Bp * p * qe - Ap * q * pe) + Mz),
    )  # fmt: skip
    return RelativeEquations(equations, (psi, theta, phi), (p, q, r), (pe, qe, re),
                             (ex, ey, ez), t, (A, B, C))  # fmt: skip
