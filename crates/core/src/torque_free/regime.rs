//! The regime of one torque-free motion (`docs/theory.md` §1, eqs (20)–(33);
//! `docs/torque_free.md`): everything the closed form needs of one initial ω, computed once by
//! [`Regime::new`] — the invariants (30)–(31), the case, and for three distinct moments the
//! Jacobi form `ω = (σ1 α1 cn u, σ2 α2 sn u, σ3 α3 dn u)` (pole e3) or
//! `(σ1 α1 dn u, σ2 α2 sn u, σ3 α3 cn u)` (pole e1), `u = u0 + λt`, with `m`, `m1` and `K(m)` —
//! and ω(t) from it ([`Regime::omega_at`]). The polhode radii and the Jacobi form are generic
//! over [`Real`], so that the lanes of [`super::exact_omegas`] run the very same formulas.

use super::{
    row, AROUND_E1, AROUND_E3, FIXED, NEAR_UNSTABLE_AXIS, PRECESSION, SEPARATRIX, SPHERICAL,
};
use crate::cmath::{frexp, ldexp};
use crate::elliptic::{first_kind_from_sn_cn, first_kind_in_period, jacobi_reduced_with, Agm};
use crate::invariants::principal_invariants;
use crate::real::{py_max, py_min, squares_difference, two_product_of_difference, Real};
use crate::so3::Vec3;

/// A motion whose distance from the separatrix, `|a² − 2k I2|`, is within this many times the
/// sum of its two terms (four roundings of them) is taken as on the separatrix: a point made
/// on it in floating point (`point_on_polhode`) lands that close, and is meant to be on it.
pub const SEPARATRIX_ROUNDING: f64 = 4.0 * f64::EPSILON;

/// The square roots of a body's moments that every motion's regime uses:
/// `√(I1 (I3 − I1))`, `√(I2 (I3 − I2))`, `√(I2 (I2 − I1))`, `√(I3 (I3 − I1))`, and the rates
/// `√((I3 − I2)/(I1 I2 I3))`, `√((I2 − I1)/(I1 I2 I3))` of `λ` (sorted moments). Generic over
/// [`Real`]: on `f64` for a body, splat into lanes ([`Radicals::splat`]), or on dual numbers
/// for the derivatives with respect to the moments ([`super::ExactTangent`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Radicals<T = f64> {
    pub r13: T,
    pub r23: T,
    pub r12: T,
    pub r33: T,
    pub rate3: T,
    pub rate1: T,
    /// `√(I1 (I3 − I1)) / √(I2 (I3 − I2))` and `√(I3 (I3 − I1)) / √(I2 (I2 − I1))`: the ratios
    /// `|cn u0 / sn u0| = cot3 |ω1/ω2|` (pole e3) and `cot1 |ω3/ω2|` (pole e1).
    pub cot3: T,
    pub cot1: T,
}

impl Radicals {
    pub fn new(moments: Vec3) -> Radicals {
        Radicals::of(moments)
    }

    /// The same numbers in every lane of `T`.
    #[inline(always)]
    pub(super) fn splat<T: Real>(&self) -> Radicals<T> {
        let c = T::splat;
        Radicals {
            r13: c(self.r13),
            r23: c(self.r23),
            r12: c(self.r12),
            r33: c(self.r33),
            rate3: c(self.rate3),
            rate1: c(self.rate1),
            cot3: c(self.cot3),
            cot1: c(self.cot1),
        }
    }
}

impl<T: Real> Radicals<T> {
    /// The radicals of the sorted `moments`.
    #[inline(always)]
    pub fn of(moments: [T; 3]) -> Radicals<T> {
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
pub(super) fn polhode_radii<T: Real>(r: &Radicals<T>, x: [T; 3], plain: &mut T::Mask) -> (T, T) {
    let q3 = T::norm2(r.r13 * x[0], r.r23 * x[1], plain);
    let q1 = T::norm2(r.r12 * x[1], r.r33 * x[2], plain);
    (q3, q1)
}

/// The Jacobi form of a motion of a body with three distinct moments, off the fixed points
/// (`√P3 = q3 > 0`, `√P1 = q1 > 0`), from the scaled ω `x` (see the module docs): amplitudes
/// and rate in the scale of `x`. Generic over [`Real`].
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct JacobiForm<T: Real> {
    /// `(α1, α2, α3)` and `λ` (scaled).
    pub(super) alpha: [T; 3],
    pub(super) lam: T,
    /// `m` and `m1` (clamped to [0, 1]; `(1, 0)` for a subnormal `m1`).
    pub(super) m: T,
    pub(super) m1: T,
    /// `σ1`, `σ3`.
    pub(super) s1: T,
    pub(super) s3: T,
    /// Of the signs of `sn u0` and `cn u0`, and `|cn u0 / sn u0|`.
    pub(super) sn0: T,
    pub(super) cn0: T,
    pub(super) cot0: T,
    /// Where the polhode circles e3 (else e1).
    pub(super) e3: T::Mask,
}

impl<T: Real> JacobiForm<T> {
    #[inline(always)]
    pub(super) fn new(moments: [T; 3], r: &Radicals<T>, x: [T; 3], q3: T, q1: T) -> JacobiForm<T> {
        let c = T::splat;
        let [i1, i2, i3] = moments;
        let [x0, x1, x2] = x;
        // a² − 2k I2 = I3 (I3 − I2) x3² − I1 (I2 − I1) x1², the two terms nearly equal near
        // the separatrix: formed without their rounding errors; within the rounding of the
        // terms themselves (a point made on the separatrix in floating point), zero
        let (d2, size) = squares_difference(
            two_product_of_difference(i3, i3, i2),
            x2,
            two_product_of_difference(i1, i2, i1),
            x0,
        );
        let d2 = T::select(d2.abs().le(c(SEPARATRIX_ROUNDING) * size), c(0.0), d2);
        // around e3 (d2 > 0), or the separatrix (d2 = 0); else around e1
        let e3 = d2.ge(c(0.0));
        // e3: (q3, q1), e1: (q1, q3)
        let (qa, qb) = (T::select(e3, q3, q1), T::select(e3, q1, q3));
        let a0 = q3 / r.r13;
        let a1 = qa / T::select(e3, r.r23, r.r12);
        let a2 = q1 / r.r33;
        let lam = qb * T::select(e3, r.rate3, r.rate1);
        let ratio = qa / qb;
        let m = T::select(e3, (i2 - i1) / (i3 - i2), (i3 - i2) / (i2 - i1)) * ratio * ratio;
        let m1 = (i3 - i1) * T::select(e3, d2, -d2) / (T::select(e3, i3 - i2, i2 - i1) * qb * qb);
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
        let cot0 = xc.abs() * T::select(e3, r.cot3, r.cot1) / x1.abs();
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
pub(super) fn jacobi_omega<T: Real>(e3: T::Mask, sa: [T; 3], sn: T, cn: T, dn: T) -> [T; 3] {
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
    /// of ω(t) (the Jacobi functions use it for `m1 ≥`
    /// [`NEAR_ONE`](crate::elliptic::NEAR_ONE)).
    pub agm: Agm,
}

impl Regime {
    /// The regime of the motion from `ω(0) = w` (sorted principal frame) for sorted moments
    /// `moments`; `symmetry` the code of [`crate::freebody::symmetry_code`].
    pub fn new(moments: Vec3, symmetry: u8, w: Vec3) -> Regime {
        Regime::with(moments, &Radicals::new(moments), symmetry, w)
    }

    /// [`Regime::new`] with the body's [`Radicals`] made once (for many motions of one body).
    /// Always inlined: the exact-flow splittings' free flow runs it in its AVX2 copy
    /// ([`crate::exact_splitting::FreeFlow::evaluate`]).
    #[inline(always)]
    pub fn with(moments: Vec3, radicals: &Radicals, symmetry: u8, w: Vec3) -> Regime {
        let mut reg = Regime::default();
        reg.fill(moments, radicals, symmetry, w);
        reg
    }

    /// [`Regime::with`] written in place over `self`: the exact-flow splittings' free flow
    /// keeps the regime of its motion, and a regime made elsewhere and moved there was a copy
    /// of its own (two calls to `memcpy`) at every flow. Every field is set again but `agm`,
    /// which only the motions that use it (elliptic, off the separatrix) fill; in the others
    /// it keeps what it held, and nothing reads it.
    #[inline(always)]
    pub fn fill(&mut self, moments: Vec3, radicals: &Radicals, symmetry: u8, w: Vec3) {
        // field by field (`*self = Regime::default()` was built on the stack and copied); the
        // pattern names every field, so that a new one cannot be left out
        let Regime {
            case,
            energy,
            momentum,
            alpha,
            lam,
            m,
            m1,
            signs,
            u0,
            pole,
            quarter,
            nu,
            axis,
            i_perp,
            agm: _,
        } = self;
        (*case, *pole, *axis) = (0, 0, 0);
        (
            *energy, *momentum, *lam, *m, *m1, *u0, *quarter, *nu, *i_perp,
        ) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        (*alpha, *signs) = ([0.0; 3], [0.0; 3]);
        let [w0, w1, w2] = w;
        let big = py_max(py_max(w0.abs(), w1.abs()), w2.abs());
        if symmetry == 3 {
            self.case = SPHERICAL;
        } else if big == 0.0 {
            self.case = FIXED;
        }
        if big == 0.0 {
            return;
        }
        // scale ω by a power of two (exactly) so that squares neither underflow nor overflow
        let e = frexp(big).1;
        let sc = ldexp(1.0, -e);
        let x = [w0 * sc, w1 * sc, w2 * sc];
        let (k, a) = principal_invariants(moments, x);
        self.energy = ldexp(k, 2 * e);
        self.momentum = ldexp(a, e);
        if symmetry == 3 {
            return;
        }
        if symmetry != 0 {
            self.set_precession(moments, symmetry, w);
        } else {
            self.set_elliptic(moments, radicals, x, e);
        }
    }

    /// A symmetric body's motion (`symmetry` 1, prolate: axis e1, `I⊥ = I3`; 2, oblate: axis
    /// e3, `I⊥ = I1`): `π = Aω` turns about the axis at the rate `−ν`,
    /// `ν = (1/I_s − 1/I⊥) I_s ω_s`; fixed when ν or the transverse ω vanishes.
    fn set_precession(&mut self, moments: Vec3, symmetry: u8, w: Vec3) {
        let [w0, w1, w2] = w;
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
        self.case = if nu == 0.0 || transverse_zero {
            FIXED
        } else {
            PRECESSION
        };
        self.nu = nu;
        self.axis = s as u8;
        self.i_perp = i_perp;
    }

    /// Three distinct moments, from the scaled ω `x` (`ω = 2^e x`): fixed on an axis (or
    /// within [`NEAR_UNSTABLE_AXIS`] of the intermediate one), else the Jacobi form (eqs
    /// (20)–(33)) with its quarter period `K(m)` and its argument `u0` at t = 0, around e3,
    /// around e1 or on the separatrix (`m1 = 0`).
    #[inline(always)]
    fn set_elliptic(&mut self, moments: Vec3, radicals: &Radicals, x: Vec3, e: i32) {
        let [x0, x1, x2] = x;
        if py_max(x0.abs(), x2.abs()) <= NEAR_UNSTABLE_AXIS * x1.abs() {
            self.case = FIXED;
            return;
        }
        let (q3, q1) = polhode_radii(radicals, x, &mut true);
        if q3 == 0.0 || q1 == 0.0 {
            // on e3 or on e1
            self.case = FIXED;
            return;
        }
        let f = JacobiForm::new(moments, radicals, x, q3, q1);
        let (m, m1) = (f.m, f.m1);
        self.case = if m1 == 0.0 {
            SEPARATRIX
        } else if f.e3 {
            AROUND_E3
        } else {
            AROUND_E1
        };
        if m1 == 0.0 {
            self.quarter = f64::INFINITY;
            let a_cn = if f.e3 { f.alpha[0] } else { f.alpha[2] };
            self.u0 = first_kind_from_sn_cn(f.sn0 / f.alpha[1], f.cn0 / a_cn, m, m1);
        } else {
            self.agm.fill(m1); // in place
            self.quarter = self.agm.quarter(); // = ellipk_m1(m1), the same sequence
            self.u0 = first_kind_in_period(f.cot0, f.sn0, f.cn0, &self.agm, self.quarter);
        }
        // written out: `array::map`'s closure was a call of its own, at every flow
        self.alpha = [
            ldexp(f.alpha[0], e),
            ldexp(f.alpha[1], e),
            ldexp(f.alpha[2], e),
        ];
        self.lam = ldexp(f.lam, e);
        self.m = m;
        self.m1 = m1;
        self.signs = [f.s1, f.s1 * f.s3, f.s3];
        self.pole = if f.e3 { 2 } else { 0 };
    }

    /// The flat row (`row::SIZE` numbers at the offsets of [`row`]) that
    /// `poinsot._core.torque_free_regimes` returns, one per motion.
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
                let p = precession_momentum(
                    self.axis as usize,
                    self.nu,
                    [moments[0] * w[0], moments[1] * w[1], moments[2] * w[2]],
                    t,
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

/// The body momentum `π(t)` of a symmetric body (symmetry axis `s`, eqs (22)–(23)): `π0`
/// turned by `−ν t` about `e_s`, `ν = (1/I_s − 1/I⊥) π_s`. Generic over [`Real`] (the
/// exact-flow splittings' derivatives run it on dual numbers).
#[inline(always)]
pub fn precession_momentum<T: Real>(s: usize, nu: T, pi: [T; 3], t: T) -> [T; 3] {
    turn_about_axis(s, -nu * t, pi)
}

/// The vector `x` turned by `angle` about principal axis `s`.
#[inline(always)]
fn turn_about_axis<T: Real>(s: usize, angle: T, x: [T; 3]) -> [T; 3] {
    let (n, c) = angle.sin_cos_std();
    let [x0, x1, x2] = x;
    match s {
        0 => [x0, c * x1 - n * x2, n * x1 + c * x2],
        1 => [n * x2 + c * x0, x1, c * x2 - n * x0],
        _ => [c * x0 - n * x1, n * x0 + c * x1, x2],
    }
}
