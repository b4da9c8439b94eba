//! Exact derivatives of the torque-free closed form (`docs/tutorials/sensitivities.md`):
//! `∂ω(t)/∂(I, ω0)`, `∂Q(t)/∂(I, ω0)`, and those of the period `4K(m)/λ` and the flip interval
//! `2K(m)/λ`, for a body with three distinct moments off the fixed points and the separatrix.
//!
//! The regime's algebra — the scaling, the polhode radii, the Jacobi form's amplitudes `α`,
//! rate `λ`, parameter `m` and the point `(sn u0, cn u0)` — is the engine's own
//! ([`Radicals::of`], [`polhode_radii`], [`JacobiForm::new`]), run on dual numbers
//! ([`Dual`]) seeded with the three sorted moments and the three components of ω0. The
//! elliptic functions carry their known derivatives (DLMF 22.13.1–3 in `u`; in `m` through
//! the amplitude, `∂am(u|m)/∂m = −dn · ∂F(φ|m)/∂m` at fixed `u`, with
//! `∂F(φ|m)/∂m = (sin³φ/6) R_D(cos²φ, 1, 1 − m sin²φ)` on `|φ| ≤ π/2` (differentiating
//! `F = sin φ R_F(cos²φ, 1 − m sin²φ, 1)`, DLMF 19.25.5 and `∂R_F/∂z = −R_D/6`), and
//! `F(φ + nπ) = F(φ) + 2nK`, `∂K/∂m = R_D(0, 1, m1)/6`). Carlson's forms have no
//! cancellation as `m → 0` or `m → 1`, so the derivatives stay accurate near the separatrix,
//! where they grow as `1/m1`.
//!
//! The attitude `Q(t) = P0 Rzxz(ψ, θ, φ) B` is the engine's own formula
//! ([`EllipticMotion::attitude_with_excess`], [`invariable_frame`], [`psi_terms`]) on the
//! same dual numbers: θ and φ from `π = Iω`, and
//! `ψ = a t/I_q + a (I_p − I_q)/(I_p I_q λ) [(Π(u) − u) − (Π(u0) − u0)]` (the first-kind part
//! `u − u0 = λt` joined to `a t/I_p` exactly; where `|n| > 1`, `ψ = a t/I_p + a (I_p − I_q)/
//! (I_p I_q λ) [Π(u) − Π(u0)]` whole, [`third_kind_from_roots`]) with
//! `Π(u) − u = 2p(Π(n|m) − K) + X(v)`
//! differentiated through Carlson's duplication itself ([`third_kind_excess_from_roots`],
//! whose first step takes `cn v` and `dn v` as they are, so that `cn v = 0` keeps its
//! derivative; `R_C(1, 1 + e)` by its series where `e` is small, so that its derivative does
//! not cancel).

use super::attitude::{invariable_frame, psi_terms, EllipticMotion};
use super::{jacobi_omega, polhode_radii, JacobiForm, Radicals, Regime, AROUND_E1, AROUND_E3};
use crate::cmath::{frexp, ldexp};
use crate::dual::Dual;
use crate::elliptic::{
    carlson_rj, first_kind_dm_reduced, jacobi_dual, parity, third_kind_excess_from_roots,
    third_kind_from_roots, OnDuals,
};
use crate::real::Real;
use crate::so3::{Mat3, Vec3};

/// The directions: the three sorted moments, then the three components of ω0 (sorted frame).
pub const DIRECTIONS: usize = 6;

type D = Dual<DIRECTIONS>;

/// A torque-free motion with the derivatives of its Jacobi form: what [`ExactTangent::omega_at`],
/// [`ExactTangent::period`] and [`ExactTangent::flip_interval`] differentiate.
#[derive(Clone, Copy, Debug)]
pub struct ExactTangent {
    regime: Regime,
    /// `λ`, `m`, `u0` and `K(m)` with their derivatives (the amplitudes `σ_i α_i` are the
    /// attitude's, `motion.sa`); `u0`'s leave out the `2 n0 ∂K/∂m` of its half period `n0`,
    /// and every later `u` counts its half periods from `n0` ([`jacobi_dual`]'s `carried`).
    lam: D,
    m: D,
    u0: D,
    n0: f64,
    quarter: D,
    /// `∂K/∂m`.
    k_m: f64,
    /// The sorted moments and `π0 = I ω0`, seeded; the attitude's terms (`n`, `Π(n|m)`,
    /// `Π(u0)`, ψ's factor, `a`, `I_p`), the invariable frame left to each `Q0`.
    moments: [D; 3],
    pi0: [D; 3],
    motion: EllipticMotion<D>,
    /// ψ takes `Π(u) − Π(u0)` whole (`|n| > 1`), with `I_p`: its first-kind part `λt` is
    /// then not split off, as where `n` is small ([`EllipticMotion::attitude_with_excess`]):
    /// near the intermediate axis (`n = −3` for moments 1, 2, 3) that split cost ∂Q/∂ω⊥ a
    /// few ulps more than mpmath's derivatives allow (1.1e-12 at ω⊥ = 1e-3).
    whole: bool,
    i_pole: D,
}

impl ExactTangent {
    /// The motion from `ω(0) = w` (sorted principal frame) of a body with the sorted moments
    /// `moments`, three distinct: an error where the closed form has no derivatives here
    /// (a fixed point, the separatrix itself, two equal moments).
    pub fn new(moments: Vec3, w: Vec3) -> Result<ExactTangent, &'static str> {
        if !(moments[0] < moments[1] && moments[1] < moments[2]) {
            return Err("the derivatives of the closed form need three distinct moments");
        }
        let regime = Regime::new(moments, 0, w);
        if !matches!(regime.case, AROUND_E1 | AROUND_E3) {
            return Err(
                "the motion is a fixed point or on the separatrix, where the closed \
                        form's period is not differentiable",
            );
        }
        let seed = |v: f64, j: usize| {
            let mut d = [0.0; DIRECTIONS];
            d[j] = 1.0;
            Dual::new(v, d)
        };
        let im = [0, 1, 2].map(|i| seed(moments[i], i));
        let big = w[0].abs().max(w[1].abs()).max(w[2].abs());
        let e = frexp(big).1;
        let sc = D::splat(ldexp(1.0, -e));
        let x = [0, 1, 2].map(|i| seed(w[i], 3 + i) * sc);
        let radicals = Radicals::of(im);
        let (q3, q1) = polhode_radii(&radicals, x, &mut true);
        let f = JacobiForm::new(im, &radicals, x, q3, q1);
        let up = D::splat(ldexp(1.0, e));
        let alpha = f.alpha.map(|a| a * up);
        let lam = f.lam * up;
        // m's derivatives are m1's, negated: m1 comes from the separatrix distance
        // a² − 2k I2, whose derivatives are formed without cancellation, where `m` itself,
        // a ratio within m1 of 1, had its derivatives cancel to ε/√m1 (6e-11 of the period's
        // gradient at 1e-6 from the intermediate axis)
        let m = Dual::new(f.m.v, f.m1.d.map(|x| -x));
        // K(m) and u0 = F(φ0 | m), φ0 = am u0 from (sn u0, cn u0) as the form gives them
        let k_m = carlson_rj(0.0, 1.0, regime.m1, regime.m1) / 6.0;
        let quarter = Dual::new(regime.quarter, m.d.map(|x| k_m * x));
        let a_cn = if f.e3 { f.alpha[0] } else { f.alpha[2] };
        let (sn0, cn0) = (f.sn0 / f.alpha[1], f.cn0 / a_cn);
        // dn² = 1 − m sn² as m1 + m cn²: two positive terms. Near the intermediate axis
        // (sn → 1, m → 1) the difference had cancelled to ε/dn² relative, and `u0`'s
        // derivative `dφ/dn` with it (4e-9 at ω⊥ = 1e-4, 5e-6 at 1e-6; every flow of an
        // exact splitting's sensitivities paid it again)
        let dn0 = (regime.m1 + regime.m * cn0.v * cn0.v).sqrt();
        let n0 = (regime.u0 / (2.0 * regime.quarter)).round();
        // within u0's half period n0: its 2 n0 ∂K/∂m is carried by `jacobi_at` and
        // `third_kind` as a count (`n0`), not in the derivatives
        let f_m = first_kind_dm_reduced(sn0.v, cn0.v, dn0, n0);
        let mut u0 = Dual::new(regime.u0, [0.0; DIRECTIONS]);
        for j in 0..DIRECTIONS {
            let dphi = cn0.v * sn0.d[j] - sn0.v * cn0.d[j];
            u0.d[j] = dphi / dn0 + f_m * m.d[j];
        }
        let s2 = f.s1 * f.s3;
        let sa = [f.s1 * alpha[0], s2 * alpha[1], f.s3 * alpha[2]];
        // the attitude's terms: a = |π0|, n, ψ's factor, Π(n|m) = G at v = K (s = 1, c = 0,
        // d = √m1, m1 = 1 − m carrying −∂m)
        let pi0 = [0, 1, 2].map(|i| im[i] * seed(w[i], 3 + i));
        let a = D::norm2(D::norm2(pi0[0], pi0[1], &mut true), pi0[2], &mut true);
        let e3 = regime.pole == 2;
        let (ip, iq, n, psi_pi) = psi_terms(e3, im, a, lam);
        let m1 = Dual::new(regime.m1, m.d.map(|x| -x));
        // Π(n|m), or Π(n|m) − K where ψ splits off the first-kind part: G or X at v = K
        let whole = n.v.abs() > 1.0;
        let (one, zero) = (D::splat(1.0), D::splat(0.0));
        let pi_complete = if whole {
            third_kind_from_roots::<_, OnDuals>(n, one, zero, m1.sqrt())
        } else {
            third_kind_excess_from_roots::<_, OnDuals>(n, one, zero, m1.sqrt())
        };
        let motion = EllipticMotion {
            sa,
            e3,
            n,
            pi_complete,
            pi_u0: D::splat(0.0),
            psi_pi,
            momentum: a,
            i_other: iq,
            p0: [[D::splat(0.0); 3]; 3],
        };
        let mut tangent = ExactTangent {
            regime,
            lam,
            m,
            u0,
            n0,
            quarter,
            k_m,
            moments: im,
            pi0,
            motion,
            whole,
            i_pole: ip,
        };
        // Π(u0) (− u0) by the route of every later time, so that ψ(0) and its derivatives are 0
        tangent.motion.pi_u0 = tangent.third_kind(tangent.jacobi_at(0.0));
        Ok(tangent)
    }

    /// `(sn u, cn u, dn u)` of `u = u0 + λt` with their derivatives, and the reduction's `p`
    /// ([`jacobi_dual`]).
    fn jacobi_at(&self, t: f64) -> (D, D, D, f64) {
        let reg = &self.regime;
        let u = self.u0 + self.lam * D::splat(t);
        jacobi_dual(u, self.m, reg.m1, reg.quarter, self.k_m, &reg.agm, self.n0)
    }

    /// `Π(u) − u − 2 n0 (Π(n|m) − K) = 2(p − n0)(Π(n|m) − K) + X(v)` with its derivatives
    /// (where [`ExactTangent::whole`], `Π(u) − 2 n0 Π(n|m) = 2(p − n0)Π(n|m) + G(v)`), from
    /// [`ExactTangent::jacobi_at`]: `X` (`G`) on `sn v = (−1)^p sn u`, `cn v = (−1)^p cn u ≥ 0`,
    /// `dn v = dn u`. The `2 n0 (Π(n|m) − K)` that `u` and `u0` share is left out of both
    /// (near the separatrix its derivative, `~ 1/m1`, had cancelled in their difference).
    fn third_kind(&self, (sn, cn, dn, p): (D, D, D, f64)) -> D {
        let par = D::splat(parity(p));
        let (n, s, c) = (self.motion.n, par * sn, par * cn);
        let g = if self.whole {
            third_kind_from_roots::<_, OnDuals>(n, s, c, dn)
        } else {
            third_kind_excess_from_roots::<_, OnDuals>(n, s, c, dn)
        };
        if p == self.n0 {
            g
        } else {
            g + D::splat(2.0 * (p - self.n0)) * self.motion.pi_complete
        }
    }

    /// `Q(t)` (sorted principal frame → space) of the motion from `Q(0) = q0`, and
    /// `∂Q_rc(t)/∂p_j` (the directions last): the engine's attitude on dual numbers (see the
    /// module docs).
    pub fn attitude_at(&self, q0: &Mat3, t: f64) -> (Mat3, [[[f64; DIRECTIONS]; 3]; 3]) {
        let jac = self.jacobi_at(t);
        let (sn, cn, dn, _) = jac;
        let mut motion = self.motion;
        motion.p0 = invariable_frame(motion.e3, self.pi0, q0);
        let v = jacobi_omega(motion.e3, motion.sa, sn, cn, dn);
        let part = self.third_kind(jac) - motion.pi_u0;
        let t = D::splat(t);
        let x = if self.whole {
            let psi = motion.momentum * t / self.i_pole + motion.psi_pi * part;
            motion.attitude_with_psi(self.moments, v, psi, &mut true)
        } else {
            motion.attitude_with_excess(self.moments, t, v, part, &mut true)
        };
        (x.map(|r| r.map(|e| e.v)), x.map(|r| r.map(|e| e.d)))
    }

    /// `ω(t)` (sorted principal frame) and `∂ω_i(t)/∂p_j` (rows `i`, the directions `j`).
    pub fn omega_at(&self, t: f64) -> (Vec3, [[f64; DIRECTIONS]; 3]) {
        let (sn, cn, dn, _) = self.jacobi_at(t);
        let w = jacobi_omega(self.motion.e3, self.motion.sa, sn, cn, dn);
        (w.map(|x| x.v), w.map(|x| x.d))
    }

    /// The period of ω, `4K(m)/λ`, and its derivatives.
    pub fn period(&self) -> Dual<DIRECTIONS> {
        D::splat(4.0) * self.quarter / self.lam
    }

    /// The flip interval (between sign changes of ω2), `2K(m)/λ`, and its derivatives.
    pub fn flip_interval(&self) -> Dual<DIRECTIONS> {
        D::splat(2.0) * self.quarter / self.lam
    }
}
