//! Forward sensitivities of a constrained system's run (`docs/tutorials/sensitivities.md`):
//! `S_j(t) = ∂y(t)/∂p_j` of the state `y = [q, q̇]` along `P` directions, integrated with the
//! motion as the variational equations, by the same method and steps.
//!
//! The model's Jacobian `∂[M, f, G, b, γ, g]/∂[q, q̇, p, u]` is derived by SymPy and compiled with
//! its expressions ([`Tangent`]); what is written here is the differentiated KKT system
//! (\[L\] (6.60)). With `K = [[M, −Gᵀ], [G, 0]]`, `x = [q̈; λ]` and
//! `K x = [f; −γ − s]`, `s = 2α (G q̇ + b) + β² g` (Baumgarte), a direction
//! `dz = [dq, dq̇, dp, du]` moves the solution by `dx`, solving
//!
//! ```text
//! K dx = [ df − dM q̈ + dGᵀ λ ;  −dγ − 2α (dG q̇ + G dq̇ + db) − β² dg − dG q̈ ]
//! ```
//!
//! with the same matrix for every direction (one elimination, `P` right-hand sides), where
//! `d(·) = Σ_k ∂(·)/∂z_k dz_k`. The augmented state is `[y (2n), S (2n × P, row-major)]`, `S`
//! component by component as a rigid body's ([`crate::sensitivity::Sensitive`]).
//!
//! A run that projects onto the constraints after each step carries the projection's
//! derivative to its columns, and the initial columns are the derivative of the consistent
//! initial state ([`initial_tangents`]): both are [`correct`], a first-order correction of a
//! direction onto the constraints by the coordinates and velocities left free.

use std::cell::RefCell;

use super::{Evaluator, Stabilization, Tangent};
use crate::linalg::{least_squares_solve, solve_augmented_many};
use crate::system::VectorField;

/// What a direction's initial column moves: nothing (a parameter), or one coordinate or one
/// velocity of the initial state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// A parameter: the direction's seed moves `p`.
    Parameter,
    /// `q0_k`.
    Coordinate(usize),
    /// `q̇0_k`.
    Velocity(usize),
}

/// A constrained system with the forward sensitivities of `P` directions, as the integrators
/// step it: [`VectorField`] of dimension `2n (1 + P)`. Inputs are constants; every
/// constraint is in play.
pub struct LagrangeSensitive<'a> {
    pub tangent: &'a Tangent,
    pub p: &'a [f64],
    pub u: &'a [f64],
    pub stabilization: Stabilization,
    /// The number of directions `P`.
    pub dirs: usize,
    /// Each direction's move of the model's numbers `[p, u]` (P × (np + nu), row-major): the
    /// inputs' part is zero in a run (inputs are constants there), and a unit seed only in
    /// [`rates_jacobian`]'s own directions.
    seeds: Vec<f64>,
    /// Whether DOP853's error control weighs the sensitivities (CVODES' `errconS`).
    pub control_all: bool,
    work: RefCell<Work<'a>>,
}

/// The working memory of one [`LagrangeSensitive`].
struct Work<'a> {
    ev: Evaluator<'a>,
    /// The solution `[q̈ (n), λ (m)]` of the last KKT solve.
    x: Vec<f64>,
    /// One direction `[dq, dq̇, dp, du]`.
    dz: Vec<f64>,
    /// The derivatives of `[M, f, G, b, γ, g]` along it.
    dparts: Vec<f64>,
    /// `[K | R_1 … R_P]`.
    kkt: Vec<f64>,
    fix: Fix,
}

impl<'a> LagrangeSensitive<'a> {
    /// The system of `tangent` with parameters `p`, constant inputs `u`, the stabilisation
    /// `stabilization`, and `P = seeds.len() / np` directions moving `p` by the rows of
    /// `seeds` (the initial state's directions have zero rows).
    pub fn new(
        tangent: &'a Tangent,
        p: &'a [f64],
        u: &'a [f64],
        stabilization: Stabilization,
        seeds: &[f64],
        dirs: usize,
        control_all: bool,
    ) -> Result<Self, String> {
        let s = tangent.shape;
        if dirs == 0 || seeds.len() != dirs * s.np {
            return Err(format!(
                "the seeds must hold P × {} numbers for P ≥ 1 directions, found {} for P = {dirs}",
                s.np,
                seeds.len()
            ));
        }
        let (np, nk) = (s.np, s.n_numbers());
        let mut numbers = vec![0.0; dirs * nk];
        for j in 0..dirs {
            numbers[j * nk..j * nk + np].copy_from_slice(&seeds[j * np..(j + 1) * np]);
        }
        Self::moving_numbers(tangent, p, u, stabilization, numbers, dirs, control_all)
    }

    /// The same, with `numbers` (P × (np + nu)) each direction's move of `[p, u]`.
    fn moving_numbers(
        tangent: &'a Tangent,
        p: &'a [f64],
        u: &'a [f64],
        stabilization: Stabilization,
        numbers: Vec<f64>,
        dirs: usize,
        control_all: bool,
    ) -> Result<Self, String> {
        let s = tangent.shape;
        if p.len() != s.np || u.len() != s.nu {
            return Err(format!(
                "{} parameters and {} inputs given, the model has {} and {}",
                p.len(),
                u.len(),
                s.np,
                s.nu
            ));
        }
        let d = s.n + s.m;
        Ok(LagrangeSensitive {
            tangent,
            p,
            u,
            stabilization,
            dirs,
            seeds: numbers,
            control_all,
            work: RefCell::new(Work {
                ev: tangent.evaluator(),
                x: vec![0.0; d],
                dz: vec![0.0; s.n_directions()],
                dparts: vec![0.0; s.n_outputs() - 1],
                kkt: vec![0.0; d * (d + dirs)],
                fix: Fix::new(s.n, s.m),
            }),
        })
    }
}

impl VectorField for LagrangeSensitive<'_> {
    fn dim(&self) -> usize {
        2 * self.tangent.shape.n * (1 + self.dirs)
    }

    fn error_blocks(&self) -> (usize, usize) {
        let p = if self.control_all { self.dirs } else { 0 };
        (2 * self.tangent.shape.n, p)
    }

    /// `[q̇, q̈]` and, for each direction, `[dq̇, dq̈]` from the differentiated KKT system (NaN
    /// where it is singular).
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let s = self.tangent.shape;
        let nk = s.n_numbers();
        let (n, m, pp) = (s.n, s.m, self.dirs);
        let st = self.stabilization;
        let w = &mut *self.work.borrow_mut();
        let (q, v) = (&y[..n], &y[n..2 * n]);
        w.ev.evaluate(t, q, v, self.p, self.u);
        let ok = w.ev.solve(v, None, st.alpha, st.beta);
        out[..n].copy_from_slice(v);
        if !ok {
            out[n..].fill(f64::NAN);
            return;
        }
        let d = n + m;
        for i in 0..d {
            w.x[i] = w.ev.unknown(i);
        }
        out[n..2 * n].copy_from_slice(&w.x[..n]);
        // K once, with a column per direction
        let ld = d + pp;
        let parts = &w.ev.parts;
        let kkt = &mut w.kkt;
        for i in 0..n {
            kkt[i * ld..i * ld + n].copy_from_slice(&parts[i * n..(i + 1) * n]);
        }
        for c in 0..m {
            let row = &parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n];
            for j in 0..n {
                kkt[(n + c) * ld + j] = row[j];
                kkt[j * ld + n + c] = -row[j];
            }
            kkt[(n + c) * ld + n..(n + c) * ld + d].fill(0.0);
        }
        let sens = &y[2 * n..];
        for j in 0..pp {
            for k in 0..2 * n {
                w.dz[k] = sens[k * pp + j];
            }
            w.dz[2 * n..].copy_from_slice(&self.seeds[j * nk..(j + 1) * nk]);
            directional(&w.ev, &w.dz, &mut w.dparts);
            let dp = &w.dparts;
            let (qdd, lam) = w.x.split_at(n);
            for i in 0..n {
                let mut r = dp[s.at_f() + i];
                for l in 0..n {
                    r -= dp[i * n + l] * qdd[l];
                }
                for c in 0..m {
                    r += dp[s.at_g_jac() + c * n + i] * lam[c];
                }
                kkt[i * ld + d + j] = r;
            }
            for c in 0..m {
                let drow = &dp[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n];
                let row = &w.ev.parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n];
                let mut dvel = dp[s.at_b() + c];
                let mut dg_qdd = 0.0;
                for l in 0..n {
                    dvel += drow[l] * v[l] + row[l] * w.dz[n + l];
                    dg_qdd += drow[l] * qdd[l];
                }
                let mut r = -dp[s.at_gamma() + c] - 2.0 * st.alpha * dvel - dg_qdd;
                if c < s.nh {
                    r -= st.beta * st.beta * dp[s.at_g() + c];
                }
                kkt[(n + c) * ld + d + j] = r;
            }
        }
        let solved = solve_augmented_many(kkt, d, ld, pp);
        for i in 0..n {
            for j in 0..pp {
                out[2 * n + i * pp + j] = sens[(n + i) * pp + j];
                out[2 * n + (n + i) * pp + j] = if solved {
                    kkt[i * ld + d + j]
                } else {
                    f64::NAN
                };
            }
        }
    }

    /// With the projection: the state projected as the plain system projects it, and each
    /// column by the projection's derivative there ([`correct`], every coordinate and
    /// velocity free).
    fn project(&self, t: f64, y: &mut [f64]) -> bool {
        let s = self.tangent.shape;
        let nk = s.n_numbers();
        if !self.stabilization.projection || s.m == 0 {
            return false;
        }
        let (n, pp) = (s.n, self.dirs);
        let w = &mut *self.work.borrow_mut();
        let (state, sens) = y.split_at_mut(2 * n);
        let (q, v) = state.split_at_mut(n);
        if !w.ev.project(t, q, v, self.p, self.u, None, 1e-13, 20) {
            v.fill(f64::NAN);
            return true;
        }
        w.ev.evaluate(t, q, v, self.p, self.u);
        let all = vec![true; n];
        for j in 0..pp {
            for k in 0..2 * n {
                w.dz[k] = sens[k * pp + j];
            }
            w.dz[2 * n..].copy_from_slice(&self.seeds[j * nk..(j + 1) * nk]);
            if !w.fix.correct(&w.ev, v, &mut w.dz, &all, &all) {
                w.dz[..2 * n].fill(f64::NAN);
            }
            for k in 0..2 * n {
                sens[k * pp + j] = w.dz[k];
            }
        }
        true
    }
}

/// The Jacobian of a constrained system's first-order equations `ẏ = [q̇, q̈]` (the physical
/// multipliers: no stabilisation; every constraint in play; constant inputs `u`) at
/// `(t, y)`: `∂ẏ/∂y` (2n × 2n), `∂ẏ/∂p` (2n × np) and `∂ẏ/∂u` (2n × nu, the input matrix of a
/// linearisation), row-major, exactly — the rates of the augmented system with `S = [I | 0]`
/// and the parameters' and inputs' unit seeds (the differentiated KKT system). `None` where
/// the KKT system is singular or the rates are not finite.
pub fn rates_jacobian(
    tangent: &Tangent,
    t: f64,
    y: &[f64],
    p: &[f64],
    u: &[f64],
) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let s = tangent.shape;
    let (n2, np) = (2 * s.n, s.np);
    if y.len() != n2 {
        return None;
    }
    let nk = s.n_numbers();
    let dirs = n2 + nk;
    let mut numbers = vec![0.0; dirs * nk];
    for k in 0..nk {
        numbers[(n2 + k) * nk + k] = 1.0;
    }
    let still = Stabilization {
        alpha: 0.0,
        beta: 0.0,
        projection: false,
    };
    let sys = LagrangeSensitive::moving_numbers(tangent, p, u, still, numbers, dirs, true).ok()?;
    let mut aug = vec![0.0; n2 * (1 + dirs)];
    aug[..n2].copy_from_slice(y);
    for i in 0..n2 {
        aug[n2 + i * dirs + i] = 1.0;
    }
    let mut out = vec![0.0; aug.len()];
    sys.rhs(t, &aug, &mut out);
    if !out.iter().all(|x| x.is_finite()) {
        return None;
    }
    let nu = s.nu;
    let (mut jy, mut jp, mut ju) = (vec![0.0; n2 * n2], vec![0.0; n2 * np], vec![0.0; n2 * nu]);
    for i in 0..n2 {
        let row = &out[n2 + i * dirs..n2 + (i + 1) * dirs];
        jy[i * n2..(i + 1) * n2].copy_from_slice(&row[..n2]);
        jp[i * np..(i + 1) * np].copy_from_slice(&row[n2..n2 + np]);
        ju[i * nu..(i + 1) * nu].copy_from_slice(&row[n2 + np..]);
    }
    Some((jy, jp, ju))
}

/// `d part_o = Σ_k ∂part_o/∂z_k dz_k` for the outputs `[M, f, G, b, γ, g]` of the last
/// evaluation of a [`Tangent`]'s evaluator.
fn directional(ev: &Evaluator, dz: &[f64], out: &mut [f64]) {
    let s = ev.shape();
    let k = s.n_directions();
    let jac = &ev.parts[s.n_outputs()..];
    for (o, x) in out.iter_mut().enumerate() {
        let row = &jac[o * k..(o + 1) * k];
        let mut acc = 0.0;
        for (a, b) in row.iter().zip(dz) {
            acc += a * b;
        }
        *x = acc;
    }
}

/// The working memory of [`Fix::correct`].
struct Fix {
    a: Vec<f64>,
    r: Vec<f64>,
    x: Vec<f64>,
    work: Vec<f64>,
    dparts: Vec<f64>,
}

impl Fix {
    fn new(n: usize, m: usize) -> Self {
        let k = n.max(m);
        Fix {
            a: vec![0.0; m * n],
            r: vec![0.0; m],
            x: vec![0.0; n],
            work: vec![0.0; k * (k + 1)],
            dparts: Vec::new(),
        }
    }

    /// Correct a direction `dz = [dq, dq̇, dp, du]` at a consistent state (velocity `v`, the
    /// evaluator's last evaluation) to first order onto the constraints: the free coordinates
    /// (`free_q`) take the least-squares correction of least norm that holds the holonomic
    /// residuals, `∂g/∂z dz = 0`; then the free velocities (`free_v`) hold the velocity
    /// residuals, `d(G q̇ + b) = 0`. With every coordinate and velocity free this is the
    /// derivative of the projection (Gauss–Newton with minimum-norm corrections, then
    /// `q̇ ← q̇ − G⁺ (G q̇ + b)`); with those a run solves for at its start, the derivative of
    /// its consistent initial state. False when a correction cannot be computed.
    fn correct(
        &mut self,
        ev: &Evaluator,
        v: &[f64],
        dz: &mut [f64],
        free_q: &[bool],
        free_v: &[bool],
    ) -> bool {
        let s = ev.shape();
        let (n, m, nh) = (s.n, s.m, s.nh);
        self.dparts.resize(s.n_outputs() - 1, 0.0);
        let g_row = |c: usize| &ev.parts[s.at_g_jac() + c * n..s.at_g_jac() + (c + 1) * n];
        let fq: Vec<usize> = (0..n).filter(|&i| free_q[i]).collect();
        if nh > 0 && !fq.is_empty() {
            directional(ev, dz, &mut self.dparts);
            for c in 0..nh {
                self.r[c] = self.dparts[s.at_g() + c];
                let row = g_row(c);
                for (col, &i) in fq.iter().enumerate() {
                    self.a[c * fq.len() + col] = row[i];
                }
            }
            if !least_squares_solve(&self.a, nh, fq.len(), &self.r, &mut self.x, &mut self.work) {
                return false;
            }
            for (col, &i) in fq.iter().enumerate() {
                dz[i] -= self.x[col];
            }
        }
        let fv: Vec<usize> = (0..n).filter(|&i| free_v[i]).collect();
        if m > 0 && !fv.is_empty() {
            directional(ev, dz, &mut self.dparts);
            for c in 0..m {
                let row = g_row(c);
                let mut r = self.dparts[s.at_b() + c];
                for l in 0..n {
                    r += self.dparts[s.at_g_jac() + c * n + l] * v[l] + row[l] * dz[n + l];
                }
                self.r[c] = r;
                for (col, &i) in fv.iter().enumerate() {
                    self.a[c * fv.len() + col] = row[i];
                }
            }
            if !least_squares_solve(&self.a, m, fv.len(), &self.r, &mut self.x, &mut self.work) {
                return false;
            }
            for (col, &i) in fv.iter().enumerate() {
                dz[n + i] -= self.x[col];
            }
        }
        true
    }
}

/// The augmented initial state `[y0, S(0)]` (2n (1 + P),) of a run from the consistent state
/// `y0 = [q0, q̇0]` at `t0`: direction `j` starts as `starts[j]` (a unit change of one given
/// coordinate or velocity, or the parameters' move `seeds[j]`), and the coordinates and
/// velocities the run solved for from the constraints (`free_q`, `free_v`) follow to first
/// order ([`Fix::correct`]). Errors name a direction the constraints do not let move (its
/// residual is left after the correction) or a singular correction.
#[allow(clippy::too_many_arguments)]
pub fn initial_tangents(
    tangent: &Tangent,
    t0: f64,
    y0: &[f64],
    p: &[f64],
    u: &[f64],
    starts: &[Start],
    seeds: &[f64],
    free_q: &[bool],
    free_v: &[bool],
) -> Result<Vec<f64>, String> {
    let s = tangent.shape;
    let (n, pp) = (s.n, starts.len());
    if y0.len() != 2 * n || p.len() != s.np || u.len() != s.nu || seeds.len() != pp * s.np {
        return Err("initial_tangents: sizes do not match the model".into());
    }
    if free_q.len() != n || free_v.len() != n {
        return Err(format!("the free masks must hold {n} flags"));
    }
    let mut ev = tangent.evaluator();
    let (q, v) = y0.split_at(n);
    ev.evaluate(t0, q, v, p, u);
    let mut fix = Fix::new(n, s.m);
    let mut dz = vec![0.0; s.n_directions()];
    let mut dparts = vec![0.0; s.n_outputs() - 1];
    let mut out = vec![0.0; 2 * n * (1 + pp)];
    out[..2 * n].copy_from_slice(y0);
    for (j, start) in starts.iter().enumerate() {
        dz.fill(0.0);
        match *start {
            Start::Parameter => {}
            Start::Coordinate(k) if k < n => dz[k] = 1.0,
            Start::Velocity(k) if k < n => dz[n + k] = 1.0,
            other => return Err(format!("direction {j}: {other:?} is not a coordinate")),
        }
        dz[2 * n..2 * n + s.np].copy_from_slice(&seeds[j * s.np..(j + 1) * s.np]);
        if !fix.correct(&ev, v, &mut dz, free_q, free_v) {
            return Err(format!(
                "direction {j}: the constraints' Jacobian is singular at the initial state"
            ));
        }
        // what is left of the constraints' residuals: a direction they do not let move
        directional(&ev, &dz, &mut dparts);
        let scale = 1.0 + dz.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let mut worst = 0.0f64;
        for c in 0..s.nh {
            worst = worst.max(dparts[s.at_g() + c].abs());
        }
        for c in 0..s.m {
            let row = ev.jacobian_row(c);
            let mut r = dparts[s.at_b() + c];
            for l in 0..n {
                r += dparts[s.at_g_jac() + c * n + l] * v[l] + row[l] * dz[n + l];
            }
            worst = worst.max(r.abs());
        }
        if worst > 1e-9 * scale {
            return Err(format!(
                "direction {j}: the constraints do not let it move alone (they are left \
                 violated at a rate of {worst:.3e}): give fewer coordinates or velocities in \
                 the initial state, so that the others are solved from the constraints and \
                 move with it"
            ));
        }
        for k in 0..2 * n {
            out[2 * n + k * pp + j] = dz[k];
        }
    }
    Ok(out)
}
