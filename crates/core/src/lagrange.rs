//! Constrained systems: Lagrange's equations with multipliers ([L] eqs (6.55)–(6.60),
//! `docs/lagrange.md`), as a [`VectorField`] the integrators step.
//!
//! A model brings its own expressions, derived in SymPy: the mass matrix `M(q, t)`, the
//! forcing `f(q, q̇, t)` (everything but `M q̈` in Lagrange's equations), the constraint
//! Jacobian `G(q, t)` with its right-hand side `b` (the velocity constraints read
//! `G q̇ + b = 0`) and velocity-product terms `γ = Ġ q̇ + ḃ`, the holonomic residuals `g(q, t)`
//! and the Jacobi integral `h`. They arrive as one compiled [`Function`] of
//! `[q, q̇, t, p, u]` (coordinates, velocities, time, parameters, inputs) whose outputs are
//! `[M, f, G, b, γ, g, h]` ([`Shape`]); nothing of the model is written here.
//!
//! What is written here, once, is the engine's mathematics:
//!
//! * the index-1 (KKT) system `[[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; −γ − s]` ([L] (6.60)), with
//!   the multipliers' sign of `docs/lagrange.md` (the generalized constraint force is `Gᵀλ`);
//! * Baumgarte's stabilisation `s = 2α (G q̇ + b) + β² g` (the position term on holonomic
//!   rows), so that a residual `e` obeys `ë + 2α ė + β² e = 0` (Baumgarte 1972);
//! * the projection onto the constraints: Gauss–Newton with minimum-norm corrections on
//!   `g(q) = 0`, then `q̇ ← q̇ − G⁺ (G q̇ + b)`;
//! * constraints that can let go (one-sided): a mask of the constraints in play, so that a
//!   released constraint's row leaves the system;
//! * the physical multipliers, generalized constraint forces `Gᵀλ`, residuals and energy at
//!   samples;
//! * a run's events ([`LagrangeEvents`]): the user's compiled expressions or callbacks, and
//!   the multipliers of one-sided constraints, whose zeros [`crate::events::Watch`] locates.

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::drivers::{Clock, Counters, Output, Sampling, Status};
use crate::events::{EventFunctions, Watch};
use crate::expressions::{Compiler, Function, Program, Scratch};
use crate::linalg::{min_norm_solve, solve_augmented, solve_spd_augmented};
use crate::observers::{NoObserver, Observer};
use crate::run::Run;
use crate::spec::RunSpec;
use crate::system::VectorField;

/// The sizes of a model: `n` coordinates, `m` constraints of which the first `nh` are
/// holonomic, `np` parameters, `nu` inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    pub n: usize,
    pub m: usize,
    pub nh: usize,
    pub np: usize,
    pub nu: usize,
}

impl Shape {
    /// The function's inputs: `[q (n), q̇ (n), t, p (np), u (nu)]`.
    pub fn n_inputs(&self) -> usize {
        2 * self.n + 1 + self.np + self.nu
    }
    /// The function's outputs: `[M (n·n, row-major), f (n), G (m·n), b (m), γ (m), g (nh), h]`.
    pub fn n_outputs(&self) -> usize {
        self.n * self.n + self.n + self.m * self.n + 2 * self.m + self.nh + 1
    }
    fn at_f(&self) -> usize {
        self.n * self.n
    }
    fn at_g_jac(&self) -> usize {
        self.at_f() + self.n
    }
    fn at_b(&self) -> usize {
        self.at_g_jac() + self.m * self.n
    }
    fn at_gamma(&self) -> usize {
        self.at_b() + self.m
    }
    fn at_g(&self) -> usize {
        self.at_gamma() + self.m
    }
    fn at_h(&self) -> usize {
        self.at_g() + self.nh
    }
}

/// A model: its sizes and its compiled expressions.
pub struct Model {
    pub shape: Shape,
    parts: Function,
}

impl Model {
    /// The model of `program` (inputs and outputs as [`Shape`] says), compiled by `compiler`
    /// (`poinsot_jit::Jit`: machine code; [`crate::expressions::Interpreter`]: interpreted).
    pub fn new(shape: Shape, program: Program, compiler: &dyn Compiler) -> Result<Self, String> {
        if shape.nh > shape.m {
            return Err(format!(
                "{} holonomic constraints among {} constraints",
                shape.nh, shape.m
            ));
        }
        if shape.n == 0 {
            return Err("a model needs at least one coordinate".into());
        }
        if program.n_inputs != shape.n_inputs() || program.n_outputs != shape.n_outputs() {
            return Err(format!(
                "the program has {} inputs and {} outputs; a model of these sizes needs {} and {}",
                program.n_inputs,
                program.n_outputs,
                shape.n_inputs(),
                shape.n_outputs()
            ));
        }
        Ok(Model {
            shape,
            parts: Function::compile(program, compiler),
        })
    }

    /// True when the expressions run as machine code (else they are interpreted).
    pub fn is_machine_code(&self) -> bool {
        self.parts.is_machine_code()
    }

    /// Working memory for evaluating this model on one thread.
    pub fn evaluator(&self) -> Evaluator<'_> {
        let s = self.shape;
        let d = s.n + s.m;
        Evaluator {
            model: self,
            scratch: self.parts.scratch(),
            input: vec![0.0; s.n_inputs()],
            parts: vec![0.0; s.n_outputs()],
            kkt: vec![0.0; d * (d + 1)],
            rows: Vec::with_capacity(s.m),
            work: vec![0.0; s.m * (s.m + 1) + s.m * s.n + 2 * s.n],
        }
    }
}

/// The working memory of one evaluator of a [`Model`].
pub struct Evaluator<'a> {
    model: &'a Model,
    scratch: Scratch,
    input: Vec<f64>,
    /// The outputs `[M, f, G, b, γ, g, h]` of the last evaluation.
    pub parts: Vec<f64>,
    /// The KKT system `[K | r]` (D × (D + 1)), its solution in the last column.
    kkt: Vec<f64>,
    /// The constraints in play in the last solve (indices).
    rows: Vec<usize>,
    work: Vec<f64>,
}

impl Evaluator<'_> {
    pub fn shape(&self) -> Shape {
        self.model.shape
    }

    /// Evaluate the model's expressions at `(q, q̇, t)` with parameters `p` and inputs `u`.
    pub fn evaluate(&mut self, t: f64, q: &[f64], v: &[f64], p: &[f64], u: &[f64]) {
        let s = self.model.shape;
        let x = &mut self.input;
        x[..s.n].copy_from_slice(&q[..s.n]);
        x[s.n..2 * s.n].copy_from_slice(&v[..s.n]);
        x[2 * s.n] = t;
        x[2 * s.n + 1..2 * s.n + 1 + s.np].copy_from_slice(&p[..s.np]);
        x[2 * s.n + 1 + s.np..].copy_from_slice(&u[..s.nu]);
        self.model
            .parts
            .eval_in(&mut self.scratch, &self.input, &mut self.parts);
    }

    /// The Jacobi integral `h` of the last evaluation.
    pub fn energy(&self) -> f64 {
        self.parts[self.model.shape.at_h()]
    }

    /// Row `c` of the constraint Jacobian G of the last evaluation.
    pub fn jacobian_row(&self, c: usize) -> &[f64] {
        let s = self.model.shape;
        &self.parts[s.at_g_jac() + c * s.n..s.at_g_jac() + (c + 1) * s.n]
    }

    /// `G q̇ + b` of constraint `c` (the velocity residual) at the last evaluation.
    pub fn velocity_residual(&self, c: usize, v: &[f64]) -> f64 {
        let s = self.model.shape;
        let mut vel = self.parts[s.at_b() + c];
        for (gj, vj) in self.jacobian_row(c).iter().zip(v) {
            vel += gj * vj;
        }
        vel
    }

    /// The holonomic residual `g_c` of the last evaluation (`c < nh`).
    pub fn residual(&self, c: usize) -> f64 {
        self.parts[self.model.shape.at_g() + c]
    }

    /// Solve the KKT system of the last evaluation (made at velocity `v`) for `(q̈, λ)` with
    /// the constraints in `active` (all when `None`) and Baumgarte's gains `(α, β)` (zero: the
    /// physical multipliers). `q̈` (n) and `λ` (one per constraint in play) are then
    /// [`Evaluator::solution`]. False when the system is singular or not finite.
    pub fn solve(&mut self, v: &[f64], active: Option<&[bool]>, alpha: f64, beta: f64) -> bool {
        let s = self.model.shape;
        self.rows.clear();
        for c in 0..s.m {
            if in_play(active, c) {
                self.rows.push(c);
            }
        }
        let n = s.n;
        let d = n + self.rows.len();
        let ld = d + 1;
        let fill = |kkt: &mut [f64], parts: &[f64], rows: &[usize]| {
            for i in 0..n {
                kkt[i * ld..i * ld + n].copy_from_slice(&parts[i * n..(i + 1) * n]);
                kkt[i * ld + d] = parts[s.at_f() + i];
            }
            for (r, &c) in rows.iter().enumerate() {
                let row = &parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n];
                let mut vel = parts[s.at_b() + c];
                for j in 0..n {
                    vel += row[j] * v[j];
                    kkt[(n + r) * ld + j] = row[j];
                    kkt[j * ld + n + r] = -row[j];
                }
                for k in 0..rows.len() {
                    kkt[(n + r) * ld + n + k] = 0.0;
                }
                let mut rhs = -parts[s.at_gamma() + c] - 2.0 * alpha * vel;
                if c < s.nh {
                    rhs -= beta * beta * parts[s.at_g() + c];
                }
                kkt[(n + r) * ld + d] = rhs;
            }
        };
        fill(&mut self.kkt, &self.parts, &self.rows);
        if self.rows.is_empty() {
            // M alone: symmetric positive definite (Cholesky), else pivoted elimination
            if solve_spd_augmented(&mut self.kkt, d, ld) {
                return true;
            }
            fill(&mut self.kkt, &self.parts, &self.rows);
        }
        solve_augmented(&mut self.kkt, d, ld)
    }

    /// The solution of the last [`Evaluator::solve`]: `(q̈ (n), λ (constraints in play))`.
    pub fn solution(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.model.shape.n;
        let d = n + self.rows.len();
        let x: Vec<f64> = (0..d).map(|i| self.kkt[i * (d + 1) + d]).collect();
        (x[..n].to_vec(), x[n..].to_vec())
    }

    /// `q̈_i` of the last solve.
    #[inline]
    fn qdd(&self, i: usize) -> f64 {
        let d = self.model.shape.n + self.rows.len();
        self.kkt[i * (d + 1) + d]
    }

    /// The constraints in play in the last solve.
    pub fn rows(&self) -> &[usize] {
        &self.rows
    }

    /// Project `(q, q̇)` onto the constraints in play at `t`: Gauss–Newton with minimum-norm
    /// corrections on the holonomic residuals (at most `max_iter` steps, until
    /// `max |g| ≤ tol (1 + max |q|)`), then `q̇ ← q̇ − G⁺ (G q̇ + b)`. False when a
    /// correction cannot be computed (a singular Jacobian).
    #[allow(clippy::too_many_arguments)]
    pub fn project(
        &mut self,
        t: f64,
        q: &mut [f64],
        v: &mut [f64],
        p: &[f64],
        u: &[f64],
        active: Option<&[bool]>,
        tol: f64,
        max_iter: usize,
    ) -> bool {
        let s = self.model.shape;
        let on = |c: usize| in_play(active, c);
        let hol: Vec<usize> = (0..s.nh).filter(|&c| on(c)).collect();
        let all: Vec<usize> = (0..s.m).filter(|&c| on(c)).collect();
        if all.is_empty() {
            return true;
        }
        let mut work = std::mem::take(&mut self.work);
        let ok = self.project_with(&mut work, t, q, v, p, u, &hol, &all, tol, max_iter);
        self.work = work;
        ok
    }

    #[allow(clippy::too_many_arguments)]
    fn project_with(
        &mut self,
        work: &mut [f64],
        t: f64,
        q: &mut [f64],
        v: &mut [f64],
        p: &[f64],
        u: &[f64],
        hol: &[usize],
        all: &[usize],
        tol: f64,
        max_iter: usize,
    ) -> bool {
        let s = self.model.shape;
        let n = s.n;
        let (jw, rest) = work.split_at_mut(s.m * n);
        let (xw, rest) = rest.split_at_mut(n);
        let (rw, sw) = rest.split_at_mut(s.m);
        if !hol.is_empty() {
            for _ in 0..max_iter {
                self.evaluate(t, q, v, p, u);
                let scale = 1.0 + q.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                let worst = hol
                    .iter()
                    .fold(0.0f64, |a, &c| a.max(self.parts[s.at_g() + c].abs()));
                if worst <= tol * scale {
                    break;
                }
                for (r, &c) in hol.iter().enumerate() {
                    jw[r * n..(r + 1) * n].copy_from_slice(
                        &self.parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n],
                    );
                    rw[r] = self.parts[s.at_g() + c];
                }
                if !min_norm_solve(jw, hol.len(), n, rw, xw, sw) {
                    return false;
                }
                for i in 0..n {
                    q[i] -= xw[i];
                }
            }
        }
        self.evaluate(t, q, v, p, u);
        for (r, &c) in all.iter().enumerate() {
            jw[r * n..(r + 1) * n]
                .copy_from_slice(&self.parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n]);
            let mut vel = self.parts[s.at_b() + c];
            for j in 0..n {
                vel += jw[r * n + j] * v[j];
            }
            rw[r] = vel;
        }
        if !min_norm_solve(jw, all.len(), n, rw, xw, sw) {
            return false;
        }
        for i in 0..n {
            v[i] -= xw[i];
        }
        true
    }
}

/// True when constraint `c` is in play (`active` absent: all are).
#[inline(always)]
fn in_play(active: Option<&[bool]>, c: usize) -> bool {
    active.map_or(true, |a| a[c])
}

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

/// Where an event of a constrained system's run comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Output `k` of the compiled event expressions, a [`Function`] of `[q, q̇, t]`.
    Expression(usize),
    /// The user's callback `k` (the slow path: a Python function).
    Callback(usize),
    /// The physical multiplier λ_c of constraint `c` (numbered among all the model's
    /// constraints), which must be in play: a one-sided constraint lets go where it falls
    /// through zero (its reaction would have to pull).
    Release(usize),
}

/// Event functions the engine calls out for (the user's Python functions, in the bindings).
pub trait Callbacks {
    /// Callback `k` at `(t, y)`; `None` when it failed (its error kept by the implementor).
    fn value(&self, k: usize, t: f64, y: &[f64]) -> Option<f64>;
}

/// No callbacks: a run whose events are all compiled.
pub struct NoCallbacks;

impl Callbacks for NoCallbacks {
    fn value(&self, _: usize, _: f64, _: &[f64]) -> Option<f64> {
        None
    }
}

/// The events of a constrained system's run ([`crate::events`]), one per [`Source`], in order.
pub struct LagrangeEvents<'a, 'm, I: Inputs, C: Callbacks> {
    sys: &'a Lagrangian<'m, I>,
    sources: &'a [Source],
    expressions: Option<&'a Function>,
    callbacks: C,
    /// Per source: the index of its multiplier among the constraints in play.
    rank: Vec<usize>,
    scratch: RefCell<EventScratch>,
}

/// The expressions' working memory, inputs `[q, q̇, t]` and outputs.
type EventScratch = (Option<Scratch>, Vec<f64>, Vec<f64>);

impl<'a, 'm, I: Inputs, C: Callbacks> LagrangeEvents<'a, 'm, I, C> {
    /// Check `sources` against the system and the expressions (a function of `[q, q̇, t]`).
    pub fn new(
        sys: &'a Lagrangian<'m, I>,
        sources: &'a [Source],
        expressions: Option<&'a Function>,
        callbacks: C,
    ) -> Result<Self, String> {
        let s = sys.model.shape;
        let outputs = match expressions {
            Some(f) => {
                let p = f.program();
                if p.n_inputs != 2 * s.n + 1 {
                    return Err(format!(
                        "the events' expressions take {} values; [q, qd, t] ({}) are needed",
                        p.n_inputs,
                        2 * s.n + 1
                    ));
                }
                p.n_outputs
            }
            None => 0,
        };
        let in_play = |c: usize| sys.active.as_ref().map_or(true, |a| a[c]);
        let mut rank = vec![0; sources.len()];
        for (i, source) in sources.iter().enumerate() {
            match *source {
                Source::Expression(k) if k >= outputs => {
                    return Err(format!(
                        "event {i} is expression {k}, and the events' expressions have {outputs}"
                    ))
                }
                Source::Release(c) if c >= s.m || !in_play(c) => {
                    return Err(format!(
                        "event {i} watches the multiplier of constraint {c}, which is not in play"
                    ))
                }
                Source::Release(c) => rank[i] = (0..c).filter(|&j| in_play(j)).count(),
                _ => {}
            }
        }
        let scratch = (
            expressions.map(|f| f.scratch()),
            vec![0.0; 2 * s.n + 1],
            vec![0.0; outputs],
        );
        Ok(LagrangeEvents {
            sys,
            sources,
            expressions,
            callbacks,
            rank,
            scratch: RefCell::new(scratch),
        })
    }

    /// The compiled expressions at `(t, y)`, into the scratch's outputs.
    fn expressions_at(&self, t: f64, y: &[f64]) -> std::cell::RefMut<'_, EventScratch> {
        let mut sc = self.scratch.borrow_mut();
        if let Some(f) = self.expressions {
            let (mem, x, out) = &mut *sc;
            let dim = y.len();
            x[..dim].copy_from_slice(y);
            x[dim] = t;
            f.eval_in(mem.as_mut().expect("made with the function"), x, out);
        }
        sc
    }

    /// The physical multipliers of the constraints in play at `(t, y)` (NaN where the system
    /// is singular, or an input failed).
    fn multipliers(&self, t: f64, y: &[f64]) -> Option<Vec<f64>> {
        let n = self.sys.model.shape.n;
        self.sys
            .accelerations(t, &y[..n], &y[n..])
            .map(|(_, lam)| lam)
    }
}

impl<I: Inputs, C: Callbacks> EventFunctions for LagrangeEvents<'_, '_, I, C> {
    fn count(&self) -> usize {
        self.sources.len()
    }

    fn value(&self, k: usize, t: f64, y: &[f64]) -> Option<f64> {
        Some(match self.sources[k] {
            Source::Expression(j) => self.expressions_at(t, y).2[j],
            Source::Callback(j) => return self.callbacks.value(j, t, y),
            Source::Release(_) => self
                .multipliers(t, y)
                .map_or(f64::NAN, |lam| lam[self.rank[k]]),
        })
    }

    fn values(&self, t: f64, y: &[f64], out: &mut [f64]) -> bool {
        let has = |f: fn(&Source) -> bool| self.sources.iter().any(f);
        let lam = if has(|s| matches!(s, Source::Release(_))) {
            self.multipliers(t, y)
        } else {
            None
        };
        let sc = has(|s| matches!(s, Source::Expression(_))).then(|| self.expressions_at(t, y));
        for (k, o) in out.iter_mut().enumerate() {
            *o = match self.sources[k] {
                Source::Expression(j) => sc.as_ref().expect("evaluated above").2[j],
                Source::Callback(j) => match self.callbacks.value(j, t, y) {
                    Some(v) => v,
                    None => return false,
                },
                Source::Release(_) => lam.as_ref().map_or(f64::NAN, |l| l[self.rank[k]]),
            };
        }
        true
    }
}

/// What the post-processing of samples gives, per sample: `q̈ (n)`, the physical `λ (m)` (NaN
/// for a constraint not in play), `Gᵀλ (n)`, `g (nh)`, `G q̇ + b (m)` and `h`.
pub struct SampleOut<'a> {
    pub qdd: &'a mut [f64],
    pub lam: &'a mut [f64],
    pub forces: &'a mut [f64],
    pub g: &'a mut [f64],
    pub velocity: &'a mut [f64],
    pub energy: &'a mut [f64],
}

/// The accelerations, physical multipliers, generalized constraint forces `Gᵀλ`, residuals
/// and energy at every sample: `t` (S), `y` (S · 2n), inputs `u` (S · nu), parameters `p`.
#[allow(clippy::too_many_arguments)]
pub fn samples(
    model: &Model,
    t: &[f64],
    y: &[f64],
    p: &[f64],
    u: &[f64],
    active: Option<&[bool]>,
    out: SampleOut,
) {
    let s = model.shape;
    let n = s.n;
    let samples_of = |i0: usize, ev: &mut Evaluator, out: &mut SampleOut, len: usize| {
        for k in 0..len {
            let i = i0 + k;
            let (q, v) = y[i * 2 * n..(i + 1) * 2 * n].split_at(n);
            ev.evaluate(t[i], q, v, p, &u[i * s.nu..(i + 1) * s.nu]);
            for c in 0..s.nh {
                out.g[k * s.nh + c] = ev.residual(c);
            }
            for c in 0..s.m {
                out.velocity[k * s.m + c] = ev.velocity_residual(c, v);
            }
            out.energy[k] = ev.energy();
            let ok = ev.solve(v, active, 0.0, 0.0);
            let d = n + ev.rows.len();
            let x = |j: usize| {
                if ok {
                    ev.kkt[j * (d + 1) + d]
                } else {
                    f64::NAN
                }
            };
            for j in 0..n {
                out.qdd[k * n + j] = x(j);
            }
            out.lam[k * s.m..(k + 1) * s.m].fill(f64::NAN);
            out.forces[k * n..(k + 1) * n].fill(0.0);
            for (r, &c) in ev.rows.iter().enumerate() {
                let lam = x(n + r);
                out.lam[k * s.m + c] = lam;
                let row = &ev.parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n];
                for j in 0..n {
                    out.forces[k * n + j] += row[j] * lam;
                }
            }
        }
    };
    let mut ev = model.evaluator();
    let mut out = out;
    samples_of(0, &mut ev, &mut out, t.len());
}

/// The method of a run: DOP853 or an explicit tableau (RK4 as its tableau); the methods that
/// need a rigid body's structure are refused at the boundary ([`crate::spec::RunSpec::check_for`]).
pub use crate::spec::Method;

/// How a member's run ended, with its counters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemberRun {
    pub status: Status,
    pub n_steps: u64,
    pub n_fev: u64,
}

use crate::drivers::STEPS_PER_CALL;

/// The one-sided constraints of a run: their indices among the model's constraints, and the
/// detection grid's number of points (`event_resolution`): a phase from `ta` detects releases
/// at points no further apart than `(t1 − ta)/(resolution − 1)` ([`crate::events::Watch`]).
#[derive(Clone, Copy, Debug)]
pub struct OneSided<'a> {
    pub constraints: &'a [usize],
    pub resolution: usize,
}

impl OneSided<'_> {
    /// No one-sided constraint.
    pub const NONE: OneSided<'static> = OneSided {
        constraints: &[],
        resolution: 2,
    };
}

/// Integrate one member: parameters `p`, constant inputs `u`, initial state `y0` (2n), its
/// samples at `t_eval` into `samples` (len(t_eval) · 2n; NaN when the run fails). A run that
/// takes `max_steps` steps before its end stops there, with the status
/// [`Status::Running`] (NaN samples), as one stopped by `stop`.
#[allow(clippy::too_many_arguments)]
pub fn run_member(
    model: &Model,
    p: &[f64],
    u: &[f64],
    y0: &[f64],
    stabilization: Stabilization,
    method: Method,
    t0: f64,
    t1: f64,
    dt: f64,
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
) -> MemberRun {
    let span = (t0, t1, dt);
    run_member_with(
        model,
        p,
        u,
        y0,
        stabilization,
        method,
        span,
        t_eval,
        samples,
        max_steps,
        stop,
        OneSided::NONE,
        &mut [],
    )
}

/// [`run_member`] with one-sided constraints: the run goes in phases, as a single run of the
/// Python package does. In each, the multiplier of every one-sided constraint in play is
/// watched ([`LagrangeEvents`], [`Source::Release`]); where one falls through zero the phase
/// ends at that instant (located inside the time loop), the constraint leaves the system and
/// the next phase starts there afresh (a new step-size choice, the samples from there on), at
/// most `max_steps` steps each. `releases` (one per one-sided constraint) gets the release
/// times, NaN for a constraint that held. `span` is `(t0, t1, dt)`.
#[allow(clippy::too_many_arguments)]
pub fn run_member_with(
    model: &Model,
    p: &[f64],
    u: &[f64],
    y0: &[f64],
    stabilization: Stabilization,
    method: Method,
    span: (f64, f64, f64),
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
    one_sided: OneSided,
    releases: &mut [f64],
) -> MemberRun {
    let (t0, t1, dt) = span;
    releases.fill(f64::NAN);
    let failed = |samples: &mut [f64]| {
        samples.fill(f64::NAN);
        MemberRun {
            status: Status::NonFinite,
            n_steps: 0,
            n_fev: 0,
        }
    };
    let s = model.shape;
    if one_sided.constraints.iter().any(|&c| c >= s.m) {
        return failed(samples);
    }
    let dim = 2 * s.n;
    let mut times = vec![0.0; t_eval.len()];
    let mut z = y0.to_vec();
    let mut active = vec![true; s.m];
    let (mut ta, mut written) = (t0, 0usize);
    let (mut n_steps, mut n_fev) = (0u64, 0u64);
    let status = loop {
        let mask = active
            .iter()
            .all(|&a| a)
            .then_some(())
            .map_or(Some(active.clone()), |_| None);
        let sys = match Lagrangian::new(model, p, Constant(u), stabilization, mask) {
            Ok(sys) => sys,
            Err(_) => return failed(samples),
        };
        let watched: Vec<Source> = one_sided
            .constraints
            .iter()
            .filter(|&&c| active[c])
            .map(|&c| Source::Release(c))
            .collect();
        let out = Output {
            t: &mut times[written..],
            y: &mut samples[written * dim..],
        };
        let sampling = Sampling {
            t_end: t1,
            t_eval: &t_eval[written..],
            every: u64::MAX,
        };
        let mut phase = Phase {
            clock: Clock { t: ta, h: 0.0 },
            counters: Counters::default(),
        };
        let status = if watched.is_empty() {
            phase.run(
                &sys,
                &mut NoObserver,
                method,
                dt,
                &mut z,
                sampling,
                out,
                max_steps,
                stop,
            )
        } else {
            let events = LagrangeEvents::new(&sys, &watched, None, NoCallbacks)
                .expect("constraints in play");
            let terminal = vec![true; watched.len()];
            let direction = vec![-1.0; watched.len()];
            let spacing = (t1 - ta) / (one_sided.resolution.max(2) - 1) as f64;
            let mut watch = Watch::new(&events, &terminal, &direction, spacing, dim);
            let status = phase.run(
                &sys, &mut watch, method, dt, &mut z, sampling, out, max_steps, stop,
            );
            if status == Status::Terminated {
                let t = phase.clock.t;
                let last = watch.log.iter().rev().find(|c| c.t == t).map(|c| c.event);
                if let Some(Source::Release(c)) = last.map(|e| watched[e]) {
                    active[c] = false;
                    if let Some(slot) = one_sided.constraints.iter().position(|&k| k == c) {
                        releases[slot] = t;
                    }
                }
            }
            status
        };
        n_steps += phase.counters.n_steps;
        n_fev += phase.counters.n_fev;
        written += phase.counters.n_out;
        ta = phase.clock.t;
        if status != Status::Terminated {
            break status;
        }
    };
    if status != Status::Finished {
        samples.fill(f64::NAN);
    }
    MemberRun {
        status,
        n_steps,
        n_fev,
    }
}

/// One phase of a member's run: its clock and counters (fresh at its start).
struct Phase {
    clock: Clock,
    counters: Counters,
}

impl Phase {
    /// Run the phase to its end (or a terminal event, `max_steps` steps, `stop`), in chunks
    /// of [`STEPS_PER_CALL`] steps between looks at `stop`.
    #[allow(clippy::too_many_arguments)]
    fn run<S: VectorField, O: Observer>(
        &mut self,
        sys: &S,
        observer: &mut O,
        method: Method,
        dt: f64,
        z: &mut [f64],
        sampling: Sampling,
        out: Output,
        max_steps: u64,
        stop: &AtomicBool,
    ) -> Status {
        let mut f = vec![0.0; sys.dim()];
        let mut run = Run {
            spec: RunSpec {
                method,
                dt,
                sampling,
                max_steps,
            },
            clock: &mut self.clock,
            z,
            f: &mut f,
            out,
            counters: &mut self.counters,
        };
        loop {
            let chunk = STEPS_PER_CALL.min(max_steps.saturating_sub(run.counters.n_steps));
            let s = run.chunk(sys, observer, chunk);
            if s != Status::Running
                || stop.load(Ordering::Relaxed)
                || run.counters.n_steps >= max_steps
            {
                break s;
            }
        }
    }
}

/// Run members `P` (members · np), `U` (members · nu), `Y0` (members · 2n) in parallel on the
/// current rayon pool; member `i`'s samples into `samples[i]` (len(t_eval) · 2n). Each member
/// depends on its own data only, so its result is the same bit for bit whatever the chunking
/// or the number of threads, and equal to a single run of it.
#[allow(clippy::too_many_arguments)]
pub fn run_members(
    model: &Model,
    params: &[f64],
    inputs: &[f64],
    y0: &[f64],
    stabilization: Stabilization,
    method: Method,
    t0: f64,
    t1: f64,
    dt: f64,
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
) -> Vec<MemberRun> {
    let span = (t0, t1, dt);
    run_members_with(
        model,
        (params, inputs, y0),
        stabilization,
        method,
        span,
        t_eval,
        samples,
        max_steps,
        stop,
        OneSided::NONE,
        &mut [],
    )
}

/// [`run_members`] with one-sided constraints ([`run_member_with`]): `data` is
/// `(P, U, Y0)`; member `i`'s release times go to `releases[i]` (one per one-sided
/// constraint).
#[allow(clippy::too_many_arguments)]
pub fn run_members_with(
    model: &Model,
    data: (&[f64], &[f64], &[f64]),
    stabilization: Stabilization,
    method: Method,
    span: (f64, f64, f64),
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
    one_sided: OneSided,
    releases: &mut [f64],
) -> Vec<MemberRun> {
    let (params, inputs, y0) = data;
    let s = model.shape;
    let dim = 2 * s.n;
    let per = t_eval.len() * dim;
    let k = one_sided.constraints.len();
    let members = samples.len() / per.max(1);
    // without one-sided constraints, a slot per member that nothing reads
    let mut none = vec![0.0; if k == 0 { members } else { 0 }];
    let releases = if k == 0 { &mut none[..] } else { releases };
    samples
        .par_chunks_mut(per.max(1))
        .zip(releases.par_chunks_mut(k.max(1)))
        .enumerate()
        .map(|(i, (rows, released))| {
            if stop.load(Ordering::Relaxed) {
                rows.fill(f64::NAN);
                released.fill(f64::NAN);
                return MemberRun {
                    status: Status::Running,
                    n_steps: 0,
                    n_fev: 0,
                };
            }
            run_member_with(
                model,
                &params[i * s.np..(i + 1) * s.np],
                &inputs[i * s.nu..(i + 1) * s.nu],
                &y0[i * dim..(i + 1) * dim],
                stabilization,
                method,
                span,
                t_eval,
                rows,
                max_steps,
                stop,
                one_sided,
                &mut released[..k],
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::{run_adaptive, run_fixed, Erk};
    use crate::expressions::{Interpreter, ADD, CONST, INPUT, MUL, OUTPUT, UNARY};
    use crate::steppers::{Control, Tableau};
    use crate::tableaux::{RK4_A, RK4_B, RK4_C};

    /// A postfix program from a little stack language: each item an instruction.
    fn program(items: &[(i64, f64)], shape: Shape) -> Program {
        let (c, v): (Vec<i64>, Vec<f64>) = items.iter().copied().unzip();
        Program::new(&c, &v, shape.n_inputs(), shape.n_outputs()).unwrap()
    }

    /// The planar pendulum in Cartesian coordinates (x, y): mass m = p0, length l = p1,
    /// gravity g = p2 along −y. L = m/2 (ẋ² + ẏ²) − m g y, one holonomic constraint
    /// g = (x² + y² − l²)/2, G = [x, y], b = 0, γ = ẋ² + ẏ², h = m/2 (ẋ² + ẏ²) + m g y.
    fn cartesian_pendulum() -> Model {
        signed_pendulum(1.0)
    }

    /// The Cartesian pendulum with its constraint times `sign`: −1 gives a string,
    /// (l² − x² − y²)/2 ≥ 0, whose multiplier λ = T/l is positive while it pulls and falls
    /// through zero where it goes slack.
    fn signed_pendulum(sign: f64) -> Model {
        let shape = Shape {
            n: 2,
            m: 1,
            nh: 1,
            np: 3,
            nu: 0,
        };
        // inputs: x0 = x, x1 = y, x2 = ẋ, x3 = ẏ, x4 = t, x5 = m, x6 = l, x7 = g
        let i = |k: usize| (INPUT, k as f64);
        let sq = |k: usize| [i(k), i(k), (MUL, 0.0)];
        let mut p: Vec<(i64, f64)> = vec![];
        // M = [[m, 0], [0, m]]
        p.extend([i(5), (OUTPUT, 0.0), (CONST, 0.0), (OUTPUT, 0.0)]);
        p.extend([(CONST, 0.0), (OUTPUT, 0.0), i(5), (OUTPUT, 0.0)]);
        // f = [0, −m g]
        p.extend([(CONST, 0.0), (OUTPUT, 0.0)]);
        p.extend([
            (CONST, -1.0),
            i(5),
            (MUL, 0.0),
            i(7),
            (MUL, 0.0),
            (OUTPUT, 0.0),
        ]);
        // G = sign · [x, y]; b = 0
        p.extend([(CONST, sign), i(0), (MUL, 0.0), (OUTPUT, 0.0)]);
        p.extend([(CONST, sign), i(1), (MUL, 0.0), (OUTPUT, 0.0)]);
        p.extend([(CONST, 0.0), (OUTPUT, 0.0)]);
        // γ = sign · (ẋ² + ẏ²)
        p.push((CONST, sign));
        p.extend(sq(2));
        p.extend(sq(3));
        p.extend([(ADD, 0.0), (MUL, 0.0), (OUTPUT, 0.0)]);
        // g = sign · (x² + y² − l²)/2
        p.push((CONST, sign));
        p.extend(sq(0));
        p.extend(sq(1));
        p.push((ADD, 0.0));
        p.extend([(CONST, -1.0)]);
        p.extend(sq(6));
        p.extend([
            (MUL, 0.0),
            (ADD, 0.0),
            (CONST, 0.5),
            (MUL, 0.0),
            (MUL, 0.0),
            (OUTPUT, 0.0),
        ]);
        // h = m/2 (ẋ² + ẏ²) + m g y
        p.extend(sq(2));
        p.extend(sq(3));
        p.extend([(ADD, 0.0), i(5), (MUL, 0.0), (CONST, 0.5), (MUL, 0.0)]);
        p.extend([
            i(5),
            i(7),
            (MUL, 0.0),
            i(1),
            (MUL, 0.0),
            (ADD, 0.0),
            (OUTPUT, 0.0),
        ]);
        Model::new(shape, program(&p, shape), &Interpreter).unwrap()
    }

    /// The pendulum in its angle θ (from the downward vertical): m l² θ̈ = −m g l sin θ, as a
    /// model with no constraint: M = [m l²], f = [−m g l sin θ], h = m l² θ̇²/2 − m g l cos θ.
    fn angle_pendulum() -> Model {
        let shape = Shape {
            n: 1,
            m: 0,
            nh: 0,
            np: 3,
            nu: 0,
        };
        // inputs: x0 = θ, x1 = θ̇, x2 = t, x3 = m, x4 = l, x5 = g
        let i = |k: usize| (INPUT, k as f64);
        let mut p = vec![i(3), i(4), (MUL, 0.0), i(4), (MUL, 0.0), (OUTPUT, 0.0)];
        p.extend([
            (CONST, -1.0),
            i(3),
            (MUL, 0.0),
            i(5),
            (MUL, 0.0),
            i(4),
            (MUL, 0.0),
        ]);
        p.extend([i(0), (UNARY, 0.0), (MUL, 0.0), (OUTPUT, 0.0)]);
        p.extend([
            i(3),
            i(4),
            (MUL, 0.0),
            i(4),
            (MUL, 0.0),
            i(1),
            i(1),
            (MUL, 0.0),
        ]);
        p.extend([(MUL, 0.0), (CONST, 0.5), (MUL, 0.0)]);
        p.extend([
            (CONST, -1.0),
            i(3),
            (MUL, 0.0),
            i(5),
            (MUL, 0.0),
            i(4),
            (MUL, 0.0),
        ]);
        p.extend([
            i(0),
            (UNARY + 1, 0.0),
            (MUL, 0.0),
            (ADD, 0.0),
            (OUTPUT, 0.0),
        ]);
        Model::new(shape, program(&p, shape), &Interpreter).unwrap()
    }

    const P: [f64; 3] = [2.0, 1.5, 9.81];

    /// The bob at the bottom with l ω0²/g = 7/2 (a string goes slack at cos θ = −1/2), and
    /// the projection onto the constraints in play after every step.
    fn slack_launch() -> ([f64; 4], Stabilization) {
        let (l, g) = (P[1], P[2]);
        let w0 = (3.5 * g / l).sqrt();
        let st = Stabilization {
            alpha: 0.0,
            beta: 0.0,
            projection: true,
        };
        ([0.0, -l, l * w0, 0.0], st)
    }

    /// DOP853 at rtol 1e-11, atol 1e-12 with SciPy's controller constants.
    fn tight_control() -> Control {
        Control {
            rtol: 1e-11,
            atol: 1e-12,
            safety: 0.9,
            min_factor: 0.2,
            max_factor: 10.0,
            max_step: f64::INFINITY,
            first_step: 0.0,
        }
    }

    /// The rod's tension from Newton's law at the bob: along the rod, m v²/l + m g cos θ; the
    /// multiplier of g = (x² + y² − l²)/2 is then −T/l (the generalized force Gᵀλ = λ (x, y)
    /// points along the position, the tension inwards).
    #[test]
    fn multiplier_is_the_rod_tension_and_accelerations_are_newtons() {
        let model = cartesian_pendulum();
        let (m, l, g) = (P[0], P[1], P[2]);
        let th: f64 = 0.7;
        let w: f64 = 1.3; // θ̇
        let q = [l * th.sin(), -l * th.cos()];
        let v = [l * w * th.cos(), l * w * th.sin()];
        let sys = Lagrangian::new(
            &model,
            &P,
            Constant(&[]),
            Stabilization {
                alpha: 0.0,
                beta: 0.0,
                projection: false,
            },
            None,
        )
        .unwrap();
        let (qdd, lam) = sys.accelerations(0.0, &q, &v).unwrap();
        let tension = m * l * w * w + m * g * th.cos();
        assert!((lam[0] + tension / l).abs() < 1e-12, "{lam:?}");
        // θ̈ = −(g/l) sin θ: the tangential acceleration l θ̈ (cos θ, sin θ) plus the
        // centripetal −l θ̇² (sin θ, −cos θ)
        let thdd = -(g / l) * th.sin();
        let want = [
            l * thdd * th.cos() - l * w * w * th.sin(),
            l * thdd * th.sin() + l * w * w * th.cos(),
        ];
        for k in 0..2 {
            assert!((qdd[k] - want[k]).abs() < 1e-12, "{qdd:?} {want:?}");
        }
    }

    /// The Cartesian pendulum integrated with Baumgarte's terms (DOP853) follows the angle
    /// model, conserves its energy, and keeps its constraint.
    #[test]
    fn cartesian_and_angle_models_move_alike() {
        let cart = cartesian_pendulum();
        let ang = angle_pendulum();
        let l = P[1];
        let th0: f64 = 1.1;
        let t_eval: Vec<f64> = (0..=20).map(|k| k as f64 * 0.25).collect();
        let control = tight_control();
        let stop = AtomicBool::new(false);
        let st = Stabilization {
            alpha: 10.0,
            beta: 10.0,
            projection: false,
        };
        let mut a = vec![0.0; t_eval.len() * 4];
        let y0 = [l * th0.sin(), -l * th0.cos(), 0.0, 0.0];
        let run = run_member(
            &cart,
            &P,
            &[],
            &y0,
            st,
            Method::Dop853(control),
            0.0,
            5.0,
            0.0,
            &t_eval,
            &mut a,
            u64::MAX,
            &stop,
        );
        assert_eq!(run.status, Status::Finished);
        let mut b = vec![0.0; t_eval.len() * 2];
        let run = run_member(
            &ang,
            &P,
            &[],
            &[th0, 0.0],
            st,
            Method::Dop853(control),
            0.0,
            5.0,
            0.0,
            &t_eval,
            &mut b,
            u64::MAX,
            &stop,
        );
        assert_eq!(run.status, Status::Finished);
        for k in 0..t_eval.len() {
            let th = b[2 * k];
            let (x, y) = (a[4 * k], a[4 * k + 1]);
            assert!((x - l * th.sin()).abs() < 1e-8, "t = {}", t_eval[k]);
            assert!((y + l * th.cos()).abs() < 1e-8, "t = {}", t_eval[k]);
        }
        // energy and constraint along the Cartesian run
        let s = cart.shape;
        let sn = t_eval.len();
        let (mut qdd, mut lam, mut f, mut g, mut vel, mut e) = (
            vec![0.0; sn * 2],
            vec![0.0; sn],
            vec![0.0; sn * 2],
            vec![0.0; sn],
            vec![0.0; sn],
            vec![0.0; sn],
        );
        samples(
            &cart,
            &t_eval,
            &a,
            &P,
            &vec![0.0; sn * s.nu],
            None,
            SampleOut {
                qdd: &mut qdd,
                lam: &mut lam,
                forces: &mut f,
                g: &mut g,
                velocity: &mut vel,
                energy: &mut e,
            },
        );
        for k in 0..sn {
            assert!((e[k] - e[0]).abs() < 1e-8 * e[0].abs().max(1.0));
            assert!(g[k].abs() < 1e-9 && vel[k].abs() < 1e-8);
            // Gᵀλ = λ (x, y)
            assert!((f[2 * k] - lam[k] * a[4 * k]).abs() < 1e-12);
        }
    }

    /// Projection puts a state back on the constraint: |q| = l and q · q̇ = 0.
    #[test]
    fn projection_restores_the_constraints() {
        let model = cartesian_pendulum();
        let l = P[1];
        let mut ev = model.evaluator();
        let mut q = [1.2 * l * 0.6, -1.1 * l * 0.8];
        let mut v = [0.3, 0.9];
        assert!(ev.project(0.0, &mut q, &mut v, &P, &[], None, 1e-13, 20));
        let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
        assert!((r - l).abs() < 1e-12, "{r}");
        assert!((q[0] * v[0] + q[1] * v[1]).abs() < 1e-12);
        // a released constraint is left alone
        let mut q2 = [2.0, 0.1];
        let mut v2 = [0.3, 0.9];
        assert!(ev.project(0.0, &mut q2, &mut v2, &P, &[], Some(&[false]), 1e-13, 20));
        assert_eq!((q2, v2), ([2.0, 0.1], [0.3, 0.9]));
    }

    /// Members of an ensemble equal single runs, bit for bit; small oscillations of the angle
    /// pendulum have the period 2π √(l/g).
    #[test]
    fn members_equal_single_runs_and_small_oscillations_have_their_period() {
        let model = angle_pendulum();
        let tab = Tableau {
            a: &RK4_A.concat(),
            b: &RK4_B,
            c: &RK4_C,
        };
        let ls = [0.5, 1.0, 2.0];
        let params: Vec<f64> = ls.iter().flat_map(|&l| [1.0, l, 9.81]).collect();
        let y0: Vec<f64> = ls.iter().flat_map(|_| [1e-4, 0.0]).collect();
        let st = Stabilization {
            alpha: 0.0,
            beta: 0.0,
            projection: false,
        };
        let t_eval: Vec<f64> = (0..=400).map(|k| k as f64 * 0.01).collect();
        let mut all = vec![0.0; 3 * t_eval.len() * 2];
        let stop = AtomicBool::new(false);
        let runs = run_members(
            &model,
            &params,
            &[],
            &y0,
            st,
            Method::Erk(tab),
            0.0,
            4.0,
            1e-3,
            &t_eval,
            &mut all,
            u64::MAX,
            &stop,
        );
        assert!(runs.iter().all(|r| r.status == Status::Finished));
        // a budget below the run's 4000 steps stops every member there
        let mut cut = vec![0.0; all.len()];
        let runs = run_members(
            &model,
            &params,
            &[],
            &y0,
            st,
            Method::Erk(tab),
            0.0,
            4.0,
            1e-3,
            &t_eval,
            &mut cut,
            1000,
            &stop,
        );
        assert!(runs
            .iter()
            .all(|r| r.status == Status::Running && r.n_steps == 1000));
        assert!(cut.iter().all(|x| x.is_nan()));
        for (i, &l) in ls.iter().enumerate() {
            let mut one = vec![0.0; t_eval.len() * 2];
            run_member(
                &model,
                &params[3 * i..3 * i + 3],
                &[],
                &y0[2 * i..2 * i + 2],
                st,
                Method::Erk(tab),
                0.0,
                4.0,
                1e-3,
                &t_eval,
                &mut one,
                u64::MAX,
                &stop,
            );
            assert_eq!(&all[i * one.len()..(i + 1) * one.len()], &one[..]);
            // θ(t) = θ0 cos(√(g/l) t) to second order in θ0
            let w = (9.81 / l).sqrt();
            for (k, &t) in t_eval.iter().enumerate() {
                assert!((one[2 * k] - 1e-4 * (w * t).cos()).abs() < 1e-10);
            }
        }
    }

    #[test]
    fn bad_models_are_refused() {
        let shape = Shape {
            n: 1,
            m: 0,
            nh: 0,
            np: 0,
            nu: 0,
        };
        let p = Program::new(&[INPUT, OUTPUT], &[0.0, 0.0], 3, 1).unwrap();
        assert!(Model::new(shape, p, &Interpreter).is_err()); // 1 output, 3 needed
        let bad = Shape { nh: 2, ..shape };
        let p = Program::new(&[INPUT, OUTPUT], &[0.0, 0.0], 3, 1).unwrap();
        assert!(Model::new(bad, p, &Interpreter).is_err());
        let m = angle_pendulum();
        assert!(Lagrangian::new(
            &m,
            &[1.0],
            Constant(&[]),
            Stabilization {
                alpha: 0.0,
                beta: 0.0,
                projection: false
            },
            None
        )
        .is_err());
    }

    /// A singular system (zero mass) makes NaN rates, not a panic.
    #[test]
    fn a_singular_system_gives_nan() {
        let m = angle_pendulum();
        let sys = Lagrangian::new(
            &m,
            &[0.0, 1.0, 9.81],
            Constant(&[]),
            Stabilization {
                alpha: 0.0,
                beta: 0.0,
                projection: false,
            },
            None,
        )
        .unwrap();
        let mut out = [0.0; 2];
        sys.rhs(0.0, &[0.3, 0.0], &mut out);
        assert!(out[1].is_nan());
    }

    /// A pendulum on a string (the Cartesian pendulum) launched from the bottom with
    /// l ω0²/g = 7/2: the string goes slack where the tension m l ω² + m g cos θ vanishes, at
    /// cos θ = (2 − l ω0²/g)/3 = −1/2 by the energy (the multiplier λ = −T/l rises through
    /// zero there). The watch locates it inside the driver's loop, with both fixed-step RK4
    /// and DOP853; an expression event (y rising through 0: the bob at the pivot's height)
    /// is logged on the way, and the terminal release ends the run there.
    #[test]
    fn a_string_goes_slack_where_the_energy_says() {
        use crate::drivers::{Output, Sampling};
        use crate::events::Watch;
        let model = cartesian_pendulum();
        let l = P[1];
        let (y0, st) = slack_launch();
        let sys = Lagrangian::new(&model, &P, Constant(&[]), st, None).unwrap();
        // the expression y (input 1 of [x, y, ẋ, ẏ, t])
        let height = Function::compile(
            Program::new(&[INPUT, OUTPUT], &[1.0, 0.0], 5, 1).unwrap(),
            &Interpreter,
        );
        let sources = [Source::Expression(0), Source::Release(0)];
        let events = LagrangeEvents::new(&sys, &sources, Some(&height), NoCallbacks).unwrap();
        let (terminal, direction) = ([false, true], [1.0, 1.0]);
        let t_eval: Vec<f64> = (0..=40).map(|k| k as f64 * 0.05).collect();
        let control = tight_control();
        for adaptive in [false, true] {
            let mut watch = Watch::new(&events, &terminal, &direction, 0.01, 4);
            let (mut ts, mut ys) = (vec![0.0; t_eval.len()], vec![0.0; t_eval.len() * 4]);
            let mut out = Output {
                t: &mut ts,
                y: &mut ys,
            };
            let sampling = Sampling {
                t_end: 2.0,
                t_eval: &t_eval,
                every: 1,
            };
            let mut clock = Clock { t: 0.0, h: 0.0 };
            let mut k = Counters::default();
            let mut z = y0.to_vec();
            let status = if adaptive {
                let mut f = vec![0.0; 4];
                run_adaptive(
                    &sys,
                    &mut watch,
                    &mut clock,
                    &mut z,
                    &mut f,
                    &control,
                    &sampling,
                    &mut out,
                    &mut k,
                    u64::MAX,
                )
            } else {
                let flat = RK4_A.concat();
                let tab = Tableau {
                    a: &flat,
                    b: &RK4_B,
                    c: &RK4_C,
                };
                let mut m = Erk::new(tab, 4);
                run_fixed(
                    &sys,
                    &mut m,
                    &mut watch,
                    &mut clock,
                    &mut z,
                    1e-3,
                    &sampling,
                    &mut out,
                    &mut k,
                    u64::MAX,
                )
            };
            assert_eq!(status, Status::Terminated, "adaptive: {adaptive}");
            let log = &watch.log;
            assert_eq!(log.len(), 2, "{log:?}");
            let (up, slack) = (&log[0], &log[1]);
            assert_eq!((up.event, slack.event), (0, 1));
            assert!(up.y[1].abs() < 1e-12 && up.t < slack.t);
            // cos θ = −y/l = −1/2 at the release, the run's end
            let tol = if adaptive { 1e-9 } else { 1e-8 };
            assert!((-slack.y[1] / l + 0.5).abs() < tol, "{:?}", slack.y);
            assert_eq!((clock.t, &z[..]), (slack.t, &slack.y[..]));
            let lam = sys.accelerations(slack.t, &z[..2], &z[2..]).unwrap().1[0];
            assert!(lam.abs() < 1e-8, "{lam}");
            // samples up to the release only
            assert!(k.n_out < t_eval.len() && t_eval[k.n_out - 1] <= slack.t);
        }
    }

    /// A member whose string goes slack ([`run_member_with`], the constraint one-sided): the
    /// release where the energy puts it (cos θ = −1/2 for l ω0²/g = 7/2, as
    /// `a_string_goes_slack_where_the_energy_says`), and after it a free fall: every later
    /// sample on the parabola from the release state. A two-sided rod keeps the bob on its
    /// circle instead.
    #[test]
    fn a_slack_string_lets_the_bob_fall_freely() {
        let model = signed_pendulum(-1.0);
        let (l, g) = (P[1], P[2]);
        let (y0, st) = slack_launch();
        let t_eval: Vec<f64> = (0..=30).map(|k| k as f64 * 0.05).collect();
        let stop = AtomicBool::new(false);
        let mut samples = vec![0.0; t_eval.len() * 4];
        let mut released = [0.0];
        let one_sided = OneSided {
            constraints: &[0],
            resolution: 2001,
        };
        let run = run_member_with(
            &model,
            &P,
            &[],
            &y0,
            st,
            Method::Dop853(tight_control()),
            (0.0, 1.5, 0.0),
            &t_eval,
            &mut samples,
            u64::MAX,
            &stop,
            one_sided,
            &mut released,
        );
        assert_eq!(run.status, Status::Finished);
        let tr = released[0];
        assert!(tr > 0.0 && tr < 1.5, "{tr}");
        // a run with the rod (the constraint two-sided) from the same start
        let rod_run = |t1: f64, t_eval: &[f64], out: &mut [f64]| {
            let control = Method::Dop853(tight_control());
            run_member(
                &model,
                &P,
                &[],
                &y0,
                st,
                control,
                0.0,
                t1,
                0.0,
                t_eval,
                out,
                u64::MAX,
                &stop,
            )
        };
        // the state at the release (the rod pulls until then)
        let mut rod = [0.0; 4];
        rod_run(tr, &[tr], &mut rod);
        let cos = -rod[1] / l;
        assert!((cos + 0.5).abs() < 1e-9, "cos θ at the release: {cos}");
        for (k, &t) in t_eval.iter().enumerate() {
            let s = &samples[4 * k..4 * k + 4];
            let r = (s[0] * s[0] + s[1] * s[1]).sqrt();
            if t < tr {
                assert!((r - l).abs() < 1e-9, "taut at t = {t}: r = {r}");
            } else {
                let d = t - tr;
                let x = rod[0] + rod[2] * d;
                let y = rod[1] + rod[3] * d - g * d * d / 2.0;
                let off = (s[0] - x).abs().max((s[1] - y).abs());
                assert!(off < 1e-8, "t = {t}: {off} off the parabola");
                assert!(r < l, "slack at t = {t}: r = {r}");
            }
        }
        // without the one-sided constraint the rod holds the bob on its circle
        rod_run(1.5, &t_eval, &mut samples);
        let last = &samples[samples.len() - 4..];
        assert!(((last[0] * last[0] + last[1] * last[1]).sqrt() - l).abs() < 1e-9);
    }
}
