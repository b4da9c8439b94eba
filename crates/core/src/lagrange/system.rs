//! A constrained system as the integrators step it (\[L\] eqs (6.55)–(6.60),
//! `docs/lagrange.md`): where its inputs `u(t, q, q̇)` come from ([`Inputs`]: constants,
//! compiled expressions), how its constraints are kept ([`Stabilization`]: Baumgarte's gains,
//! the projection), and the system itself ([`Lagrangian`]), a [`VectorField`] whose
//! right-hand side is the KKT system with Baumgarte's terms.

use std::cell::{Cell, RefCell};

use super::{Evaluator, Model};
use crate::expressions::{Function, Scratch};
use crate::system::VectorField;

/// Where a system's inputs `u(t, q, q̇)` come from.
pub trait Inputs {
    /// The number of inputs.
    fn count(&self) -> usize;
    /// Write `u` at `(t, q, q̇)`; false when a call out of the engine failed.
    fn values(&self, t: f64, q: &[f64], v: &[f64], u: &mut [f64]) -> bool;
}

/// Inputs held constant.
pub struct Constant<'a>(pub &'a [f64]);

impl Inputs for Constant<'_> {
    fn count(&self) -> usize {
        self.0.len()
    }
    #[inline(always)]
    fn values(&self, _: f64, _: &[f64], _: &[f64], u: &mut [f64]) -> bool {
        u.copy_from_slice(self.0);
        true
    }
}

/// Inputs given as expressions of `[t, q, q̇]` compiled to machine code (feedback laws, time
/// profiles): `n_inputs = 1 + 2n`, one output per input.
pub struct CompiledInputs<'a> {
    pub function: &'a Function,
    scratch: RefCell<Scratch>,
    args: RefCell<Vec<f64>>,
}

impl<'a> CompiledInputs<'a> {
    pub fn new(function: &'a Function) -> Self {
        CompiledInputs {
            function,
            scratch: RefCell::new(function.scratch()),
            args: RefCell::new(vec![0.0; function.program().n_inputs]),
        }
    }
}

impl Inputs for CompiledInputs<'_> {
    fn count(&self) -> usize {
        self.function.program().n_outputs
    }
    fn values(&self, t: f64, q: &[f64], v: &[f64], u: &mut [f64]) -> bool {
        let mut args = self.args.borrow_mut();
        let n = q.len();
        args[0] = t;
        args[1..1 + n].copy_from_slice(q);
        args[1 + n..1 + 2 * n].copy_from_slice(v);
        self.function
            .eval_in(&mut self.scratch.borrow_mut(), &args, u);
        true
    }
}

/// How the constraints are kept: Baumgarte's gains `(α, β)` (zero for none) and, with
/// `projection`, the projection after every step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stabilization {
    pub alpha: f64,
    pub beta: f64,
    pub projection: bool,
}

/// A constrained system as the integrators step it: the state `y = [q, q̇]` (2n).
pub struct Lagrangian<'a, I: Inputs> {
    pub model: &'a Model,
    pub p: &'a [f64],
    pub inputs: I,
    pub stabilization: Stabilization,
    /// The constraints in play (a released one-sided constraint is out); `None`: all.
    pub active: Option<Vec<bool>>,
    ev: RefCell<Evaluator<'a>>,
    u: RefCell<Vec<f64>>,
    failed: Cell<bool>,
}

impl<'a, I: Inputs> Lagrangian<'a, I> {
    pub fn new(
        model: &'a Model,
        p: &'a [f64],
        inputs: I,
        stabilization: Stabilization,
        active: Option<Vec<bool>>,
    ) -> Result<Self, String> {
        let s = model.shape;
        if p.len() != s.np {
            return Err(format!(
                "{} parameters given, the model has {}",
                p.len(),
                s.np
            ));
        }
        if inputs.count() != s.nu {
            return Err(format!(
                "{} inputs given, the model has {}",
                inputs.count(),
                s.nu
            ));
        }
        if let Some(a) = &active {
            if a.len() != s.m {
                return Err(format!(
                    "the mask of constraints in play has {} entries, the model has {} constraints",
                    a.len(),
                    s.m
                ));
            }
        }
        Ok(Lagrangian {
            model,
            p,
            inputs,
            stabilization,
            active,
            ev: RefCell::new(model.evaluator()),
            u: RefCell::new(vec![0.0; s.nu]),
            failed: Cell::new(false),
        })
    }

    /// Evaluate the model at `(t, q, q̇)` with the inputs there: false when an input failed.
    fn evaluate(&self, ev: &mut Evaluator, t: f64, q: &[f64], v: &[f64]) -> bool {
        let mut u = self.u.borrow_mut();
        if !self.inputs.values(t, q, v, &mut u) {
            self.failed.set(true);
            return false;
        }
        ev.evaluate(t, q, v, self.p, &u);
        true
    }

    /// `(q̈, λ)` at `(t, q, q̇)` with the physical multipliers (no stabilisation), one `λ` per
    /// constraint in play; `None` when the system is singular there.
    pub fn accelerations(&self, t: f64, q: &[f64], v: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let mut ev = self.ev.borrow_mut();
        if !self.evaluate(&mut ev, t, q, v) {
            return None;
        }
        ev.solve(v, self.active.as_deref(), 0.0, 0.0)
            .then(|| ev.solution())
    }
}

impl<I: Inputs> VectorField for Lagrangian<'_, I> {
    fn dim(&self) -> usize {
        2 * self.model.shape.n
    }

    /// `ẏ = [q̇, q̈]` from the KKT system with Baumgarte's terms (NaN where it is singular: the
    /// drivers then name the time).
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let n = self.model.shape.n;
        let (q, v) = y.split_at(n);
        let mut ev = self.ev.borrow_mut();
        let st = self.stabilization;
        let ok = self.evaluate(&mut ev, t, q, &v[..n])
            && ev.solve(v, self.active.as_deref(), st.alpha, st.beta);
        out[..n].copy_from_slice(&v[..n]);
        for i in 0..n {
            out[n + i] = if ok { ev.qdd(i) } else { f64::NAN };
        }
    }

    fn project(&self, t: f64, y: &mut [f64]) -> bool {
        if !self.stabilization.projection || self.model.shape.m == 0 {
            return false;
        }
        let n = self.model.shape.n;
        let (q, v) = y.split_at_mut(n);
        let mut u = self.u.borrow_mut();
        if !self.inputs.values(t, q, v, &mut u) {
            self.failed.set(true);
            return true;
        }
        let ok =
            self.ev
                .borrow_mut()
                .project(t, q, v, self.p, &u, self.active.as_deref(), 1e-13, 20);
        if !ok {
            v.fill(f64::NAN);
        }
        true
    }

    fn failed(&self) -> bool {
        self.failed.get()
    }
}
