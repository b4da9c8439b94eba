"""The samples of a Lagrangian motion (:class:`LagrangianSolution`): coordinates, velocities,
and what the core computes at each sample (accelerations, multipliers, reactions, residuals,
energy), with the notebook displays of every result."""

from __future__ import annotations

import numpy as np

from ..display import Displayable
from ..sensitivity import SensitivityMixin
from .arguments import input_values

__all__ = ["LagrangianSolution"]


def generalized_force_unit(coordinate_unit: str) -> str:
    """The unit of a generalized force conjugate to a coordinate in ``coordinate_unit``: the
    work per unit of the coordinate (``"N"`` for m, ``"N·m"`` for rad, ``"J"`` for none)."""
    return {"m": "N", "rad": "N·m", "": "J", "1": "J"}.get(coordinate_unit,
                                                          f"J/{coordinate_unit}")  # fmt: skip


class LagrangianSolution(SensitivityMixin, Displayable):
    """Samples of a Lagrangian motion (with the notebook displays and figures of every
    result: ``_repr_html_``, ``.plot()``, ``.show()``).

    Attributes
    ----------
    t : (n_samples,)
    q, qd : (n_samples, n_coordinates), in the order the coordinates were given
    multipliers : (n_samples, n_constraints), holonomic first, sign as in (6.60)
    constraint_forces : (n_samples, n_coordinates): ``Σ_k λ_k G_kj`` (generalized; for Cartesian
        coordinates of a point, the physical reaction force on it)
    constraint_residual : (n_samples, n_holonomic): g(q, t) (NaN for a released one-sided
        constraint, whose g is then a gap, not an error)
    constraint_velocity_residual : (n_samples, n_constraints): G q̇ + b (NaN likewise)
    energy : (n_samples,): the Jacobi integral ``h = Σ q̇ ∂L/∂q̇ − L``
    accelerations : (n_samples, n_coordinates)
    t_events, y_events : lists, one array per event (runs with ``events=``)
    releases : list of (t, constraint, state)
        The one-sided constraints that let go, when, and the state ``[q, q̇]`` then (their
        multipliers are zero after).
    sensitivities : poinsot.sensitivity.Sensitivities or None
        With ``simulate(..., sensitivities=)``: ``∂[q, q̇](tᵢ)/∂p`` (:meth:`sensitivity`, outputs
        ``"q"``, ``"qd"``, ``"state"``; :mod:`poinsot.lagrange.sensitivity`).
    """

    #: The default output and parameter of :meth:`lyapunov_exponents`.
    _growth = ("state", "q0")
    t_events: tuple = ()
    y_events: tuple = ()
    releases: tuple = ()
    terminated = False

    def __init__(self, system, t, y, num, *, method, nfev, stabilization, phases=None):
        n = system.n_coordinates
        self.system = system
        self.params = dict(num.params)
        #: values of the system's inputs at each sample (n_samples, k)
        self.inputs = input_values(num.u_of, t, y, n, len(system.inputs))
        self.coordinates = list(system.coordinates)
        self.t = np.asarray(t, dtype=float)
        self.q = np.asarray(y)[:, :n]
        self.qd = np.asarray(y)[:, n:]
        self.method, self.nfev, self.stabilization = method, nfev, stabilization
        m, nh = system.n_constraints, system.n_holonomic
        self.multipliers = np.zeros((len(self.t), m))
        self.accelerations = np.zeros((len(self.t), n))
        self.constraint_forces = np.zeros((len(self.t), n))
        self.constraint_residual = np.zeros((len(self.t), nh))
        self.constraint_velocity_residual = np.zeros((len(self.t), m))
        self.energy = np.zeros(len(self.t))
        phases = phases or [(self.t[0] if len(self.t) else 0.0, num)]
        starts = np.array([p[0] for p in phases])
        which = np.maximum(np.searchsorted(starts, self.t, side="right") - 1, 0)
        y = np.asarray(y, dtype=float)
        for k, (_, pnum) in enumerate(phases):
            at = np.nonzero(which == k)[0]
            if not len(at):
                continue
            out = pnum.batch(self.t[at], self.q[at], self.qd[at], self.inputs[at])
            self.accelerations[at] = out["qdd"]
            self.energy[at] = out["energy"]
            # constraints out of play (released): multipliers zero, residuals NaN (a gap, not
            # an error)
            active = getattr(pnum, "active", None)
            gone = np.zeros(m, dtype=bool) if active is None else ~active
            lam = out["lam"].copy()
            lam[:, gone] = 0.0
            self.multipliers[at] = lam
            self.constraint_forces[at] = out["constraint_forces"]
            pos, vel = out["g"].copy(), out["velocity_residual"].copy()
            pos[:, gone[:nh]] = np.nan
            vel[:, gone] = np.nan
            self.constraint_residual[at] = pos
            self.constraint_velocity_residual[at] = vel

    def evaluate(self, expr):
        """A SymPy expression (or a sequence of them) in the coordinates, their speeds, t, the
        multipliers :attr:`~poinsot.lagrange.LagrangianSystem.lam_vec` and the parameters, at
        every sample: array (n_samples,) (or (n_samples, k)). One vectorised ``lambdify``.

        Examples
        --------
        >>> from poinsot.models import pendulum_cartesian
        >>> model = pendulum_cartesian()
        >>> sol = model.simulate((0, 1), t_eval=[0, 0.5, 1])
        >>> x, y = model.system.coordinates
        >>> bool(abs(sol.evaluate(x**2 + y**2) - 1).max() < 1e-6)
        True
        """
        import sympy as sp

        system = self.system
        many = not isinstance(expr, sp.Basic)
        exprs = list(expr) if many else [expr]
        names = system.plain
        values = {k: sp.Float(v) for k, v in self.params.items()}
        body = [names.of(e).xreplace(values) for e in exprs]
        fn = sp.lambdify((system.t, names.q, names.v, names.lam, names.u), body, modules="numpy",
                         cse=True)  # fmt: skip
        cols = fn(self.t, self.q.T, self.qd.T, self.multipliers.T, self.inputs.T)
        out = np.column_stack([np.broadcast_to(np.asarray(c, float), self.t.shape) for c in cols])
        return out if many else out[:, 0]

    @property
    def invariants(self):
        """The system's :meth:`~poinsot.lagrange.LagrangianSystem.constants_of_motion` along
        this motion, as :class:`~poinsot.conservation.Invariant` objects (all conserved by
        the problem; their change is integration error)."""
        import sympy as sp

        from ..conservation import Invariant

        out = []
        for name, symbol, unit, expr, reason in self.system.constants_of_motion():
            values = self.evaluate(expr)
            terms = sp.Add.make_args(sp.expand(expr))
            size = np.abs(self.evaluate(terms)).sum(axis=1).max()  # when x(0) = 0
            scale = float(abs(values[0])) or float(size) or 1.0
            out.append(Invariant(name, symbol, unit, values, True, reason, scale))
        return out

    # ----------------------------------------------------------------- export
    def export_units(self) -> dict:
        """The units of the exported per-coordinate and per-constraint fields, one per column:
        ``constraint_forces`` (a generalized force, :func:`generalized_force_unit`), and for
        the constraints, whose units the system does not know, what they are in terms of
        them: ``multipliers`` (``J/(unit of g1)`` for a holonomic g1 = 0, ``W/(unit of G3 qd +
        b3)`` for a velocity constraint: ``λ_k G_kj`` is a generalized force),
        ``constraint_residual`` and ``constraint_velocity_residual``."""
        m, nh = self.multipliers.shape[1], self.constraint_residual.shape[1]
        holo = [f"unit of g{k + 1}" for k in range(nh)]
        rate = [f"unit of G{k + 1} qd + b{k + 1}" for k in range(nh, m)]
        return {
            "constraint_forces": [generalized_force_unit(self.system.unit_of(q))
                                  for q in self.coordinates],
            "multipliers": [f"J/({u})" for u in holo] + [f"W/({u})" for u in rate],
            "constraint_residual": holo,
            "constraint_velocity_residual": [f"({u})/s" for u in holo] + rate,
        }  # fmt: skip

    def variables(self) -> dict:
        """Every exported field as ``name → (dims, values, attrs)``, coordinates included
        (:meth:`to_netcdf`, :meth:`to_xarray`): ``q``, ``qd``, ``accelerations`` and
        ``constraint_forces`` along ``coordinate`` (each coordinate's unit in
        ``units_by_coordinate``), the multipliers and residuals along ``constraint`` /
        ``holonomic_constraint``, the energy, and with sensitivities ``sensitivity (time,
        state_component, parameter)``. A dimension of length zero (no constraint) is left
        out with its fields."""
        names = [str(q).replace("(t)", "") for q in self.coordinates]
        units = ", ".join(f"{n}: {self.system.unit_of(q) or '1'}"
                          for n, q in zip(names, self.coordinates, strict=True))  # fmt: skip
        per = {"units_by_coordinate": units}
        more = self.export_units()
        forces = ", ".join(f"{n}: {u}" for n, u in zip(names, more["constraint_forces"],
                                                       strict=True))  # fmt: skip
        by_constraint = {k: ", ".join(f"{i + 1}: {u}" for i, u in enumerate(v))
                         for k, v in more.items()}  # fmt: skip
        out = {
            "time": (("time",), self.t, {"units": "s"}),
            "coordinate": (("coordinate",), np.array(names), {}),
            "q": (("time", "coordinate"), self.q, {**per, "long_name": "coordinates"}),
            "qd": (("time", "coordinate"), self.qd,
                   {**per, "long_name": "velocities (per second)"}),
            "accelerations": (("time", "coordinate"), self.accelerations,
                              {**per, "long_name": "accelerations (per second squared)"}),
            "constraint_forces": (("time", "coordinate"), self.constraint_forces,
                                  {"long_name": "generalized constraint forces G^T lambda",
                                   "units_by_coordinate": forces}),
            "energy": (("time",), self.energy, {"long_name": "Jacobi integral h", "units": "J"}),
        }  # fmt: skip
        m, nh = self.multipliers.shape[1], self.constraint_residual.shape[1]
        exprs = [str(g) for g in self.system.holonomic] + [
            str(c) for c in getattr(self.system, "nonholonomic", ())]  # fmt: skip
        if m:
            out["constraint"] = (("constraint",), np.array((exprs + [""] * m)[:m]), {})
            lam = {"long_name": "Lagrange multipliers, sign as in (6.60)",
                   "units_by_constraint": by_constraint["multipliers"]}  # fmt: skip
            out["multipliers"] = (("time", "constraint"), self.multipliers, lam)
            out["constraint_velocity_residual"] = (
                ("time", "constraint"), self.constraint_velocity_residual,
                {"long_name": "G qd + b",
                 "units_by_constraint": by_constraint["constraint_velocity_residual"]})  # fmt: skip
        if nh:
            out["holonomic_constraint"] = (("holonomic_constraint",), np.array(exprs[:nh]), {})
            g = {"long_name": "g(q, t)",
                 "units_by_constraint": by_constraint["constraint_residual"]}  # fmt: skip
            out["constraint_residual"] = (("time", "holonomic_constraint"),
                                          self.constraint_residual, g)  # fmt: skip
        if self.sensitivities is not None:
            labels = [f"q[{n}]" for n in names] + [f"qd[{n}]" for n in names]
            sens = {
                "long_name": "forward sensitivity d state / d parameter",
                "units": "the state component's over the parameter's",
            }
            if self.sensitivities.t0 is not None:
                sens |= {"t0": self.sensitivities.t0, "t0_long_name": "time of the initial "
                         "state the derivatives are taken at"}  # fmt: skip
            out["sensitivity"] = (("time", "state_component", "parameter"),
                                  self.sensitivities.S, sens)  # fmt: skip
            out["state_component"] = (("state_component",), np.array(labels), {})
            out["parameter"] = (("parameter",),
                                np.array(self.sensitivities.directions.labels), {})  # fmt: skip
        return out

    def _attrs(self) -> dict:
        return {"method": self.method, "stabilization": str(self.stabilization),
                "params": ", ".join(f"{k} = {v!r}" for k, v in self.params.items())}  # fmt: skip

    def to_netcdf(self, path) -> None:
        """Write :meth:`variables` to a NetCDF-3 file (atomically, with SciPy's writer: no
        xarray needed)."""
        from .._io import write_netcdf

        write_netcdf(path, self.variables(), self._attrs())

    def to_xarray(self):
        """An ``xarray.Dataset`` of :meth:`variables` (needs the ``xarray`` extra)."""
        from .._io import xarray_dataset

        return xarray_dataset(self.variables(), self._attrs())

    def __getitem__(self, coordinate):
        """The samples (n_samples,) of one coordinate: ``sol[x]``."""
        return self.q[:, self.coordinates.index(coordinate)]

    def __repr__(self):
        return (
            f"LagrangianSolution(n={len(self.t)}, coordinates={self.coordinates}, "
            f"method={self.method!r}, stabilization={self.stabilization!r})"
        )
