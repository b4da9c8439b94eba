//! The integrators' steps: pure functions of (system, time, state, step).
//!
//! Each step reads a state and writes the next one into a preallocated buffer; it keeps
//! nothing between calls (diffrax's "pure step"). Every driver calls these same functions.
//!
//! * [`erk_step`]: an explicit Runge–Kutta method given by its tableau (RK4 and any user
//!   tableau); [`rk4_rigid_step`]: RK4 on a rigid state held in registers, in the
//!   stage-point form ([`rk4_points_driver`], [`rk4_points_driven`]) where a system splits.
//! * [`rkmk_step`]: Runge–Kutta–Munthe-Kaas on R⁹ × SO(3): the attitude advances as
//!   `Q = Q_n exp(θ̂)` with `θ̇ = dexp⁻¹_{−θ}(ω)` (Munthe-Kaas 1999, BIT 39; Iserles et al.
//!   2000, Acta Numerica §5).
//! * [`splitting_step`]: kick–drift–kick, the exact free-rotor flow between two half kicks of
//!   the forces (Dullweber, Leimkuhler & McLachlan 1997, J. Chem. Phys. 107), on the momentum
//!   state `[R, V, Q, π]`.
//! * [`dop853_step`]: Dormand–Prince 8(5,3) with its error estimate ([`dop853_error_norm`]),
//!   7th-order dense output ([`dop853_dense`], [`dop853_interpolate`]) and the standard
//!   step-size controller ([`step_size_factor`], [`initial_step_size`]).

use crate::layout::{Body, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::real::Real;
use crate::rigid::{free_rotor, pivot_constrained, ANY_ROTOR};
use crate::so3::{dexpinv3, exp_so3};
use crate::system::{RigidStructure, VectorField};
use crate::tableaux::{
    DOP853_A, DOP853_C, DOP853_D, DOP853_E3, DOP853_E5, DOP853_INTERPOLATOR_POWER, DOP853_STAGES,
    DOP853_STAGES_EXTENDED, RK4_A, RK4_B, RK4_C,
};

/// An explicit Runge–Kutta tableau: `a` row-major `s × s` (strictly lower), `b` and `c` (s).
#[derive(Clone, Copy, Debug)]
pub struct Tableau<'a> {
    pub a: &'a [f64],
    pub b: &'a [f64],
    pub c: &'a [f64],
}

impl Tableau<'_> {
    /// Number of stages.
    #[inline(always)]
    pub fn stages(&self) -> usize {
        self.b.len()
    }
}

/// RK4's `A` row-major, as a [`Tableau`] holds it.
const RK4_A_ROWS: [f64; 16] = {
    let mut a = [0.0; 16];
    let mut i = 0;
    while i < 16 {
        a[i] = RK4_A[i / 4][i % 4];
        i += 1;
    }
    a
};

/// The classical RK4 tableau ([`RK4_A`], [`RK4_B`], [`RK4_C`]).
pub const RK4: Tableau<'static> = Tableau {
    a: &RK4_A_ROWS,
    b: &RK4_B,
    c: &RK4_C,
};

/// One step of the explicit Runge–Kutta method `tab`: stages
/// `k_i = f(t + C_i h, y + h Σ_j A_ij k_j)`, result `y + h Σ_i B_i k_i` in `out`.
/// `k` (s·n) receives the stage derivatives, `ytmp` (n) is work space.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn erk_step<S: VectorField + ?Sized>(
    sys: &S,
    tab: &Tableau,
    t: f64,
    y: &[f64],
    h: f64,
    k: &mut [f64],
    ytmp: &mut [f64],
    out: &mut [f64],
) {
    let s = tab.stages();
    let n = sys.dim();
    for i in 0..s {
        // `out` holds the sums Σ_m a_im k_m until the end of the step
        combine(&tab.a[i * s..i * s + i], k, n, &mut out[..n]);
        for idx in 0..n {
            ytmp[idx] = y[idx] + h * out[idx];
        }
        sys.rhs(t + tab.c[i] * h, ytmp, &mut k[i * n..(i + 1) * n]);
    }
    combine(&tab.b[..s], k, n, &mut out[..n]);
    for idx in 0..n {
        out[idx] = y[idx] + h * out[idx];
    }
}

/// `acc = Σ_m w_m k_m` (each `k_m` of length `n`, stored one after another), summed in the
/// order of `m` for each component, a stage at a time so that the component loop vectorises.
/// A zero weight's term is left out: it adds nothing to a finite sum (`x + 0·k = x`, and the
/// sum, starting at +0, is never −0).
#[inline(always)]
fn combine(w: &[f64], k: &[f64], n: usize, acc: &mut [f64]) {
    acc.fill(0.0);
    for (m, &wm) in w.iter().enumerate() {
        if wm != 0.0 {
            for (a, &km) in acc.iter_mut().zip(&k[m * n..(m + 1) * n]) {
                *a += wm * km;
            }
        }
    }
}

type State = [f64; STATE_SIZE];

/// One step of classical RK4 on a rigid state held in registers: the system's own
/// [`RigidStructure::rk4`] (by default [`rk4_registers`] on the whole state).
#[inline(always)]
pub fn rk4_rigid_step<S: RigidStructure + ?Sized>(sys: &S, t: f64, y: &State, h: f64) -> State {
    sys.rk4(t, y, h)
}

/// One step of classical RK4 on a state of `N` numbers held in registers, rates `f(t, y)`:
/// `k1 = f(t, y)`, `k2 = f(t + h/2, y + h/2 k1)`, `k3 = f(t + h/2, y + h/2 k2)`,
/// `k4 = f(t + h, y + h k3)`, `y + h/6 (k1 + 2 k2 + 2 k3 + k4)` — the RK4 tableau's step, in
/// the same order of operations as [`erk_step`] up to the grouping of the update.
/// Generic over [`Real`]: on dual numbers it is the derivative of this very step
/// ([`crate::sensitivity::SensitiveRegisters`]), its values the `f64` step's bit for bit.
#[inline(always)]
pub fn rk4_registers<T: Real, const N: usize>(
    f: impl Fn(f64, &[T; N]) -> [T; N],
    t: f64,
    y: &[T; N],
    h: f64,
) -> [T; N] {
    let half = 0.5 * h;
    // the first stage, then three in a loop with one call of the rates: rates inlined into
    // the step (on dual numbers, thousands of instructions) are compiled twice, not four
    // times. `sum` is `k1 + 2 k2 + 2 k3 + k4` added in that order.
    let mut k = f(t, y);
    let mut sum = k;
    for (ts, a, last) in [
        (t + half, half, false),
        (t + half, half, false),
        (t + h, h, true),
    ] {
        k = f(ts, &axpy(y, a, &k));
        for i in 0..N {
            sum[i] = if last {
                sum[i] + k[i]
            } else {
                sum[i] + k[i].scale(2.0)
            };
        }
    }
    let c = h / 6.0;
    let mut o = [T::splat(0.0); N];
    for i in 0..N {
        o[i] = y[i] + sum[i].scale(c);
    }
    o
}

/// Classical RK4 in its stage-point form, on an autonomous *driver* `x' = f(x)` given as the
/// accumulation `acc(b, a, x) = b + a f(x)`:
///
/// `x2 = x + h/2 f(x)`, `x3 = x + h/2 f(x2)`, `x4 = x + h f(x3)`,
/// `x⁺ = (x2 + 2 x3 + x4 − x)/3 + h/6 f(x4)`.
///
/// In exact arithmetic this is `x + h/6 (k1 + 2 k2 + 2 k3 + k4)` of [`rk4_registers`]
/// (`h k1 = 2 (x2 − x)`, `h k2 = 2 (x3 − x)`, `h k3 = x4 − x`); the stage derivatives are
/// never formed, so a rate that is a sum of products (Euler's equation (20), a cross
/// product) costs two fused multiply-adds per component and stage where `k = f(x)` and
/// `x + a k` cost three. Returns `x⁺` and the four stage points `x, x2, x3, x4` at which a
/// driven state is evaluated ([`rk4_points_driven`]).
#[inline(always)]
pub fn rk4_points_driver<const N: usize>(
    acc: impl Fn(&[f64; N], f64, &[f64; N]) -> [f64; N],
    x: &[f64; N],
    h: f64,
) -> ([f64; N], [[f64; N]; 4]) {
    let half = 0.5 * h;
    let x2 = acc(x, half, x);
    let x3 = acc(x, half, &x2);
    let x4 = acc(x, h, &x3);
    (
        acc(&rk4_points_mean(x, &x2, &x3, &x4), h / 6.0, &x4),
        [*x, x2, x3, x4],
    )
}

/// Classical RK4 in stage-point form ([`rk4_points_driver`]) on a state `z' = g(z, x)` driven
/// by a driver whose stage points are given, `g` as the accumulation
/// `acc(b, a, z, x) = b + a g(z, x)`: in exact arithmetic RK4 on the pair `(z, x)`. A system
/// that splits into a driver and small driven parts keeps only one part's numbers live.
#[inline(always)]
pub fn rk4_points_driven<const M: usize, const N: usize>(
    acc: impl Fn(&[f64; M], f64, &[f64; M], &[f64; N]) -> [f64; M],
    z: &[f64; M],
    stages: &[[f64; N]; 4],
    h: f64,
) -> [f64; M] {
    let half = 0.5 * h;
    let z2 = acc(z, half, z, &stages[0]);
    let z3 = acc(z, half, &z2, &stages[1]);
    let z4 = acc(z, h, &z3, &stages[2]);
    acc(&rk4_points_mean(z, &z2, &z3, &z4), h / 6.0, &z4, &stages[3])
}

/// `(x2 + 2 x3 + x4 − x)/3`: the part of the stage-point RK4 update made of stage points,
/// formed as `x + (x2 + 2 x3 + x4 − 4x)/3` so that the rounding of `1/3` (a relative bias of
/// −2⁻⁵⁴, the same sign at every step) touches only the step's increment, not the state.
#[inline(always)]
fn rk4_points_mean<const N: usize>(
    x: &[f64; N],
    x2: &[f64; N],
    x3: &[f64; N],
    x4: &[f64; N],
) -> [f64; N] {
    const THIRD: f64 = 1.0 / 3.0;
    let mut o = [0.0; N];
    for i in 0..N {
        let s = (-4.0f64).mul_add(x[i], 2.0f64.mul_add(x3[i], x2[i]) + x4[i]);
        o[i] = s.mul_add(THIRD, x[i]);
    }
    o
}

/// `y + a k`.
#[inline(always)]
fn axpy<T: Real, const N: usize>(y: &[T; N], a: f64, k: &[T; N]) -> [T; N] {
    let mut o = [T::splat(0.0); N];
    for i in 0..N {
        o[i] = y[i] + k[i].scale(a);
    }
    o
}

/// `Q_out = Q_y E` on the attitude blocks of two states.
#[inline(always)]
fn rotate_attitude<T: Real>(y: &[T], e: &[[T; 3]; 3], out: &mut [T]) {
    for r in 0..3 {
        let q0 = y[Q_AT + 3 * r];
        let q1 = y[Q_AT + 3 * r + 1];
        let q2 = y[Q_AT + 3 * r + 2];
        for k in 0..3 {
            out[Q_AT + 3 * r + k] = q0 * e[0][k] + q1 * e[1][k] + q2 * e[2][k];
        }
    }
}

/// One Runge–Kutta–Munthe-Kaas step of the rigid-body state with tableau `tab`. `R, V, ω`
/// follow the tableau in their vector space; the attitude follows it in the Lie algebra:
/// `θ_i = h Σ_j A_ij κ_j`, `Q_i = Q exp(θ̂_i)`, `κ_i = dexp⁻¹_{−θ_i}(ω_i)`, and
/// `Q_new = Q exp(h Σ B_i κ_i)`. Work space: `k` (s·n), `ytmp` (n), `kth` (s).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn rkmk_step<S: VectorField + ?Sized>(
    sys: &S,
    tab: &Tableau,
    t: f64,
    y: &[f64],
    h: f64,
    k: &mut [f64],
    ytmp: &mut [f64],
    kth: &mut [[f64; 3]],
    out: &mut [f64],
) {
    let s = tab.stages();
    let n = sys.dim();
    for i in 0..s {
        for idx in 0..n {
            let mut acc = 0.0;
            for m in 0..i {
                acc += tab.a[i * s + m] * k[m * n + idx];
            }
            ytmp[idx] = y[idx] + h * acc;
        }
        let mut th = [0.0; 3];
        for m in 0..i {
            for j in 0..3 {
                th[j] += tab.a[i * s + m] * kth[m][j];
            }
        }
        for v in th.iter_mut() {
            *v *= h;
        }
        let e = exp_so3(th);
        rotate_attitude(y, &e, ytmp);
        sys.rhs(t + tab.c[i] * h, ytmp, &mut k[i * n..(i + 1) * n]);
        kth[i] = dexpinv3(
            [-th[0], -th[1], -th[2]],
            [ytmp[OMEGA_AT], ytmp[OMEGA_AT + 1], ytmp[OMEGA_AT + 2]],
        );
    }
    for idx in 0..n {
        let mut acc = 0.0;
        for i in 0..s {
            acc += tab.b[i] * k[i * n + idx];
        }
        out[idx] = y[idx] + h * acc;
    }
    let mut th = [0.0; 3];
    for i in 0..s {
        for j in 0..3 {
            th[j] += tab.b[i] * kth[i][j];
        }
    }
    let e = exp_so3([h * th[0], h * th[1], h * th[2]]);
    rotate_attitude(y, &e, out);
}

/// [`rkmk_step`] with the classical RK4 tableau on a rigid state held in registers, rates
/// `f(t, y)`: the same operations in the same order (each stage point `y + h (a k)`, the
/// single nonzero coefficient of its row; `θ_i = h (a kθ)`, `Q_i = Q exp(θ̂_i)`,
/// `kθ_i = dexp⁻¹_{−θ_i}(ω_i)`; `Q_new = Q exp(h Σ b_i kθ_i)`), so its numbers are the
/// generic step's up to the sign of a zero. Its pieces are a stage's point
/// ([`rkmk4_point`]), its rates and its carry ([`rkmk4_first_carry`], [`rkmk4_carry`]), then
/// [`rkmk4_last`]; a block of lanes runs them one after the other across its lanes
/// ([`crate::lanes::BlockRkmk4Stages`]).
#[inline(always)]
pub fn rkmk4_registers<T: Real>(
    f: impl Fn(f64, &[T; STATE_SIZE]) -> [T; STATE_SIZE],
    t: f64,
    y: &[T; STATE_SIZE],
    h: f64,
) -> [T; STATE_SIZE] {
    // the stages in a loop with one call of the rates, as in `rk4_registers`; the carry
    // updated in place (on dual numbers a new carry per stage was a 4 kB `memcpy`)
    let mut c = [T::splat(0.0); RKMK4_CARRY];
    for i in 0..4 {
        let (ys, kt) = match i {
            0 => (*y, first_kt(y)),
            1 => rkmk4_point::<1, T>(y, h, &c),
            2 => rkmk4_point::<2, T>(y, h, &c),
            _ => rkmk4_point::<3, T>(y, h, &c),
        };
        let k = f(t + RK4_C[i] * h, &ys);
        match i {
            0 => rkmk4_carry_into::<0, T>(&k, &kt, &mut c),
            1 => rkmk4_carry_into::<1, T>(&k, &kt, &mut c),
            2 => rkmk4_carry_into::<2, T>(&k, &kt, &mut c),
            _ => rkmk4_carry_into::<3, T>(&k, &kt, &mut c),
        }
    }
    rkmk4_last(y, h, &c)
}

/// Numbers an RKMK4 step carries from a stage to the next: the stage's rates `k` and `kθ`,
/// and the running sums `0 + Σ b_j k_j` and `0 + Σ b_j kθ_j` (summed in the generic step's
/// order).
pub type Rkmk4Carry<T = f64> = [T; RKMK4_CARRY];
pub const RKMK4_CARRY: usize = 2 * STATE_SIZE + 6;
const CARRY_K: usize = 0;
const CARRY_SUM: usize = STATE_SIZE;
const CARRY_KT: usize = 2 * STATE_SIZE;
const CARRY_SUM_T: usize = 2 * STATE_SIZE + 3;

/// The carry of stage `I` (0-based) from its rates `k`, `kθ` and the previous carry.
#[inline(always)]
pub fn rkmk4_carry<const I: usize, T: Real>(
    k: &[T; STATE_SIZE],
    kt: &[T; 3],
    prev: Option<&Rkmk4Carry<T>>,
) -> Rkmk4Carry<T> {
    let mut c = prev.copied().unwrap_or([T::splat(0.0); RKMK4_CARRY]);
    rkmk4_carry_into::<I, T>(k, kt, &mut c);
    c
}

/// [`rkmk4_carry`] in place: `c`, the previous carry (zeros before the first stage), becomes
/// stage `I`'s.
#[inline(always)]
fn rkmk4_carry_into<const I: usize, T: Real>(
    k: &[T; STATE_SIZE],
    kt: &[T; 3],
    c: &mut Rkmk4Carry<T>,
) {
    let b = RK4_B[I];
    for i in 0..STATE_SIZE {
        c[CARRY_K + i] = k[i];
        c[CARRY_SUM + i] = c[CARRY_SUM + i] + k[i].scale(b);
    }
    for j in 0..3 {
        c[CARRY_KT + j] = kt[j];
        c[CARRY_SUM_T + j] = c[CARRY_SUM_T + j] + kt[j].scale(b);
    }
}

/// RKMK4's first carry from the rates `k_1 = f(t, y)`, with `kθ_1 = dexp⁻¹_0(ω)` (as the
/// generic step forms it); across a block's lanes too ([`crate::lanes::BlockRkmk4Stages`]).
#[inline(always)]
pub fn rkmk4_first_carry<T: Real>(y: &[T; STATE_SIZE], k: &[T; STATE_SIZE]) -> Rkmk4Carry<T> {
    rkmk4_carry::<0, T>(k, &first_kt(y), None)
}

/// The first stage's `kθ_1 = dexp⁻¹_0(ω)`.
#[inline(always)]
fn first_kt<T: Real>(y: &[T; STATE_SIZE]) -> [T; 3] {
    dexpinv3([T::splat(-0.0); 3], omega(y))
}

/// RKMK4's stage `I + 1` (`I` in 1..=3) but its rates: the stage point `y + h (a k)` with
/// the attitude `Q exp(θ̂)`, `θ = h (a kθ)` (`a = A[I][I−1]`, `k`, `kθ` the previous stage's),
/// and its `kθ = dexp⁻¹_{−θ}(ω)`.
#[inline(always)]
pub fn rkmk4_point<const I: usize, T: Real>(
    y: &[T; STATE_SIZE],
    h: f64,
    c: &Rkmk4Carry<T>,
) -> ([T; STATE_SIZE], [T; 3]) {
    let a = RK4_A[I][I - 1];
    let mut ys = [T::splat(0.0); STATE_SIZE];
    for i in 0..STATE_SIZE {
        ys[i] = y[i] + c[CARRY_K + i].scale(a).scale(h);
    }
    // no `array::map`: its closure is left out of line, compiled for the baseline
    let th = [
        c[CARRY_KT].scale(a).scale(h),
        c[CARRY_KT + 1].scale(a).scale(h),
        c[CARRY_KT + 2].scale(a).scale(h),
    ];
    rotate_attitude(y, &exp_so3(th), &mut ys);
    let kt = dexpinv3([-th[0], -th[1], -th[2]], omega(&ys));
    (ys, kt)
}

/// RKMK4's new state from the last carry: `y + h Σ b_i k_i`, the attitude
/// `Q exp(h Σ b_i kθ_i)`.
#[inline(always)]
pub fn rkmk4_last<T: Real>(y: &[T; STATE_SIZE], h: f64, c: &Rkmk4Carry<T>) -> [T; STATE_SIZE] {
    let mut out = [T::splat(0.0); STATE_SIZE];
    for i in 0..STATE_SIZE {
        out[i] = y[i] + c[CARRY_SUM + i].scale(h);
    }
    let th = [
        c[CARRY_SUM_T].scale(h),
        c[CARRY_SUM_T + 1].scale(h),
        c[CARRY_SUM_T + 2].scale(h),
    ];
    rotate_attitude(y, &exp_so3(th), &mut out);
    out
}

/// ω of a state.
#[inline(always)]
fn omega<T: Real>(y: &[T]) -> [T; 3] {
    [y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]]
}

/// `y` = `z` with ω = π/I in the ω slot (zero along a zero moment).
#[inline(always)]
pub fn momentum_to_velocity<S: RigidStructure + ?Sized>(sys: &S, z: &[f64]) -> State {
    velocity_of(sys.body(), z)
}

/// [`momentum_to_velocity`] of a body.
#[inline(always)]
pub fn velocity_of<T: Real>(body: &Body<T>, z: &[T]) -> [T; STATE_SIZE] {
    let mut y = [T::splat(0.0); STATE_SIZE];
    y.copy_from_slice(&z[..STATE_SIZE]);
    for k in 0..3 {
        y[OMEGA_AT + k] = z[OMEGA_AT + k] * body.inv_moments[k];
    }
    y
}

/// The momentum state `[R, V, Q, π = I ω]` of the splitting method from a state.
#[inline(always)]
pub fn velocity_to_momentum<S: RigidStructure + ?Sized>(sys: &S, y: &[f64], z: &mut [f64]) {
    z[..STATE_SIZE].copy_from_slice(&y[..STATE_SIZE]);
    for k in 0..3 {
        z[OMEGA_AT + k] = sys.body().moments[k] * y[OMEGA_AT + k];
    }
}

/// Momentum kick by the forces over `h`, in place: `V += h F/M` (a free body; about a pivot
/// its reaction balances F) and `π += h τ`.
#[inline(always)]
pub fn kick<S: RigidStructure + ?Sized>(sys: &S, t: f64, z: &mut [f64], h: f64) {
    let y = momentum_to_velocity(sys, z);
    kick_by(sys.body(), &sys.wrench(t, &y), z, h);
}

/// [`kick`] by the wrench `w = (F, τ)` (formed elsewhere: across a block's lanes,
/// [`crate::lanes::BlockSplittingStages`]).
#[inline(always)]
pub fn kick_by<T: Real>(body: &Body<T>, w: &[T; 6], z: &mut [T], h: f64) {
    let hh = T::splat(h);
    if !body.has_pivot {
        let c = hh * body.inv_mass;
        z[V_AT] = z[V_AT] + c * w[0];
        z[V_AT + 1] = z[V_AT + 1] + c * w[1];
        z[V_AT + 2] = z[V_AT + 2] + c * w[2];
    }
    z[OMEGA_AT] = z[OMEGA_AT] + hh * w[3];
    z[OMEGA_AT + 1] = z[OMEGA_AT + 1] + hh * w[4];
    z[OMEGA_AT + 2] = z[OMEGA_AT + 2] + hh * w[5];
}

/// One kick–drift–kick step on the momentum state `z = [R, V, Q, π]` (principal frame):
/// `kick(h/2) ∘ drift(h) ∘ kick(h/2)`, the drift the exact free rotor
/// ([`free_rotor_step`]) and `R += h V` (or, about a pivot, `R, V` slaved to the attitude).
/// Second order and symplectic for forces that depend on `(t, R, Q)` only; torque-free it
/// keeps `|L|`, the spatial `L` and `QᵀQ = I` to round-off.
#[inline(always)]
pub fn splitting_step<S: RigidStructure + ?Sized>(
    sys: &S,
    t: f64,
    z: &[f64],
    h: f64,
    out: &mut [f64],
) {
    splitting_step_with::<S, ANY_ROTOR>(sys, t, z, h, out)
}

/// [`splitting_step`] with the free rotor's branch named at compile time ([`free_rotor`]).
#[inline(always)]
pub fn splitting_step_with<S: RigidStructure + ?Sized, const ROTOR: u8>(
    sys: &S,
    t: f64,
    z: &[f64],
    h: f64,
    out: &mut [f64],
) {
    out[..STATE_SIZE].copy_from_slice(&z[..STATE_SIZE]);
    let body = *sys.body();
    kick(sys, t, out, 0.5 * h);
    drift::<ROTOR, f64>(&body, out, h);
    kick(sys, t + h, out, 0.5 * h);
    hold_pivot(&body, out);
}

/// The splitting step's drift over `h`, in place on the momentum state: the exact free rotor
/// ([`free_rotor`], its branch `ROTOR`) and, for a free body, `R += h V`; about a pivot `R`
/// and `V` follow the new attitude ([`hold_pivot`]), so that the next kick's forces act where
/// the centre of mass now is (with the drift's `R`, a force that depends on the position
/// about a pivot off the centre of mass made the step first order).
#[inline(always)]
pub fn drift<const ROTOR: u8, T: Real>(body: &Body<T>, z: &mut [T], h: f64) {
    free_rotor::<ROTOR, T>(body, z, h);
    if body.has_pivot {
        hold_pivot(body, z);
    } else {
        for k in 0..3 {
            z[R_AT + k] = z[R_AT + k] + T::splat(h) * z[V_AT + k];
        }
    }
}

/// About a pivot, the splitting step's end: `R`, `V` of the momentum state reset from its
/// attitude and `ω = π/I` ([`pivot_constrained`]); nothing for a free body.
#[inline(always)]
pub fn hold_pivot<T: Real>(body: &Body<T>, z: &mut [T]) {
    if body.has_pivot {
        let y = pivot_constrained(body, velocity_of(body, z));
        z[R_AT..R_AT + 3].copy_from_slice(&y[R_AT..R_AT + 3]);
        z[V_AT..V_AT + 3].copy_from_slice(&y[V_AT..V_AT + 3]);
    }
}

/// One Dormand–Prince 8(5,3) step from `(t, y)` with `f = ẏ(t, y)` (first same as last).
/// `out_y` receives the 8th-order solution and `out_f` its derivative; `k`
/// (DOP853_STAGES_EXTENDED · n) keeps the 12 stages and `out_f` (row 12) for
/// [`dop853_error_norm`] and [`dop853_dense`].
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn dop853_step<S: VectorField + ?Sized>(
    sys: &S,
    t: f64,
    y: &[f64],
    f: &[f64],
    h: f64,
    k: &mut [f64],
    ytmp: &mut [f64],
    out_y: &mut [f64],
    out_f: &mut [f64],
) {
    let n = sys.dim();
    let (y, ytmp) = (&y[..n], &mut ytmp[..n]);
    k[..n].copy_from_slice(&f[..n]);
    for s in 1..=DOP853_STAGES {
        // rows 1–11: the stages; row 12: the derivative at the new point (B is row 12 of A).
        // Summed stage by stage over whole rows (they vectorise), each element's terms in
        // the same order as element by element: the same numbers
        ytmp.fill(0.0);
        for (m, a) in DOP853_A[s][..s].iter().enumerate() {
            for (acc, km) in ytmp.iter_mut().zip(&k[m * n..(m + 1) * n]) {
                *acc += a * km;
            }
        }
        for (acc, yi) in ytmp.iter_mut().zip(y) {
            *acc = yi + h * *acc;
        }
        if s == DOP853_STAGES {
            out_y[..n].copy_from_slice(&ytmp[..n]);
        }
        sys.rhs(t + DOP853_C[s] * h, ytmp, &mut k[s * n..(s + 1) * n]);
    }
    out_f[..n].copy_from_slice(&k[DOP853_STAGES * n..(DOP853_STAGES + 1) * n]);
}

/// The scaled error of the last DOP853 step: Hairer's combination of the 5th- and 3rd-order
/// estimators, `|h| Σe5² / √((Σe5² + 0.01 Σe3²) n)` with `e = (Σ_i E_i k_i)/sc`,
/// `sc = atol + rtol max(|y|, |y_new|)`, over the blocks `(ns, p)` of the `n` components
/// ([`crate::system::VectorField::error_blocks`]): the first `ns` components, and each of the
/// `p` directions' `ns` sensitivities after them; the largest of these norms. A step is
/// accepted below 1.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn dop853_error_norm(
    k: &[f64],
    n: usize,
    blocks: (usize, usize),
    h: f64,
    y: &[f64],
    y_new: &[f64],
    rtol: f64,
    atol: f64,
) -> f64 {
    let (ns, p) = blocks;
    let block = |first: usize, stride: usize| {
        let mut e5 = 0.0;
        let mut e3 = 0.0;
        for c in 0..ns {
            let idx = first + c * stride;
            let scale = atol + y[idx].abs().max(y_new[idx].abs()) * rtol;
            let mut a5 = 0.0;
            let mut a3 = 0.0;
            for i in 0..=DOP853_STAGES {
                a5 += DOP853_E5[i] * k[i * n + idx];
                a3 += DOP853_E3[i] * k[i * n + idx];
            }
            a5 /= scale;
            a3 /= scale;
            e5 += a5 * a5;
            e3 += a3 * a3;
        }
        if e5 == 0.0 && e3 == 0.0 {
            return 0.0;
        }
        h.abs() * e5 / ((e5 + 0.01 * e3) * ns as f64).sqrt()
    };
    // one call of `block` (a closure called twice is left out of line, in the baseline)
    let mut err = f64::NAN;
    for j in 0..=p {
        let e = if j == 0 {
            block(0, 1)
        } else {
            block(ns + j - 1, p)
        };
        err = if j == 0 { e } else { err.max(e) };
    }
    err
}

/// The coefficients `fd` (7 · n) of the 7th-order interpolant over the last step
/// `[t_old, t_old + h]` from `y_old` to `y` (`f = ẏ` at the end): three more stages (rows
/// 13–15 of `k`) and the dense-output matrix `D`. Always inlined: the state's length is then
/// a constant of the system, and its loops are unrolled without link-time optimisation.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn dop853_dense<S: VectorField + ?Sized>(
    sys: &S,
    t_old: f64,
    h: f64,
    y_old: &[f64],
    y: &[f64],
    f: &[f64],
    k: &mut [f64],
    ytmp: &mut [f64],
    fd: &mut [f64],
) {
    let n = sys.dim();
    // every slice cut to its length once, so that the loops below carry no bounds checks
    let (y_old, y, f, ytmp) = (&y_old[..n], &y[..n], &f[..n], &mut ytmp[..n]);
    let k = &mut k[..DOP853_STAGES_EXTENDED * n];
    let fd = &mut fd[..7 * n];
    // the sums run stage by stage over whole rows (contiguous, so they vectorise), each
    // element's terms added in the same order as element by element: the same numbers
    for s in DOP853_STAGES + 1..DOP853_STAGES_EXTENDED {
        let (done, next) = k.split_at_mut(s * n);
        ytmp.fill(0.0);
        for (m, a) in DOP853_A[s][..s].iter().enumerate() {
            for (acc, km) in ytmp.iter_mut().zip(&done[m * n..(m + 1) * n]) {
                *acc += a * km;
            }
        }
        for (acc, yo) in ytmp.iter_mut().zip(y_old) {
            *acc = yo + h * *acc;
        }
        sys.rhs(t_old + DOP853_C[s] * h, ytmp, &mut next[..n]);
    }
    let k = &*k;
    for idx in 0..n {
        let dy = y[idx] - y_old[idx];
        fd[idx] = dy;
        fd[n + idx] = h * k[idx] - dy;
        fd[2 * n + idx] = 2.0 * dy - h * (f[idx] + k[idx]);
    }
    for (r, d) in DOP853_D.iter().enumerate() {
        let row = &mut fd[(3 + r) * n..(4 + r) * n];
        row.fill(0.0);
        for (s, c) in d.iter().enumerate() {
            for (acc, ks) in row.iter_mut().zip(&k[s * n..(s + 1) * n]) {
                *acc += c * ks;
            }
        }
        for acc in row.iter_mut() {
            *acc *= h;
        }
    }
}

/// The DOP853 interpolant at the fraction `x` ∈ [0, 1] of the step, into `out`:
/// `y_old + x(F0 + (1−x)(F1 + x(F2 + (1−x)(F3 + …))))`.
#[inline(always)]
pub fn dop853_interpolate(fd: &[f64], y_old: &[f64], x: f64, out: &mut [f64]) {
    let n = y_old.len();
    let p = DOP853_INTERPOLATOR_POWER;
    for idx in 0..n {
        let mut acc = 0.0;
        for i in 0..p {
            acc += fd[(p - 1 - i) * n + idx];
            acc *= if i % 2 == 0 { x } else { 1.0 - x };
        }
        out[idx] = y_old[idx] + acc;
    }
}

/// The parameters of the standard step-size controller.
#[derive(Clone, Copy, Debug)]
pub struct Control {
    pub rtol: f64,
    pub atol: f64,
    pub safety: f64,
    pub min_factor: f64,
    pub max_factor: f64,
    pub max_step: f64,
    /// 0 selects the first step automatically ([`initial_step_size`]).
    pub first_step: f64,
}

impl Control {
    /// The controller with tolerances `rtol`, `atol` and SciPy's constants: safety 0.9, the
    /// factor within [0.2, 10], no largest step, the first step chosen automatically.
    pub const fn with_tolerances(rtol: f64, atol: f64) -> Self {
        Control {
            rtol,
            atol,
            safety: 0.9,
            min_factor: 0.2,
            max_factor: 10.0,
            max_step: f64::INFINITY,
            first_step: 0.0,
        }
    }
}

/// The standard controller (Hairer, Nørsett & Wanner §II.4): the next step is the last one
/// times `safety · err^(−1/(q+1))`, clipped to `[min_factor, max_factor]` (and not above 1
/// right after a rejection); `q` the order of the error estimator.
#[inline(always)]
pub fn step_size_factor(error_norm: f64, error_order: f64, rejected: bool, c: &Control) -> f64 {
    let exponent = -1.0 / (error_order + 1.0);
    if error_norm < 1.0 {
        let mut factor = if error_norm == 0.0 {
            c.max_factor
        } else {
            c.max_factor.min(c.safety * error_norm.powf(exponent))
        };
        if rejected {
            factor = factor.min(1.0);
        }
        return factor;
    }
    c.min_factor.max(c.safety * error_norm.powf(exponent))
}

/// An empirical first step (Hairer, Nørsett & Wanner §II.4, as SciPy's
/// `select_initial_step`): `h0 = 0.01 |y0|/|f0|` in the scaled RMS norm, then
/// `h1 = (0.01/max(|f0|, |f'|))^(1/(q+1))`, the smaller of `100 h0`, `h1`, the interval and
/// `max_step`. One more evaluation of the vector field.
#[allow(clippy::too_many_arguments)]
pub fn initial_step_size<S: VectorField + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    f0: &[f64],
    t_end: f64,
    order: f64,
    c: &Control,
    ytmp: &mut [f64],
    ftmp: &mut [f64],
) -> f64 {
    let n = sys.dim();
    let interval = (t_end - t0).abs();
    if interval == 0.0 {
        return 0.0;
    }
    let (rtol, atol) = (c.rtol, c.atol);
    let mut d0 = 0.0;
    let mut d1 = 0.0;
    for idx in 0..n {
        let scale = atol + y0[idx].abs() * rtol;
        d0 += (y0[idx] / scale).powi(2);
        d1 += (f0[idx] / scale).powi(2);
    }
    let d0 = (d0 / n as f64).sqrt();
    let d1 = (d1 / n as f64).sqrt();
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0 = h0.min(interval);
    for idx in 0..n {
        ytmp[idx] = y0[idx] + h0 * f0[idx];
    }
    sys.rhs(t0 + h0, ytmp, ftmp);
    let mut d2 = 0.0;
    for idx in 0..n {
        let scale = atol + y0[idx].abs() * rtol;
        d2 += ((ftmp[idx] - f0[idx]) / scale).powi(2);
    }
    let d2 = (d2 / n as f64).sqrt() / h0;
    let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
        1e-6f64.max(h0 * 1e-3)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (order + 1.0))
    };
    (100.0 * h0).min(h1).min(interval).min(c.max_step)
}

/// The steps in registers of a [`RigidStructure`] whose structure offers nothing cheaper, as
/// trait items for its `impl`: `default_rigid_steps!(rk4, rkmk4, splitting)` (or some of them)
/// writes [`rk4_registers`], [`rkmk4_registers`] on the system's rates and [`splitting_step`].
#[macro_export]
macro_rules! default_rigid_steps {
    ($($step:ident),+) => { $($crate::default_rigid_steps!(@one $step);)+ };
    (@one rk4) => {
        #[inline(always)]
        fn rk4(&self, t: f64, y: &$crate::rigid::State, h: f64) -> $crate::rigid::State {
            $crate::steppers::rk4_registers(
                #[inline(always)]
                |t, y| self.rates(t, y),
                t,
                y,
                h,
            )
        }
    };
    (@one rkmk4) => {
        #[inline(always)]
        fn rkmk4(&self, t: f64, y: &$crate::rigid::State, h: f64) -> $crate::rigid::State {
            $crate::steppers::rkmk4_registers(
                #[inline(always)]
                |t, y| self.rates(t, y),
                t,
                y,
                h,
            )
        }
    };
    (@one splitting) => {
        #[inline(always)]
        fn splitting(&self, t: f64, z: &$crate::rigid::State, h: f64) -> $crate::rigid::State {
            let mut out = [0.0; $crate::layout::STATE_SIZE];
            $crate::steppers::splitting_step(self, t, z, h, &mut out);
            out
        }
    };
}
