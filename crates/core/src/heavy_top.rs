//! The heavy symmetric top (Lagrange's top) in closed form (`docs/theory.md` §6, "The heavy
//! symmetric top"; Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed., §5.7; Whittaker,
//! *Analytical Dynamics*, §71; Landau & Lifshitz, *Mechanics*, §35).
//!
//! A symmetric body (moments `A`, `A`, `C` about the tip) turns about a fixed tip on its axis
//! under gravity (`M g l`). In z-x-z Euler angles of the axis frame relative to a space frame
//! with z up (ψ precession, θ nutation, φ spin), the spin `ω₃ = φ̇ + ψ̇ cos θ`, the vertical
//! momentum `L_z = A ψ̇ sin²θ + C ω₃ cos θ` and the energy are constants, and `u = cos θ` obeys
//!
//! ```text
//!     u̇² = f(u) = (α − β u)(1 − u²) − (b − a u)²,                                    (T1)
//!     a = C ω₃ / A,  b = L_z / A,  β = 2 M g l / A,  α = β u₀ + θ̇₀² + ψ̇₀² sin²θ₀.
//! ```
//!
//! `f` is a cubic with roots `u₁ ≤ u₀ ≤ u₂ ≤ 1 ≤ u₃`; with `m = (u₂ − u₁)/(u₃ − u₁)` and
//! `λ = √(β (u₃ − u₁)) / 2`,
//!
//! ```text
//!     u(t) = u₁ + (u₂ − u₁) sn²(τ | m),   τ = τ₀ + λ t,                                (T2)
//!     ψ(t) = ψ₀ + (b − a)/(2 (1 − u₁) λ) ΔΠ(n₊) + (b + a)/(2 (1 + u₁) λ) ΔΠ(n₋),         (T3)
//!     φ(t) = φ₀ + (ω₃ − a) t − (b − a)/(2 (1 − u₁) λ) ΔΠ(n₊) + (b + a)/(2 (1 + u₁) λ) ΔΠ(n₋),
//! ```
//!
//! `ΔΠ(n) = Π(n; am τ | m) − Π(n; am τ₀ | m)`, `n₊ = (u₂ − u₁)/(1 − u₁)`,
//! `n₋ = −(u₂ − u₁)/(1 + u₁)` (from `ψ̇ = (b − a u)/(1 − u²)` and `φ̇ = ω₃ − ψ̇ u` by partial
//! fractions). The nutation period is `2K(m)/λ`; over it ψ advances by
//! `(b − a)/((1 − u₁) λ) Π(n₊|m) + (b + a)/((1 + u₁) λ) Π(n₋|m)`, the mean precession rate
//! times the period.
//!
//! The roots are found about `u₀` (`x = u − u₀`, the cubic's Taylor coefficients from the
//! initial rates, so a small nutation keeps its digits): the largest `x₃ ≥ 1 − u₀` by
//! bisection and Newton, then `x₁ ≤ 0 ≤ x₂` from the deflated quadratic, polished by Newton.
//! Without nutation (`u₁ = u₂`: steady precession, a sleeping top) θ is constant and ψ, φ
//! turn uniformly.

use crate::elliptic::{
    ellipk_m1, ellippi, ellippi_complete, first_kind_from_sn_cn, jacobi_reduced,
};

/// Everything the closed form needs of one motion, made once ([`TopMotion::new`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TopMotion {
    /// The initial angles `(ψ₀, θ₀, φ₀)`.
    pub angles0: [f64; 3],
    /// `u₀ = cos θ₀` and the roots `u₁ ≤ u₂ ≤ u₃` of (T1) as offsets from `u₀`.
    pub u0: f64,
    pub x: [f64; 3],
    /// `a = C ω₃ / A`, `w = b − a u₀ = ψ̇₀ sin²θ₀` (`b = L_z / A`), the spin `ω₃`.
    pub a: f64,
    pub w: f64,
    pub spin: f64,
    /// The parameter `m`, its complement, `λ`, `K(m)`, `τ₀`.
    pub m: f64,
    pub m1: f64,
    pub lam: f64,
    pub quarter: f64,
    pub tau0: f64,
    /// `n₊`, `n₋` and the factors of `ΔΠ(n₊)`, `ΔΠ(n₋)` in (T3).
    pub n: [f64; 2],
    pub factor: [f64; 2],
    /// `Π(n; am τ₀ | m)` for `n₊`, `n₋`.
    pub pi0: [f64; 2],
    /// No nutation: θ constant, ψ̇ and φ̇ constant (`rates`).
    pub steady: bool,
    pub rates: [f64; 2],
}

/// The constants and turning points of a motion, as `TopMotion::summary` gives them:
/// `[u₁, u₂, u₃, nutation period, mean precession rate, ω₃, m]`.
pub const SUMMARY_SIZE: usize = 7;

impl TopMotion {
    /// The motion of the top `(A, C, M g l)` from the angles `(ψ₀, θ₀, φ₀)` and their rates
    /// `(ψ̇₀, θ̇₀, φ̇₀)`.
    pub fn new(a_moment: f64, c_moment: f64, mgl: f64, angles: [f64; 3], rates: [f64; 3]) -> Self {
        let [_, th0, _] = angles;
        let [psid, thd, phid] = rates;
        let (s, u0) = th0.sin_cos();
        let s2 = s * s;
        let spin = phid + psid * u0;
        let a = c_moment * spin / a_moment;
        let beta = 2.0 * mgl / a_moment;
        let w = psid * s2; // b − a u₀
        let e = thd * thd + psid * psid * s2; // α − β u₀
                                              // Taylor coefficients of f about u₀: g(x) = q0 + q1 x + q2 x² + β x³
        let q0 = (s * thd) * (s * thd);
        let q1 = -beta * s2 - 2.0 * u0 * e + 2.0 * a * w;
        let q2 = 2.0 * beta * u0 - e - a * a;
        let one_minus_u0 = 2.0 * (0.5 * th0).sin().powi(2);
        let one_plus_u0 = 2.0 * (0.5 * th0).cos().powi(2);
        let [x1, x2, x3] = cubic_roots(beta, [q0, q1, q2], (one_minus_u0, one_plus_u0));
        let mut top = TopMotion {
            angles0: angles,
            u0,
            x: [x1, x2, x3],
            a,
            w,
            spin,
            ..TopMotion::default()
        };
        let width = x2 - x1;
        if !width.is_finite() || width <= 1e-15 * (x3 - x1) {
            top.steady = true;
            top.rates = [psid, phid];
            top.lam = 0.5 * (beta * (x3 - x1)).sqrt();
            return top;
        }
        top.m = width / (x3 - x1);
        top.m1 = (x3 - x2) / (x3 - x1);
        top.lam = 0.5 * (beta * (x3 - x1)).sqrt();
        top.quarter = ellipk_m1(top.m1);
        // sn²τ₀ = −x₁/(x₂ − x₁), cn²τ₀ = x₂/(x₂ − x₁), sn τ₀ of the sign of u̇₀ = −θ̇₀ sin θ₀
        let sn0 = (-x1 / width).sqrt().copysign(-thd * s);
        let cn0 = (x2 / width).sqrt();
        top.tau0 = first_kind_from_sn_cn(sn0, cn0, top.m, top.m1);
        let one_minus_u1 = one_minus_u0 - x1;
        let one_plus_u1 = one_plus_u0 + x1;
        top.n = [width / one_minus_u1, -width / one_plus_u1];
        // b ∓ a = w ∓ a (1 ∓ u₀), without the cancellation of b − a near the vertical
        top.factor = [
            (w - a * one_minus_u0) / (2.0 * one_minus_u1 * top.lam),
            (w + a * one_plus_u0) / (2.0 * one_plus_u1 * top.lam),
        ];
        top.pi0 = [0, 1].map(|k| top.third_kind(k, top.tau0));
        top
    }

    /// `Π(n_k; am τ | m)` ([`ellippi`] at the amplitude `pπ + atan2(sn v, cn v)` of
    /// `τ = 2pK + v`, `|v| ≤ K`).
    fn third_kind(&self, k: usize, tau: f64) -> f64 {
        let (sn, cn, _, p, _) = jacobi_reduced(tau, self.m, self.m1, self.quarter);
        let par = if (p * 0.5).fract() == 0.0 { 1.0 } else { -1.0 };
        let am = p * std::f64::consts::PI + (par * sn).atan2(par * cn);
        ellippi(self.n[k], am, self.m, self.m1)
    }

    /// `[ψ, θ, φ, ψ̇, θ̇, φ̇]` at `t`.
    pub fn at(&self, t: f64) -> [f64; 6] {
        let [psi0, th0, phi0] = self.angles0;
        if self.steady {
            let [psid, phid] = self.rates;
            return [psi0 + psid * t, th0, phi0 + phid * t, psid, 0.0, phid];
        }
        let [x1, x2, _] = self.x;
        let tau = self.tau0 + self.lam * t;
        let (sn, cn, dn, _, _) = jacobi_reduced(tau, self.m, self.m1, self.quarter);
        let width = x2 - x1;
        let x = x1 + width * sn * sn; // u − u₀
        let u = self.u0 + x;
        // sin²θ = (1 − u)(1 + u), each formed from the half angles of θ₀
        let one_minus_u = 2.0 * (0.5 * th0).sin().powi(2) - x;
        let one_plus_u = 2.0 * (0.5 * th0).cos().powi(2) + x;
        let sin_th = (one_minus_u * one_plus_u).sqrt();
        let theta = sin_th.atan2(u);
        let d = [0, 1].map(|k| self.factor[k] * (self.third_kind(k, tau) - self.pi0[k]));
        let psi = psi0 + d[0] + d[1];
        let phi = phi0 + (self.spin - self.a) * t - d[0] + d[1];
        let udot = 2.0 * width * self.lam * sn * cn * dn;
        let psid = (self.w - self.a * x) / (one_minus_u * one_plus_u); // (b − a u)/sin²θ
        let thd = -udot / sin_th;
        [psi, theta, phi, psid, thd, self.spin - psid * u]
    }

    /// `[u₁, u₂, u₃, nutation period, mean precession rate, ω₃, m]`: the turning points of
    /// `cos θ`, the period of θ (infinite without nutation) and ψ's mean rate over it.
    pub fn summary(&self) -> [f64; SUMMARY_SIZE] {
        let [x1, x2, x3] = self.x;
        let (period, rate) = if self.steady {
            (f64::INFINITY, self.rates[0])
        } else {
            let period = 2.0 * self.quarter / self.lam;
            let advance = 2.0
                * (self.factor[0] * ellippi_complete(self.n[0], self.m, self.m1)
                    + self.factor[1] * ellippi_complete(self.n[1], self.m, self.m1));
            (period, advance / period)
        };
        [
            self.u0 + x1,
            self.u0 + x2,
            self.u0 + x3,
            period,
            rate,
            self.spin,
            self.m,
        ]
    }
}

/// The roots `x₁ ≤ 0 ≤ x₂`, `x₃ ≥ 1 − u₀` of (T1) about `u₀` (`x = u − u₀`), from the
/// cubic's Taylor coefficients `g(x) = q0 + q1 x + q2 x² + β x³` (see the module docs): `x₃`
/// by bisection and Newton, then `x₁` and `x₂` from the deflated quadratic, polished by
/// Newton within `[−(1 + u₀), 0]` and `[0, 1 − u₀]` (`bounds`: `(1 − u₀, 1 + u₀)`).
fn cubic_roots(beta: f64, [q0, q1, q2]: [f64; 3], bounds: (f64, f64)) -> [f64; 3] {
    let (one_minus_u0, one_plus_u0) = bounds;
    let g = |x: f64| ((beta * x + q2) * x + q1) * x + q0;
    let dg = |x: f64| (3.0 * beta * x + 2.0 * q2) * x + q1;
    // x₃ ≥ 1 − u₀: g(1 − u₀) = f(1) = −(b − a)² ≤ 0
    let mut lo = one_minus_u0;
    let mut hi = lo.max(1.0);
    while g(hi) <= 0.0 && hi < 1e300 {
        lo = hi;
        hi *= 2.0;
    }
    let x3 = polish(&g, &dg, bisect(&g, lo, hi), lo, hi);
    // the deflated quadratic x² + p1 x + p0 = g(x) / (β (x − x₃)): p0 = x₁ x₂ ≤ 0
    let p1 = q2 / beta + x3;
    let p0 = -q0 / (beta * x3);
    let disc = (p1 * p1 - 4.0 * p0).max(0.0);
    let r = -0.5 * (p1 + disc.sqrt().copysign(p1));
    let (mut x1, mut x2) = if r == 0.0 {
        (0.0, 0.0)
    } else {
        (r.min(p0 / r), r.max(p0 / r))
    };
    if q0 == 0.0 {
        // a turning point at t = 0: u₀ is itself a root
        if x1.abs() < x2.abs() {
            x1 = 0.0;
        } else {
            x2 = 0.0;
        }
    }
    x1 = polish(&g, &dg, x1.min(0.0), -one_plus_u0, 0.0);
    x2 = polish(&g, &dg, x2.max(0.0), 0.0, one_minus_u0);
    [x1, x2, x3]
}

/// A root of `g` in `[lo, hi]` (`g(lo) ≤ 0 < g(hi)` or the reverse), by bisection to a
/// relative width of 1e-6.
fn bisect(g: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let rising = g(hi) > g(lo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (hi - lo) <= 1e-6 * mid.abs().max(1e-300) {
            break;
        }
        if (g(mid) > 0.0) == rising {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `x` polished by Newton's method on `g`, kept in `[lo, hi]`, until the step stops shrinking.
fn polish(g: &impl Fn(f64) -> f64, dg: &impl Fn(f64) -> f64, mut x: f64, lo: f64, hi: f64) -> f64 {
    let mut last = f64::INFINITY;
    for _ in 0..60 {
        let d = dg(x);
        if d == 0.0 {
            break;
        }
        let step = g(x) / d;
        if step.is_nan() || step.abs() >= last {
            break;
        }
        last = step.abs();
        x = (x - step).clamp(lo, hi);
        if step == 0.0 {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// θ(t) of a top satisfies u̇² = f(u) and ψ̇, φ̇ their formulas; the angles' derivatives
    /// by central differences equal the rates the closed form gives.
    #[test]
    fn the_closed_form_satisfies_its_equations() {
        let (a, c, mgl) = (0.2758, 0.045, 4.905);
        let top = TopMotion::new(a, c, mgl, [0.3, 0.6, 0.1], [0.5, 0.2, 100.0]);
        let h = 1e-5;
        for &t in &[0.0, 0.13, 1.7, 4.2] {
            let y = top.at(t);
            let (p, m) = (top.at(t + h), top.at(t - h));
            for k in 0..3 {
                let fd = (p[k] - m[k]) / (2.0 * h);
                assert!(
                    (fd - y[3 + k]).abs() < 1e-6 * (1.0 + y[3 + k].abs()),
                    "{t} {k}"
                );
            }
        }
        let y0 = top.at(0.0);
        assert!((y0[1] - 0.6).abs() < 1e-15 && (y0[0] - 0.3).abs() < 1e-15);
        assert!((y0[3] - 0.5).abs() < 1e-12 && (y0[4] - 0.2).abs() < 1e-12);
    }
}
