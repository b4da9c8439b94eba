//! A constrained model and its mathematics (\[L\] eqs (6.55)–(6.60), `docs/lagrange.md`): the
//! sizes ([`Shape`]) and compiled expressions `[M, f, G, b, γ, g, h]` of a model ([`Model`]),
//! and the working memory that evaluates them ([`Evaluator`]): the index-1 (KKT) system
//! `[[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; −γ − s]` (\[L\] (6.60)) with Baumgarte's stabilisation
//! `s = 2α (G q̇ + b) + β² g`, the projection onto the constraints (Gauss–Newton with
//! minimum-norm corrections on `g(q) = 0`, then `q̇ ← q̇ − G⁺ (G q̇ + b)`), and the physical
//! multipliers, generalized constraint forces `Gᵀλ`, residuals and energy at samples
//! ([`samples`]).

use crate::expressions::{Compiler, Function, Program, Scratch};
use crate::linalg::{min_norm_solve, solve_augmented, solve_spd_augmented};

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
    /// The directions a model's Jacobian is taken along: `[q (n), q̇ (n), p (np), u (nu)]`.
    pub fn n_directions(&self) -> usize {
        2 * self.n + self.np + self.nu
    }
    /// The model's numbers a direction moves besides the state: `[p (np), u (nu)]`.
    pub fn n_numbers(&self) -> usize {
        self.np + self.nu
    }
    /// The outputs of a model's [`Tangent`]: `[M, f, G, b, γ, g, h]`, then the Jacobian of
    /// `[M, f, G, b, γ, g]` (all but `h`) along `[q, q̇, p, u]`, row-major (one row of
    /// [`Shape::n_directions`] numbers per output).
    pub fn n_tangent_outputs(&self) -> usize {
        self.n_outputs() + (self.n_outputs() - 1) * self.n_directions()
    }
    pub(super) fn at_f(&self) -> usize {
        self.n * self.n
    }
    pub(super) fn at_g_jac(&self) -> usize {
        self.at_f() + self.n
    }
    pub(super) fn at_b(&self) -> usize {
        self.at_g_jac() + self.m * self.n
    }
    pub(super) fn at_gamma(&self) -> usize {
        self.at_b() + self.m
    }
    pub(super) fn at_g(&self) -> usize {
        self.at_gamma() + self.m
    }
    pub(super) fn at_h(&self) -> usize {
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
        Evaluator::of(self.shape, &self.parts)
    }
}

/// A model's expressions with their Jacobian (\[L\] (6.60) differentiated,
/// `docs/tutorials/sensitivities.md`): one compiled program of `[q, q̇, t, p, u]` whose outputs
/// are `[M, f, G, b, γ, g, h]` then `∂[M, f, G, b, γ, g]/∂[q, q̇, p, u]`
/// ([`Shape::n_tangent_outputs`]), derived by SymPy and sharing subexpressions with the
/// model's own: what a run with forward sensitivities evaluates.
pub struct Tangent {
    pub shape: Shape,
    function: Function,
}

impl Tangent {
    /// The tangent of a model of sizes `shape` from `program`, compiled by `compiler`.
    pub fn new(shape: Shape, program: Program, compiler: &dyn Compiler) -> Result<Self, String> {
        if program.n_inputs != shape.n_inputs() || program.n_outputs != shape.n_tangent_outputs() {
            return Err(format!(
                "the tangent's program has {} inputs and {} outputs; a model of these sizes \
                 needs {} and {}",
                program.n_inputs,
                program.n_outputs,
                shape.n_inputs(),
                shape.n_tangent_outputs()
            ));
        }
        Ok(Tangent {
            shape,
            function: Function::compile(program, compiler),
        })
    }

    /// Working memory for evaluating the model and its Jacobian on one thread: its
    /// [`Evaluator::parts`] hold the model's outputs, then the Jacobian ([`Evaluator::jacobian`]).
    pub fn evaluator(&self) -> Evaluator<'_> {
        Evaluator::of(self.shape, &self.function)
    }
}

/// The working memory of one evaluator of a [`Model`].
pub struct Evaluator<'a> {
    shape: Shape,
    function: &'a Function,
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

impl<'a> Evaluator<'a> {
    /// The working memory of `function`, the expressions of a model of sizes `shape` (its
    /// outputs start with `[M, f, G, b, γ, g, h]`).
    fn of(shape: Shape, function: &'a Function) -> Self {
        let s = shape;
        let d = s.n + s.m;
        Evaluator {
            shape,
            function,
            scratch: function.scratch(),
            input: vec![0.0; s.n_inputs()],
            parts: vec![0.0; function.program().n_outputs],
            kkt: vec![0.0; d * (d + 1)],
            rows: Vec::with_capacity(s.m),
            work: vec![0.0; s.m * (s.m + 1) + s.m * s.n + 2 * s.n],
        }
    }

    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// `∂part_o/∂z_k` of the last evaluation of a [`Tangent`]'s evaluator: output `o` of
    /// `[M, f, G, b, γ, g]`, direction `k` of `[q, q̇, p, u]`.
    #[inline(always)]
    pub fn jacobian(&self, o: usize, k: usize) -> f64 {
        let s = self.shape;
        self.parts[s.n_outputs() + o * s.n_directions() + k]
    }

    /// Evaluate the model's expressions at `(q, q̇, t)` with parameters `p` and inputs `u`.
    pub fn evaluate(&mut self, t: f64, q: &[f64], v: &[f64], p: &[f64], u: &[f64]) {
        let s = self.shape;
        let x = &mut self.input;
        x[..s.n].copy_from_slice(&q[..s.n]);
        x[s.n..2 * s.n].copy_from_slice(&v[..s.n]);
        x[2 * s.n] = t;
        x[2 * s.n + 1..2 * s.n + 1 + s.np].copy_from_slice(&p[..s.np]);
        x[2 * s.n + 1 + s.np..].copy_from_slice(&u[..s.nu]);
        self.function
            .eval_in(&mut self.scratch, &self.input, &mut self.parts);
    }

    /// The Jacobi integral `h` of the last evaluation.
    pub fn energy(&self) -> f64 {
        self.parts[self.shape.at_h()]
    }

    /// Row `c` of the constraint Jacobian G of the last evaluation.
    pub fn jacobian_row(&self, c: usize) -> &[f64] {
        let s = self.shape;
        &self.parts[s.at_g_jac() + c * s.n..s.at_g_jac() + (c + 1) * s.n]
    }

    /// `G q̇ + b` of constraint `c` (the velocity residual) at the last evaluation.
    pub fn velocity_residual(&self, c: usize, v: &[f64]) -> f64 {
        let s = self.shape;
        let mut vel = self.parts[s.at_b() + c];
        for (gj, vj) in self.jacobian_row(c).iter().zip(v) {
            vel += gj * vj;
        }
        vel
    }

    /// The holonomic residual `g_c` of the last evaluation (`c < nh`).
    pub fn residual(&self, c: usize) -> f64 {
        self.parts[self.shape.at_g() + c]
    }

    /// Solve the KKT system of the last evaluation (made at velocity `v`) for `(q̈, λ)` with
    /// the constraints in `active` (all when `None`) and Baumgarte's gains `(α, β)` (zero: the
    /// physical multipliers). `q̈` (n) and `λ` (one per constraint in play) are then
    /// [`Evaluator::solution`]. False when the system is singular or not finite.
    pub fn solve(&mut self, v: &[f64], active: Option<&[bool]>, alpha: f64, beta: f64) -> bool {
        let s = self.shape;
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
        let n = self.shape.n;
        let d = n + self.rows.len();
        let x: Vec<f64> = (0..d).map(|i| self.kkt[i * (d + 1) + d]).collect();
        (x[..n].to_vec(), x[n..].to_vec())
    }

    /// `q̈_i` of the last solve.
    #[inline]
    pub(super) fn qdd(&self, i: usize) -> f64 {
        let d = self.shape.n + self.rows.len();
        self.kkt[i * (d + 1) + d]
    }

    /// Unknown `i` of the last solve: `q̈_i` for `i < n`, then the multipliers of the
    /// constraints in play.
    #[inline]
    pub(super) fn unknown(&self, i: usize) -> f64 {
        let d = self.shape.n + self.rows.len();
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
        let s = self.shape;
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
        let s = self.shape;
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
