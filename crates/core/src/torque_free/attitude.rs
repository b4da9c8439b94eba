//! The attitude `Q(t)` of one torque-free motion (`docs/theory.md` §1, eqs (20)–(33);
//! `docs/torque_free.md`): z-x-z Euler angles `(ψ, θ, φ)` of the body relative to the
//! invariable frame (z along L), with pole the axis the polhode circles, `cos θ = π_pole/a`,
//! `tan φ = π_1'/π_2'` and `ψ(t) = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]`
//! (Landau & Lifshitz, *Mechanics*, §37; Whittaker, *Analytical Dynamics*, §69); symmetric
//! bodies `Q(t) = exp(t L̂/I⊥) Q0 exp(ν t ê_s)`, fixed points `Q0 exp(Ω t)` (eqs (22)–(23)).
//! What the elliptic attitude needs beyond the regime is made once ([`AttitudeSetup`]); its
//! formulas at each time are generic over [`Real`] ([`EllipticMotion`]), so that the lanes of
//! [`super::exact_attitudes`] run the very same formulas as [`attitude_at`].

use super::{jacobi_omega, Regime, FIXED, PRECESSION, SPHERICAL};
use crate::elliptic::{
    ellippi_excess_complete, jacobi_reduced_with, parity, third_kind_excess,
    third_kind_excess_reduced, third_kind_u, TINY_M1,
};
use crate::real::{sin_cos, Mask, Real, Wide, WideMask};
use crate::so3::{exp_so3, matmul, zxz_matrix, zxz_matrix_sc, Mat3, Vec3};

/// `(θ, φ)` of the body relative to the invariable frame from the body momentum `π`:
/// relabelled as `(π3, −π2, π1)` when the pole is e1.
#[inline(always)]
pub(super) fn relabelled_angles(pole: u8, p: Vec3) -> (f64, f64) {
    let [b0, b1, b2] = if pole == 0 { [p[2], -p[1], p[0]] } else { p };
    (b0.hypot(b1).atan2(b2), b0.atan2(b1))
}

/// `Rzxz(ψ, θ, φ)` of the body momentum `π` (relabelled as [`relabelled_angles`] where `e3`
/// is clear) from `(sin ψ, cos ψ)` and the ratios `sin θ = ρ/|π|`, `cos θ = π_p/|π|`,
/// `(sin φ, cos φ) = (π_1', π_2')/ρ`, `ρ = |(π_1', π_2')|` (no angle formed; `φ = 0` where
/// ρ = 0): the rotation [`EllipticMotion::attitude`] forms at every time and
/// [`invariable_frame`] at the start. Generic over [`Real`]; `plain` as [`Real::norm2`].
#[inline(always)]
pub(super) fn body_rotation<T: Real>(
    e3: T::Mask,
    pi: [T; 3],
    psi: [T; 2],
    plain: &mut T::Mask,
) -> [[T; 3]; 3] {
    let c = T::splat;
    let b0 = T::select(e3, pi[0], pi[2]);
    let b1 = T::select(e3, pi[1], -pi[1]);
    let b2 = T::select(e3, pi[2], pi[0]);
    let rho = T::norm2(b0, b1, plain);
    let r = T::norm2(rho, b2, plain);
    let flat = rho.equal(c(0.0)); // θ = 0 or π: φ = atan2(0, 0) = 0
    let phi = [
        T::select(flat, c(0.0), b0 / rho),
        T::select(flat, c(1.0), b1 / rho),
    ];
    zxz_matrix_sc(psi, [rho / r, b2 / r], phi)
}

/// The invariable frame `P0 = Q0 Bᵀ R0ᵀ` of the motion whose body momentum at t = 0 is `pi0`
/// (`R0` its [`body_rotation`] at ψ = 0, `B` the relabelling about e1), so that
/// `Q(t) = P0 Rzxz(ψ, θ, φ) B` starts at `Q(0) = q0` with `ψ(0) = 0`. Generic over [`Real`]
/// (the closed form's derivatives run it on dual numbers, [`super::ExactTangent`]).
#[inline(always)]
pub(super) fn invariable_frame<T: Real<Mask = bool>>(
    e3: bool,
    pi0: [T; 3],
    q0: &Mat3,
) -> [[T; 3]; 3] {
    invariable_frame_with(e3, pi0, |r, k| T::splat(q0[r][k]), &mut true)
}

/// [`invariable_frame`] with `Q(0)`'s entries `q0(row, column)` and the pole `e3` per lane:
/// the form the free flows in lanes take, `plain` as [`body_rotation`]'s.
#[inline(always)]
pub(super) fn invariable_frame_with<T: Real>(
    e3: T::Mask,
    pi0: [T; 3],
    q0: impl Fn(usize, usize) -> T,
    plain: &mut T::Mask,
) -> [[T; 3]; 3] {
    let c = T::splat;
    let r0 = body_rotation(e3, pi0, [c(0.0), c(1.0)], plain);
    let mut p0 = [[c(0.0); 3]; 3];
    for (r, row) in p0.iter_mut().enumerate() {
        // about e1, Q0 Bᵀ: Bᵀ = B = [[0, 0, 1], [0, −1, 0], [1, 0, 0]]
        let qb = [
            T::select(e3, q0(r, 0), q0(r, 2)),
            T::select(e3, q0(r, 1), -q0(r, 1)),
            T::select(e3, q0(r, 2), q0(r, 0)),
        ];
        for (k, x) in row.iter_mut().enumerate() {
            *x = qb[0] * r0[k][0] + qb[1] * r0[k][1] + qb[2] * r0[k][2];
        }
    }
    p0
}

/// ψ's terms of an elliptic motion about the pole e3 (`e3`) or e1 from the sorted `moments`,
/// `a = |L|` and the rate `λ`: `(I_p, I_q, n, a (I_p − I_q)/(I_p I_q λ))`, the characteristic
/// `n = −I3 (I2 − I1)/(I1 (I3 − I2))` (pole e3; `−I1 (I3 − I2)/(I3 (I2 − I1))` about e1) of
/// `ψ = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]`. Generic over [`Real`].
#[inline(always)]
pub(super) fn psi_terms<T: Real>(e3: bool, moments: [T; 3], a: T, lam: T) -> (T, T, T, T) {
    let [i1, i2, i3] = moments;
    let (ip, iq, n) = if e3 {
        (i3, i1, -i3 * (i2 - i1) / (i1 * (i3 - i2)))
    } else {
        (i1, i3, -i1 * (i3 - i2) / (i3 * (i2 - i1)))
    };
    (ip, iq, n, a * (ip - iq) / (ip * iq * lam))
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
    /// `Π(u0) = ∫₀^u0 du/(1 − n sn² u)` on the separatrix and where `m1 <` [`TINY_M1`]
    /// (their forms, [`third_kind_u`]); elsewhere `Π(u0) − u0`, the part beyond the first
    /// kind ([`third_kind_excess_reduced`]: `ψ = a t/I_q + a (I_p − I_q)/(I_p I_q λ)
    /// [(Π(u) − u) − (Π(u0) − u0)]`, with `u − u0 = λt` taken exactly).
    pub pi_u0: f64,
    /// `Π(n|m) − K(m)` ([`ellippi_excess_complete`]; zero on the separatrix and where
    /// `m1 <` [`TINY_M1`]).
    pub pi_complete: f64,
    /// `ψ`'s factor of `Π(u) − Π(u0)`: `a (I_p − I_q)/(I_p I_q λ)`.
    pub psi_pi: f64,
}

/// Whether the attitude of an elliptic regime takes `Π(u)` from the reduction ω(t) made
/// ([`third_kind_excess_reduced`], in lanes too): off the separatrix and `m1 ≥` [`TINY_M1`] (below,
/// [`third_kind_u`]'s separatrix forms).
#[inline(always)]
pub(super) fn reduced_third_kind(reg: &Regime) -> bool {
    reg.m1 >= TINY_M1 && reg.quarter.is_finite()
}

impl AttitudeSetup {
    /// The attitude setup of the motion from `w` with regime `reg` and `Q(0) = q0` (sorted
    /// principal frame → space). All zeros outside the elliptic cases.
    pub fn new(moments: Vec3, reg: &Regime, w: Vec3, q0: &Mat3) -> AttitudeSetup {
        if !reg.is_elliptic() {
            return AttitudeSetup::default();
        }
        let mut att = AttitudeSetup::frame(moments, reg, w, q0);
        att.pi_u0 = if reduced_third_kind(reg) {
            att.pi_complete = ellippi_excess_complete(att.n, reg.m, reg.m1, reg.quarter);
            // Π(u0) − u0 by the very route of every later time, so that ψ(0) = 0 exactly
            let red = jacobi_reduced_with(reg.u0, reg.m, reg.m1, reg.quarter, &reg.agm);
            EllipticMotion::of(reg, &att).third_kind(red)
        } else {
            third_kind_u(att.n, reg.u0, reg.m, reg.m1, reg.quarter)
        };
        att
    }

    /// [`AttitudeSetup::new`] without its third-kind integrals (`Π(u0)` and `Π(n|m)` left
    /// zero): the invariable frame `p0`, `n`, `I_p`, `I_q` and ψ's factor of an elliptic
    /// regime, the part every start of a motion needs ([`ThirdKindStart`] takes the rest).
    #[inline(always)]
    pub fn frame(moments: Vec3, reg: &Regime, w: Vec3, q0: &Mat3) -> AttitudeSetup {
        let e3 = reg.pole == 2;
        let pi0 = [moments[0] * w[0], moments[1] * w[1], moments[2] * w[2]];
        let (ip, iq, n, psi_pi) = psi_terms(e3, moments, reg.momentum, reg.lam);
        AttitudeSetup {
            p0: invariable_frame(e3, pi0, q0),
            n,
            i_pole: ip,
            i_other: iq,
            pi_u0: 0.0,
            pi_complete: 0.0,
            psi_pi,
        }
    }
}

/// `Π(u) − Π(u0)` of an elliptic motion less its first-kind part `u − u0 = λt`, from the
/// reductions of `u` and `u0` (the exact-flow splitting's free flow,
/// [`crate::exact_splitting::FreeFlow`]; `docs/theory.md` §5): with `u = 2pK + v`,
/// `u0 = 2p0 K + v0` (|v|, |v0| ≤ K), `Π = 2pΠ(n|m) + G(v)` and `G(v) = v + X(v)` (DLMF
/// 19.25.14: the first-kind part of `G`, `s R_F(c², d², 1)`, is `v` itself;
/// [`third_kind_excess`]), so
/// `Π(u) − Π(u0) − λt = X(v) − X(v0) + 2(p − p0) (Π(n|m) − K)`.
/// The first-kind part is never evaluated: ψ takes it as `λt`, exactly, where its difference
/// `v − v0` of rounded arguments, times ψ's factor `1/λ`, had lost digits as `λ → 0` (a
/// nearly symmetric body about its middle axis: 2e-10 in Q at `I2 − I1 = 1e-11`). `X(v0)`
/// comes from the start's own Jacobi functions, `(sn, cn, dn)(u0) = ω_i/(σ_i α_i)` (no
/// reduction of `u0`), and `Π(n|m) − K` only once `p ≠ p0` (a short flow stays in its half
/// period and never needs it).
#[derive(Clone, Copy, Debug)]
pub struct ThirdKindStart {
    /// `X(v0)` and `p0`.
    x0: f64,
    p0: f64,
    /// `Π(n|m) − K`, once needed.
    pi_complete: Option<f64>,
}

impl ThirdKindStart {
    /// The start of the motion from `w` with regime `reg` and frame `att`
    /// ([`AttitudeSetup::frame`]); `None` where the attitude does not take `Π(u)` from the
    /// reduction (outside the elliptic cases, on the separatrix, `m1 <` [`TINY_M1`]).
    #[inline(always)]
    pub fn new(reg: &Regime, att: &AttitudeSetup, w: Vec3) -> Option<ThirdKindStart> {
        if !(reg.is_elliptic() && reduced_third_kind(reg)) {
            return None;
        }
        // ω = (σ1 α1 cn, σ2 α2 sn, σ3 α3 dn) about e3, (dn, sn, cn) about e1
        let f = |i: usize| w[i] / (reg.signs[i] * reg.alpha[i]);
        let (sn, cn, dn) = if reg.pole == 2 {
            (f(1), f(0), f(2))
        } else {
            (f(1), f(2), f(0))
        };
        // `u0 = 2 p0 K + v0` as `reduce_quarter` splits an argument
        let two_k = 2.0 * reg.quarter;
        let p0 = (reg.u0 / two_k).round_ties_even();
        let par = parity(p0);
        Some(ThirdKindStart {
            x0: third_kind_excess(att.n, par * sn, par * cn, dn),
            p0,
            pi_complete: None,
        })
    }

    /// `Π(u) − Π(u0) − λt` from the reduction `(sn u, cn u, dn u, p)` of `u`
    /// ([`jacobi_reduced_with`]).
    #[inline(always)]
    fn difference(&mut self, reg: &Regime, n: f64, sn: f64, cn: f64, dn: f64, p: f64) -> f64 {
        let par = parity(p);
        let g = third_kind_excess(n, par * sn, par * cn, dn) - self.x0;
        if p == self.p0 {
            return g;
        }
        let pc = *self
            .pi_complete
            .get_or_insert_with(|| ellippi_excess_complete(n, reg.m, reg.m1, reg.quarter));
        g + 2.0 * (p - self.p0) * pc
    }
}

/// `(ω(t), Q(t))` of the elliptic motion from `ω(0) = w` ([`motion_at`]'s values to
/// round-off) with `Π(u) − Π(u0)` by [`ThirdKindStart`]: one reduction of `u = u0 + λt`
/// for ω and Π, and no `Π(u0)` or `Π(n|m)` made up front (eqs (20)–(33)).
#[inline(always)]
pub fn motion_from_start(
    moments: Vec3,
    reg: &Regime,
    att: &AttitudeSetup,
    start: &mut ThirdKindStart,
    t: f64,
) -> (Vec3, Mat3) {
    let u = reg.u0 + reg.lam * t;
    let (sn, cn, dn, p, _) = jacobi_reduced_with(u, reg.m, reg.m1, reg.quarter, &reg.agm);
    let motion = EllipticMotion::of(reg, att);
    let omega = jacobi_omega(reg.pole == 2, motion.sa, sn, cn, dn);
    let excess = start.difference(reg, att.n, sn, cn, dn, p);
    (
        omega,
        motion.attitude_with_excess(moments, t, omega, excess, &mut true),
    )
}

/// What `Q(t)` of an elliptic motion needs at each time beyond the reduction of `u = u0 + λt`
/// (see the module docs), generic over [`Real`]: one motion (`f64`, [`attitude_at`]) or one
/// per lane ([`exact_attitudes`](super::exact_attitudes)), each lane bit for bit its single
/// run.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct EllipticMotion<T: Real> {
    /// The signed amplitudes `σ_i α_i` and the pole (e3 where set).
    pub(super) sa: [T; 3],
    pub(super) e3: T::Mask,
    /// [`AttitudeSetup`]'s `n`, `Π(n|m) − K`, `Π(u0) − u0`, ψ's factor; `a`, `I_q`; the
    /// invariable frame.
    pub(super) n: T,
    pub(super) pi_complete: T,
    pub(super) pi_u0: T,
    pub(super) psi_pi: T,
    pub(super) momentum: T,
    pub(super) i_other: T,
    pub(super) p0: [[T; 3]; 3],
}

impl EllipticMotion<f64> {
    pub(super) fn of(reg: &Regime, att: &AttitudeSetup) -> EllipticMotion<f64> {
        EllipticMotion {
            sa: [0, 1, 2].map(|i| reg.signs[i] * reg.alpha[i]),
            e3: reg.pole == 2,
            n: att.n,
            pi_complete: att.pi_complete,
            pi_u0: att.pi_u0,
            psi_pi: att.psi_pi,
            momentum: reg.momentum,
            i_other: att.i_other,
            p0: att.p0,
        }
    }
}

impl<const N: usize> EllipticMotion<Wide<N>> {
    /// Lane `l` holds `motions[l]`.
    #[inline(always)]
    pub(super) fn gather(motions: &[EllipticMotion<f64>; N]) -> EllipticMotion<Wide<N>> {
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
            i_other: wide(&|m| m.i_other),
            p0: [0, 1, 2].map(|r| [0, 1, 2].map(|c| wide(&|m| m.p0[r][c]))),
        }
    }
}

impl<T: Real> EllipticMotion<T> {
    /// `Π(u) − u`, `Π(u) = ∫₀^u du/(1 − n sn² u)`, from the reduction `(sn u, cn u, dn u, p,
    /// v)` of `u = 2pK + v` ([`third_kind_excess_reduced`] on `sn v = (−1)^p sn u`,
    /// `cn v = (−1)^p cn u`).
    #[inline(always)]
    fn third_kind(&self, (sn, cn, dn, p, _): (T, T, T, T, T)) -> T {
        let par = parity(p);
        third_kind_excess_reduced(self.n, par * sn, par * cn, dn, p, self.pi_complete)
    }

    /// `Q(t)` (sorted principal frame → space) from the reduction `(sn, cn, dn, p, v)` of
    /// `u = u0 + λt`: ω(t) in the Jacobi form, the angles θ, φ of the body momentum `π = Iω`
    /// (relabelled `(π3, −π2, π1)` about e1) as ratios, `cos θ = π_p/a`,
    /// `tan φ = π_1'/π_2'`, and `ψ = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]`
    /// as `a t/I_q + a (I_p − I_q)/(I_p I_q λ) [(Π(u) − u) − (Π(u0) − u0)]`
    /// ([`EllipticMotion::attitude_with_excess`]): `Q = P0 Rzxz(ψ, θ, φ)` (columns relabelled
    /// back about e1). `plain` is cleared in the lanes whose sums of squares `f64` would take
    /// by `hypot` ([`Real::norm2`]).
    #[inline(always)]
    pub(super) fn attitude(
        &self,
        moments: Vec3,
        t: T,
        red: (T, T, T, T, T),
        plain: &mut T::Mask,
    ) -> [[T; 3]; 3] {
        let (sn, cn, dn, _, _) = red;
        let w = jacobi_omega(self.e3, self.sa, sn, cn, dn);
        let excess = self.third_kind(red) - self.pi_u0;
        self.attitude_with_excess(moments.map(T::splat), t, w, excess, plain)
    }

    /// [`EllipticMotion::attitude`] from ω(t) `v` (the Jacobi form) and
    /// `(Π(u) − u) − (Π(u0) − u0)` `excess`: `ψ = a t/I_q + a (I_p − I_q)/(I_p I_q λ) excess`,
    /// the first-kind part `a (I_p − I_q)/(I_p I_q λ) (u − u0)` of ψ's integral joined to
    /// `a t/I_p` exactly (`u − u0 = λt`).
    #[inline(always)]
    pub(super) fn attitude_with_excess(
        &self,
        moments: [T; 3],
        t: T,
        v: [T; 3],
        excess: T,
        plain: &mut T::Mask,
    ) -> [[T; 3]; 3] {
        let psi = self.momentum * t / self.i_other + self.psi_pi * excess;
        self.attitude_with_psi(moments, v, psi, plain)
    }

    /// `Q = P0 Rzxz(ψ, θ, φ)` from ω(t) `v` (the Jacobi form) and ψ.
    #[inline(always)]
    pub(super) fn attitude_with_psi(
        &self,
        moments: [T; 3],
        v: [T; 3],
        psi: T,
        plain: &mut T::Mask,
    ) -> [[T; 3]; 3] {
        let c = T::splat;
        let pi = [moments[0] * v[0], moments[1] * v[1], moments[2] * v[2]];
        let (sps, cps) = sin_cos(psi);
        let rot = body_rotation(self.e3, pi, [sps, cps], plain);
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

/// `Q(t) = exp(t L̂/I⊥) Q0 exp(ν t ê_s)`, `L = Q0 π0` in space: the attitude of a symmetric
/// body (symmetry axis `s`, transverse moment `i_perp`, `ν = (1/I_s − 1/I⊥) π_s`; eqs
/// (22)–(23)) from `Q(0) = q0` and the body momentum `pi`. Generic over [`Real`] (the
/// exact-flow splittings' derivatives run it on dual numbers).
#[inline]
pub fn precession_attitude<T: Real>(
    s: usize,
    i_perp: T,
    nu: T,
    pi: [T; 3],
    q0: &[[T; 3]; 3],
    t: T,
) -> [[T; 3]; 3] {
    let f = t / i_perp;
    let l = q0.map(|row| f * (row[0] * pi[0] + row[1] * pi[1] + row[2] * pi[2]));
    let r = exp_so3(l);
    // R Q0, then the body turn about e_s: columns (s+1, s+2) rotated by ν t
    let mut out = [[T::splat(0.0); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = r[i][0] * q0[0][j] + r[i][1] * q0[1][j] + r[i][2] * q0[2][j];
        }
    }
    let (sn, cs) = (nu * t).sin_cos_std();
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

/// `Q(t) = Q0 exp(Ω t)`: the attitude at a fixed point of Euler's equation, where ω is constant
/// (eqs (22)–(23)), by Rodrigues' formula ([`exp_so3`]). Beyond the angle where `exp_so3`'s
/// fast reduction of its sine and cosine stops being exact (`2²⁰ π/2`: a slow spin at
/// t = 10¹⁰, which double precision still resolves), Rodrigues' formula on the unit axis with
/// the standard library's sine and cosine: the true rotation, not only a rotation.
#[inline]
pub fn fixed_point_attitude(q0: &Mat3, w: Vec3, t: f64) -> Mat3 {
    let v = [t * w[0], t * w[1], t * w[2]];
    let theta = v[0].hypot(v[1]).hypot(v[2]);
    if !(theta > WIDE_ANGLE && theta.is_finite()) {
        return matmul(q0, &exp_so3(v));
    }
    let n = [v[0] / theta, v[1] / theta, v[2] / theta];
    let (s, c) = theta.sin_cos();
    let b = 1.0 - c;
    // I + sin θ N + (1 − cos θ) N², N = hat(n), N² = n nᵀ − I
    let r = [
        [
            1.0 + b * (n[0] * n[0] - 1.0),
            b * n[0] * n[1] - s * n[2],
            b * n[0] * n[2] + s * n[1],
        ],
        [
            b * n[0] * n[1] + s * n[2],
            1.0 + b * (n[1] * n[1] - 1.0),
            b * n[1] * n[2] - s * n[0],
        ],
        [
            b * n[0] * n[2] - s * n[1],
            b * n[1] * n[2] + s * n[0],
            1.0 + b * (n[2] * n[2] - 1.0),
        ],
    ];
    matmul(q0, &r)
}

/// `2²⁰ π/2`: beyond it [`crate::real::sin_cos`]'s three-part reduction loses digits.
const WIDE_ANGLE: f64 = 1_647_099.329_165_285_5;

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
            let pi = [moments[0] * w[0], moments[1] * w[1], moments[2] * w[2]];
            precession_attitude(reg.axis as usize, reg.i_perp, reg.nu, pi, q0, t)
        }
        _ if reduced_third_kind(reg) => {
            // the reduction of u that ω(t) makes ([`Regime::omega_at`]), shared with Π(u)
            let u = reg.u0 + reg.lam * t;
            let red = jacobi_reduced_with(u, reg.m, reg.m1, reg.quarter, &reg.agm);
            EllipticMotion::of(reg, att).attitude(moments, t, red, &mut true)
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

/// `(ω(t), Q(t))` of the motion from `ω(0) = w`, `Q(0) = q0`: [`Regime::omega_at`] and
/// [`attitude_at`] at once, the elliptic cases reducing `u = u0 + λt` once for both (the
/// exact-flow splittings' free flow, [`crate::exact_splitting::FreeFlow`]). Bit for bit the
/// two functions' values.
pub fn motion_at(
    moments: Vec3,
    reg: &Regime,
    att: &AttitudeSetup,
    w: Vec3,
    q0: &Mat3,
    t: f64,
) -> (Vec3, Mat3) {
    if reg.is_elliptic() && reduced_third_kind(reg) {
        let u = reg.u0 + reg.lam * t;
        let red = jacobi_reduced_with(u, reg.m, reg.m1, reg.quarter, &reg.agm);
        let (sn, cn, dn, _, _) = red;
        let motion = EllipticMotion::of(reg, att);
        let omega = jacobi_omega(reg.pole == 2, motion.sa, sn, cn, dn);
        (omega, motion.attitude(moments, t, red, &mut true))
    } else {
        (
            reg.omega_at(moments, w, t),
            attitude_at(moments, reg, att, w, q0, t),
        )
    }
}
