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

use crate::dual::Dual;
use crate::elliptic::{
    atan2_right, carlson_rf_rj_from_roots, carlson_rj, ellipk_m1, first_kind_from_sn_cn,
    jacobi_dual, jacobi_reduced, parity, third_kind_negative, third_kind_with_p, Agm, Libm,
    OnDuals, RcOnePlus,
};
use crate::real::Real;
use crate::so3::{zxz_body_rates, zxz_matrix_sc};

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
    /// The third-kind terms of (T3) ([`Terms`]), and their values at `τ₀`.
    pub terms: Terms<f64>,
    pub pi0: [f64; 2],
    /// `1 + u₁` and `1 − u₂`, the band's gaps to the vertical ([`gaps`]), and which of them
    /// come from the cubic's values at `∓1` (`gap_by_product`).
    pub gaps: [f64; 2],
    pub gap_by_product: [bool; 2],
    /// `u₃ − 1` ([`upper_pair`] where the band's top nears `u₃`).
    pub u3_minus_1: f64,
    /// No nutation: θ constant, ψ̇ and φ̇ constant (`rates`).
    pub steady: bool,
    pub rates: [f64; 2],
}

/// The constants and turning points of a motion, as `TopMotion::summary` gives them:
/// `[u₁, u₂, u₃, nutation period, mean precession rate, ω₃, m, θ_min, θ_max]`.
pub const SUMMARY_SIZE: usize = 9;

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
        // no nutation when the turning points are apart by no more than the roots' rounding:
        // q₁'s terms' size over g's curvature (g'' ≈ β (x₃ − x₁)). Relative to x₃ − x₁, a
        // fast top's nutation (x₃ ~ a²/β) was taken for none, and its precession for zero
        let rounding =
            64.0 * f64::EPSILON * (beta * s2 + 2.0 * (u0 * e).abs() + 2.0 * (a * w).abs())
                / (beta * (x3 - x1));
        if !width.is_finite() || width <= rounding {
            top.steady = true;
            top.rates = [psid, phid];
            top.lam = 0.5 * (beta * (x3 - x1)).sqrt();
            return top;
        }
        top.gap_by_product = gap_by_product((one_minus_u0, one_plus_u0), top.x, w, a);
        top.gaps = gaps(
            top.gap_by_product,
            [one_minus_u0, one_plus_u0],
            top.x,
            w,
            a,
            beta,
        );
        let mut upper = x3 - x2;
        top.u3_minus_1 = x3 - one_minus_u0;
        if upper < 0.5 * one_minus_u0 {
            let one_minus_u1 = one_minus_u0 - x1;
            let [y, z] = upper_pair(beta, e, a, w, one_minus_u0, one_minus_u1, top.gaps[0]);
            top.x = [x1, one_minus_u0 - z, one_minus_u0 + y];
            top.gaps[1] = z;
            top.u3_minus_1 = y;
            upper = y + z;
        }
        let [x1, x2, x3] = top.x;
        let width = x2 - x1;
        top.m = width / (x3 - x1);
        top.m1 = upper / (x3 - x1);
        top.lam = 0.5 * (beta * (x3 - x1)).sqrt();
        top.quarter = ellipk_m1(top.m1);
        // sn²τ₀ = −x₁/(x₂ − x₁), cn²τ₀ = x₂/(x₂ − x₁), sn τ₀ of the sign of u̇₀ = −θ̇₀ sin θ₀
        let sn0 = (-x1 / width).sqrt().copysign(-thd * s);
        let cn0 = (x2 / width).sqrt();
        top.tau0 = first_kind_from_sn_cn(sn0, cn0, top.m, top.m1);
        top.terms = Terms::new::<Libm>(TermsOf {
            x: top.x,
            bounds: [one_minus_u0, one_plus_u0],
            gaps: top.gaps,
            u3_minus_1: top.u3_minus_1,
            w,
            a,
            beta,
            lam: top.lam,
            m: top.m,
            m1: top.m1,
        });
        let (sn, cn, dn, p, _) = jacobi_reduced(top.tau0, top.m, top.m1, top.quarter);
        top.pi0 = top.terms.at::<Libm>(sn, cn, dn, p);
        top
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
        let (sn, cn, dn, p, _) = jacobi_reduced(tau, self.m, self.m1, self.quarter);
        let width = x2 - x1;
        let x = x1 + width * sn * sn; // u − u₀
        let u = self.u0 + x;
        // sin²θ = (1 − u)(1 + u), each a sum of two positive numbers (the band's gap to the
        // vertical and a part of its width): no cancellation near either vertical
        let one_minus_u = self.gaps[1] + width * cn * cn;
        let one_plus_u = self.gaps[0] + width * sn * sn;
        let sin_th = (one_minus_u * one_plus_u).sqrt();
        let theta = sin_th.atan2(u);
        let terms = self.terms.at::<Libm>(sn, cn, dn, p);
        let d = [0, 1].map(|k| terms[k] - self.pi0[k]);
        let psi = psi0 + d[0] + d[1];
        let phi = phi0 + (self.spin - self.a) * t - d[0] + d[1];
        let udot = 2.0 * width * self.lam * sn * cn * dn;
        let psid = (self.w - self.a * x) / (one_minus_u * one_plus_u); // (b − a u)/sin²θ
        let thd = -udot / sin_th;
        [psi, theta, phi, psid, thd, self.spin - psid * u]
    }

    /// `[u₁, u₂, u₃, nutation period, mean precession rate, ω₃, m, θ_min, θ_max]`: the
    /// turning points of `cos θ`, the period of θ (infinite without nutation) and ψ's mean rate
    /// over it, and the band of θ. `θ = atan2(√((1 − u)(1 + u)), u)` at `u₂` and `u₁` from the
    /// band's gaps to the verticals ([`gaps`]): near a vertical `1 ∓ u` formed from `u` would
    /// keep few of its digits (a band reaching within 2e-6 rad of the upward vertical had lost
    /// five).
    pub fn summary(&self) -> [f64; SUMMARY_SIZE] {
        let [x1, x2, x3] = self.x;
        let (period, rate) = if self.steady {
            (f64::INFINITY, self.rates[0])
        } else {
            let period = 2.0 * self.quarter / self.lam;
            let advance = 2.0 * (self.terms.complete[0] + self.terms.complete[1]);
            (period, advance / period)
        };
        let band = if self.steady {
            [self.angles0[1]; 2]
        } else {
            let [gap_bottom, gap_top] = self.gaps;
            let width = x2 - x1;
            let theta = |one_minus_u: f64, one_plus_u: f64, u: f64| {
                (one_minus_u * one_plus_u).sqrt().atan2(u)
            };
            [
                theta(gap_top, gap_bottom + width, self.u0 + x2),
                theta(gap_top + width, gap_bottom, self.u0 + x1),
            ]
        };
        [
            self.u0 + x1,
            self.u0 + x2,
            self.u0 + x3,
            period,
            rate,
            self.spin,
            self.m,
            band[0],
            band[1],
        ]
    }
}

/// The directions of [`TopTangent`]: `A`, `C`, `M g l`, the initial angles `(ψ₀, θ₀, φ₀)` and
/// their rates `(ψ̇₀, θ̇₀, φ̇₀)`.
pub const TOP_DIRECTIONS: usize = 9;

type D9 = Dual<TOP_DIRECTIONS>;

/// `(sin x, cos x)` of a dual `x`.
fn sin_cos_dual(x: D9) -> (D9, D9) {
    let (s, c) = x.v.sin_cos();
    (
        Dual::new(s, x.d.map(|d| c * d)),
        Dual::new(c, x.d.map(|d| -s * d)),
    )
}

/// A nutating heavy top with the derivatives of its closed form (T1)–(T3) along
/// [`TOP_DIRECTIONS`]: the motion's algebra on dual numbers — the cubic's coefficients, its
/// roots by the implicit function theorem (`∂x/∂p = −(∂g/∂p)/g'(x)` at each polished root),
/// `m`, `λ`, the start `τ₀`, `n±` and the factors of (T3) — the Jacobi functions with their
/// derivatives in `τ` and `m` ([`jacobi_dual`]) and the third-kind integrals through
/// Carlson's duplication ([`third_kind_from_roots`]). `τ₀` is found from `u(τ₀) = u₀` and
/// `u̇(τ₀) = −θ̇₀ sin θ₀` together (their derivatives, by least squares: the first degenerates
/// at a turning point, the second at mid-swing), so a top released from rest has them too.
#[derive(Clone, Copy, Debug)]
pub struct TopTangent {
    top: TopMotion,
    agm: Agm,
    /// `∂K/∂m`.
    k_m: f64,
    angles0: [D9; 3],
    u0: D9,
    /// `1 + u₁`, `1 − u₂` ([`gaps`]).
    gaps: [D9; 2],
    x: [D9; 3],
    a: D9,
    w: D9,
    spin: D9,
    m: D9,
    lam: D9,
    quarter: D9,
    tau0: D9,
    terms: Terms<D9>,
    pi0: [D9; 2],
}

impl TopTangent {
    /// The top `(A, C, M g l)` from the angles `(ψ₀, θ₀, φ₀)` and their rates (as
    /// [`TopMotion::new`]); an error where the closed form has no derivatives: without
    /// nutation (steady precession, a sleeping top: the turning points merge) or reaching the
    /// vertical.
    pub fn new(
        a_moment: f64,
        c_moment: f64,
        mgl: f64,
        angles: [f64; 3],
        rates: [f64; 3],
    ) -> Result<TopTangent, &'static str> {
        let top = TopMotion::new(a_moment, c_moment, mgl, angles, rates);
        if top.steady {
            return Err(
                "the top does not nutate (steady precession or a sleeping top): its \
                        turning points merge, where the closed form is not differentiable",
            );
        }
        if !(top.m1 > 0.0 && top.m1.is_finite()) {
            return Err(
                "the top's axis reaches the vertical, where the closed form's \
                        nutation period is not differentiable",
            );
        }
        let seed = |v: f64, j: usize| {
            let mut d = [0.0; TOP_DIRECTIONS];
            d[j] = 1.0;
            Dual::new(v, d)
        };
        let (am, cm, mg) = (seed(a_moment, 0), seed(c_moment, 1), seed(mgl, 2));
        let angles0 = [0, 1, 2].map(|k| seed(angles[k], 3 + k));
        let [psid, thd, phid] = [0, 1, 2].map(|k| seed(rates[k], 6 + k));
        let c = D9::splat;
        // the algebra of TopMotion::new
        let (s, u0) = sin_cos_dual(angles0[1]);
        let s2 = s * s;
        let spin = phid + psid * u0;
        let a = cm * spin / am;
        let beta = c(2.0) * mg / am;
        let w = psid * s2;
        let e = thd * thd + psid * psid * s2;
        let q0 = (s * thd) * (s * thd);
        let q1 = -beta * s2 - c(2.0) * u0 * e + c(2.0) * a * w;
        let q2 = c(2.0) * beta * u0 - e - a * a;
        let (sh, ch) = sin_cos_dual(c(0.5) * angles0[1]);
        let bounds = [c(2.0) * sh * sh, c(2.0) * ch * ch]; // 1 − u₀, 1 + u₀
                                                           // each polished root x: g(x) = 0, so ∂x/∂p = −(∂g/∂p)/g'(x)
        let x = top.x.map(|xi| {
            let xd = c(xi);
            let g = ((beta * xd + q2) * xd + q1) * xd + q0;
            let slope = (3.0 * beta.v * xi + 2.0 * q2.v) * xi + q1.v;
            Dual::new(xi, g.d.map(|d| -d / slope))
        });
        let [x1, x2, x3] = x;
        let width = x2 - x1;
        let m = width / (x3 - x1);
        let lam = c(0.5) * (beta * (x3 - x1)).sqrt();
        let agm = Agm::new(top.m1);
        let k_m = carlson_rj(0.0, 1.0, top.m1, top.m1) / 6.0;
        let quarter = Dual::new(top.quarter, m.d.map(|d| k_m * d));
        // τ₀: u₀ = u(τ₀) (P) and u̇₀ = u̇(τ₀) (V), differentiated; each `a dτ + r = 0`
        let tau0 = {
            let (sn, cn, dn, _) = jacobi_dual(c(top.tau0), m, top.m1, top.quarter, k_m, &agm, 0.0);
            let (l, wv) = (lam.v, width.v);
            // (P) x₁ + (x₂ − x₁) sn² = 0, times λ to the units of (V)
            let p = x1 + width * sn * sn;
            let a_p = l * 2.0 * wv * sn.v * cn.v * dn.v;
            // (V) 2 (x₂ − x₁) λ sn cn dn + θ̇₀ sin θ₀ = 0
            let v = c(2.0) * width * lam * sn * cn * dn + thd * s;
            let (snv, cnv, dnv) = (sn.v, cn.v, dn.v);
            let g_tau = cnv * cnv * dnv * dnv - snv * snv * dnv * dnv - m.v * snv * snv * cnv * cnv;
            let a_v = 2.0 * wv * l * g_tau;
            // the residuals' derivatives at fixed τ: the duals' own, less the part through τ
            // (here τ is a constant, so sn, cn, dn carry only their m parts)
            let norm = a_p * a_p + a_v * a_v;
            let mut d = [0.0; TOP_DIRECTIONS];
            for (j, dj) in d.iter_mut().enumerate() {
                *dj = -(a_p * l * p.d[j] + a_v * v.d[j]) / norm;
            }
            Dual::new(top.tau0, d)
        };
        let mut gaps = gaps(top.gap_by_product, bounds, x, w, a, beta);
        // the values TopMotion::new refined ([`upper_pair`]), with these derivatives
        gaps[1] = Dual::new(top.gaps[1], gaps[1].d);
        let u3_minus_1 = Dual::new(top.u3_minus_1, (x3 - bounds[0]).d);
        let m1 = Dual::new(top.m1, m.d.map(|d| -d));
        let terms = Terms::new::<OnDuals>(TermsOf {
            x,
            bounds,
            gaps,
            u3_minus_1,
            w,
            a,
            beta,
            lam,
            m,
            m1,
        });
        let mut tangent = TopTangent {
            top,
            agm,
            k_m,
            angles0,
            u0,
            gaps,
            x,
            a,
            w,
            spin,
            m,
            lam,
            quarter,
            tau0,
            terms,
            pi0: [c(0.0); 2],
        };
        let (sn, cn, dn, p) = tangent.jacobi_at(0.0);
        tangent.pi0 = tangent.terms.at::<OnDuals>(sn, cn, dn, p);
        Ok(tangent)
    }

    /// `(sn τ, cn τ, dn τ)` of `τ = τ₀ + λt` with their derivatives, and the reduction's `p`.
    fn jacobi_at(&self, t: f64) -> (D9, D9, D9, f64) {
        let tau = self.tau0 + self.lam * D9::splat(t);
        jacobi_dual(
            tau,
            self.m,
            self.top.m1,
            self.top.quarter,
            self.k_m,
            &self.agm,
            0.0,
        )
    }

    /// `[ψ, θ, φ, ψ̇, θ̇, φ̇]` at `t` ([`TopMotion::at`]) and their derivatives (rows) along
    /// [`TOP_DIRECTIONS`].
    pub fn at(&self, t: f64) -> ([f64; 6], [[f64; TOP_DIRECTIONS]; 6]) {
        let c = D9::splat;
        let jac = self.jacobi_at(t);
        let (sn, cn, dn, _) = jac;
        let [x1, x2, _] = self.x;
        let width = x2 - x1;
        let x = x1 + width * sn * sn;
        let u = self.u0 + x;
        let one_minus_u = self.gaps[1] + width * cn * cn;
        let one_plus_u = self.gaps[0] + width * sn * sn;
        let sin_th = (one_minus_u * one_plus_u).sqrt();
        // θ = atan2(sin θ, u): dθ = (u d sinθ − sinθ du)/(u² + sin²θ)
        let r2 = u.v * u.v + sin_th.v * sin_th.v;
        let theta = Dual::new(
            sin_th.v.atan2(u.v),
            std::array::from_fn(|j| (u.v * sin_th.d[j] - sin_th.v * u.d[j]) / r2),
        );
        let terms = self.terms.at::<OnDuals>(sn, cn, dn, jac.3);
        let d = [0, 1].map(|k| terms[k] - self.pi0[k]);
        let psi = self.angles0[0] + d[0] + d[1];
        let phi = self.angles0[2] + (self.spin - self.a) * c(t) - d[0] + d[1];
        let udot = c(2.0) * width * self.lam * sn * cn * dn;
        let psid = (self.w - self.a * x) / (one_minus_u * one_plus_u);
        let thd = -udot / sin_th;
        let phid = self.spin - psid * u;
        let out = [psi, theta, phi, psid, thd, phid];
        (out.map(|x| x.v), out.map(|x| x.d))
    }

    /// The attitude of the axis frame (`Rzxz(ψ, θ, φ)`, axis frame → the space frame with z up)
    /// and the angular velocity in the axis frame ([`zxz_body_rates`]) at `t`, with their
    /// derivatives along [`TOP_DIRECTIONS`] (the last index): the same dual numbers as
    /// [`TopTangent::at`].
    #[allow(clippy::type_complexity)]
    pub fn attitude_at(
        &self,
        t: f64,
    ) -> (
        [[f64; 3]; 3],
        [[[f64; TOP_DIRECTIONS]; 3]; 3],
        [f64; 3],
        [[f64; TOP_DIRECTIONS]; 3],
    ) {
        let (v, d) = self.at(t);
        let dual = |k: usize| Dual::new(v[k], d[k]);
        let angles = [dual(0), dual(1), dual(2)];
        let rates = [dual(3), dual(4), dual(5)];
        let sc = angles.map(|a| {
            let (s, c) = a.sin_cos_std();
            [s, c]
        });
        let q = zxz_matrix_sc(sc[0], sc[1], sc[2]);
        let w = zxz_body_rates(angles, rates);
        (
            q.map(|r| r.map(|x| x.v)),
            q.map(|r| r.map(|x| x.d)),
            w.map(|x| x.v),
            w.map(|x| x.d),
        )
    }

    /// `[u₁, u₂, nutation period, mean precession rate]` ([`TopMotion::summary`]) with their
    /// derivatives along [`TOP_DIRECTIONS`].
    pub fn summary(&self) -> ([f64; 4], [[f64; TOP_DIRECTIONS]; 4]) {
        let c = D9::splat;
        let period = c(2.0) * self.quarter / self.lam;
        let advance = c(2.0) * (self.terms.complete[0] + self.terms.complete[1]);
        let out = [
            self.u0 + self.x[0],
            self.u0 + self.x[1],
            period,
            advance / period,
        ];
        (out.map(|x| x.v), out.map(|x| x.d))
    }
}

/// What [`Terms::new`] takes of a motion: the roots `x` about `u₀`, `(1 − u₀, 1 + u₀)`, the
/// gaps `(1 + u₁, 1 − u₂)` ([`gaps`]), `w = b − a u₀`, `a`, `β`, `λ`, `m` and `m1`.
struct TermsOf<T> {
    x: [T; 3],
    bounds: [T; 2],
    gaps: [T; 2],
    u3_minus_1: T,
    w: T,
    a: T,
    beta: T,
    lam: T,
    m: T,
    m1: T,
}

/// The two third-kind terms of (T3), `F₊ Π(n₊; am τ | m)` and `F₋ Π(n₋; am τ | m)` with
/// `F± = (b ∓ a)/(2 (1 ∓ u₁) λ)`, in forms that keep their digits where the band reaches near
/// either vertical, on `f64` or on dual numbers ([`TopTangent`]):
///
/// - `n₊ = (u₂ − u₁)/(1 − u₁)` tends to 1 as the band reaches the upward vertical (`1 − u₂ →
///   0`), where `Π(n₊) ~ (1 − n₊)^−½` and `F₊ → 0` as `(1 − u₂)^½`, `b − a` formed with the
///   rounding of `w` and `a (1 − u₀)`. Below `n₊ = ½` or where `1 − u₂ ≥ u₃ − 1`, `R_J`'s
///   `1 − n₊ sn²` is `(1 − u)/(1 − u₁) = (1 − u₂ + (u₂ − u₁) cn²)/(1 − u₁)`, a sum of positive
///   numbers ([`third_kind_with_p`]). Above, DLMF 19.7.9 pairs `Π(n₊)` with `Π(ν)`, `ν = m/n₊ =
///   (1 − u₁)/(u₃ − u₁)`: `Π(n₊; φ) = −(ν/3) s³ R_J(c², d², 1, 1 − ν s²) + atan2(s g, c d)/g`,
///   `g² = (1 − n₊)(n₊ − m)/n₊ = (1 − u₂)(u₃ − 1)/((1 − u₁)(u₃ − u₁))`, with
///   `1 − ν s² = (u₃ − 1 + (1 − u₁) cn²)/(u₃ − u₁)`; and `F₊/g = ±√(β (u₃ − u₁))/(2λ) = ±1`
///   by `f(1) = −(b − a)² = −β (1 − u₁)(1 − u₂)(u₃ − 1)`: finite at `1 − u₂ = 0` (a swing
///   through the upward vertical, where ψ steps by π), and free of the rounding of `b − a`.
/// - `n₋ = −(u₂ − u₁)/(1 + u₁)` tends to −∞ as it reaches the hanging vertical (a top with
///   little spin), where `F₋ → ∞` as `1/√(1 + u₁)` and `s R_F + (n/3) s³ R_J` cancels:
///   [`third_kind_negative`] with `p = u₂ − u₁`, `q = 1 + u₁`, so `F₋ Π = (b + a)/(2λ) X +
///   (b + a)/(2λ √q) Y`, and `(b + a)/√q = ±√(β (1 + u₂)(1 + u₃))` by
///   `f(−1) = −(b + a)² = −β q (1 + u₂)(1 + u₃)`: finite even at `q = 0` (no spin, the axis
///   through the vertical, where ψ steps by π).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Terms<T> {
    /// `n₊`, `F₊`.
    n_plus: T,
    f_plus: T,
    /// `1 − u₂`, `u₂ − u₁`, `1 − u₁`, `1 + u₁`, `m`.
    gap_top: T,
    width: T,
    one_minus_u1: T,
    gap_bottom: T,
    m: T,
    /// Whether `n₊ > ½` and `1 − u₂ < u₃ − 1`, where its transformed form is taken; then
    /// `ν s³ R_J`'s factor `−F₊ ν/3 = −(b − a)/(6λ (u₃ − u₁))`, `u₃ − 1`, `u₃ − u₁`, `g` and
    /// `F₊/g`.
    top_transformed: bool,
    xp_factor: T,
    u3_minus_1: T,
    u3_minus_u1: T,
    g_plus: T,
    yp_factor: T,
    /// Whether `n₋ < −1`, where the transformed form is taken (above, `s R_F + (n₋/3) s³ R_J`
    /// does not cancel, and `R_J`'s `1 − n₋ sn² = (1 + u)/(1 + u₁)`), and `F₋`.
    bottom_transformed: bool,
    f_minus: T,
    /// `(b + a)/(2λ)` and `(b + a)/(2λ √(1 + u₁))`: the factors of `X` and `Y`.
    x_factor: T,
    y_factor: T,
    /// `F± Π(n±|m)`, the complete integrals' terms.
    pub complete: [T; 2],
}

impl<T: Real<Mask = bool>> Terms<T> {
    fn new<R: RcOnePlus<T>>(t: TermsOf<T>) -> Terms<T> {
        let c = T::splat;
        let [one_minus_u0, one_plus_u0] = t.bounds;
        let [x1, x2, x3] = t.x;
        let [gap_bottom, gap_top] = t.gaps;
        let width = x2 - x1;
        let one_minus_u1 = one_minus_u0 - x1;
        // b ∓ a = w ∓ a (1 ∓ u₀), without the cancellation of b − a near the vertical
        let b_plus_a = t.w + t.a * one_plus_u0;
        let b_minus_a = t.w - t.a * one_minus_u0;
        let two_lam = c(2.0) * t.lam;
        let f_plus = b_minus_a / (two_lam * one_minus_u1);
        let u3_minus_1 = t.u3_minus_1;
        let u3_minus_u1 = x3 - x1;
        let g_plus = (gap_top * u3_minus_1 / (one_minus_u1 * u3_minus_u1)).sqrt();
        // F₊/g and F₋√q by the cubic's factored values at ±1, exact whichever way the gaps
        // were found, and free of the rounding of b ∓ a but for its sign
        let yp_factor = (t.beta * u3_minus_u1).sqrt().copysign(b_minus_a) / two_lam;
        let root = (t.beta * (one_plus_u0 + x2) * (one_plus_u0 + x3))
            .sqrt()
            .copysign(b_plus_a);
        let mut terms = Terms {
            n_plus: width / one_minus_u1,
            f_plus,
            // (not where u₃ → 1 too: there ν → 1, and F₊ = 0 at b = a exactly)
            top_transformed: gap_top.lt(width) && gap_top.lt(u3_minus_1),
            xp_factor: -b_minus_a / (c(3.0) * two_lam * u3_minus_u1),
            u3_minus_1,
            u3_minus_u1,
            g_plus,
            yp_factor,
            gap_top,
            width,
            one_minus_u1,
            gap_bottom,
            m: t.m,
            bottom_transformed: width.gt(gap_bottom),
            f_minus: b_plus_a / (two_lam * gap_bottom),
            x_factor: b_plus_a / two_lam,
            y_factor: root / two_lam,
            complete: [c(0.0); 2],
        };
        // at v = K: s = 1, c = 0; the upward term's angle is π/2 (its limit as g → 0, where
        // atan2(g, 0) would be 0 at g = 0: the step of ψ at the upward vertical)
        let half_pi = c(std::f64::consts::FRAC_PI_2);
        terms.complete = terms.with_angle::<R>(c(1.0), c(0.0), t.m1.sqrt(), half_pi);
        terms
    }

    /// The terms at `τ = 2pK + v` from `(sn τ, cn τ, dn τ)` and `p` ([`jacobi_reduced`]):
    /// `2p F±Π(n±|m)` and the terms at `v`.
    #[inline(always)]
    fn at<R: RcOnePlus<T>>(&self, sn: T, cn: T, dn: T, p: f64) -> [T; 2] {
        let par = T::splat(parity(p));
        let g = self.reduced::<R>(par * sn, par * cn, dn);
        if p == 0.0 {
            return g;
        }
        let p2 = T::splat(2.0 * p);
        [g[0] + p2 * self.complete[0], g[1] + p2 * self.complete[1]]
    }

    /// The terms at `|v| ≤ K` from `s = sn v`, `c = cn v ≥ 0`, `d = dn v`.
    #[inline(always)]
    fn reduced<R: RcOnePlus<T>>(&self, s: T, c: T, d: T) -> [T; 2] {
        self.with_angle::<R>(s, c, d, atan2_right(s * self.g_plus, c * d))
    }

    /// [`Terms::reduced`] with the upward term's `atan2(s g, c d)` given.
    #[inline(always)]
    fn with_angle<R: RcOnePlus<T>>(&self, s: T, c: T, d: T, angle: T) -> [T; 2] {
        let plus = if self.top_transformed {
            let p_nu = (self.u3_minus_1 + self.one_minus_u1 * c * c) / self.u3_minus_u1;
            let (_, rj) = carlson_rf_rj_from_roots::<T, R>(c, d, p_nu);
            self.xp_factor * s * s * s * rj + self.yp_factor * angle
        } else {
            let p_plus = (self.gap_top + self.width * c * c) / self.one_minus_u1;
            self.f_plus * third_kind_with_p::<T, R>(self.n_plus, s, c, d, p_plus)
        };
        if !self.bottom_transformed {
            let n_minus = -self.width / self.gap_bottom;
            let p_minus = (self.gap_bottom + self.width * s * s) / self.gap_bottom;
            let minus = third_kind_with_p::<T, R>(n_minus, s, c, d, p_minus);
            return [plus, self.f_minus * minus];
        }
        let [x, y] = third_kind_negative::<T, R>(self.width, self.gap_bottom, s, c, d, self.m);
        [plus, self.x_factor * x + self.y_factor * y]
    }
}

/// Whether the band's gaps to the vertical, `1 + u₁` and `1 − u₂`, are better found from the
/// cubic's values at `∓1` ([`gaps`]) than as `(1 + u₀) + x₁` and `(1 − u₀) − x₂`: whichever
/// rounds less, relative to the gap. The sum loses `(1 ∓ u₀)/gap` where it cancels (the band
/// reaching near a vertical); the product carries the rounding of `(b ∓ a)² = (w ∓ a (1 ∓
/// u₀))²`, `2 (|w| + |a| (1 ∓ u₀))/|b ∓ a|`, and for `1 − u₂` that of `u₃ − 1 = x₃ − (1 − u₀)`,
/// `x₃/(u₃ − 1)`; its other factors are sums of positive numbers. (Only a swing that reaches a
/// vertical makes `b ∓ a` exactly 0: the gap is then 0.)
fn gap_by_product(
    (one_minus_u0, one_plus_u0): (f64, f64),
    [x1, x2, x3]: [f64; 3],
    w: f64,
    a: f64,
) -> [bool; 2] {
    let cancel = |gap: f64, bound: f64| {
        if gap > 0.0 {
            bound / gap
        } else {
            f64::INFINITY
        }
    };
    let square = |b: f64, bound: f64| {
        let b_a = w + b * a * bound;
        if b_a == 0.0 {
            0.0
        } else {
            2.0 * (w.abs() + a.abs() * bound) / b_a.abs()
        }
    };
    let u3_minus_1 = x3 - one_minus_u0;
    let top = if u3_minus_1 > 0.0 {
        square(-1.0, one_minus_u0) + x3 / u3_minus_1
    } else {
        f64::INFINITY
    };
    [
        square(1.0, one_plus_u0) < cancel(one_plus_u0 + x1, one_plus_u0),
        top < cancel(one_minus_u0 - x2, one_minus_u0),
    ]
}

/// `[u₃ − 1, 1 − u₂]`, the upper pair of roots of (T1) about `u = 1`, where the top of the band
/// nears `u₃` (the motion near its separatrix: an upright top below the sleeping threshold,
/// a pendulum about to swing over the top), and `x₃ − x₂` found about `u₀` would keep few
/// digits (Newton's accuracy at a near-double root: 1e-5 relative in `m1 = 6e-6`). About 1
/// the cubic is `f(1 + v) = β v³ + (2β − E − a²) v² + 2(a D − E) v − D²`, `E = α − β`,
/// `D = b − a`; deflated by its root `v₁ = u₁ − 1`, its small roots `y = u₃ − 1 ≥ 0` and
/// `−z = u₂ − 1 ≤ 0` have `y − z = (E + a²)/β − (1 + u₁)` and `y z = D²/(β (1 − u₁))`, each
/// from the initial state as directly as the motion allows (`E = θ̇₀² + ψ̇₀² sin²θ₀ − β (1 −
/// u₀)`), and `y + z = √((y − z)² + 4 y z)` without cancellation.
fn upper_pair(
    beta: f64,
    e: f64,
    a: f64,
    w: f64,
    one_minus_u0: f64,
    one_minus_u1: f64,
    one_plus_u1: f64,
) -> [f64; 2] {
    let d = w - a * one_minus_u0;
    let diff = (e + a * a) / beta - (one_minus_u0 + one_plus_u1);
    let prod = d * d / (beta * one_minus_u1);
    let r = (diff * diff + 4.0 * prod).sqrt();
    if diff >= 0.0 {
        let y = 0.5 * (diff + r);
        [y, if y > 0.0 { prod / y } else { 0.0 }]
    } else {
        let z = 0.5 * (r - diff);
        [prod / z, z]
    }
}

/// `1 + u₁` and `1 − u₂`, the gaps of the nutation band to the two verticals. Where
/// [`gap_by_product`] says so, from `f(−1) = −(b + a)² = −β (1 + u₁)(1 + u₂)(1 + u₃)` and
/// `f(1) = −(b − a)² = −β (1 − u₁)(1 − u₂)(u₃ − 1)` ((T1) factored), whose other factors are
/// sums of positive numbers: a top with little spin passes close to the hanging vertical, and
/// `(1 + u₀) + x₁` kept none of the gap's digits (its ψ then jumps there by nearly π). On `f64`
/// or on dual numbers; `b ∓ a = w ∓ a (1 ∓ u₀)`.
fn gaps<T: Real>(by_product: [bool; 2], bounds: [T; 2], x: [T; 3], w: T, a: T, beta: T) -> [T; 2] {
    let [one_minus_u0, one_plus_u0] = bounds;
    let [x1, x2, x3] = x;
    let bottom = if by_product[0] {
        let b_plus_a = w + a * one_plus_u0;
        b_plus_a * b_plus_a / (beta * (one_plus_u0 + x2) * (one_plus_u0 + x3))
    } else {
        one_plus_u0 + x1
    };
    let top = if by_product[1] {
        let b_minus_a = w - a * one_minus_u0;
        b_minus_a * b_minus_a / (beta * (one_minus_u0 - x1) * (x3 - one_minus_u0))
    } else {
        one_minus_u0 - x2
    };
    [bottom, top]
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
    // from beyond `1 − u₀` itself: there `g` is `−(b − a)²`, and at `b = a` its rounding can
    // be positive (a swing through the upward vertical had taken `u₃ = 1`, the band for none)
    while (g(hi) <= 0.0 || hi <= one_minus_u0) && hi < 1e300 {
        lo = hi;
        hi *= 2.0;
    }
    let x3 = polish(&g, &dg, bisect(&g, lo, hi), lo, hi);
    // the deflated quadratic x² + p1 x + p0 = g(x) / (β (x − x₃)): p0 = x₁ x₂ ≤ 0 and
    // p1 = −(x₁ + x₂) = q₂/β + x₃, or, where that sum cancels (a fast top: x₃ ≈ a²/β far above
    // the band), (p0 − q₁/β)/x₃ from x₁x₂ + x₃(x₁ + x₂) = q₁/β
    let p0 = -q0 / (beta * x3);
    let p1 = if (q2 / beta + x3).abs() < 0.5 * x3 {
        (p0 - q1 / beta) / x3
    } else {
        q2 / beta + x3
    };
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
    use crate::torque_free::tests::richardson;

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

    /// The closed form's derivatives (angles, rates, turning points, nutation period, mean
    /// precession rate) along the top's constants and its initial state against Richardson
    /// differences of the f64 closed form: a nutating top, one released from rest (cusps:
    /// θ̇₀ = ψ̇₀ = 0, a turning point at t = 0), one started at a turning point with a
    /// precession rate (θ̇₀ = 0, ψ̇₀ ≠ 0), a slow top and one started mid-swing.
    #[test]
    fn the_closed_forms_derivatives_equal_differences_of_the_closed_form() {
        let (a, c, mgl) = (0.2758, 0.045, 4.905);
        for (angles, rates, t) in [
            ([0.3, 0.6, 0.1], [0.5, 0.2, 100.0], 1.7),
            ([0.0, 0.6, 0.0], [0.0, 0.0, 100.0], 0.9),
            ([0.2, 0.8, -0.4], [3.0, 0.0, 60.0], 2.3),
            ([0.1, 1.1, 0.0], [0.7, -0.4, 12.0], 3.1),
            ([0.0, 0.5, 0.2], [1.5, 1.3, 40.0], 0.45),
        ] {
            let tangent = TopTangent::new(a, c, mgl, angles, rates).expect("a nutating top");
            let plain = TopMotion::new(a, c, mgl, angles, rates);
            let (value, d) = tangent.at(t);
            let (summary, ds) = tangent.summary();
            let moved = |j: usize, h: f64| {
                let mut p = [
                    a, c, mgl, angles[0], angles[1], angles[2], rates[0], rates[1], rates[2],
                ];
                p[j] += h;
                let top = TopMotion::new(p[0], p[1], p[2], [p[3], p[4], p[5]], [p[6], p[7], p[8]]);
                let y = top.at(t);
                let sm = top.summary();
                [
                    y[0], y[1], y[2], y[3], y[4], y[5], sm[0], sm[1], sm[3], sm[4],
                ]
            };
            let got = plain.at(t);
            let sm = plain.summary();
            for k in 0..6 {
                assert!(
                    (value[k] - got[k]).abs() <= 1e-12 * got[k].abs().max(1.0),
                    "{k}"
                );
            }
            for (k, i) in [(0, 0), (1, 1), (2, 3), (3, 4)] {
                assert!(
                    (summary[k] - sm[i]).abs() <= 1e-12 * sm[i].abs().max(1.0),
                    "s{k}"
                );
            }
            for j in 0..TOP_DIRECTIONS {
                let h = 1e-4 * [a, c, mgl, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0][j].max(1e-2);
                let want = [
                    d[0][j], d[1][j], d[2][j], d[3][j], d[4][j], d[5][j], ds[0][j], ds[1][j],
                    ds[2][j], ds[3][j],
                ];
                for (k, w) in want.into_iter().enumerate() {
                    let fd = richardson(|x| moved(j, x)[k], h);
                    assert!(
                        (w - fd).abs() <= 1e-7 * fd.abs().max(1.0),
                        "{angles:?} {rates:?}: output {k}, direction {j}: {w} against {fd}"
                    );
                }
            }
        }
    }
}
