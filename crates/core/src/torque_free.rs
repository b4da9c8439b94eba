//! The torque-free rotation in closed form (`docs/theory.md` §1, "Torque-free body",
//! eqs (20)–(33); `docs/torque_free.md`): the port of `poinsot.kernels.torque_free`, formula
//! for formula and in the same order of operations.
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

use crate::cmath::{frexp, ldexp};
use crate::elliptic::{
    ellipk_m1, first_kind_from_sn_cn, jacobi_reduced_with, third_kind_u, Agm, NEAR_ONE,
};
use crate::invariants::principal_invariants;
use crate::so3::{exp_so3, matmul, Mat3, Vec3};
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

/// Python's `max(a, b)` (`a` unless `b > a`) and `min(a, b)` (`a` unless `b < a`).
#[inline(always)]
fn py_max(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}
#[inline(always)]
fn py_min(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// The square roots of a body's moments that every motion's regime uses:
/// `√(I1 (I3 − I1))`, `√(I2 (I3 − I2))`, `√(I2 (I2 − I1))`, `√(I3 (I3 − I1))` (sorted moments).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Radicals {
    pub r13: f64,
    pub r23: f64,
    pub r12: f64,
    pub r33: f64,
}

impl Radicals {
    pub fn new(moments: Vec3) -> Radicals {
        let [i1, i2, i3] = moments;
        Radicals {
            r13: (i1 * (i3 - i1)).sqrt(),
            r23: (i2 * (i3 - i2)).sqrt(),
            r12: (i2 * (i2 - i1)).sqrt(),
            r33: (i3 * (i3 - i1)).sqrt(),
        }
    }
}

/// `√(a² + b²)`: the square root of the sum where the squares neither overflow nor underflow
/// (the regime's scaled values), else `hypot`.
#[inline(always)]
fn norm2(a: f64, b: f64) -> f64 {
    let s = a * a + b * b;
    if s.is_normal() && s < 1e300 {
        s.sqrt()
    } else {
        a.hypot(b)
    }
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
    /// The AGM sequence of `m1` (elliptic cases with `m1 ≥` [`NEAR_ONE`]), made once for
    /// every time of ω(t).
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
        let [i1, i2, i3] = moments;
        if py_max(x0.abs(), x2.abs()) <= NEAR_UNSTABLE_AXIS * x1.abs() {
            reg.case = FIXED;
            return reg;
        }
        let Radicals { r13, r23, r12, r33 } = *radicals;
        let q3 = norm2(r13 * x0, r23 * x1); // √P3, P3 = 2k I3 − a² (scaled)
        let q1 = norm2(r12 * x1, r33 * x2); // √P1, P1 = a² − 2k I1
        if q3 == 0.0 || q1 == 0.0 {
            // on e3 or on e1
            reg.case = FIXED;
            return reg;
        }
        let d2 = i3 * (i3 - i2) * x2 * x2 - i1 * (i2 - i1) * x0 * x0; // a² − 2k I2
        let (a0, a1, a2, lam, mut m, mut m1, pole);
        if d2 >= 0.0 {
            // around e3, or the separatrix (d2 = 0)
            a0 = q3 / r13;
            a1 = q3 / r23;
            a2 = q1 / r33;
            lam = q1 * ((i3 - i2) / (i1 * i2 * i3)).sqrt();
            let ratio = q3 / q1;
            m = (i2 - i1) / (i3 - i2) * ratio * ratio;
            m1 = (i3 - i1) * d2 / ((i3 - i2) * q1 * q1);
            pole = 2u8;
        } else {
            // around e1
            a0 = q3 / r13;
            a1 = q1 / r12;
            a2 = q1 / r33;
            lam = q3 * ((i2 - i1) / (i1 * i2 * i3)).sqrt();
            let ratio = q1 / q3;
            m = (i3 - i2) / (i2 - i1) * ratio * ratio;
            m1 = (i3 - i1) * (-d2) / ((i2 - i1) * q3 * q3);
            pole = 0u8;
        }
        m = py_min(py_max(m, 0.0), 1.0);
        m1 = py_min(py_max(m1, 0.0), 1.0);
        if m1 < 1e-300 {
            // subnormal: the separatrix is the orbit to within O(m1)
            m = 1.0;
            m1 = 0.0;
        }
        let mut s1 = if x0 > 0.0 { 1.0 } else { -1.0 };
        let mut s3 = if x2 > 0.0 { 1.0 } else { -1.0 };
        // Signs: the ODE needs σ1 = σ2 σ3. Off the separatrix cn takes both signs, so the sign
        // of the cn-component is +1 (absorbed in the phase); on the separatrix cn = sech u > 0
        // and each of the four arcs keeps the signs of both ω1 and ω3.
        let (sn0, cn0);
        if pole == 2 {
            if m1 != 0.0 {
                s1 = 1.0;
            }
            sn0 = s1 * s3 * x1 / a1;
            cn0 = s1 * x0 / a0;
        } else {
            if m1 != 0.0 {
                s3 = 1.0;
            }
            sn0 = s1 * s3 * x1 / a1;
            cn0 = s3 * x2 / a2;
        }
        reg.u0 = first_kind_from_sn_cn(sn0, cn0, m, m1);
        reg.case = if m1 == 0.0 {
            SEPARATRIX
        } else if pole == 2 {
            AROUND_E3
        } else {
            AROUND_E1
        };
        reg.alpha = [ldexp(a0, e), ldexp(a1, e), ldexp(a2, e)];
        reg.lam = ldexp(lam, e);
        reg.m = m;
        reg.m1 = m1;
        reg.signs = [s1, s1 * s3, s3];
        reg.pole = pole;
        if m1 >= NEAR_ONE && m > 0.0 {
            reg.agm = Agm::new(m1);
            reg.quarter = reg.agm.quarter(); // = ellipk_m1(m1), the same sequence
        } else {
            reg.quarter = ellipk_m1(m1);
        }
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
                let (first, last) = if self.pole == 2 { (cn, dn) } else { (dn, cn) };
                [
                    self.signs[0] * self.alpha[0] * first,
                    self.signs[1] * self.alpha[1] * sn,
                    self.signs[2] * self.alpha[2] * last,
                ]
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
        AttitudeSetup {
            p0,
            n,
            i_pole: ip,
            i_other: iq,
            pi_u0: third_kind_u(n, reg.u0, reg.m, reg.m1, reg.quarter),
        }
    }
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
        _ => {
            let v = reg.omega_at(moments, w, t);
            let (theta, phi) = relabelled_angles(
                reg.pole,
                [moments[0] * v[0], moments[1] * v[1], moments[2] * v[2]],
            );
            let ip = att.i_pole;
            let iq = att.i_other;
            let lam = reg.lam;
            let a = reg.momentum;
            let u = reg.u0 + lam * t;
            let big_pi = third_kind_u(att.n, u, reg.m, reg.m1, reg.quarter) - att.pi_u0;
            let psi = a * t / ip + a * (ip - iq) / (ip * iq * lam) * big_pi; // ψ(0) = 0
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

/// `Sᵀ ω`: body-frame ω in the sorted principal frame.
#[inline(always)]
fn to_sorted(s: &Mat3, w: Vec3) -> Vec3 {
    [
        s[0][0] * w[0] + s[1][0] * w[1] + s[2][0] * w[2],
        s[0][1] * w[0] + s[1][1] * w[1] + s[2][1] * w[2],
        s[0][2] * w[0] + s[1][2] * w[1] + s[2][2] * w[2],
    ]
}

/// `S v`: sorted-frame `v` in the body frame.
#[inline(always)]
fn from_sorted(s: &Mat3, v: Vec3) -> Vec3 {
    [
        s[0][0] * v[0] + s[0][1] * v[1] + s[0][2] * v[2],
        s[1][0] * v[0] + s[1][1] * v[1] + s[1][2] * v[2],
        s[2][0] * v[0] + s[2][1] * v[1] + s[2][2] * v[2],
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
/// the regime, then every time. Members are shared among rayon's threads.
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
    let member = |w: &Vec3, block: &mut [Vec3]| {
        let ws = to_sorted(s, *w);
        let reg = Regime::with(moments, &radicals, symmetry, ws);
        for (o, &t) in block.iter_mut().zip(ts) {
            *o = from_sorted(s, reg.omega_at(moments, ws, t));
        }
    };
    if ws.len() > 1 && ws.len() * n >= PARALLEL_MIN {
        ws.par_iter()
            .zip(out.par_chunks_mut(n))
            .for_each(|(w, block)| member(w, block));
    } else {
        ws.iter()
            .zip(out.chunks_mut(n))
            .for_each(|(w, block)| member(w, block));
    }
}

/// `Q(t)` (body → space) of the torque-free motions from the body-frame ω `ws` and attitudes
/// `q0s` (one per member, or one shared), at the times `ts`, into `out` (member-major).
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
    let member = |i: usize, block: &mut [Mat3]| {
        let q = &q0s[if q0s.len() > 1 { i } else { 0 }];
        let q0s_sorted = matmul(q, s); // Q0 S: sorted principal frame → space
        let w = to_sorted(s, ws[i]);
        let reg = Regime::new(moments, symmetry, w);
        let att = AttitudeSetup::new(moments, &reg, w, &q0s_sorted);
        for (o, &t) in block.iter_mut().zip(ts) {
            let qs = attitude_at(moments, &reg, &att, w, &q0s_sorted, t);
            let mut q = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    // Q = Qs Sᵀ
                    q[r][c] = qs[r][0] * s[c][0] + qs[r][1] * s[c][1] + qs[r][2] * s[c][2];
                }
            }
            *o = q;
        }
    };
    if ws.len() > 1 && ws.len() * n >= PARALLEL_MIN / 8 {
        out.par_chunks_mut(n)
            .enumerate()
            .for_each(|(i, block)| member(i, block));
    } else {
        out.chunks_mut(n)
            .enumerate()
            .for_each(|(i, block)| member(i, block));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::freebody::{euler_omega_dot, symmetry_code, SYMMETRY_RTOL};

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
}
