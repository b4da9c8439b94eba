//! What a run is, as data: the method (the registry's kinds: RK4 in registers, an explicit
//! tableau, Runge–Kutta–Munthe-Kaas, the splitting method, adaptive DOP853, each with the data
//! it needs), its step, its sampling and its step budget. Every run of the crate, a single
//! body's, a constrained system's, a carrier's passenger's or an ensemble's, is a system and a
//! [`RunSpec`]; what a run did comes back as named [`crate::drivers::Counters`].
//!
//! The method is parsed from its name once ([`Method::parse`], the registry's names), at the
//! boundary; nothing below matches a method by name.
//!
//! This module is the registry of the crate's methods: what users call them and what each
//! declares ([`REGISTRY`], read by the Python package to list its methods), their kinds
//! ([`Method`]) and the one table that builds each kind's stepper for a run
//! ([`Method::on_rigid`], [`Method::on_field`]), which every driver of the crate uses (the
//! bindings' single runs, the ensembles' members, the constrained systems' phases). A new
//! fixed-step method is its stepper (a [`FixedMethod`]), its entry here and its test.

use crate::drivers::{Erk, FixedMethod, Rk4Rigid, RkmkRigid, Sampling, Splitting};
use crate::exact_splitting::{Composition, ExactSplitting};
use crate::steppers::{Control, Tableau, RK4};
use crate::system::{RigidStructure, VectorField};

/// A method users name, as the registry declares it.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// The name users give (`simulate(..., method=name)`).
    pub name: &'static str,
    /// The kind of step that runs it ([`Method::NAMES`]).
    pub kind: &'static str,
    /// Its global order of accuracy (checked by the order tests).
    pub order: u32,
    /// The data it runs with: a tableau (a name of `poinsot._core.tableau`) or, for the
    /// exact-flow splittings, a composition (of `poinsot._core.composition`); "" for none.
    pub tableau: &'static str,
    /// Invariants it keeps to round-off: "orthogonality" (Q on SO(3)), "angular_momentum"
    /// (|L| and the spatial L, torque-free), "symplectic" (bounded energy error).
    pub conserves: &'static [&'static str],
    /// It takes kicks from the forces: every force must depend on time, position and
    /// attitude only.
    pub kicks: bool,
    /// One line for users (the Python class's docstring, the tables of methods).
    pub summary: &'static str,
}

/// The registry: every method the crate runs by name, in the order users see them.
pub const REGISTRY: &[Entry] = &[
    Entry {
        name: "dop853",
        kind: "dop853",
        order: 8,
        tableau: "dop853",
        conserves: &[],
        kicks: false,
        summary: "Adaptive Dormand–Prince 8(5,3): error control, dense output (Hairer, Nørsett & Wanner, Solving ODEs I, §II.5, §II.10).",
    },
    Entry {
        name: "rk4",
        kind: "rk4",
        order: 4,
        tableau: "rk4",
        conserves: &[],
        kicks: false,
        summary: "Classical fourth-order Runge–Kutta; conserves nothing exactly (its drift is reported).",
    },
    Entry {
        name: "rkmk4",
        kind: "rkmk",
        order: 4,
        tableau: "rk4",
        conserves: &["orthogonality"],
        kicks: false,
        summary: "Runge–Kutta–Munthe-Kaas with RK4's tableau on SO(3) (Munthe-Kaas 1999, BIT 39): Q stays a rotation.",
    },
    Entry {
        name: "splitting",
        kind: "splitting",
        order: 2,
        tableau: "",
        conserves: &["orthogonality", "angular_momentum", "symplectic"],
        kicks: true,
        summary: "Strang splitting, free rotor and kicks (McLachlan 1993; Dullweber, Leimkuhler & McLachlan 1997): symplectic.",
    },
    Entry {
        name: "exact-splitting",
        kind: "exact-splitting",
        order: 2,
        tableau: "strang",
        conserves: &["orthogonality", "angular_momentum", "symplectic"],
        kicks: true,
        summary: "Strang splitting of the exact torque-free flow (Jacobi elliptic functions) and kicks: exact without torques, O(ε h²) under a torque of size ε (Celledoni, Fassò, Säfström & Zanna 2008); under one central gravity the orbit drifts by Kepler's exact flow (Wisdom & Holman 1991).",
    },
    Entry {
        name: "exact-splitting4",
        kind: "exact-splitting",
        order: 4,
        tableau: "bm4",
        conserves: &["orthogonality", "angular_momentum", "symplectic"],
        kicks: true,
        summary: "Exact torque-free flows and kicks composed by Blanes & Moan's SRKN6b (2002): order 4, six flows a step.",
    },
    Entry {
        name: "exact-splitting6",
        kind: "exact-splitting",
        order: 6,
        tableau: "bm6",
        conserves: &["orthogonality", "angular_momentum", "symplectic"],
        kicks: true,
        summary: "Exact torque-free flows and kicks composed by Blanes & Moan's SRKN14a (2002), as FRB (ACM TOMS 903): order 6, fifteen flows a step.",
    },
];

/// What a caller does with a run's method once its stepper is built: the table of
/// constructors ([`Method::on_rigid`], [`Method::on_field`]) hands it the fixed-step method as
/// its own type (so that the driver is compiled for it) or the adaptive method's controller.
pub trait UseMethod<S: VectorField + ?Sized> {
    type Output;
    /// Run the fixed-step method `method` ([`crate::drivers::run_fixed`]).
    fn fixed<M: FixedMethod<S> + Send>(self, method: M) -> Self::Output;
    /// Run the adaptive method with `control` ([`crate::drivers::run_adaptive`]).
    fn adaptive(self, control: Control) -> Self::Output;
}

/// A run's method, with its tableau (explicit Runge–Kutta and RKMK) or its controller (DOP853).
#[derive(Clone, Copy, Debug)]
pub enum Method<'a> {
    /// Classical RK4 on a rigid body's state in registers ([`crate::drivers::Rk4Rigid`]).
    Rk4,
    /// Any explicit Runge–Kutta tableau ([`crate::drivers::Erk`]), on any vector field.
    Erk(Tableau<'a>),
    /// Runge–Kutta–Munthe-Kaas with a tableau, on SO(3) ([`crate::drivers::RkmkRigid`]).
    Rkmk(Tableau<'a>),
    /// The splitting method: free-rotor flows and kicks ([`crate::drivers::Splitting`]).
    Splitting,
    /// Adaptive Dormand–Prince 8(5,3) with its step-size controller, on any vector field.
    Dop853(Control),
    /// Exact torque-free flows and kicks composed ([`crate::exact_splitting::ExactSplitting`]).
    ExactSplitting(Composition<'a>),
}

/// What a method may need beyond its name: a tableau (explicit Runge–Kutta, RKMK), a
/// composition (exact-flow splitting) or a controller (DOP853); unused parts are ignored.
#[derive(Clone, Copy, Debug)]
pub struct MethodData<'a> {
    pub tableau: Tableau<'a>,
    pub composition: Option<Composition<'a>>,
    pub control: Control,
}

impl<'a> Method<'a> {
    /// The registry's kinds, by name: those of any vector field first.
    pub const NAMES: [&'static str; 6] = [
        "dop853",
        "erk",
        "rk4",
        "rkmk",
        "splitting",
        "exact-splitting",
    ];

    /// The method named `name` (one of [`Method::NAMES`]) with its `tableau` (checked: `a`
    /// s × s, `b` and `c` s, at least one stage, for `"erk"` and `"rkmk"`), its composition
    /// (checked when made, for `"exact-splitting"`) or `control` (for `"dop853"`); the error
    /// names the argument and the rule.
    pub fn parse(name: &str, data: MethodData<'a>) -> Result<Self, String> {
        let MethodData {
            tableau,
            composition,
            control,
        } = data;
        let needs_tableau = || -> Result<Tableau<'a>, String> {
            let s = tableau.b.len();
            if s == 0 || tableau.a.len() != s * s || tableau.c.len() != s {
                return Err(format!(
                    "method {name:?} needs a tableau: `a` (s, s), `b` (s,), `c` (s,) with s ≥ 1, \
                     found {}, {}, {} numbers",
                    tableau.a.len(),
                    tableau.b.len(),
                    tableau.c.len()
                ));
            }
            Ok(tableau)
        };
        match name {
            "rk4" => Ok(Method::Rk4),
            "erk" => Ok(Method::Erk(needs_tableau()?)),
            "rkmk" => Ok(Method::Rkmk(needs_tableau()?)),
            "splitting" => Ok(Method::Splitting),
            "exact-splitting" => composition
                .map(Method::ExactSplitting)
                .ok_or_else(|| format!("method {name:?} needs a composition: flows and kicks")),
            "dop853" => {
                check_control(&control)?;
                Ok(Method::Dop853(control))
            }
            _ => Err(format!(
                "`method` must be one of {:?}, found {name:?}",
                Method::NAMES
            )),
        }
    }

    /// Its name in the registry.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4 => "rk4",
            Method::Erk(_) => "erk",
            Method::Rkmk(_) => "rkmk",
            Method::Splitting => "splitting",
            Method::Dop853(_) => "dop853",
            Method::ExactSplitting(_) => "exact-splitting",
        }
    }

    /// True for the adaptive method (no fixed step).
    pub fn is_adaptive(&self) -> bool {
        matches!(self, Method::Dop853(_))
    }

    /// The kinds with error control and no fixed step.
    pub const ADAPTIVE_KINDS: [&'static str; 1] = ["dop853"];

    /// The kinds that run on any vector field ([`Method::on_field`]): the adaptive method and
    /// explicit tableaux, classical RK4's included.
    pub const FIELD_KINDS: [&'static str; 3] = ["dop853", "erk", "rk4"];

    /// True for the methods that use a rigid body's structure (the rotation group, the
    /// free-rotor flows); the others ([`Method::FIELD_KINDS`]) run on any vector field.
    pub fn needs_rigid_body(&self) -> bool {
        !Method::FIELD_KINDS.contains(&self.name())
    }

    /// The table of constructors for a rigid body (`sys`): each kind's stepper, built once
    /// for the call and handed to `user`.
    pub fn on_rigid<S, U>(&self, sys: &S, user: U) -> U::Output
    where
        S: RigidStructure + ?Sized,
        U: UseMethod<S>,
    {
        match *self {
            Method::Rk4 => user.fixed(Rk4Rigid),
            Method::Erk(tab) => user.fixed(Erk::new(tab, sys.dim())),
            Method::Rkmk(tab) => user.fixed(RkmkRigid::new(tab)),
            Method::Splitting => user.fixed(Splitting),
            Method::ExactSplitting(c) => user.fixed(ExactSplitting::new(sys.body(), c)),
            Method::Dop853(control) => user.adaptive(control),
        }
    }

    /// The table of constructors for any vector field (`sys`): the adaptive method and
    /// explicit tableaux, classical RK4 as its tableau; a method that needs a rigid body's
    /// structure is refused.
    pub fn on_field<S, U>(&self, sys: &S, user: U) -> Result<U::Output, String>
    where
        S: VectorField + ?Sized,
        U: UseMethod<S>,
    {
        match *self {
            Method::Rk4 => Ok(user.fixed(Erk::new(RK4, sys.dim()))),
            Method::Erk(tab) => Ok(user.fixed(Erk::new(tab, sys.dim()))),
            Method::Dop853(control) => Ok(user.adaptive(control)),
            _ => Err(self.rigid_only()),
        }
    }

    fn rigid_only(&self) -> String {
        format!(
            "method {:?} needs a rigid body's structure; this system runs \"dop853\" and \
             \"erk\" (an explicit tableau, RK4's included)",
            self.name()
        )
    }
}

/// The controller's numbers, checked: positive finite tolerances, `0 < safety ≤ 1`,
/// `0 < min_factor ≤ 1 ≤ max_factor`, a positive `max_step` (∞ allowed) and a first step ≥ 0
/// (0: chosen by the controller).
fn check_control(c: &Control) -> Result<(), String> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    let checks = [
        (positive(c.rtol), "`rtol` must be a positive number"),
        (positive(c.atol), "`atol` must be a positive number"),
        (
            positive(c.safety) && c.safety <= 1.0,
            "`safety` must be in (0, 1]",
        ),
        (
            positive(c.min_factor) && c.min_factor <= 1.0,
            "`min_factor` must be in (0, 1]",
        ),
        (
            c.max_factor.is_finite() && c.max_factor >= 1.0,
            "`max_factor` must be a number ≥ 1",
        ),
        (
            c.max_step > 0.0 && !c.max_step.is_nan(),
            "`max_step` must be positive",
        ),
        (
            c.first_step.is_finite() && c.first_step >= 0.0,
            "`first_step` must be ≥ 0 (0: automatic)",
        ),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some((_, rule)) => Err(format!("{rule}, found {c:?}")),
        None => Ok(()),
    }
}

/// A run: its method, the step of a fixed-step method, what it saves until when, and the most
/// steps it may take.
#[derive(Clone, Copy, Debug)]
pub struct RunSpec<'a> {
    pub method: Method<'a>,
    /// Step of a fixed-step method (unused by DOP853, whose first step is its controller's).
    pub dt: f64,
    pub sampling: Sampling<'a>,
    pub max_steps: u64,
}

impl<'a> RunSpec<'a> {
    /// The run, checked: a positive finite step for a fixed-step method, a finite end, sample
    /// times finite and non-decreasing, and a positive step budget.
    pub fn new(
        method: Method<'a>,
        dt: f64,
        sampling: Sampling<'a>,
        max_steps: u64,
    ) -> Result<Self, String> {
        let fixed_step_ok = dt.is_finite() && dt > 0.0;
        if !(method.is_adaptive() || fixed_step_ok) {
            return Err(format!(
                "`dt` must be a positive number for method {:?}, found {dt}",
                method.name()
            ));
        }
        if !sampling.t_end.is_finite() {
            return Err(format!(
                "`t_end` must be a finite time, found {}",
                sampling.t_end
            ));
        }
        let times = sampling.t_eval;
        if let Some(k) = times.iter().position(|t| !t.is_finite()) {
            return Err(format!("`t_eval[{k}]` must be finite, found {}", times[k]));
        }
        if let Some(k) = times.windows(2).position(|w| w[1] < w[0]) {
            return Err(format!(
                "`t_eval` must be non-decreasing, found t_eval[{}] = {} after {}",
                k + 1,
                times[k + 1],
                times[k]
            ));
        }
        if sampling.every == 0 {
            return Err("`save_every` must be a positive integer".into());
        }
        if max_steps == 0 {
            return Err("`max_steps` must be a positive integer".into());
        }
        Ok(RunSpec {
            method,
            dt,
            sampling,
            max_steps,
        })
    }

    /// Refused unless the system runs the method: one without a rigid body's structure runs
    /// only DOP853 and explicit tableaux.
    pub fn check_for(&self, rigid_body: bool) -> Result<(), String> {
        if self.method.needs_rigid_body() && !rigid_body {
            return Err(self.method.rigid_only());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::steppers::RK4;

    const CONTROL: Control = Control::with_tolerances(1e-8, 1e-10);
    const NO_TABLEAU: Tableau<'static> = Tableau {
        a: &[],
        b: &[],
        c: &[],
    };

    /// A method's data: `tableau`, Strang's composition and `control`.
    fn data(tableau: Tableau<'static>, control: Control) -> MethodData<'static> {
        let (kick_first, flows, kicks) = crate::tableaux::composition("strang").unwrap();
        MethodData {
            tableau,
            composition: Some(Composition::new(kick_first, flows, kicks).unwrap()),
            control,
        }
    }

    #[test]
    fn every_name_parses_to_its_method_and_back() {
        for name in Method::NAMES {
            let m = Method::parse(name, data(RK4, CONTROL)).unwrap();
            assert_eq!(m.name(), name);
            assert_eq!(m.is_adaptive(), name == "dop853");
            assert_eq!(
                m.needs_rigid_body(),
                ["rkmk", "splitting", "exact-splitting"].contains(&name)
            );
        }
        let e = Method::parse("rk45", data(RK4, CONTROL)).unwrap_err();
        assert!(
            e.contains("`method` must be one of") && e.contains("\"rk45\""),
            "{e}"
        );
    }

    #[test]
    fn a_tableau_and_a_controller_are_checked() {
        assert!(Method::parse("erk", data(NO_TABLEAU, CONTROL)).is_err());
        assert!(Method::parse("rkmk", data(NO_TABLEAU, CONTROL)).is_err());
        let bad = Tableau {
            c: &RK4.c[..3],
            ..RK4
        };
        assert!(Method::parse("erk", data(bad, CONTROL))
            .unwrap_err()
            .contains("3 numbers"));
        assert!(Method::parse("rk4", data(NO_TABLEAU, CONTROL)).is_ok()); // needs none
        for broken in [
            Control {
                rtol: 0.0,
                ..CONTROL
            },
            Control {
                atol: f64::NAN,
                ..CONTROL
            },
            Control {
                safety: 1.5,
                ..CONTROL
            },
            Control {
                min_factor: 0.0,
                ..CONTROL
            },
            Control {
                max_factor: 0.5,
                ..CONTROL
            },
            Control {
                max_step: 0.0,
                ..CONTROL
            },
            Control {
                first_step: -1.0,
                ..CONTROL
            },
        ] {
            assert!(
                Method::parse("dop853", data(NO_TABLEAU, broken)).is_err(),
                "{broken:?}"
            );
        }
    }

    #[test]
    fn a_run_is_checked_once() {
        let sampling = |t_eval: &'static [f64]| Sampling {
            t_end: 1.0,
            t_eval,
            every: 1,
        };
        let ok = RunSpec::new(Method::Splitting, 0.1, sampling(&[0.0, 0.5, 1.0]), 10).unwrap();
        assert!(ok.check_for(true).is_ok());
        assert!(ok.check_for(false).unwrap_err().contains("\"splitting\""));
        assert!(RunSpec::new(Method::Rk4, 0.0, sampling(&[]), 10).is_err());
        assert!(RunSpec::new(Method::Dop853(CONTROL), 0.0, sampling(&[]), 10).is_ok());
        let e = RunSpec::new(Method::Rk4, 0.1, sampling(&[0.0, 0.5, 0.2]), 10).unwrap_err();
        assert!(e.contains("t_eval[2] = 0.2 after 0.5"), "{e}");
        assert!(RunSpec::new(Method::Rk4, 0.1, sampling(&[0.0, f64::NAN]), 10).is_err());
        assert!(RunSpec::new(Method::Rk4, 0.1, sampling(&[]), 0).is_err());
    }
}
