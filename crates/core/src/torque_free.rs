//! The torque-free rotation in closed form (`docs/theory.md` §1, "Torque-free body",
//! eqs (20)–(33); `docs/torque_free.md`).
//!
//! Every function works in the *sorted principal frame*: moments ascending `I1 ≤ I2 ≤ I3`, ω in
//! those axes. The batched functions at the end map body-frame inputs through the sorted axes
//! `S` (columns, body coordinates).
//!
//! **The regime.** Everything the closed form needs of one initial ω is computed once by
//! [`Regime::new`]:
//!
//! * the invariants (30)–(31): `k` (`2k = Σ I_i ω_i²`) and `a = |L|`;
//! * the case: [`SPHERICAL`] (ω constant), [`FIXED`] (a fixed point: ω constant),
//!   [`PRECESSION`] (a symmetric body: `π = Aω` turns about the symmetry axis `s` at the rate
//!   `−ν`, `ν = (1/I_s − 1/I⊥) π_s`), or, for three distinct moments, [`AROUND_E3`],
//!   [`AROUND_E1`] (the polhode circles e3 or e1) and [`SEPARATRIX`];
//! * for the last three, the Jacobi form `ω = (σ1 α1 cn u, σ2 α2 sn u, σ3 α3 dn u)` (pole e3)
//!   or `(σ1 α1 dn u, σ2 α2 sn u, σ3 α3 cn u)` (pole e1), `u = u0 + λt`, parameter `m` and its
//!   complement `m1` (formed without cancellation, so the solution stays accurate arbitrarily
//!   close to the separatrix), and the quarter period `K(m)`.
//!
//! The invariants' combinations `P3 = 2k I3 − a² ≥ 0` and `P1 = a² − 2k I1 ≥ 0` are formed as
//! sums of squares (no cancellation), through `hypot` and after scaling ω by a power of two, so
//! that the solution is scale invariant over the whole floating-point range.
//!
//! **The attitude.** z-x-z Euler angles `(ψ, θ, φ)` of the body relative to the invariable
//! frame (z along L), with pole the axis the polhode circles (e3, or e1 through the
//! right-handed relabelling `(e3, −e2, e1)`): `cos θ = π_pole/a`, `tan φ = π_1'/π_2'` and
//! `ψ(t) = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]`, `Π(u) = ∫₀^u du/(1 − n sn² u)`,
//! `n = −I_p (I2 − I1)/(I1 (I3 − I2))` (pole e3; swap 1 ↔ 3 for pole e1), n < 0 (Landau &
//! Lifshitz, *Mechanics*, §37; Whittaker, *Analytical Dynamics*, §69). Symmetric bodies:
//! `Q(t) = exp(t L̂/I⊥) Q0 exp(ν t ê_s)`; fixed points: `Q0 exp(Ω t)`.
//!
//! **Ensembles in lanes.** The Jacobi form's formulas (the polhode radii, the Jacobi form, the
//! AGM sequence, `u0`, ω(t)) are written once, generic over [`Real`]: [`Regime::with`] and
//! [`Regime::omega_at`] run them on `f64` for one motion; [`exact_omegas`] runs them on
//! [`WIDTH`] motions at a time in SIMD lanes ([`omegas_in_lanes`]: structure of arrays, the
//! member loop innermost, the instruction set chosen at run time), each lane computing bit for
//! bit what its single run computes. The attitude's formulas are generic too
//! ([`EllipticMotion`]: `Π(u)` from the reduction of `u` that ω(t) makes, by Carlson's `R_F`
//! and `R_J` with a polynomial `atan`; θ and φ as ratios of the body momentum's components;
//! ψ's sine and cosine by [`sin_cos`]): [`attitude_at`] runs them on `f64`,
//! [`exact_attitudes`] in lanes ([`attitudes_in_lanes`]). Members off the plain elliptic case
//! (fixed points, the separatrix and `m1 <` [`NEAR_ONE`], extreme scales, symmetric bodies)
//! run one by one.

use crate::cmath::{frexp, ldexp};
use crate::elliptic::{
    ellippi_complete, first_kind_from_sn_cn, first_kind_in_period, jacobi_reduced_with, parity,
    reduce_quarter, third_kind_reduced, third_kind_u, Agm, NEAR_ONE, TINY_M1,
};
use crate::invariants::principal_invariants;
use crate::real::{py_max, py_min, sin_cos, Mask, Real, Wide, WideMask, WIDTH};
use crate::so3::{exp_so3, matmul, zxz_matrix_sc, Mat3, Vec3};
use rayon::prelude::*;

/// Case: a spherical body (ω constant).
pub const SPHERICAL: u8 = 0;
/// Case: a symmetric body, ω precessing about the symmetry axis.
pub const PRECESSION: u8 = 1;
/// Case: a fixed point of Euler's equation (ω constant).
pub const FIXED: u8 = 2;
/// Case: the polhode circles e3.
pub const AROUND_E3: u8 = 3;
/// Case: the polhode circles e1.
pub const AROUND_E1: u8 = 4;
/// Case: on the separatrix (m = 1).
pub const SEPARATRIX: u8 = 5;
/// The polhode family of each case, as `FreeRigidBody.classify` names it.
pub const CASE_NAMES: [&str; 6] = [
    "spherical",
    "symmetric",
    "fixed point",
    "around e3",
    "around e1",
    "separatrix",
];

/// ω within this relative distance of the intermediate axis is taken as that fixed point:
/// leaving it takes longer than ln(1e140)/σ ≈ 322/σ, and the invariants' differences that set
/// the orbit underflow in double precision.
pub const NEAR_UNSTABLE_AXIS: f64 = 1e-140;

/// Offsets of the flat regime row (`poinsot.kernels.torque_free`'s layout), see
/// [`Regime::to_row`].
pub mod row {
    pub const CASE: usize = 0;
    pub const ENERGY: usize = 1;
    pub const MOMENTUM: usize = 2;
    pub const ALPHA: usize = 3; // 3 entries
    pub const LAM: usize = 6;
    pub const M: usize = 7;
    pub const M1: usize = 8;
    pub const SIGNS: usize = 9; // 3 entries
    pub const U0: usize = 12;
    pub const POLE: usize = 13;
    pub const QUARTER: usize = 14;
    pub const NU: usize = 15;
    pub const AXIS: usize = 16;
    pub const I_PERP: usize = 17;
    pub const SIZE: usize = 18;
}

/// The square roots of a body's moments that every motion's regime uses:
/// `√(I1 (I3 − I1))`, `√(I2 (I3 − I2))`, `√(I2 (I2 − I1))`, `√(I3 (I3 − I1))`, and the rates
/// `√((I3 − I2)/(I1 I2 I3))`, `√((I2 − I1)/(I1 I2 I3))` of `λ` (sorted moments).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Radicals {
    pub r13: f64,
    pub r23: f64,
    pub r12: f64,
    pub r33: f64,
    pub rate3: f64,
    pub rate1: f64,
    /// `√(I1 (I3 − I1)) / √(I2 (I3 − I2))` and `√(I3 (I3 − I1)) / √(I2 (I2 − I1))`: the ratios
    /// `|cn u0 / sn u0| = cot3 |ω1/ω2|` (pole e3) and `cot1 |ω3/ω2|` (pole e1).
    pub cot3: f64,
    pub cot1: f64,
}

impl Radicals {
    pub fn new(moments: Vec3) -> Radicals {
        let [i1, i2, i3] = moments;
        Radicals {
            r13: (i1 * (i3 - i1)).sqrt(),
            r23: (i2 * (i3 - i2)).sqrt(),
            r12: (i2 * (i2 - i1)).sqrt(),
            r33: (i3 * (i3 - i1)).sqrt(),
            rate3: ((i3 - i2) / (i1 * i2 * i3)).sqrt(),
            rate1: ((i2 - i1) / (i1 * i2 * i3)).sqrt(),
            cot3: (i1 * (i3 - i1)).sqrt() / (i2 * (i3 - i2)).sqrt(),
            cot1: (i3 * (i3 - i1)).sqrt() / (i2 * (i2 - i1)).sqrt(),
        }
    }
}

/// `(√P3, √P1)`, `P3 = 2k I3 − a²`, `P1 = a² − 2k I1` as sums of squares (no cancellation):
/// `P3 = I1 (I3 − I1) x1² + I2 (I3 − I2) x2²`, `P1 = I2 (I2 − I1) x2² + I3 (I3 − I1) x3²`
/// (scaled ω `x`; [`Real::norm2`], which clears `plain` in the lanes it leaves to `f64`).
#[inline(always)]
fn polhode_radii<T: Real>(r: &Radicals, x: [T; 3], plain: &mut T::Mask) -> (T, T) {
    let c = T::splat;
    let q3 = T::norm2(c(r.r13) * x[0], c(r.r23) * x[1], plain);
    let q1 = T::norm2(c(r.r12) * x[1], c(r.r33) * x[2], plain);
    (q3, q1)
}

/// The Jacobi form of a motion of a body with three distinct moments, off the fixed points
/// (`√P3 = q3 > 0`, `√P1 = q1 > 0`), from the scaled ω `x` (see the module docs): amplitudes
/// and rate in the scale of `x`. Generic over [`Real`].
#[derive(Clone, Copy, Debug, Default)]
struct JacobiForm<T: Real> {
    /// `(α1, α2, α3)` and `λ` (scaled).
    alpha: [T; 3],
    lam: T,
    /// `m` and `m1` (clamped to [0, 1]; `(1, 0)` for a subnormal `m1`).
    m: T,
    m1: T,
    /// `σ1`, `σ3`.
    s1: T,
    s3: T,
    /// Of the signs of `sn u0` and `cn u0`, and `|cn u0 / sn u0|`.
    sn0: T,
    cn0: T,
    cot0: T,
    /// Where the polhode circles e3 (else e1).
    e3: T::Mask,
}

impl<T: Real> JacobiForm<T> {
    #[inline(always)]
    fn new(moments: Vec3, r: &Radicals, x: [T; 3], q3: T, q1: T) -> JacobiForm<T> {
        let c = T::splat;
        let [i1, i2, i3] = moments;
        let [x0, x1, x2] = x;
        let d2 = c(i3 * (i3 - i2)) * x2 * x2 - c(i1 * (i2 - i1)) * x0 * x0; // a² − 2k I2
                                                                            // around e3 (d2 > 0), or the separatrix (d2 = 0); else around e1
        let e3 = d2.ge(c(0.0));
        // e3: (q3, q1), e1: (q1, q3)
        let (qa, qb) = (T::select(e3, q3, q1), T::select(e3, q1, q3));
        let a0 = q3 / c(r.r13);
        let a1 = qa / T::select(e3, c(r.r23), c(r.r12));
        let a2 = q1 / c(r.r33);
        let lam = qb * T::select(e3, c(r.rate3), c(r.rate1));
        let ratio = qa / qb;
        let m = T::select(e3, c((i2 - i1) / (i3 - i2)), c((i3 - i2) / (i2 - i1))) * ratio * ratio;
        let m1 =
            c(i3 - i1) * T::select(e3, d2, -d2) / (T::select(e3, c(i3 - i2), c(i2 - i1)) * qb * qb);
        let m = py_min(py_max(m, c(0.0)), c(1.0));
        let m1 = py_min(py_max(m1, c(0.0)), c(1.0));
        // subnormal: the separatrix is the orbit to within O(m1)
        let sep = m1.lt(c(1e-300));
        let m = T::select(sep, c(1.0), m);
        let m1 = T::select(sep, c(0.0), m1);
        // Signs: the ODE needs σ1 = σ2 σ3. Off the separatrix cn takes both signs, so the sign
        // of the cn-component is +1 (absorbed in the phase); on the separatrix cn = sech u > 0
        // and each of the four arcs keeps the signs of both ω1 and ω3.
        let off = m1.unequal(c(0.0));
        let s1 = T::select(e3 & off, c(1.0), T::select(x0.gt(c(0.0)), c(1.0), c(-1.0)));
        let s3 = T::select(!e3 & off, c(1.0), T::select(x2.gt(c(0.0)), c(1.0), c(-1.0)));
        // sn u0 = σ1 σ3 ω2/α2, cn u0 = σ1 ω1/α1 (pole e3) or σ3 ω3/α3 (pole e1)
        let sn0 = s1 * s3 * x1;
        let xc = T::select(e3, x0, x2);
        let cn0 = T::select(e3, s1, s3) * xc;
        let cot0 = xc.abs() * T::select(e3, c(r.cot3), c(r.cot1)) / x1.abs();
        JacobiForm {
            alpha: [a0, a1, a2],
            lam,
            m,
            m1,
            s1,
            s3,
            sn0,
            cn0,
            cot0,
            e3,
        }
    }
}

/// ω (sorted principal frame) from the Jacobi functions: `(cn, sn, dn)` (pole e3) or
/// `(dn, sn, cn)` (pole e1) times the signed amplitudes `σ_i α_i`.
#[inline(always)]
fn jacobi_omega<T: Real>(e3: T::Mask, sa: [T; 3], sn: T, cn: T, dn: T) -> [T; 3] {
    let (first, last) = (T::select(e3, cn, dn), T::select(e3, dn, cn));
    [sa[0] * first, sa[1] * sn, sa[2] * last]
}

/// The regime of one torque-free motion: everything the closed form needs of `ω(0)` (see the
/// module docs). Fields unused by a case are zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Regime {
    /// One of [`SPHERICAL`], [`PRECESSION`], [`FIXED`], [`AROUND_E3`], [`AROUND_E1`],
    /// [`SEPARATRIX`].
    pub case: u8,
    /// `k`, `2k = Σ I_i ω_i²` (30).
    pub energy: f64,
    /// `a = |L|` (31).
    pub momentum: f64,
    /// The amplitudes `α_i` of the Jacobi form.
    pub alpha: Vec3,
    /// `λ`: `u = u0 + λ t`.
    pub lam: f64,
    /// The parameter `m` and its complement `m1 = 1 − m`.
    pub m: f64,
    pub m1: f64,
    /// The signs `σ_i` (`σ2 = σ1 σ3`).
    pub signs: Vec3,
    /// `u0`, the argument at t = 0.
    pub u0: f64,
    /// The pole: 2 (e3) or 0 (e1).
    pub pole: u8,
    /// The quarter period `K(m)`.
    pub quarter: f64,
    /// The precession rate `ν` of a symmetric body.
    pub nu: f64,
    /// The symmetry axis of a symmetric body: 0 (prolate) or 2 (oblate).
    pub axis: u8,
    /// The transverse moment `I⊥` of a symmetric body.
    pub i_perp: f64,
    /// The AGM sequence of `m1` (elliptic cases off the separatrix), made once for every time
    /// of ω(t) (the Jacobi functions use it for `m1 ≥` [`NEAR_ONE`]).
    pub agm: Agm,
}

impl Regime {
    /// The regime of the motion from `ω(0) = w` (sorted principal frame) for sorted moments
    /// `moments`; `symmetry` the code of [`crate::freebody::symmetry_code`].
    pub fn new(moments: Vec3, symmetry: u8, w: Vec3) -> Regime {
        Regime::with(moments, &Radicals::new(moments), symmetry, w)
    }

    /// [`Regime::new`] with the body's [`Radicals`] made once (for many motions of one body).
    pub fn with(moments: Vec3, radicals: &Radicals, symmetry: u8, w: Vec3) -> Regime {
        let mut reg = Regime::default();
        let [w0, w1, w2] = w;
        let big = py_max(py_max(w0.abs(), w1.abs()), w2.abs());
        if symmetry == 3 {
            reg.case = SPHERICAL;
        } else if big == 0.0 {
            reg.case = FIXED;
        }
        if big == 0.0 {
            return reg;
        }
        // scale ω by a power of two (exactly) so that squares neither underflow nor overflow
        let e = frexp(big).1;
        let sc = ldexp(1.0, -e);
        let x0 = w0 * sc;
        let x1 = w1 * sc;
        let x2 = w2 * sc;
        let (k, a) = principal_invariants(moments, [x0, x1, x2]);
        reg.energy = ldexp(k, 2 * e);
        reg.momentum = ldexp(a, e);
        if symmetry == 3 {
            return reg;
        }
        if symmetry != 0 {
            // prolate (1): axis e1, I⊥ = I3; oblate (2): axis e3, I⊥ = I1
            let s: usize = if symmetry == 2 { 2 } else { 0 };
            let i_perp = if symmetry == 2 {
                moments[0]
            } else {
                moments[2]
            };
            let ws = if s == 2 { w2 } else { w0 };
            let nu = (1.0 / moments[s] - 1.0 / i_perp) * moments[s] * ws;
            let transverse_zero = if s == 2 {
                w0 == 0.0 && w1 == 0.0
            } else {
                w1 == 0.0 && w2 == 0.0
            };
            reg.case = if nu == 0.0 || transverse_zero {
                FIXED
            } else {
                PRECESSION
            };
            reg.nu = nu;
            reg.axis = s as u8;
            reg.i_perp = i_perp;
            return reg;
        }
        if py_max(x0.abs(), x2.abs()) <= NEAR_UNSTABLE_AXIS * x1.abs() {
            reg.case = FIXED;
            return reg;
        }
        let x = [x0, x1, x2];
        let (q3, q1) = polhode_radii(radicals, x, &mut true);
        if q3 == 0.0 || q1 == 0.0 {
            // on e3 or on e1
            reg.case = FIXED;
            return reg;
        }
        let f = JacobiForm::new(moments, radicals, x, q3, q1);
        let (m, m1) = (f.m, f.m1);
        reg.case = if m1 == 0.0 {
            SEPARATRIX
        } else if f.e3 {
            AROUND_E3
        } else {
            AROUND_E1
        };
        if m1 == 0.0 {
            reg.quarter = f64::INFINITY;
            let a_cn = if f.e3 { f.alpha[0] } else { f.alpha[2] };
            reg.u0 = first_kind_from_sn_cn(f.sn0 / f.alpha[1], f.cn0 / a_cn, m, m1);
        } else {
            reg.agm = Agm::new(m1);
            reg.quarter = reg.agm.quarter(); // = ellipk_m1(m1), the same sequence
            reg.u0 = first_kind_in_period(f.cot0, f.sn0, f.cn0, &reg.agm, reg.quarter);
        }
        reg.alpha = f.alpha.map(|a| ldexp(a, e));
        reg.lam = ldexp(f.lam, e);
        reg.m = m;
        reg.m1 = m1;
        reg.signs = [f.s1, f.s1 * f.s3, f.s3];
        reg.pole = if f.e3 { 2 } else { 0 };
        reg
    }

    /// The flat row (`row::SIZE` numbers at the offsets of [`row`]) of
    /// `poinsot.kernels.torque_free.regime_into`.
    pub fn to_row(&self) -> [f64; row::SIZE] {
        let mut out = [0.0; row::SIZE];
        out[row::CASE] = self.case as f64;
        out[row::ENERGY] = self.energy;
        out[row::MOMENTUM] = self.momentum;
        out[row::ALPHA..row::ALPHA + 3].copy_from_slice(&self.alpha);
        out[row::LAM] = self.lam;
        out[row::M] = self.m;
        out[row::M1] = self.m1;
        out[row::SIGNS..row::SIGNS + 3].copy_from_slice(&self.signs);
        out[row::U0] = self.u0;
        out[row::POLE] = self.pole as f64;
        out[row::QUARTER] = self.quarter;
        out[row::NU] = self.nu;
        out[row::AXIS] = self.axis as f64;
        out[row::I_PERP] = self.i_perp;
        out
    }

    /// Whether ω(t) is given by Jacobi functions (three distinct moments, off the fixed points).
    #[inline]
    pub fn is_elliptic(&self) -> bool {
        matches!(self.case, AROUND_E1 | AROUND_E3 | SEPARATRIX)
    }

    /// The period of ω(t): `4K(m)/λ` (three distinct moments), `2π/|ν|` (symmetric); `inf` on
    /// the separatrix, NaN where ω is constant (fixed points, spherical bodies).
    pub fn period(&self) -> f64 {
        match self.case {
            PRECESSION => 2.0 * std::f64::consts::PI / self.nu.abs(),
            AROUND_E1 | AROUND_E3 => 4.0 * self.quarter / self.lam,
            SEPARATRIX => f64::INFINITY,
            _ => f64::NAN,
        }
    }

    /// Time between successive sign changes of ω2 (the tennis-racket flips): `2K(m)/λ`; `inf`
    /// on the separatrix, NaN where there is no flip (symmetric bodies, fixed points).
    pub fn flip_interval(&self) -> f64 {
        match self.case {
            AROUND_E1 | AROUND_E3 => 2.0 * self.quarter / self.lam,
            SEPARATRIX => f64::INFINITY,
            _ => f64::NAN,
        }
    }

    /// ω(t) (sorted principal frame) of the motion from `w` (the ω this regime was made from).
    pub fn omega_at(&self, moments: Vec3, w: Vec3, t: f64) -> Vec3 {
        match self.case {
            SPHERICAL | FIXED => w,
            PRECESSION => {
                let p = turn_about_axis(
                    self.axis as usize,
                    -self.nu * t,
                    [moments[0] * w[0], moments[1] * w[1], moments[2] * w[2]],
                );
                [p[0] / moments[0], p[1] / moments[1], p[2] / moments[2]]
            }
            _ => {
                let (sn, cn, dn, _, _) = jacobi_reduced_with(
                    self.u0 + self.lam * t,
                    self.m,
                    self.m1,
                    self.quarter,
                    &self.agm,
                );
                let sa = [0, 1, 2].map(|i| self.signs[i] * self.alpha[i]);
                jacobi_omega(self.pole == 2, sa, sn, cn, dn)
            }
        }
    }
}

/// The vector `x` turned by `angle` about principal axis `s`.
#[inline(always)]
fn turn_about_axis(s: usize, angle: f64, x: Vec3) -> Vec3 {
    let c = angle.cos();
    let n = angle.sin();
    let [x0, x1, x2] = x;
    match s {
        0 => [x0, c * x1 - n * x2, n * x1 + c * x2],
        1 => [n * x2 + c * x0, x1, c * x2 - n * x0],
        _ => [c * x0 - n * x1, n * x0 + c * x1, x2],
    }
}

pub use crate::so3::zxz_matrix;

/// `(θ, φ)` of the body relative to the invariable frame from the body momentum `π`:
/// relabelled as `(π3, −π2, π1)` when the pole is e1.
#[inline(always)]
fn relabelled_angles(pole: u8, p: Vec3) -> (f64, f64) {
    let [b0, b1, b2] = if pole == 0 { [p[2], -p[1], p[0]] } else { p };
    (b0.hypot(b1).atan2(b2), b0.atan2(b1))
}

/// What the elliptic attitude needs beyond the regime: the invariable frame `p0`
/// (`Q(t) = P0 Rzxz(ψ, θ, φ) B`), the characteristic `n`, `I_p`, `I_q` and `Π(u0)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AttitudeSetup {
    /// The invariable frame → space.
    pub p0: Mat3,
    /// The characteristic `n` of the third-kind integral (n < 0).
    pub n: f64,
    /// The moment about the pole, `I_p`.
    pub i_pole: f64,
    /// The moment about the other end axis, `I_q`.
    pub i_other: f64,
    /// `Π(u0) = ∫₀^u0 du/(1 − n sn² u)`.
    pub pi_u0: f64,
    /// The complete integral `Π(n|m)` (zero on the separatrix and where `m1 <` [`TINY_M1`]).
    pub pi_complete: f64,
    /// `ψ`'s factor of `Π(u) − Π(u0)`: `a (I_p − I_q)/(I_p I_q λ)`.
    pub psi_pi: f64,
}

/// Whether the attitude of an elliptic regime takes `Π(u)` from the reduction ω(t) made
/// ([`third_kind_reduced`], in lanes too): off the separatrix and `m1 ≥` [`TINY_M1`] (below,
/// [`third_kind_u`]'s separatrix forms).
#[inline(always)]
fn reduced_third_kind(reg: &Regime) -> bool {
    reg.m1 >= TINY_M1 && reg.quarter.is_finite()
}

impl AttitudeSetup {
    /// The attitude setup of the motion from `w` with regime `reg` and `Q(0) = q0` (sorted
    /// principal frame → space). All zeros outside the elliptic cases.
    pub fn new(moments: Vec3, reg: &Regime, w: Vec3, q0: &Mat3) -> AttitudeSetup {
        if !reg.is_elliptic() {
            return AttitudeSetup::default();
        }
        let [i1, i2, i3] = moments;
        let (ip, iq, n) = if reg.pole == 2 {
            (i3, i1, -i3 * (i2 - i1) / (i1 * (i3 - i2)))
        } else {
            (i1, i3, -i1 * (i3 - i2) / (i3 * (i2 - i1)))
        };
        let (theta, phi) = relabelled_angles(reg.pole, [i1 * w[0], i2 * w[1], i3 * w[2]]);
        let r0 = zxz_matrix(0.0, theta, phi);
        // P0 = Q0 Bᵀ R0ᵀ: Q(0) = Q0 with ψ(0) = 0
        let mut qb = [[0.0; 3]; 3];
        for r in 0..3 {
            qb[r] = if reg.pole == 2 {
                q0[r]
            } else {
                // Bᵀ = B = [[0, 0, 1], [0, −1, 0], [1, 0, 0]]
                [q0[r][2], -q0[r][1], q0[r][0]]
            };
        }
        let mut p0 = [[0.0; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                p0[r][c] = qb[r][0] * r0[c][0] + qb[r][1] * r0[c][1] + qb[r][2] * r0[c][2];
            }
        }
        let a = reg.momentum;
        let mut att = AttitudeSetup {
            p0,
            n,
            i_pole: ip,
            i_other: iq,
            pi_u0: 0.0,
            pi_complete: 0.0,
            psi_pi: a * (ip - iq) / (ip * iq * reg.lam),
        };
        att.pi_u0 = if reduced_third_kind(reg) {
            att.pi_complete = ellippi_complete(n, reg.m, reg.m1);
            // Π at t = 0 by the very route of every later time, so that ψ(0) = 0 exactly
            let (sn, cn, dn, p, _) =
                jacobi_reduced_with(reg.u0, reg.m, reg.m1, reg.quarter, &reg.agm);
            EllipticMotion::of(reg, &att).third_kind(sn, cn, dn, p)
        } else {
            third_kind_u(n, reg.u0, reg.m, reg.m1, reg.quarter)
        };
        att
    }
}

/// What `Q(t)` of an elliptic motion needs at each time beyond the reduction of `u = u0 + λt`
/// (see the module docs), generic over [`Real`]: one motion (`f64`, [`attitude_at`]) or one
/// per lane ([`exact_attitudes`]), each lane bit for bit its single run.
#[derive(Clone, Copy, Debug, Default)]
struct EllipticMotion<T: Real> {
    /// The signed amplitudes `σ_i α_i` and the pole (e3 where set).
    sa: [T; 3],
    e3: T::Mask,
    /// [`AttitudeSetup`]'s `n`, `Π(n|m)`, `Π(u0)`, ψ's factor; `a`, `I_p`; the invariable frame.
    n: T,
    pi_complete: T,
    pi_u0: T,
    psi_pi: T,
    momentum: T,
    i_pole: T,
    p0: [[T; 3]; 3],
}

impl EllipticMotion<f64> {
    fn of(reg: &Regime, att: &AttitudeSetup) -> EllipticMotion<f64> {
        EllipticMotion {
            sa: [0, 1, 2].map(|i| reg.signs[i] * reg.alpha[i]),
            e3: reg.pole == 2,
            n: att.n,
            pi_complete: att.pi_complete,
            pi_u0: att.pi_u0,
            psi_pi: att.psi_pi,
            momentum: reg.momentum,
            i_pole: att.i_pole,
            p0: att.p0,
        }
    }
}

impl<const N: usize> EllipticMotion<Wide<N>> {
    /// Lane `l` holds `motions[l]`.
    #[inline(always)]
    fn gather(motions: &[EllipticMotion<f64>; N]) -> EllipticMotion<Wide<N>> {
        let wide = |f: &dyn Fn(&EllipticMotion<f64>) -> f64| {
            let mut x = [0.0; N];
            for (xl, m) in x.iter_mut().zip(motions) {
                *xl = f(m);
            }
            Wide(x)
        };
        let mut e3 = WideMask::<N>::splat(true);
        for (l, m) in motions.iter().enumerate() {
            e3.and_lane(l, m.e3);
        }
        EllipticMotion {
            sa: [0, 1, 2].map(|i| wide(&|m| m.sa[i])),
            e3,
            n: wide(&|m| m.n),
            pi_complete: wide(&|m| m.pi_complete),
            pi_u0: wide(&|m| m.pi_u0),
            psi_pi: wide(&|m| m.psi_pi),
            momentum: wide(&|m| m.momentum),
            i_pole: wide(&|m| m.i_pole),
            p0: [0, 1, 2].map(|r| [0, 1, 2].map(|c| wide(&|m| m.p0[r][c]))),
        }
    }
}

impl<T: Real> EllipticMotion<T> {
    /// `Π(u) = ∫₀^u du/(1 − n sn² u)` from the reduction `(sn u, cn u, dn u, p)`
    /// ([`third_kind_reduced`] on `sn v = (−1)^p sn u`, `cn v = (−1)^p cn u`).
    #[inline(always)]
    fn third_kind(&self, sn: T, cn: T, dn: T, p: T) -> T {
        let par = parity(p);
        third_kind_reduced(self.n, par * sn, par * cn, dn, p, self.pi_complete)
    }

    /// `Q(t)` (sorted principal frame → space) from the reduction `(sn, cn, dn, p)` of
    /// `u = u0 + λt`: ω(t) in the Jacobi form, the angles θ, φ of the body momentum `π = Iω`
    /// (relabelled `(π3, −π2, π1)` about e1) as ratios, `cos θ = π_p/a`,
    /// `tan φ = π_1'/π_2'`, and `ψ = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]`:
    /// `Q = P0 Rzxz(ψ, θ, φ)` (columns relabelled back about e1). `plain` is cleared in the
    /// lanes whose sums of squares `f64` would take by `hypot` ([`Real::norm2`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn attitude(
        &self,
        moments: Vec3,
        t: T,
        sn: T,
        cn: T,
        dn: T,
        p: T,
        plain: &mut T::Mask,
    ) -> [[T; 3]; 3] {
        let c = T::splat;
        let v = jacobi_omega(self.e3, self.sa, sn, cn, dn);
        let big_pi = self.third_kind(sn, cn, dn, p) - self.pi_u0;
        let psi = self.momentum * t / self.i_pole + self.psi_pi * big_pi;
        let pi = [
            c(moments[0]) * v[0],
            c(moments[1]) * v[1],
            c(moments[2]) * v[2],
        ];
        let b0 = T::select(self.e3, pi[0], pi[2]);
        let b1 = T::select(self.e3, pi[1], -pi[1]);
        let b2 = T::select(self.e3, pi[2], pi[0]);
        let rho = T::norm2(b0, b1, plain);
        let r = T::norm2(rho, b2, plain);
        let flat = rho.equal(c(0.0)); // θ = 0 or π: φ = atan2(0, 0) = 0
        let phi = [
            T::select(flat, c(0.0), b0 / rho),
            T::select(flat, c(1.0), b1 / rho),
        ];
        let (sps, cps) = sin_cos(psi);
        let rot = zxz_matrix_sc([sps, cps], [rho / r, b2 / r], phi);
        let mut x = [[c(0.0); 3]; 3];
        for (xr, pr) in x.iter_mut().zip(&self.p0) {
            for (k, xk) in xr.iter_mut().enumerate() {
                *xk = pr[0] * rot[0][k] + pr[1] * rot[1][k] + pr[2] * rot[2][k];
            }
        }
        // about e1 the columns of (P0 R) B: (x2, −x1, x0)
        x.map(|row| {
            [
                T::select(self.e3, row[0], row[2]),
                T::select(self.e3, row[1], -row[1]),
                T::select(self.e3, row[2], row[0]),
            ]
        })
    }
}

/// `Q Sᵀ`: an attitude with the sorted principal frame as body frame, turned to the body frame.
#[inline(always)]
fn sorted_to_body<T: Real>(qs: &[[T; 3]; 3], s: &Mat3) -> [[T; 3]; 3] {
    let c = T::splat;
    qs.map(|row| [0, 1, 2].map(|k| row[0] * c(s[k][0]) + row[1] * c(s[k][1]) + row[2] * c(s[k][2])))
}

/// `Q(t) = Q0 exp(Ω t)`: the attitude at a fixed point of Euler's equation, where ω is constant
/// (eqs (22)–(23)), by Rodrigues' formula ([`exp_so3`]).
#[inline]
pub fn fixed_point_attitude(q0: &Mat3, w: Vec3, t: f64) -> Mat3 {
    matmul(q0, &exp_so3([t * w[0], t * w[1], t * w[2]]))
}

/// `Q(t)` (sorted principal frame → space) of the motion from `ω(0) = w`, `Q(0) = q0`, with the
/// regime `reg` and the attitude setup `att`.
pub fn attitude_at(
    moments: Vec3,
    reg: &Regime,
    att: &AttitudeSetup,
    w: Vec3,
    q0: &Mat3,
    t: f64,
) -> Mat3 {
    match reg.case {
        SPHERICAL | FIXED => fixed_point_attitude(q0, w, t),
        PRECESSION => {
            // Q(t) = exp(t L/I⊥) Q0 exp(ν t e_s), L = Q0 (I w) in space
            let s = reg.axis as usize;
            let pi = [moments[0] * w[0], moments[1] * w[1], moments[2] * w[2]];
            let f = t / reg.i_perp;
            let l = q0.map(|row| f * (row[0] * pi[0] + row[1] * pi[1] + row[2] * pi[2]));
            let r = exp_so3(l);
            // R Q0, then the body turn about e_s: columns (s+1, s+2) rotated by ν t
            let mut out = matmul(&r, q0);
            let angle = reg.nu * t;
            let cs = angle.cos();
            let sn = angle.sin();
            let a = (s + 1) % 3;
            let b = (s + 2) % 3;
            for row in out.iter_mut() {
                let x = row[a];
                let y = row[b];
                row[a] = cs * x + sn * y;
                row[b] = -sn * x + cs * y;
            }
            out
        }
        _ if reduced_third_kind(reg) => {
            // the reduction of u that ω(t) makes ([`Regime::omega_at`]), shared with Π(u)
            let u = reg.u0 + reg.lam * t;
            let (sn, cn, dn, p, _) = jacobi_reduced_with(u, reg.m, reg.m1, reg.quarter, &reg.agm);
            EllipticMotion::of(reg, att).attitude(moments, t, sn, cn, dn, p, &mut true)
        }
        _ => {
            let v = reg.omega_at(moments, w, t);
            let (theta, phi) = relabelled_angles(
                reg.pole,
                [moments[0] * v[0], moments[1] * v[1], moments[2] * v[2]],
            );
            // the separatrix and m1 < TINY_M1: Π(u) by its separatrix forms
            let u = reg.u0 + reg.lam * t;
            let big_pi = third_kind_u(att.n, u, reg.m, reg.m1, reg.quarter) - att.pi_u0;
            let psi = reg.momentum * t / att.i_pole + att.psi_pi * big_pi; // ψ(0) = 0
            let x = matmul(&att.p0, &zxz_matrix(psi, theta, phi));
            if reg.pole == 2 {
                x
            } else {
                // columns of (P0 R) B: (x2, −x1, x0)
                x.map(|row| [row[2], -row[1], row[0]])
            }
        }
    }
}

// ------------------------------------------------------------------------- batched, body frame

/// `Sᵀ ω`: body-frame ω in the sorted principal frame. A component smaller than the largest
/// times 2⁻¹⁰²² (subnormal once ω is scaled to its largest component: zero to round-off) is
/// flushed to a zero of its sign, so that the closed forms never work with the few digits a
/// subnormal carries (ω = (2.2e-313, 0, 0.125) gave an attitude 3e-11 off the rotation about
/// e3 it is to round-off).
#[inline(always)]
fn to_sorted<T: Real>(s: &Mat3, w: [T; 3]) -> [T; 3] {
    let c = T::splat;
    let v = [
        c(s[0][0]) * w[0] + c(s[1][0]) * w[1] + c(s[2][0]) * w[2],
        c(s[0][1]) * w[0] + c(s[1][1]) * w[1] + c(s[2][1]) * w[2],
        c(s[0][2]) * w[0] + c(s[1][2]) * w[1] + c(s[2][2]) * w[2],
    ];
    let floor = py_max(py_max(v[0].abs(), v[1].abs()), v[2].abs()) * c(f64::MIN_POSITIVE);
    v.map(|x| T::select(x.abs().lt(floor), c(0.0).copysign(x), x))
}

/// `S v`: sorted-frame `v` in the body frame.
#[inline(always)]
fn from_sorted<T: Real>(s: &Mat3, v: [T; 3]) -> [T; 3] {
    let c = T::splat;
    [
        c(s[0][0]) * v[0] + c(s[0][1]) * v[1] + c(s[0][2]) * v[2],
        c(s[1][0]) * v[0] + c(s[1][1]) * v[1] + c(s[1][2]) * v[2],
        c(s[2][0]) * v[0] + c(s[2][1]) * v[1] + c(s[2][2]) * v[2],
    ]
}

/// Below this many evaluations (members × times) the batched functions run on one thread.
const PARALLEL_MIN: usize = 4096;

/// The regime of the motion from body-frame ω `w`, for a body with sorted moments `moments`
/// and sorted axes `s` (columns, body coordinates).
pub fn regime_of(moments: Vec3, s: &Mat3, symmetry: u8, w: Vec3) -> Regime {
    Regime::new(moments, symmetry, to_sorted(s, w))
}

/// ω(t), body frame, of the torque-free motions from the body-frame ω `ws` at the times `ts`
/// (from t = 0), into `out` (`ws.len() · ts.len()` vectors, member-major). One pass per member:
/// the regime, then every time. Bodies with three distinct moments run [`WIDTH`] members at a
/// time in SIMD lanes ([`omegas_in_lanes`]), each lane computing bit for bit what its single
/// run computes; blocks of members are shared among rayon's threads.
pub fn exact_omegas(
    moments: Vec3,
    s: &Mat3,
    symmetry: u8,
    ws: &[Vec3],
    ts: &[f64],
    out: &mut [Vec3],
) {
    let n = ts.len();
    assert_eq!(
        out.len(),
        ws.len() * n,
        "exact_omegas: `out` has the wrong length"
    );
    if n == 0 {
        return;
    }
    let radicals = Radicals::new(moments);
    let block = |ws: &[Vec3], out: &mut [Vec3]| {
        if symmetry == 0 {
            omegas_in_lanes::<WIDTH>(moments, s, &radicals, ws, ts, out);
        } else {
            for (w, o) in ws.iter().zip(out.chunks_mut(n)) {
                omegas_one_by_one(moments, s, &radicals, symmetry, *w, ts, o);
            }
        }
    };
    if ws.len() > 1 && ws.len() * n >= PARALLEL_MIN {
        ws.par_chunks(LANES_BLOCK)
            .zip(out.par_chunks_mut(n * LANES_BLOCK))
            .for_each(|(w, o)| block(w, o));
    } else {
        block(ws, out);
    }
}

/// Members per rayon task of [`exact_omegas`].
const LANES_BLOCK: usize = 256;

/// ω(t) (body frame) of one member at the times `ts`: its [`Regime`], then every time.
#[inline]
fn omegas_one_by_one(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    symmetry: u8,
    w: Vec3,
    ts: &[f64],
    out: &mut [Vec3],
) {
    let ws = to_sorted(s, w);
    let reg = Regime::with(moments, radicals, symmetry, ws);
    for (o, &t) in out.iter_mut().zip(ts) {
        *o = from_sorted(s, reg.omega_at(moments, ws, t));
    }
}

/// What ω(t) needs of [`WIDTH`] motions in lanes (a body with three distinct moments): the
/// [`Regime`]'s elliptic fields, with `rm1 = √m1` and `sa = σ α`.
struct LaneMotion<const N: usize> {
    u0: Wide<N>,
    lam: Wide<N>,
    rm1: Wide<N>,
    quarter: Wide<N>,
    sa: [Wide<N>; 3],
    e3: WideMask<N>,
    agm: Agm<Wide<N>>,
}

/// `x` times `2^e` for integer `e` in [−1022, 1023] (a power of two made from its bits).
#[inline(always)]
fn times_pow2<const N: usize>(x: Wide<N>, e: Wide<N>) -> Wide<N> {
    let mut p = [0.0; N];
    for l in 0..N {
        p[l] = f64::from_bits(((e.0[l] as i64 + 1023) as u64) << 52);
    }
    x * Wide(p)
}

impl<const N: usize> LaneMotion<N> {
    /// The motions from the sorted-frame ω `w`, and the lanes where they are what
    /// [`Regime::with`] makes ("plain": a normal scale, off the fixed points, `m1 ≥`
    /// [`NEAR_ONE`], `m > 0`, every sum of squares safe, normal amplitudes). The other lanes'
    /// values are meaningless; they are evaluated one at a time.
    #[inline(always)]
    fn new(moments: Vec3, radicals: &Radicals, w: [Wide<N>; 3]) -> (LaneMotion<N>, WideMask<N>) {
        let c = Wide::<N>::splat;
        let big = py_max(py_max(w[0].abs(), w[1].abs()), w[2].abs());
        // frexp's exponent of a normal `big` (ω scaled by 2^-e exactly, as `Regime::with`)
        let mut e = [0.0; N];
        let mut plain = WideMask::<N>::splat(true);
        for l in 0..N {
            let biased = (big.0[l].to_bits() >> 52) & 0x7ff;
            plain.and_lane(l, (1..=2044).contains(&biased));
            e[l] = biased as f64 - 1022.0;
        }
        let e = Wide(e);
        let x = [
            times_pow2(w[0], -e),
            times_pow2(w[1], -e),
            times_pow2(w[2], -e),
        ];
        // off the intermediate axis (`NEAR_UNSTABLE_AXIS`)
        plain = plain & py_max(x[0].abs(), x[2].abs()).gt(c(NEAR_UNSTABLE_AXIS) * x[1].abs());
        let (q3, q1) = polhode_radii(radicals, x, &mut plain);
        let f = JacobiForm::new(moments, radicals, x, q3, q1);
        plain = plain & f.m1.ge(c(NEAR_ONE)) & f.m.gt(c(0.0));
        // benign values in the other lanes, where the loops below end at once
        let m1 = Wide::<N>::select(plain, f.m1, c(0.5));
        let agm = Agm::new(m1);
        let quarter = agm.quarter();
        let u0 = first_kind_in_period(f.cot0, f.sn0, f.cn0, &agm, quarter);
        let alpha = [
            times_pow2(f.alpha[0], e),
            times_pow2(f.alpha[1], e),
            times_pow2(f.alpha[2], e),
        ];
        let lam = times_pow2(f.lam, e);
        for l in 0..N {
            let normal = alpha[0].0[l].is_normal()
                && alpha[1].0[l].is_normal()
                && alpha[2].0[l].is_normal()
                && lam.0[l].is_normal();
            plain.and_lane(l, normal);
        }
        let s2 = f.s1 * f.s3;
        let motion = LaneMotion {
            u0,
            lam,
            rm1: m1.sqrt(),
            quarter,
            sa: [f.s1 * alpha[0], s2 * alpha[1], f.s3 * alpha[2]],
            e3: f.e3,
            agm,
        };
        (motion, plain)
    }

    /// ω(t) (sorted principal frame) in every lane: as [`Regime::omega_at`].
    #[inline(always)]
    fn omega_at(&self, t: Wide<N>) -> [Wide<N>; 3] {
        let u = self.u0 + self.lam * t;
        let (sn, cn, dn, _, _) = reduce_quarter(u, self.rm1, self.quarter, &self.agm);
        jacobi_omega(self.e3, self.sa, sn, cn, dn)
    }
}

crate::multiversion! {
    /// [`exact_omegas`] for a body with three distinct moments, [`WIDTH`] members at a time in
    /// SIMD lanes; a lane off the plain elliptic case ([`LaneMotion::new`]: fixed points, the
    /// separatrix and its neighbourhood `m1 <` [`NEAR_ONE`], extreme scales) is evaluated on its own.
    /// The instruction set is chosen at run time (AVX-512, AVX2, the baseline), as in
    /// [`crate::lanes`].
    pub fn omegas_in_lanes, omegas_in_lanes_with [const N: usize] (
        moments: Vec3,
        s: &Mat3,
        radicals: &Radicals,
        ws: &[Vec3],
        ts: &[f64],
        out: &mut [Vec3],
    ) -> () where [] => omegas_in_lanes_any::<N>, up to Avx512;
}

/// The lanes' loop, inlined into each target's copy of it: groups of `N` members in the
/// lanes; the members left over in one more group when they fill a quarter of it, else each
/// alone, its times in the lanes (or one by one when they are fewer than the lanes).
#[inline(always)]
fn omegas_in_lanes_any<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    ws: &[Vec3],
    ts: &[f64],
    out: &mut [Vec3],
) {
    let n = ts.len();
    let whole = if ws.len() % N * 4 >= N {
        ws.len()
    } else {
        ws.len() / N * N
    };
    let (out_whole, out_rest) = out.split_at_mut(whole * n);
    for (wg, og) in ws[..whole].chunks(N).zip(out_whole.chunks_mut(N * n)) {
        members_in_lanes::<N>(moments, s, radicals, wg, ts, og);
    }
    for (w, o) in ws[whole..].iter().zip(out_rest.chunks_exact_mut(n)) {
        if n < N || !times_in_lanes::<N>(moments, s, radicals, *w, ts, o) {
            omegas_one_by_one(moments, s, radicals, 0, *w, ts, o);
        }
    }
}

/// ω (body frame) of up to `N` members `wg` at the times `ts`, one member per lane (lanes past
/// the last member repeat it, their results dropped); the members the lanes do not cover
/// ([`LaneMotion::new`]) one by one.
#[inline(always)]
fn members_in_lanes<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    wg: &[Vec3],
    ts: &[f64],
    og: &mut [Vec3],
) {
    let n = ts.len();
    let lanes = wg.len();
    // structure of arrays
    let mut w = [Wide::<N>::default(); 3];
    for l in 0..N {
        let v = wg[l.min(lanes - 1)];
        for c in 0..3 {
            w[c].0[l] = v[c];
        }
    }
    let (motion, plain) = LaneMotion::new(moments, radicals, to_sorted(s, w));
    for (j, &t) in ts.iter().enumerate() {
        let v = from_sorted(s, motion.omega_at(Wide::<N>::splat(t)));
        for l in 0..lanes {
            og[l * n + j] = [v[0].0[l], v[1].0[l], v[2].0[l]];
        }
    }
    for l in 0..lanes {
        if !plain.get(l) {
            omegas_one_by_one(
                moments,
                s,
                radicals,
                0,
                wg[l],
                ts,
                &mut og[l * n..(l + 1) * n],
            );
        }
    }
}

/// ω (body frame) of one member at the times `ts`, `N` times at once in the lanes (the member
/// in every lane); `false` (nothing written) where the member is not a plain lane
/// ([`LaneMotion::new`]).
#[inline(always)]
fn times_in_lanes<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    w: Vec3,
    ts: &[f64],
    out: &mut [Vec3],
) -> bool {
    let w = [Wide::splat(w[0]), Wide::splat(w[1]), Wide::splat(w[2])];
    let (motion, plain) = LaneMotion::<N>::new(moments, radicals, to_sorted(s, w));
    if !plain.get(0) {
        return false;
    }
    for (tc, oc) in ts.chunks(N).zip(out.chunks_mut(N)) {
        // lanes past the last time repeat it (their results dropped)
        let mut t = [0.0; N];
        for l in 0..N {
            t[l] = tc[l.min(tc.len() - 1)];
        }
        let v = from_sorted(s, motion.omega_at(Wide(t)));
        for (l, o) in oc.iter_mut().enumerate() {
            *o = [v[0].0[l], v[1].0[l], v[2].0[l]];
        }
    }
    true
}

/// What an ensemble asks of each motion without its time history: the polhode family (the
/// case code of [`Regime`]), the period of ω(t) ([`Regime::period`]) and the time between
/// flips ([`Regime::flip_interval`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Family {
    pub case: u8,
    pub period: f64,
    pub flip_interval: f64,
}

impl Family {
    /// The family, period and flip interval of a regime.
    pub fn of(reg: &Regime) -> Family {
        Family {
            case: reg.case,
            period: reg.period(),
            flip_interval: reg.flip_interval(),
        }
    }
}

/// [`Family`] of each torque-free motion from the body-frame ω `ws` into `out`: bodies with
/// three distinct moments [`WIDTH`] members at a time in SIMD lanes (the regime's elliptic
/// fields as [`LaneMotion::new`] makes them for ω(t): `4K/λ`, `2K/λ`, the pole), each lane
/// bit for bit its member's [`regime_of`]; the lanes off the plain elliptic case, and
/// symmetric bodies, one by one. Blocks of members are shared among rayon's threads.
pub fn families(moments: Vec3, s: &Mat3, symmetry: u8, ws: &[Vec3], out: &mut [Family]) {
    assert_eq!(out.len(), ws.len(), "families: `out` has the wrong length");
    let radicals = Radicals::new(moments);
    let block = |ws: &[Vec3], out: &mut [Family]| {
        if symmetry == 0 {
            families_in_lanes::<WIDTH>(moments, s, &radicals, ws, out);
        } else {
            for (w, o) in ws.iter().zip(out.iter_mut()) {
                *o = Family::of(&Regime::with(
                    moments,
                    &radicals,
                    symmetry,
                    to_sorted(s, *w),
                ));
            }
        }
    };
    if ws.len() >= PARALLEL_MIN {
        ws.par_chunks(FAMILY_BLOCK)
            .zip(out.par_chunks_mut(FAMILY_BLOCK))
            .for_each(|(w, o)| block(w, o));
    } else {
        block(ws, out);
    }
}

/// Members per rayon task of [`families`].
const FAMILY_BLOCK: usize = 4096;

crate::multiversion! {
    /// [`families`] of a body with three distinct moments in lanes, the instruction set chosen at
    /// run time (as [`omegas_in_lanes`]).
    fn families_in_lanes, families_in_lanes_with [const N: usize] (
        moments: Vec3,
        s: &Mat3,
        radicals: &Radicals,
        ws: &[Vec3],
        out: &mut [Family],
    ) -> () where [] => families_in_lanes_any::<N>, up to Avx512;
}

/// Groups of `N` members in the lanes (lanes past the last member repeat it, their results
/// dropped); a lane off the plain case gets its member's own [`Regime`].
#[inline(always)]
fn families_in_lanes_any<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    ws: &[Vec3],
    out: &mut [Family],
) {
    for (wg, og) in ws.chunks(N).zip(out.chunks_mut(N)) {
        let lanes = wg.len();
        let mut w = [Wide::<N>::default(); 3];
        for l in 0..N {
            let v = wg[l.min(lanes - 1)];
            for c in 0..3 {
                w[c].0[l] = v[c];
            }
        }
        let (motion, plain) = LaneMotion::new(moments, radicals, to_sorted(s, w));
        // the formulas of Regime::period and Regime::flip_interval, lane by lane
        let period = Wide::<N>::splat(4.0) * motion.quarter / motion.lam;
        let flip = Wide::<N>::splat(2.0) * motion.quarter / motion.lam;
        for (l, o) in og.iter_mut().enumerate() {
            *o = if plain.get(l) {
                Family {
                    case: if motion.e3.get(l) {
                        AROUND_E3
                    } else {
                        AROUND_E1
                    },
                    period: period.0[l],
                    flip_interval: flip.0[l],
                }
            } else {
                Family::of(&Regime::with(moments, radicals, 0, to_sorted(s, wg[l])))
            };
        }
    }
}

/// `Q(t)` (body → space) of the torque-free motions from the body-frame ω `ws` and attitudes
/// `q0s` (one per member, or one shared), at the times `ts`, into `out` (member-major). Bodies
/// with three distinct moments run [`WIDTH`] members at a time in SIMD lanes
/// ([`attitudes_in_lanes`]), each lane computing bit for bit what its single run
/// ([`attitude_at`]) computes; blocks of members are shared among rayon's threads.
pub fn exact_attitudes(
    moments: Vec3,
    s: &Mat3,
    symmetry: u8,
    ws: &[Vec3],
    q0s: &[Mat3],
    ts: &[f64],
    out: &mut [Mat3],
) {
    let n = ts.len();
    assert_eq!(
        out.len(),
        ws.len() * n,
        "exact_attitudes: `out` has the wrong length"
    );
    assert!(
        q0s.len() == 1 || q0s.len() == ws.len(),
        "exact_attitudes: one Q0 or one per member"
    );
    if n == 0 {
        return;
    }
    let block = |i0: usize, ws: &[Vec3], out: &mut [Mat3]| {
        let q0s = if q0s.len() > 1 {
            &q0s[i0..i0 + ws.len()]
        } else {
            q0s
        };
        if symmetry == 0 {
            attitudes_in_lanes::<WIDTH>(moments, s, ws, q0s, ts, out);
        } else {
            for (i, (w, o)) in ws.iter().zip(out.chunks_mut(n)).enumerate() {
                let q0 = &q0s[if q0s.len() > 1 { i } else { 0 }];
                attitudes_one_by_one(moments, s, symmetry, *w, q0, ts, o);
            }
        }
    };
    if ws.len() > 1 && ws.len() * n >= PARALLEL_MIN / 8 {
        ws.par_chunks(ATTITUDE_BLOCK)
            .zip(out.par_chunks_mut(n * ATTITUDE_BLOCK))
            .enumerate()
            .for_each(|(b, (w, o))| block(b * ATTITUDE_BLOCK, w, o));
    } else {
        block(0, ws, out);
    }
}

/// Members per rayon task of [`exact_attitudes`].
const ATTITUDE_BLOCK: usize = 64;

/// The regime and attitude setup of one member (sorted frame), and `Q0 S`.
#[inline]
fn attitude_member(
    moments: Vec3,
    s: &Mat3,
    symmetry: u8,
    w: Vec3,
    q0: &Mat3,
) -> (Vec3, Regime, AttitudeSetup, Mat3) {
    let q0s_sorted = matmul(q0, s); // Q0 S: sorted principal frame → space
    let w = to_sorted(s, w);
    let reg = Regime::new(moments, symmetry, w);
    let att = AttitudeSetup::new(moments, &reg, w, &q0s_sorted);
    (w, reg, att, q0s_sorted)
}

/// `Q(t)` (body frame) of one member at the times `ts`: its regime, then every time.
fn attitudes_one_by_one(
    moments: Vec3,
    s: &Mat3,
    symmetry: u8,
    w: Vec3,
    q0: &Mat3,
    ts: &[f64],
    out: &mut [Mat3],
) {
    let (w, reg, att, q0s_sorted) = attitude_member(moments, s, symmetry, w, q0);
    for (o, &t) in out.iter_mut().zip(ts) {
        *o = sorted_to_body(&attitude_at(moments, &reg, &att, w, &q0s_sorted, t), s);
    }
}

/// The elliptic motion of a member as the lanes run it, when it is a plain lane: three
/// distinct moments, off the fixed points and the separatrix, `m1 ≥` [`NEAR_ONE`] (the Jacobi
/// functions from the AGM sequence) and `m > 0`.
#[inline]
fn plain_motion(
    moments: Vec3,
    s: &Mat3,
    w: Vec3,
    q0: &Mat3,
) -> Option<(Regime, EllipticMotion<f64>)> {
    let (_, reg, att, _) = attitude_member(moments, s, 0, w, q0);
    let plain = reg.is_elliptic()
        && reduced_third_kind(&reg)
        && reg.m1 >= NEAR_ONE
        && reg.m > 0.0
        && att.psi_pi.is_finite()
        && att.pi_u0.is_finite();
    plain.then(|| (reg, EllipticMotion::of(&reg, &att)))
}

/// `u = u0 + λt` and its quarter-period reduction in lanes, as [`Regime::omega_at`] makes it.
struct LaneReduction<const N: usize> {
    u0: Wide<N>,
    lam: Wide<N>,
    rm1: Wide<N>,
    quarter: Wide<N>,
    agm: Agm<Wide<N>>,
}

impl<const N: usize> LaneReduction<N> {
    #[inline(always)]
    fn gather(regs: &[Regime; N]) -> LaneReduction<N> {
        let wide = |f: fn(&Regime) -> f64| {
            let mut x = [0.0; N];
            for (xl, r) in x.iter_mut().zip(regs) {
                *xl = f(r);
            }
            Wide(x)
        };
        let m1 = wide(|r| r.m1);
        LaneReduction {
            u0: wide(|r| r.u0),
            lam: wide(|r| r.lam),
            rm1: m1.sqrt(),
            quarter: wide(|r| r.quarter),
            agm: Agm::new(m1),
        }
    }

    /// `Q(t)` (body frame) in every lane of `motion`, `plain` cleared where a lane leaves
    /// the sums of squares the lanes take.
    #[inline(always)]
    fn attitude(
        &self,
        motion: &EllipticMotion<Wide<N>>,
        moments: Vec3,
        s: &Mat3,
        t: Wide<N>,
        plain: &mut WideMask<N>,
    ) -> [[Wide<N>; 3]; 3] {
        let u = self.u0 + self.lam * t;
        let (sn, cn, dn, p, _) = reduce_quarter(u, self.rm1, self.quarter, &self.agm);
        sorted_to_body(&motion.attitude(moments, t, sn, cn, dn, p, plain), s)
    }
}

#[inline(always)]
fn lane_matrix<const N: usize>(q: &[[Wide<N>; 3]; 3], l: usize) -> Mat3 {
    q.map(|row| row.map(|x| x.0[l]))
}

crate::multiversion! {
    /// [`exact_attitudes`] of a body with three distinct moments in lanes, the instruction set
    /// chosen at run time (as [`omegas_in_lanes`]); `q0s` one per member or one shared.
    pub fn attitudes_in_lanes, attitudes_in_lanes_with [const N: usize] (
        moments: Vec3,
        s: &Mat3,
        ws: &[Vec3],
        q0s: &[Mat3],
        ts: &[f64],
        out: &mut [Mat3],
    ) -> () where [] => attitudes_in_lanes_any::<N>, up to Avx512;
}

/// The lanes' loop, inlined into each target's copy: groups of `N` members in the lanes (the
/// last group when it fills a quarter of them), the members left over each alone, its times in
/// the lanes (or one by one when they are fewer than the lanes).
#[inline(always)]
fn attitudes_in_lanes_any<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    ws: &[Vec3],
    q0s: &[Mat3],
    ts: &[f64],
    out: &mut [Mat3],
) {
    let n = ts.len();
    let q0 = |i: usize| &q0s[if q0s.len() > 1 { i } else { 0 }];
    let whole = if ws.len() % N * 4 >= N {
        ws.len()
    } else {
        ws.len() / N * N
    };
    let (out_whole, out_rest) = out.split_at_mut(whole * n);
    for (g, og) in out_whole.chunks_mut(N * n).enumerate() {
        let i0 = g * N;
        let lanes = (whole - i0).min(N);
        let members: Vec<usize> = (i0..i0 + lanes).collect();
        members_attitudes_in_lanes::<N>(moments, s, &members, ws, q0s, ts, og);
    }
    for (k, o) in out_rest.chunks_exact_mut(n).enumerate() {
        let i = whole + k;
        if n < N || !times_attitudes_in_lanes::<N>(moments, s, ws[i], q0(i), ts, o) {
            attitudes_one_by_one(moments, s, 0, ws[i], q0(i), ts, o);
        }
    }
}

/// `Q(t)` (body frame) of the members `members` (up to `N`), one per lane (lanes past the last
/// repeat a plain member, their results dropped), at the times `ts`; the members off the plain
/// lanes one by one.
#[inline(always)]
fn members_attitudes_in_lanes<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    members: &[usize],
    ws: &[Vec3],
    q0s: &[Mat3],
    ts: &[f64],
    og: &mut [Mat3],
) {
    let n = ts.len();
    let q0 = |i: usize| &q0s[if q0s.len() > 1 { i } else { 0 }];
    let found: Vec<Option<(Regime, EllipticMotion<f64>)>> = members
        .iter()
        .map(|&i| plain_motion(moments, s, ws[i], q0(i)))
        .collect();
    let mut plain = WideMask::<N>::splat(true);
    if let Some(&(reg0, mot0)) = found.iter().flatten().next() {
        // lanes without a plain motion take the first plain one (benign values)
        let mut regs = [reg0; N];
        let mut motions = [mot0; N];
        for l in 0..N {
            match found.get(l) {
                Some(Some((reg, mot))) => {
                    regs[l] = *reg;
                    motions[l] = *mot;
                }
                _ => plain.and_lane(l, false),
            }
        }
        let red = LaneReduction::gather(&regs);
        let motion = EllipticMotion::gather(&motions);
        for (j, &t) in ts.iter().enumerate() {
            let q = red.attitude(&motion, moments, s, Wide::splat(t), &mut plain);
            for l in 0..members.len() {
                og[l * n + j] = lane_matrix(&q, l);
            }
        }
    } else {
        plain = WideMask::splat(false);
    }
    for (l, &i) in members.iter().enumerate() {
        if !plain.get(l) {
            let o = &mut og[l * n..(l + 1) * n];
            attitudes_one_by_one(moments, s, 0, ws[i], q0(i), ts, o);
        }
    }
}

/// `Q(t)` (body frame) of one member at the times `ts`, `N` times at once in the lanes;
/// `false` (nothing kept) where the member is not a plain lane at every time.
#[inline(always)]
fn times_attitudes_in_lanes<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    w: Vec3,
    q0: &Mat3,
    ts: &[f64],
    out: &mut [Mat3],
) -> bool {
    let Some((reg, mot)) = plain_motion(moments, s, w, q0) else {
        return false;
    };
    let red = LaneReduction::gather(&[reg; N]);
    let motion = EllipticMotion::gather(&[mot; N]);
    let mut plain = WideMask::<N>::splat(true);
    for (tc, oc) in ts.chunks(N).zip(out.chunks_mut(N)) {
        // lanes past the last time repeat it (their results dropped)
        let mut t = [0.0; N];
        for l in 0..N {
            t[l] = tc[l.min(tc.len() - 1)];
        }
        let q = red.attitude(&motion, moments, s, Wide(t), &mut plain);
        for (l, o) in oc.iter_mut().enumerate() {
            *o = lane_matrix(&q, l);
        }
    }
    plain.all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::freebody::{euler_omega_dot, symmetry_code, SYMMETRY_RTOL};
    use crate::isa::Isa;

    const EYE: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn the_readme_flip_interval() {
        // README: FreeRigidBody((1, 2, 3)).flip_interval((1e-3, 1, 1e-3)) = 27.5308405537...
        let reg = Regime::new([1.0, 2.0, 3.0], 0, [1e-3, 1.0, 1e-3]);
        assert_eq!(reg.case, AROUND_E3);
        assert!(
            rel(reg.flip_interval(), 27.530_840_553_7) < 5e-12,
            "{}",
            reg.flip_interval()
        );
        assert!(rel(reg.period(), 2.0 * reg.flip_interval()) < 1e-16);
        // ω2 has flipped after one interval
        let w = reg.omega_at([1.0, 2.0, 3.0], [1e-3, 1.0, 1e-3], reg.flip_interval());
        assert!((w[1] + 1.0).abs() < 1e-6);
    }

    #[test]
    fn energy_and_momentum_are_conserved_along_the_exact_omega() {
        let moments = [1.0, 2.0, 3.0];
        for w0 in [
            [0.3, 1.0, 0.2],
            [1e-3, 1.0, 1e-3],
            [0.9, -0.2, 0.4],
            [-0.1, 0.5, 1.3],
            [1e-9, 1.0, -1e-9],
        ] {
            let reg = Regime::new(moments, 0, w0);
            let (k0, a0) = principal_invariants(moments, w0);
            assert!(rel(reg.energy, k0) < 1e-15 && rel(reg.momentum, a0) < 1e-15);
            for j in 0..400 {
                let t = 0.173 * j as f64;
                let w = reg.omega_at(moments, w0, t);
                let (k, a) = principal_invariants(moments, w);
                assert!(rel(k, k0) < 1e-14 && rel(a, a0) < 1e-14, "{w0:?} t {t}");
            }
        }
    }

    #[test]
    fn the_exact_omega_solves_eulers_equation() {
        let moments = [1.0, 2.0, 3.0];
        let h = 1e-5;
        for w0 in [[0.3, 1.0, 0.2], [0.9, -0.2, 0.4], [0.4, 0.3, -1.0]] {
            let reg = Regime::new(moments, 0, w0);
            let at0 = reg.omega_at(moments, w0, 0.0);
            for i in 0..3 {
                assert!((at0[i] - w0[i]).abs() < 1e-15);
            }
            for j in 0..50 {
                let t = 0.41 * j as f64;
                let (p, m) = (
                    reg.omega_at(moments, w0, t + h),
                    reg.omega_at(moments, w0, t - h),
                );
                let f = euler_omega_dot(moments, reg.omega_at(moments, w0, t));
                for i in 0..3 {
                    assert!(((p[i] - m[i]) / (2.0 * h) - f[i]).abs() < 1e-8);
                }
            }
        }
        // a symmetric body precesses: the same check
        let sym = [1.0, 1.0, 2.0];
        let code = symmetry_code(sym, SYMMETRY_RTOL);
        let w0 = [0.3, -0.4, 0.8];
        let reg = Regime::new(sym, code, w0);
        assert_eq!(reg.case, PRECESSION);
        let t = 0.7;
        let (p, m) = (reg.omega_at(sym, w0, t + h), reg.omega_at(sym, w0, t - h));
        let f = euler_omega_dot(sym, reg.omega_at(sym, w0, t));
        for i in 0..3 {
            assert!(((p[i] - m[i]) / (2.0 * h) - f[i]).abs() < 1e-9);
        }
    }

    #[test]
    fn classification() {
        let i = [1.0, 2.0, 3.0];
        assert_eq!(Regime::new(i, 0, [0.0, 1.0, 0.0]).case, FIXED);
        assert_eq!(Regime::new(i, 0, [0.0, 0.0, 0.0]).case, FIXED);
        assert_eq!(Regime::new(i, 0, [0.1, 0.2, 1.0]).case, AROUND_E3);
        assert_eq!(Regime::new(i, 0, [1.0, 0.2, 0.1]).case, AROUND_E1);
        // a² = 2k I2 exactly: I1(I2 − I1) ω1² = I3(I3 − I2) ω3² = 0.5625 for I = (1, 2, 2.25)
        let sep = Regime::new([1.0, 2.0, 2.25], 0, [0.75, 0.5, 1.0]);
        assert_eq!(sep.case, SEPARATRIX);
        assert_eq!((sep.m, sep.m1), (1.0, 0.0));
        assert!(sep.flip_interval().is_infinite() && sep.period().is_infinite());
        assert_eq!(Regime::new([2.0; 3], 3, [0.1, 0.2, 0.3]).case, SPHERICAL);
        assert!(Regime::new([2.0; 3], 3, [0.1, 0.2, 0.3]).period().is_nan());
        assert_eq!(CASE_NAMES[AROUND_E1 as usize], "around e1");
    }

    fn orthogonality_error(q: &Mat3) -> f64 {
        let mut e: f64 = 0.0;
        for r in 0..3 {
            for c in 0..3 {
                let d: f64 = (0..3).map(|k| q[k][r] * q[k][c]).sum();
                e = e.max((d - if r == c { 1.0 } else { 0.0 }).abs());
            }
        }
        e
    }

    #[test]
    fn the_attitude_keeps_l_fixed_in_space_and_solves_the_kinematics() {
        // L in space, Q (I ω), is constant; Q̇ = Q hat(ω)
        let moments = [1.0, 2.0, 3.0];
        let s = EYE;
        let q0 = zxz_matrix(0.3, 1.1, -0.7);
        for (code, mom, w0) in [
            (0u8, moments, [0.3, 1.0, 0.2]),
            (0, moments, [1.0, 0.2, -0.1]),
            (2, [1.0, 1.0, 2.0], [0.3, -0.4, 0.8]),
            (1, [1.0, 2.0, 2.0], [0.3, -0.4, 0.8]),
            (0, moments, [0.0, 0.0, 1.5]),
        ] {
            let ts: Vec<f64> = (0..60).map(|j| 0.37 * j as f64).collect();
            let mut qs = vec![[[0.0; 3]; 3]; ts.len()];
            let mut ws = vec![[0.0; 3]; ts.len()];
            exact_attitudes(mom, &s, code, &[w0], &[q0], &ts, &mut qs);
            exact_omegas(mom, &s, code, &[w0], &ts, &mut ws);
            let l_of = |q: &Mat3, w: Vec3| {
                let p = [mom[0] * w[0], mom[1] * w[1], mom[2] * w[2]];
                q.map(|row| row[0] * p[0] + row[1] * p[1] + row[2] * p[2])
            };
            let l0 = l_of(&q0, w0);
            for (q, w) in qs.iter().zip(&ws) {
                assert!(orthogonality_error(q) < 1e-14);
                let l = l_of(q, *w);
                for i in 0..3 {
                    assert!((l[i] - l0[i]).abs() < 1e-13, "{code} {w0:?}");
                }
            }
            for i in 0..3 {
                for j in 0..3 {
                    assert!((qs[0][i][j] - q0[i][j]).abs() < 1e-15);
                }
            }
            // Q̇ = Q hat(ω) by central differences at t = 1
            let h = 1e-5;
            let mut three = [[[0.0; 3]; 3]; 3];
            exact_attitudes(
                mom,
                &s,
                code,
                &[w0],
                &[q0],
                &[1.0 - h, 1.0, 1.0 + h],
                &mut three,
            );
            let mut w1 = [[0.0; 3]];
            exact_omegas(mom, &s, code, &[w0], &[1.0], &mut w1);
            let qw = matmul(&three[1], &crate::so3::hat(w1[0]));
            for i in 0..3 {
                for j in 0..3 {
                    let d = (three[2][i][j] - three[0][i][j]) / (2.0 * h);
                    assert!((d - qw[i][j]).abs() < 1e-8, "{code} {w0:?}");
                }
            }
        }
    }

    #[test]
    fn scale_invariance_and_rows() {
        // ω scaled by 2^k: the same motion in time scaled by 2^-k
        let moments = [1.0, 2.0, 3.0];
        let w0 = [0.3, 1.0, 0.2];
        let a = Regime::new(moments, 0, w0);
        let b = Regime::new(moments, 0, w0.map(|x| x * 2f64.powi(-500)));
        assert_eq!(a.m, b.m);
        assert_eq!(a.m1, b.m1);
        assert_eq!(a.lam * 2f64.powi(-500), b.lam);
        let r = a.to_row();
        assert_eq!(r[row::CASE], AROUND_E3 as f64);
        assert_eq!(r[row::LAM], a.lam);
        assert_eq!(r[row::QUARTER], a.quarter);
    }

    /// Initial ω across every regime: random directions and magnitudes, the fixed points and
    /// their neighbourhoods, the separatrix and its neighbourhood (m1 from 1e-3 to 1e-12, on
    /// both sides), extreme and subnormal scales, zero.
    fn sample_omegas() -> Vec<Vec3> {
        let mut ws = Vec::new();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for i in 0..3000 {
            let scale = [1.0, 1e-3, 7.5, 1e150, 1e-150][i % 5];
            ws.push([uniform(), uniform(), uniform()].map(|x| scale * x));
        }
        let r3 = 3f64.sqrt();
        for d in [1e-3, 1e-5, 1e-6, 1e-9, 1e-12, -1e-3, -1e-6, -1e-12, 0.0] {
            ws.push([r3 * (1.0 + d), 0.4, 1.0]);
            ws.push([-r3 * (1.0 + d), -0.4, 1.0]);
        }
        for special in [
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0],
            [1e-150, 1.0, 1e-150],
            [1e-130, 1.0, -1e-130],
            [1e-8, 1.0, 1e-8],
            [1.0, 1e-12, 1e-12],
            [1e-12, 1e-12, 1.0],
            [1e300, 1e300, 1e300],
            [1e-310, 2e-310, -1e-310],
            [5e-324, 0.0, 5e-324],
            [1.7e308, 1.0, 1.0],
            [f64::NAN, 1.0, 0.5],
            [f64::INFINITY, 0.2, 1.0],
            [0.3, 1.0, 0.2],
        ] {
            ws.push(special);
        }
        // the specials again, each inside a block of ordinary members
        for j in 0..40 {
            let k = ws.len() - 1 - j % 30;
            ws.push(ws[k]);
            ws.push([0.3, -0.2 + 0.01 * j as f64, 0.9]);
        }
        ws
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || a.is_nan() && b.is_nan()
    }

    /// Members in SIMD lanes compute bit for bit what each member's single run (its `Regime`
    /// and `omega_at`) computes, in every regime, on every instruction set the CPU offers;
    /// and the lanes carry the ordinary members (not only the single runs' fallback).
    #[test]
    fn lanes_equal_single_runs_bit_for_bit() {
        // more times than lanes, not a multiple of them
        let mut ts = vec![0.0, 0.3, 1.0, 7.7, 100.0, -3.0, 1e4, 2.5e-10];
        ts.extend((0..WIDTH + 3).map(|j| 0.61 * j as f64 - 2.0));
        let ws = sample_omegas();
        for moments in [
            [1.0, 2.0, 3.0],
            [0.2, 1.5, 10.0],
            [1.0, 2.0, 2.25],
            [1.0, 1.0 + 1e-9, 2.0],
        ] {
            let s = zxz_matrix(0.3, 1.1, -0.7);
            let radicals = Radicals::new(moments);
            let mut want = vec![[0.0; 3]; ws.len() * ts.len()];
            for (w, o) in ws.iter().zip(want.chunks_mut(ts.len())) {
                omegas_one_by_one(moments, &s, &radicals, 0, *w, &ts, o);
            }
            let mut runs: Vec<(&str, Vec<Vec3>)> = Vec::new();
            let mut got = vec![[0.0; 3]; want.len()];
            omegas_in_lanes::<WIDTH>(moments, &s, &radicals, &ws, &ts, &mut got);
            runs.push(("dispatched", got.clone()));
            omegas_in_lanes::<8>(moments, &s, &radicals, &ws, &ts, &mut got);
            runs.push(("dispatched, 8 lanes", got.clone()));
            for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
                omegas_in_lanes_with::<WIDTH>(isa, moments, &s, &radicals, &ws, &ts, &mut got);
                runs.push((isa.name(), got.clone()));
            }
            // the batched entry point, on rayon's threads
            exact_omegas(moments, &s, 0, &ws, &ts, &mut got);
            runs.push(("exact_omegas", got.clone()));
            // members left over (fewer than the lanes), alone: their times in the lanes
            for (w, o) in ws.iter().zip(got.chunks_mut(ts.len())) {
                exact_omegas(moments, &s, 0, &[*w], &ts, o);
            }
            runs.push(("one member, times in lanes", got.clone()));
            for (name, got) in &runs {
                for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        (0..3).all(|c| same(a[c], b[c])),
                        "{name} {moments:?} member {:?} t {}: {a:?} {b:?}",
                        ws[i / ts.len()],
                        ts[i % ts.len()]
                    );
                }
            }
            // most members run in the lanes proper
            let mut plain = 0;
            for chunk in ws.chunks(WIDTH) {
                let mut w = [Wide::<WIDTH>::default(); 3];
                for l in 0..WIDTH {
                    for c in 0..3 {
                        w[c].0[l] = chunk[l.min(chunk.len() - 1)][c];
                    }
                }
                let (_, p) = LaneMotion::new(moments, &radicals, to_sorted(&s, w));
                plain += (0..chunk.len()).filter(|&l| p.get(l)).count();
            }
            assert!(
                plain * 10 > ws.len() * 9,
                "{moments:?}: {plain} of {}",
                ws.len()
            );
        }
    }

    /// The attitudes in lanes compute bit for bit what each member's single run
    /// (`attitude_at`) computes, in every regime (the members off the plain lanes run alone),
    /// on every instruction set the CPU offers, one Q0 shared or one per member; and the lanes
    /// carry the ordinary members.
    #[test]
    fn attitude_lanes_equal_single_runs_bit_for_bit() {
        let mut ts = vec![0.0, 0.3, 1.0, 7.7, 100.0, -3.0, 1e4, 2.5e-10];
        ts.extend((0..WIDTH + 3).map(|j| 0.61 * j as f64 - 2.0));
        let ws = sample_omegas();
        let q0s: Vec<Mat3> = (0..ws.len())
            .map(|i| zxz_matrix(0.1 * i as f64, 0.3 + 0.01 * i as f64, -0.2 * i as f64))
            .collect();
        for moments in [
            [1.0, 2.0, 3.0],
            [0.2, 1.5, 10.0],
            [1.0, 2.0, 2.25],
            [1.0, 1.0 + 1e-9, 2.0],
        ] {
            let s = zxz_matrix(0.3, 1.1, -0.7);
            for q0 in [&q0s[..], &q0s[..1]] {
                let pick = |i: usize| &q0[if q0.len() > 1 { i } else { 0 }];
                let mut want = vec![[[0.0; 3]; 3]; ws.len() * ts.len()];
                for (i, (w, o)) in ws.iter().zip(want.chunks_mut(ts.len())).enumerate() {
                    attitudes_one_by_one(moments, &s, 0, *w, pick(i), &ts, o);
                }
                let mut runs: Vec<(&str, Vec<Mat3>)> = Vec::new();
                let mut got = vec![[[0.0; 3]; 3]; want.len()];
                attitudes_in_lanes::<WIDTH>(moments, &s, &ws, q0, &ts, &mut got);
                runs.push(("dispatched", got.clone()));
                attitudes_in_lanes::<8>(moments, &s, &ws, q0, &ts, &mut got);
                runs.push(("dispatched, 8 lanes", got.clone()));
                for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
                    attitudes_in_lanes_with::<WIDTH>(isa, moments, &s, &ws, q0, &ts, &mut got);
                    runs.push((isa.name(), got.clone()));
                }
                exact_attitudes(moments, &s, 0, &ws, q0, &ts, &mut got);
                runs.push(("exact_attitudes", got.clone()));
                for (i, (w, o)) in ws.iter().zip(got.chunks_mut(ts.len())).enumerate() {
                    exact_attitudes(moments, &s, 0, &[*w], &[*pick(i)], &ts, o);
                }
                runs.push(("one member, times in lanes", got.clone()));
                for (name, got) in &runs {
                    for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                        assert!(
                            (0..9).all(|k| same(a[k / 3][k % 3], b[k / 3][k % 3])),
                            "{name} {moments:?} member {:?} t {}: {a:?} {b:?}",
                            ws[i / ts.len()],
                            ts[i % ts.len()]
                        );
                    }
                }
            }
            // most members run in the lanes proper
            let plain = ws
                .iter()
                .filter(|w| plain_motion(moments, &s, **w, &q0s[0]).is_some())
                .count();
            assert!(
                plain * 10 > ws.len() * 8,
                "{moments:?}: {plain} of {}",
                ws.len()
            );
        }
    }

    /// The attitude from the reduction ω(t) makes (`third_kind_reduced`, `carlson_rj_above`,
    /// the angles as ratios) equals the one from the angles by atan2 and `third_kind_u`
    /// (libm's atan, the integral's own reduction) to round-off.
    #[test]
    fn the_reduced_attitude_equals_the_angle_route() {
        for moments in [[1.0, 2.0, 3.0], [0.2, 1.5, 10.0], [1.0, 2.0, 2.25]] {
            for w in [
                [0.3, 1.0, 0.2],
                [1.0, 0.2, -0.1],
                [-0.05, 1.0, 0.01],
                [0.9, -0.4, 1.3],
            ] {
                let q0 = zxz_matrix(0.4, 0.9, -1.2);
                let reg = Regime::new(moments, 0, w);
                assert!(reg.is_elliptic() && reduced_third_kind(&reg));
                let att = AttitudeSetup::new(moments, &reg, w, &q0);
                for t in [0.0, 0.7, 3.1, 25.0, -11.0, 400.0] {
                    let got = attitude_at(moments, &reg, &att, w, &q0, t);
                    // the angle route
                    let v = reg.omega_at(moments, w, t);
                    let (theta, phi) = relabelled_angles(
                        reg.pole,
                        [moments[0] * v[0], moments[1] * v[1], moments[2] * v[2]],
                    );
                    let u = reg.u0 + reg.lam * t;
                    let u0 = reg.u0;
                    let big = third_kind_u(att.n, u, reg.m, reg.m1, reg.quarter)
                        - third_kind_u(att.n, u0, reg.m, reg.m1, reg.quarter);
                    let psi = reg.momentum * t / att.i_pole + att.psi_pi * big;
                    let x = matmul(&att.p0, &zxz_matrix(psi, theta, phi));
                    let want = if reg.pole == 2 {
                        x
                    } else {
                        x.map(|row| [row[2], -row[1], row[0]])
                    };
                    let tol = 4e-15 * (1.0 + psi.abs());
                    for k in 0..9 {
                        let (a, b) = (got[k / 3][k % 3], want[k / 3][k % 3]);
                        assert!((a - b).abs() <= tol, "{moments:?} {w:?} t {t}: {a} {b}");
                    }
                }
                // ψ(0) = 0 exactly: Q(0) = Q0 to the round-off of the frame's products
                let q = attitude_at(moments, &reg, &att, w, &q0, 0.0);
                for k in 0..9 {
                    assert!((q[k / 3][k % 3] - q0[k / 3][k % 3]).abs() < 2e-15);
                }
            }
        }
    }

    #[test]
    fn families_in_lanes_equal_each_members_regime_bit_for_bit() {
        // the members of the ω lanes' test (near the axes, the separatrix, extreme scales),
        // many of them, so that the threads' blocks and a partial group of lanes run
        let base = sample_omegas();
        let ws: Vec<Vec3> = (0..PARALLEL_MIN + 77)
            .map(|i| base[i % base.len()].map(|x| x * (1.0 + (i / base.len()) as f64 * 1e-3)))
            .collect();
        for (moments, symmetry) in [
            ([1.0, 2.0, 3.0], 0),
            ([0.2, 1.5, 10.0], 0),
            ([1.0, 2.0, 2.25], 0),
            ([1.0, 2.0, 2.0], 2),
        ] {
            let s = zxz_matrix(0.3, 1.1, -0.7);
            let want: Vec<Family> = ws
                .iter()
                .map(|w| Family::of(&regime_of(moments, &s, symmetry, *w)))
                .collect();
            let mut got = vec![Family::default(); ws.len()];
            let mut runs: Vec<(&str, Vec<Family>)> = Vec::new();
            families(moments, &s, symmetry, &ws, &mut got);
            runs.push(("families", got.clone()));
            families(moments, &s, symmetry, &ws[..100], &mut got[..100]);
            runs.push(("few members, one thread", got.clone()));
            if symmetry == 0 {
                let radicals = Radicals::new(moments);
                for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
                    families_in_lanes_with::<WIDTH>(isa, moments, &s, &radicals, &ws, &mut got);
                    runs.push((isa.name(), got.clone()));
                }
                families_in_lanes::<8>(moments, &s, &radicals, &ws, &mut got);
                runs.push(("8 lanes", got.clone()));
            }
            for (name, got) in &runs {
                for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        a.case == b.case
                            && same(a.period, b.period)
                            && same(a.flip_interval, b.flip_interval),
                        "{name} {moments:?} member {:?}: {a:?} {b:?}",
                        ws[i]
                    );
                }
            }
            // every family occurs where the body has them
            if symmetry == 0 {
                for case in [AROUND_E1, AROUND_E3, FIXED] {
                    assert!(want.iter().any(|f| f.case == case), "{moments:?} {case}");
                }
            }
        }
    }

    /// The time of 10⁶ closed forms at one time each (run with `--ignored --nocapture`).
    #[test]
    #[ignore]
    fn time_exact_omegas() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let ws: Vec<Vec3> = (0..1_000_000)
            .map(|_| {
                [0; 3].map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
                })
            })
            .collect();
        for nt in [1usize, 10, 100] {
            let ts: Vec<f64> = (0..nt).map(|j| 1.0 + 0.3 * j as f64).collect();
            let ws = &ws[..ws.len() / nt.min(10)];
            let mut out = vec![[0.0; 3]; ws.len() * nt];
            let radicals = Radicals::new([1.0, 2.0, 3.0]);
            for name in [
                "exact_omegas",
                "one by one",
                "8 lanes",
                "16 lanes",
                "32 lanes",
                "64 lanes",
                "32 lanes, AVX2",
                "16 lanes, AVX2",
                "16 lanes, baseline",
            ] {
                let mut best = f64::INFINITY;
                for _ in 0..5 {
                    let t0 = std::time::Instant::now();
                    match name {
                        "exact_omegas" => exact_omegas([1.0, 2.0, 3.0], &EYE, 0, ws, &ts, &mut out),
                        "one by one" => {
                            for (w, o) in ws.iter().zip(out.chunks_mut(nt)) {
                                omegas_one_by_one([1.0, 2.0, 3.0], &EYE, &radicals, 0, *w, &ts, o)
                            }
                        }
                        "8 lanes" => omegas_in_lanes::<8>(
                            [1.0, 2.0, 3.0],
                            &EYE,
                            &radicals,
                            ws,
                            &ts,
                            &mut out,
                        ),
                        "16 lanes" => omegas_in_lanes::<16>(
                            [1.0, 2.0, 3.0],
                            &EYE,
                            &radicals,
                            ws,
                            &ts,
                            &mut out,
                        ),
                        "16 lanes, AVX2" => {
                            if !Isa::Avx2.available() {
                                break;
                            }
                            let ms = [1.0, 2.0, 3.0];
                            omegas_in_lanes_with::<16>(
                                Isa::Avx2,
                                ms,
                                &EYE,
                                &radicals,
                                ws,
                                &ts,
                                &mut out,
                            )
                        }
                        "64 lanes" => omegas_in_lanes::<64>(
                            [1.0, 2.0, 3.0],
                            &EYE,
                            &radicals,
                            ws,
                            &ts,
                            &mut out,
                        ),
                        "32 lanes, AVX2" => {
                            if !Isa::Avx2.available() {
                                break;
                            }
                            let ms = [1.0, 2.0, 3.0];
                            omegas_in_lanes_with::<32>(
                                Isa::Avx2,
                                ms,
                                &EYE,
                                &radicals,
                                ws,
                                &ts,
                                &mut out,
                            )
                        }
                        "16 lanes, baseline" => omegas_in_lanes_any::<16>(
                            [1.0, 2.0, 3.0],
                            &EYE,
                            &radicals,
                            ws,
                            &ts,
                            &mut out,
                        ),
                        _ => omegas_in_lanes::<32>(
                            [1.0, 2.0, 3.0],
                            &EYE,
                            &radicals,
                            ws,
                            &ts,
                            &mut out,
                        ),
                    }
                    best = best.min(t0.elapsed().as_secs_f64());
                }
                eprintln!(
                    "{nt:4} times, {name:18}: {:.3e} /s",
                    (ws.len() * nt) as f64 / best
                );
            }
        }
    }
}
