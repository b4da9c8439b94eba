//! Forward sensitivities of a rigid body's run (`docs/tutorials/sensitivities.md`): the
//! derivatives `S_j(t) = ∂y(t)/∂p_j` of the state with respect to `P` parameters, integrated
//! alongside the motion as the variational equations `Ṡ_j = ∂f/∂y S_j + ∂f/∂p_j`, by the same
//! method and the same steps (Hairer, Nørsett & Wanner, *Solving ODEs I*, §I.14).
//!
//! **No derivative is written by hand.** The right-hand side is the engine's own, eqs
//! (07)–(09) with the built-in forces ([`rigid_rates`], [`wrench_of`]), evaluated on dual
//! numbers ([`Dual`]): the state's derivative parts are the columns `S_j`, the body's
//! principal moments and the forces' parameter rows carry their own seeds, and the result's
//! derivative parts are `∂f/∂y S_j + ∂f/∂p_j` exactly. The directions run [`BLOCK`] at a time,
//! one AVX-512 instruction per operation of their derivatives.
//!
//! **Discrete sensitivities.** An explicit Runge–Kutta method applied to the augmented system
//! `(y, S)` computes, in `S`, the exact derivative of its own `y` map (the method is linear in
//! its stages, so differentiating the step and stepping the variational equations commute:
//! Hairer, Nørsett & Wanner, §II.6 on internal differentiation). With RK4 or an explicit
//! tableau at a fixed step, `S` is the derivative of what was computed, to round-off; with
//! DOP853 the accepted steps are held (their dependence on `p` is not differentiated, as in
//! CVODES) and the error control weighs `S` too unless [`Sensitive::control_all`] is off.
//!
//! The augmented state is `[y (18), S (18 × P, row-major)]`: the motion in the engine's
//! principal frame, then the derivatives of each of its components along the directions.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::drivers::FixedMethod;
use crate::dual::Dual;
use crate::exact_splitting::{
    compose, free_flow_tangent, off_orbit, translate, Composition, SubStep,
};
use crate::forces::{central_point_force, kepler_part, wrench_of, Force};
use crate::layout::{Body, FORCE_PARAMS, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::real::Real;
use crate::relative::{
    absolute_state, relative_rates, CarrierMotion, RelativeOptions, MOTION_SIZE,
    RELATIVE_STATE_SIZE,
};
use crate::rigid::ANY_ROTOR;
use crate::rigid::{pivot_constrained, rigid_rates, shift_torque_to_pivot, State};
use crate::so3::{exp_so3, Mat3};
use crate::steppers::{drift, hold_pivot, kick_by, rk4_registers, rkmk4_registers, velocity_of};
use crate::system::VectorField;

/// Directions per dual evaluation: eight derivatives, one AVX-512 register.
pub const BLOCK: usize = 8;

type D = Dual<BLOCK>;
/// The dual numbers of the rates inlined into the drivers' copies with FMA (RK4, RKMK4 and
/// the vector field's rates): a product's derivatives fused ([`Dual`]). The splittings' kicks
/// and closed forms run partly out of line, in the baseline, and keep [`D`].
type DF = Dual<BLOCK, true>;

/// What a direction's initial column moves: nothing (a parameter of the body or a force),
/// or one component of the initial state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// A parameter: the initial column is zero.
    None,
    /// `ω0_k`: in the body frame, or in the space frame where the run reads ω0 there.
    Omega(usize),
    /// The rotation vector `δ_k` of the initial attitude, `Q0 → exp(δ̂) Q0` (space frame).
    Attitude(usize),
    /// `R0_k`.
    Position(usize),
    /// `V0_k`.
    Velocity(usize),
}

impl Start {
    /// The start of a code pair `(kind, k)`: 0 none, 1 ω0, 2 attitude, 3 R0, 4 V0; `None`
    /// for an unknown code or a component outside 0..3.
    pub fn from_code(kind: i64, k: i64) -> Option<Start> {
        let k = usize::try_from(k).ok().filter(|k| *k < 3)?;
        Some(match kind {
            0 => Start::None,
            1 => Start::Omega(k),
            2 => Start::Attitude(k),
            3 => Start::Position(k),
            4 => Start::Velocity(k),
            _ => return None,
        })
    }
}

/// The seeds of one block of directions: the body and the forces' parameter rows as dual
/// numbers, built once.
struct BlockSeeds<T = D> {
    body: Body<T>,
    params: Vec<[T; FORCE_PARAMS]>,
}

/// The seeds of every block of directions: direction `j` moves the principal moments by
/// `moment_seeds[j]` and force `i`'s parameter row by `force_seeds[j · forces + i]`.
fn block_seeds<const F: bool>(
    body: &Body,
    forces: &[Force],
    moment_seeds: &[[f64; 3]],
    force_seeds: &[[f64; FORCE_PARAMS]],
) -> Vec<BlockSeeds<Dual<BLOCK, F>>> {
    let p = moment_seeds.len();
    let nf = forces.len();
    (0..p.div_ceil(BLOCK).max(1))
        .map(|b| {
            let (lo, hi) = (b * BLOCK, ((b + 1) * BLOCK).min(p));
            let seeded = |v: f64, seed: &dyn Fn(usize) -> f64| {
                let mut x = Dual::<BLOCK, F>::splat(v);
                for l in 0..hi.saturating_sub(lo) {
                    x.d[l] = seed(lo + l);
                }
                x
            };
            let dm = [0, 1, 2].map(|k| seeded(0.0, &|j| moment_seeds[j][k]));
            let params = (0..nf)
                .map(|i| {
                    std::array::from_fn(|m| seeded(forces[i].p[m], &|j| force_seeds[j * nf + i][m]))
                })
                .collect();
            BlockSeeds {
                body: body.lift(dm),
                params,
            }
        })
        .collect()
}

/// The wrench of the built-in forces about the reference point, on dual numbers: what
/// [`crate::systems::Rigid`]'s wrench computes, in the same order.
#[inline(always)]
fn wrench_block<const F: bool>(
    forces: &[Force],
    seeds: &BlockSeeds<Dual<BLOCK, F>>,
    y: &[Dual<BLOCK, F>; STATE_SIZE],
) -> [Dual<BLOCK, F>; 6] {
    let mut w = [Dual::splat(0.0); 6];
    for (f, p) in forces.iter().zip(&seeds.params) {
        let v = wrench_of(f.kind, p, &seeds.body, y);
        for k in 0..6 {
            w[k] = w[k] + v[k];
        }
    }
    shift_torque_to_pivot(&seeds.body, y, w)
}

/// The augmented system `(y, S)` of a body under built-in forces: [`VectorField`] of
/// dimension `18 (1 + P)`, `S` stored component by component (`y[18 + P i + j] = ∂y_i/∂p_j`)
/// so that a component's derivatives are one contiguous row.
pub struct Sensitive<'a> {
    pub body: Body,
    pub forces: &'a [Force],
    /// The number of directions `P`.
    pub p: usize,
    /// Whether DOP853's error control weighs the sensitivities (CVODES' `errconS`).
    pub control_all: bool,
    blocks: Vec<BlockSeeds>,
    fused: Vec<BlockSeeds<DF>>,
}

impl<'a> Sensitive<'a> {
    /// The augmented system of `body` under `forces` with `P` directions: direction `j`
    /// moves the principal moments (engine order) by `moment_seeds[j]` and force `i`'s
    /// parameter row by `force_seeds[j · forces + i]`.
    pub fn new(
        body: Body,
        forces: &'a [Force],
        moment_seeds: &[[f64; 3]],
        force_seeds: &[[f64; FORCE_PARAMS]],
        control_all: bool,
    ) -> Self {
        let blocks = block_seeds(&body, forces, moment_seeds, force_seeds);
        let fused = block_seeds(&body, forces, moment_seeds, force_seeds);
        let p = moment_seeds.len();
        Sensitive {
            body,
            forces,
            p,
            control_all,
            blocks,
            fused,
        }
    }

    /// Directions `lo..hi` of the augmented state `y` as dual numbers.
    #[inline(always)]
    fn state_block<const F: bool>(
        &self,
        y: &[f64],
        lo: usize,
        hi: usize,
    ) -> [Dual<BLOCK, F>; STATE_SIZE] {
        lift_block(y, self.p, lo, hi)
    }

    /// Write the dual state `r` back: its value (when `value`) and directions `lo..hi`.
    #[inline(always)]
    fn write_block<const F: bool>(
        &self,
        r: &[Dual<BLOCK, F>; STATE_SIZE],
        out: &mut [f64],
        lo: usize,
        hi: usize,
        value: bool,
    ) {
        store_block(r, out, self.p, lo, hi, value)
    }

    /// The blocks of directions: `(lo, hi, seeds)`.
    fn blocks(&self) -> impl Iterator<Item = (usize, usize, &BlockSeeds)> {
        blocks_of(&self.blocks, self.p)
    }

    /// The blocks of directions with their fused seeds ([`DF`]).
    fn fused_blocks(&self) -> impl Iterator<Item = (usize, usize, &BlockSeeds<DF>)> {
        blocks_of(&self.fused, self.p)
    }
}

/// The blocks of `p` directions with their seeds: `(lo, hi, seeds)`.
fn blocks_of<T>(
    seeds: &[BlockSeeds<T>],
    p: usize,
) -> impl Iterator<Item = (usize, usize, &BlockSeeds<T>)> {
    seeds
        .iter()
        .enumerate()
        .map(move |(b, s)| (b * BLOCK, ((b + 1) * BLOCK).min(p), s))
}

/// Directions `lo..hi` (at most [`BLOCK`]) of an augmented state `y = [x (N), S (N × p)]` as
/// `N` dual numbers.
#[inline(always)]
fn lift_block<const N: usize, const F: bool>(
    y: &[f64],
    p: usize,
    lo: usize,
    hi: usize,
) -> [Dual<BLOCK, F>; N] {
    // one copy for each width: a copy whose length is known only at run time is a call to
    // memcpy, 2N of them a dual evaluation
    macro_rules! widths {
        ($($w:literal)*) => {
            match hi - lo {
                $($w => lift_rows::<N, $w, F>(y, p, lo),)*
                _ => unreachable!("a block holds 1 to {BLOCK} directions"),
            }
        };
    }
    widths!(1 2 3 4 5 6 7 8)
}

#[inline(always)]
fn lift_rows<const N: usize, const W: usize, const F: bool>(
    y: &[f64],
    p: usize,
    lo: usize,
) -> [Dual<BLOCK, F>; N] {
    // a loop, not `array::from_fn`: its closure was left out of line (a call per lift)
    let mut out = [Dual::default(); N];
    for (i, x) in out.iter_mut().enumerate() {
        let row = N + p * i + lo;
        x.v = y[i];
        x.d[..W].copy_from_slice(&y[row..row + W]);
    }
    out
}

/// Write `N` dual numbers back into an augmented state: the value (when `value`) and
/// directions `lo..hi`.
#[inline(always)]
fn store_block<const N: usize, const F: bool>(
    r: &[Dual<BLOCK, F>; N],
    out: &mut [f64],
    p: usize,
    lo: usize,
    hi: usize,
    value: bool,
) {
    macro_rules! widths {
        ($($w:literal)*) => {
            match hi - lo {
                $($w => store_rows::<N, $w, F>(r, out, p, lo, value),)*
                _ => unreachable!("a block holds 1 to {BLOCK} directions"),
            }
        };
    }
    widths!(1 2 3 4 5 6 7 8)
}

#[inline(always)]
fn store_rows<const N: usize, const W: usize, const F: bool>(
    r: &[Dual<BLOCK, F>; N],
    out: &mut [f64],
    p: usize,
    lo: usize,
    value: bool,
) {
    for (i, x) in r.iter().enumerate() {
        if value {
            out[i] = x.v;
        }
        let row = N + p * i + lo;
        out[row..row + W].copy_from_slice(&x.d[..W]);
    }
}

impl VectorField for Sensitive<'_> {
    #[inline(always)]
    fn dim(&self) -> usize {
        STATE_SIZE * (1 + self.p)
    }

    /// `ẏ = f(y, p)` and `Ṡ_j = ∂f/∂y S_j + ∂f/∂p_j`: the engine's rates (eqs (07)–(09) with
    /// the built-in forces about the reference point) on dual numbers, in their copy for the
    /// widest instruction set up to AVX2 ([`sensitive_rates`]).
    #[inline(always)]
    fn rhs(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        sensitive_rates(self, y, out)
    }

    /// About a pivot, `R = P + Q c` and `V = Q (ω × c)` reset from the attitude
    /// ([`pivot_constrained`]), and their sensitivities with them.
    #[inline(always)]
    fn project(&self, _t: f64, y: &mut [f64]) -> bool {
        if !self.body.has_pivot {
            return false;
        }
        for (lo, hi, seeds) in self.blocks() {
            let r = pivot_constrained(&seeds.body, self.state_block(y, lo, hi));
            self.write_block(&r, y, lo, hi, lo == 0);
        }
        true
    }

    #[inline(always)]
    fn error_blocks(&self) -> (usize, usize) {
        (STATE_SIZE, if self.control_all { self.p } else { 0 })
    }
}

/// [`Sensitive`]'s rates.
#[inline(always)]
fn sensitive_rates_any(sys: &Sensitive<'_>, y: &[f64], out: &mut [f64]) {
    for (lo, hi, seeds) in sys.fused_blocks() {
        let yd: [DF; STATE_SIZE] = sys.state_block(y, lo, hi);
        let r = rigid_rates(&seeds.body, &yd, wrench_block(sys.forces, seeds, &yd));
        sys.write_block(&r, out, lo, hi, lo == 0);
    }
}

crate::multiversion! {
    /// [`Sensitive`]'s rates in a copy compiled for AVX2 + FMA where the CPU has them (else
    /// the baseline): the dual numbers' fused multiply-adds in hardware, their directions two
    /// vectors of four. The adaptive driver that calls them is one copy, compiled for the
    /// baseline (a copy of it for each instruction set, the rates inlined into each, would
    /// cost build time for a call's worth of gain). Every copy gives the same numbers.
    fn sensitive_rates, sensitive_rates_with [] (
        sys: &Sensitive<'_>,
        y: &[f64],
        out: &mut [f64],
    ) -> () where [] => sensitive_rates_any, up to Avx2;
}

/// RK4 (`LIE = false`) or RKMK4 (`true`) on the augmented system of a rigid body: the plain
/// run's register step ([`rk4_registers`], [`rkmk4_registers`]: the same operations in the
/// same order) on dual numbers for each block of directions, then the pivot's constraint. So
/// under forces `y` is the plain run's bit for bit, and `S` the exact derivative of the
/// method's own map (on SO(3) for RKMK4), to round-off. One lift of the state and one store a
/// step (RK4 on the generic tableau, [`crate::steppers::erk_step`], had gone through memory
/// at every stage).
pub struct SensitiveRegisters<const LIE: bool>;

impl<'a, const LIE: bool> FixedMethod<Sensitive<'a>> for SensitiveRegisters<LIE> {
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(&mut self, sys: &Sensitive<'a>, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        for (lo, hi, seeds) in sys.fused_blocks() {
            let yd: [DF; STATE_SIZE] = sys.state_block(z, lo, hi);
            // the rates inlined into the step, compiled in the driver's instruction set: a
            // closure left out of line is compiled for the baseline (SSE2, `fma` in software)
            macro_rules! rates {
                () => {
                    #[inline(always)]
                    |_t: f64, y: &[DF; STATE_SIZE]| {
                        rigid_rates(&seeds.body, y, wrench_block(sys.forces, seeds, y))
                    }
                };
            }
            let stepped = if LIE {
                rkmk4_registers(rates!(), t, &yd, h)
            } else {
                rk4_registers(rates!(), t, &yd, h)
            };
            sys.write_block(&stepped, out, lo, hi, lo == 0);
        }
        sys.project(t + h, out);
    }
}

/// The splitting method on the augmented system of a rigid body: the derivative of its
/// discrete step (kick, the free rotor's sub-flows, kick, on dual numbers), on the momentum
/// state `[R, V, Q, π = I ω]` and its derivatives (the moments' seeds move `π` too).
pub struct SensitiveSplitting;

impl<'a> FixedMethod<Sensitive<'a>> for SensitiveSplitting {
    fn evals_per_step(&self) -> u64 {
        2
    }
    #[inline(always)]
    fn step(&mut self, sys: &Sensitive<'a>, _t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        for (lo, hi, seeds) in sys.blocks() {
            let body = &seeds.body;
            let mut zd = sys.state_block(z, lo, hi);
            // the built-in forces do not depend on the time: each kick at its own time alike
            let kick = |zd: &mut [D; STATE_SIZE]| {
                let y = velocity_of(body, zd);
                kick_by(body, &wrench_block(sys.forces, seeds, &y), zd, 0.5 * h);
            };
            kick(&mut zd);
            drift::<ANY_ROTOR, D>(body, &mut zd, h);
            kick(&mut zd);
            hold_pivot(body, &mut zd);
            sys.write_block(&zd, out, lo, hi, lo == 0);
        }
    }
    /// `π = I ω`, and its derivatives.
    fn init(&self, sys: &Sensitive<'a>, y: &[f64], z: &mut [f64]) {
        z.copy_from_slice(y);
        for (lo, hi, seeds) in sys.blocks() {
            let mut zd = sys.state_block(y, lo, hi);
            for k in 0..3 {
                zd[OMEGA_AT + k] = seeds.body.moments[k] * zd[OMEGA_AT + k];
            }
            sys.write_block(&zd, z, lo, hi, lo == 0);
        }
    }
    /// `ω = π/I`, and its derivatives.
    fn output(&self, sys: &Sensitive<'a>, z: &[f64], y: &mut [f64]) {
        y.copy_from_slice(z);
        for (lo, hi, seeds) in sys.blocks() {
            let yd = velocity_of(&seeds.body, &sys.state_block(z, lo, hi));
            sys.write_block(&yd, y, lo, hi, lo == 0);
        }
    }
}

/// The exact-flow splittings on the augmented system of a rigid body: the derivative of their
/// discrete step ([`compose`]'s sub-steps: kicks on dual numbers, as [`SensitiveSplitting`]'s,
/// and the closed form's exact derivatives for each free flow, [`free_flow_tangent`], with the
/// centre of mass's own flow, Kepler's under one central gravity, [`translate`]), on the
/// momentum state and its derivatives. A flow where the closed form has no derivatives (two
/// equal moments, a fixed point, the separatrix) leaves the derivatives NaN, and the run stops
/// there as not finite.
pub struct SensitiveExactSplitting<'c> {
    pub composition: Composition<'c>,
}

impl<'a> FixedMethod<Sensitive<'a>> for SensitiveExactSplitting<'_> {
    fn evals_per_step(&self) -> u64 {
        self.composition.kicks_per_step()
    }
    #[inline]
    fn step(&mut self, sys: &Sensitive<'a>, _t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        let c = &self.composition;
        let orbit = kepler_part(&sys.body, sys.forces);
        for (lo, hi, seeds) in sys.blocks() {
            let body = &seeds.body;
            let orbit = orbit.map(|i| &seeds.params[i]);
            let mut zd = sys.state_block(z, lo, hi);
            let mut differentiable = true;
            // the built-in forces do not depend on the time: each kick at its own time alike
            compose(c, h, |sub| match sub {
                SubStep::Kick { k, .. } => {
                    let y = velocity_of(body, &zd);
                    let mut w = wrench_block(sys.forces, seeds, &y);
                    if let Some(p) = orbit {
                        off_orbit(&mut w, &central_point_force(p, body, &y));
                    }
                    kick_by(body, &w, &mut zd, c.kicks[k] * h);
                }
                SubStep::Flow { d, .. } => {
                    differentiable &= free_flow_tangent(body, &mut zd, d);
                    translate(body, orbit, &mut zd, d, |x| x.v);
                }
            });
            hold_pivot(body, &mut zd);
            if !differentiable {
                for x in zd.iter_mut() {
                    x.d = [f64::NAN; BLOCK];
                }
            }
            sys.write_block(&zd, out, lo, hi, lo == 0);
        }
    }
    /// `π = I ω`, and its derivatives.
    fn init(&self, sys: &Sensitive<'a>, y: &[f64], z: &mut [f64]) {
        SensitiveSplitting.init(sys, y, z);
    }
    /// `ω = π/I`, and its derivatives.
    fn output(&self, sys: &Sensitive<'a>, z: &[f64], y: &mut [f64]) {
        SensitiveSplitting.output(sys, z, y);
    }
}

/// The augmented initial state `[z0, S(0)]` (`18 (1 + P)`, `S` by components) of the engine state
/// `z0` (principal frame; `axes` the principal axes as columns in body coordinates) and the
/// directions' starts: the derivatives of the initial state the run builds from ω0 (body
/// frame, or space frame when `omega_space`: `ω = Q0ᵀ ω0`), `Q0 → exp(δ̂) Q0`, `R0` and `V0`,
/// by the same dual numbers (the rotation's [`exp_so3`] at `δ = 0`, the pivot's
/// [`pivot_constrained`] about a pivot).
pub fn initial_tangents(
    body: &Body,
    axes: &Mat3,
    z0: &State,
    starts: &[Start],
    omega_space: bool,
) -> Vec<f64> {
    let p = starts.len();
    let mut out = vec![0.0; STATE_SIZE * (1 + p)];
    out[..STATE_SIZE].copy_from_slice(z0);
    set_tangents(body, axes, z0, starts, omega_space, STATE_SIZE, &mut out);
    out
}

/// The augmented initial state of a relative motion (`z0`, 33 numbers, principal frame; the
/// body's part `[r, v, Q_r, ω_r]` laid out as a rigid body's): the directions move `ω_r0`
/// (body frame), `Q_r0 → exp(δ̂) Q_r0` (carrier frame), `r0` and `v_r0` as
/// [`initial_tangents`] moves a rigid body's; the carrier's part does not move.
pub fn relative_initial_tangents(
    body: &Body,
    axes: &Mat3,
    z0: &[f64; RELATIVE_STATE_SIZE],
    starts: &[Start],
) -> Vec<f64> {
    let p = starts.len();
    let mut out = vec![0.0; RELATIVE_STATE_SIZE * (1 + p)];
    out[..RELATIVE_STATE_SIZE].copy_from_slice(z0);
    let mut rigid = [0.0; STATE_SIZE];
    rigid.copy_from_slice(&z0[..STATE_SIZE]);
    set_tangents(
        body,
        axes,
        &rigid,
        starts,
        false,
        RELATIVE_STATE_SIZE,
        &mut out,
    );
    out
}

/// The initial columns of [`initial_tangents`] into `out`, an augmented state of `size`
/// numbers per column (the rigid body's 18 first).
fn set_tangents(
    body: &Body,
    axes: &Mat3,
    z0: &State,
    starts: &[Start],
    omega_space: bool,
    size: usize,
    out: &mut [f64],
) {
    let p = starts.len();
    let lifted = body.lift([D::splat(0.0); 3]);
    for lo in (0..p.max(1)).step_by(BLOCK) {
        let hi = (lo + BLOCK).min(p);
        let seed = |what: fn(Start) -> Option<usize>, k: usize| {
            let mut x = D::splat(0.0);
            for l in 0..hi - lo {
                x.d[l] = if what(starts[lo + l]) == Some(k) {
                    1.0
                } else {
                    0.0
                };
            }
            x
        };
        let omega = |s: Start| {
            if let Start::Omega(k) = s {
                Some(k)
            } else {
                None
            }
        };
        let turn = |s: Start| {
            if let Start::Attitude(k) = s {
                Some(k)
            } else {
                None
            }
        };
        let at_r = |s: Start| {
            if let Start::Position(k) = s {
                Some(k)
            } else {
                None
            }
        };
        let at_v = |s: Start| {
            if let Start::Velocity(k) = s {
                Some(k)
            } else {
                None
            }
        };
        let mut y = [D::default(); STATE_SIZE];
        // Q = exp(δ̂) Q0 (engine Q = Q_body E: the space-frame turn acts alike on both)
        let e = exp_so3([0, 1, 2].map(|k| seed(turn, k)));
        for r in 0..3 {
            for c in 0..3 {
                let mut q = D::splat(0.0);
                for m in 0..3 {
                    q = q + e[r][m] * D::splat(z0[Q_AT + 3 * m + c]);
                }
                y[Q_AT + 3 * r + c] = q;
            }
        }
        // ω0 as the run read it: ω_p = Eᵀ ω_body, or ω_p = Qᵀ ω_space
        let w_p = [0, 1, 2].map(|k| D::splat(z0[OMEGA_AT + k]));
        for j in 0..3 {
            let mut w = D::splat(0.0);
            for k in 0..3 {
                w = w + if omega_space {
                    let ws: f64 = (0..3).map(|c| z0[Q_AT + 3 * k + c] * w_p[c].v).sum();
                    y[Q_AT + 3 * k + j] * (D::splat(ws) + seed(omega, k))
                } else {
                    let wb: f64 = (0..3).map(|c| axes[k][c] * w_p[c].v).sum();
                    D::splat(axes[k][j]) * (D::splat(wb) + seed(omega, k))
                };
            }
            y[OMEGA_AT + j] = w;
        }
        for k in 0..3 {
            y[R_AT + k] = D::splat(z0[R_AT + k]) + seed(at_r, k);
            y[V_AT + k] = D::splat(z0[V_AT + k]) + seed(at_v, k);
        }
        let y = pivot_constrained(&lifted, y);
        for (i, x) in y.iter().enumerate() {
            let row = size + p * i;
            out[row + lo..row + hi].copy_from_slice(&x.d[..hi - lo]);
        }
    }
}

/// A body moving relative to a carrier under built-in forces, with the forward sensitivities
/// of `P` directions: the augmented state `[y (33), S (33 × P, row-major)]` advanced by the
/// relative equations ([`relative_rates`], with the forces on the absolute state
/// [`absolute_state`], as [`crate::relative::Relative`] evaluates them) on dual numbers.
pub struct RelativeSensitive<'a, C: CarrierMotion + ?Sized> {
    pub body: Body,
    pub forces: &'a [Force],
    pub carrier: &'a C,
    pub options: RelativeOptions,
    pub p: usize,
    pub control_all: bool,
    blocks: Vec<BlockSeeds<DF>>,
    failed: AtomicBool,
}

impl<'a, C: CarrierMotion + ?Sized> RelativeSensitive<'a, C> {
    /// The augmented relative system (the seeds as [`Sensitive::new`] takes them).
    pub fn new(
        body: Body,
        forces: &'a [Force],
        carrier: &'a C,
        options: RelativeOptions,
        moment_seeds: &[[f64; 3]],
        force_seeds: &[[f64; FORCE_PARAMS]],
        control_all: bool,
    ) -> Self {
        RelativeSensitive {
            blocks: block_seeds(&body, forces, moment_seeds, force_seeds),
            body,
            forces,
            carrier,
            options,
            p: moment_seeds.len(),
            control_all,
            failed: AtomicBool::new(false),
        }
    }
}

impl<C: CarrierMotion + ?Sized> VectorField for RelativeSensitive<'_, C> {
    #[inline(always)]
    fn dim(&self) -> usize {
        RELATIVE_STATE_SIZE * (1 + self.p)
    }

    /// The relative equations on dual numbers, in their copy for the widest instruction set
    /// up to AVX2 ([`relative_sensitive_rates`]).
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let motion = self.carrier.motion(t).unwrap_or_else(|| {
            self.failed.store(true, Ordering::Relaxed);
            [f64::NAN; MOTION_SIZE]
        });
        relative_sensitive_rates(self, &motion, y, out)
    }

    #[inline(always)]
    fn error_blocks(&self) -> (usize, usize) {
        (
            RELATIVE_STATE_SIZE,
            if self.control_all { self.p } else { 0 },
        )
    }

    #[inline(always)]
    fn failed(&self) -> bool {
        self.failed.load(Ordering::Relaxed)
    }
}

/// [`RelativeSensitive`]'s rates with the carrier's `motion` at their time.
#[inline(always)]
fn relative_sensitive_rates_any<C: CarrierMotion + ?Sized>(
    sys: &RelativeSensitive<'_, C>,
    motion: &[f64; MOTION_SIZE],
    y: &[f64],
    out: &mut [f64],
) {
    for (lo, hi, seeds) in blocks_of(&sys.blocks, sys.p) {
        let yd: [DF; RELATIVE_STATE_SIZE] = lift_block(y, sys.p, lo, hi);
        let w = wrench_block(sys.forces, seeds, &absolute_state(&yd, motion));
        let mut r = [DF::default(); RELATIVE_STATE_SIZE];
        relative_rates(&seeds.body, sys.options, &yd, motion, w, &mut r);
        store_block(&r, out, sys.p, lo, hi, lo == 0);
    }
}

crate::multiversion! {
    /// [`RelativeSensitive`]'s rates in their copies, as [`sensitive_rates`].
    fn relative_sensitive_rates, relative_sensitive_rates_with [C: CarrierMotion + ?Sized] (
        sys: &RelativeSensitive<'_, C>,
        motion: &[f64; MOTION_SIZE],
        y: &[f64],
        out: &mut [f64],
    ) -> () where [] => relative_sensitive_rates_any, up to Avx2;
}

#[cfg(test)]
#[path = "sensitivity_tests.rs"]
mod tests;
