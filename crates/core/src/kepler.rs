//! Kepler's flow: the exact motion of a point under the gravity `−μ r/|r|³` of a fixed centre,
//! over any time, for any conic (ellipse, parabola, hyperbola), in universal variables
//! (`docs/theory.md`, "Exact-flow splitting", eqs (K1)–(K4)). The exact-flow splittings
//! ([`crate::exact_splitting`]) drift a free body's centre of mass by it when a central gravity
//! acts, and kick with the rest of the forces only (the splitting of Wisdom & Holman 1991,
//! *Astron. J.* 102, 1528).
//!
//! With `χ` the universal anomaly, `z = α χ²`, `α = 2/r₀ − v₀²/μ` and Stumpff's functions
//! `c₂(z) = (1 − cos √z)/z`, `c₃(z) = (√z − sin √z)/z^{3/2}` (Danby, *Fundamentals of
//! Celestial Mechanics*, 2nd ed., §6.9; Battin, *An Introduction to the Mathematics and
//! Methods of Astrodynamics*, §4.5):
//!
//! * (K1) Kepler's equation `√μ t = σ₀ χ² c₂ + (1 − α r₀) χ³ c₃ + r₀ χ`, `σ₀ = r₀·v₀/√μ`,
//!   whose derivative in `χ` is the radius `r = σ₀ χ (1 − z c₃) + (1 − α r₀) χ² c₂ + r₀`;
//! * (K2) `r = f r₀ + g v₀` with `f = 1 − χ² c₂/r₀` and `√μ g = σ₀ χ² c₂ + r₀ χ (1 − z c₃)`
//!   (Kepler's equation solved for `g = t − χ³ c₃/√μ`, which cancels at large `t`);
//! * (K3) `v = ḟ r₀ + ġ v₀` with `ḟ = √μ χ (z c₃ − 1)/(r r₀)` and `ġ = 1 − χ² c₂/r`.
//!
//! `χ` is found on `f64` by Laguerre's iteration (Conway 1986, *Celest. Mech.* 39, 199),
//! which converges from any start for an ellipse; then one Newton step of (K1) on the
//! caller's numbers ([`kepler_flow`]): on dual numbers it carries the implicit derivative
//! `∂χ = −∂K/K'` exactly, so the flow's derivatives are those of the flow computed.

use crate::real::Scalar;
use crate::so3::Vec3;

/// `1/n!` for `n = 0..18` (each `n!` an exact double).
const INV_FACTORIAL: [f64; 18] = [
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40320.0,
    1.0 / 362880.0,
    1.0 / 3628800.0,
    1.0 / 39916800.0,
    1.0 / 479001600.0,
    1.0 / 6227020800.0,
    1.0 / 87178291200.0,
    1.0 / 1307674368000.0,
    1.0 / 20922789888000.0,
    1.0 / 355687428096000.0,
];

/// `(c₂(z), c₃(z))` (K1): their series where `|z| < 0.1`, brought there by quartering `z`
/// and undone by the doubling formulas `c₀(4z) = 2c₀² − 1`, `c₁(4z) = c₀c₁`, `c₂(4z) = c₁²/2`,
/// `c₃(4z) = (c₂ + c₀c₃)/4` (Danby §6.9), with `c₀ = 1 − z c₂`, `c₁ = 1 − z c₃`: arithmetic
/// only, so that dual numbers differentiate it, and no cancellation at small `z`.
#[inline]
pub fn stumpff<T: Scalar>(z: T) -> (T, T) {
    let s = T::splat;
    let mut x = z;
    let mut quarterings = 0;
    while x.abs().gt(s(0.1)) && quarterings < 64 {
        x = x * s(0.25);
        quarterings += 1;
    }
    // c_k(x) = Σ_j (−x)^j/(k + 2j)!, Horner from j = 7 (|x|⁸/18! < 1e-23)
    let series = |k: usize| {
        let mut acc = s(INV_FACTORIAL[k + 14]);
        for j in (0..7).rev() {
            acc = s(INV_FACTORIAL[k + 2 * j]) - x * acc;
        }
        acc
    };
    let (mut c2, mut c3) = (series(2), series(3));
    for _ in 0..quarterings {
        let c0 = s(1.0) - x * c2;
        let c1 = s(1.0) - x * c3;
        c3 = (c2 + c0 * c3) * s(0.25);
        c2 = c1 * c1 * s(0.5);
        x = x * s(4.0);
    }
    (c2, c3)
}

/// What (K1)–(K3) need of a start `(r₀, v₀)` under `μ`.
#[derive(Clone, Copy, Debug)]
struct Start<T> {
    r0: T,
    sigma0: T,
    alpha: T,
    sqrt_mu: T,
}

impl<T: Scalar> Start<T> {
    #[inline]
    fn new(mu: T, r0: &[T; 3], v0: &[T; 3]) -> Self {
        let rr = (r0[0] * r0[0] + r0[1] * r0[1] + r0[2] * r0[2]).sqrt();
        let vv = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2];
        let sqrt_mu = mu.sqrt();
        Start {
            r0: rr,
            sigma0: (r0[0] * v0[0] + r0[1] * v0[1] + r0[2] * v0[2]) / sqrt_mu,
            alpha: T::splat(2.0) / rr - vv / mu,
            sqrt_mu,
        }
    }

    /// Kepler's equation's residual `K(χ) − √μ t` and its first two derivatives in `χ` (K1).
    #[inline]
    fn residual(&self, chi: T, t: T) -> (T, T, T) {
        let one = T::splat(1.0);
        let z = self.alpha * chi * chi;
        let (c2, c3) = stumpff(z);
        let b = one - self.alpha * self.r0;
        let k = self.sigma0 * chi * chi * c2 + b * chi * chi * chi * c3 + self.r0 * chi
            - self.sqrt_mu * t;
        let k1 = self.sigma0 * chi * (one - z * c3) + b * chi * chi * c2 + self.r0;
        let k2 = self.sigma0 * (one - z * c2) + b * chi * (one - z * c3);
        (k, k1, k2)
    }
}

/// The universal anomaly `χ` of a flow of `t` from `(r₀, v₀)` under `μ` (K1), by Laguerre's
/// iteration (Conway 1986). It starts from the inverted series of (K1),
/// `χ ≈ u/r₀ − σ₀u²/(2r₀³) + (σ₀²/(2r₀⁵) − (1 − αr₀)/(6r₀⁴)) u³` with `u = √μ t`, where the
/// flow is short (`|α| (u/r₀)² < 0.1`), else from `u/r₀`. It stops once a step is below
/// `1e-7 |χ|` (the iteration converges cubically, so what is left is far below round-off, and
/// [`kepler_flow`]'s Newton step polishes it), after at most 60 iterations: NaN where it does not converge (the run then stops as not finite).
pub fn universal_anomaly(mu: f64, r0: &Vec3, v0: &Vec3, t: f64) -> f64 {
    if t == 0.0 {
        return 0.0;
    }
    let start = Start::new(mu, r0, v0);
    let r = start.r0;
    let u = start.sqrt_mu * t;
    let mut chi = u / r;
    if (start.alpha * chi * chi).abs() < 0.1 {
        let b = 1.0 - start.alpha * r;
        let s = start.sigma0;
        chi += u
            * u
            * (-s / (2.0 * r * r * r) + u * (s * s / (2.0 * r.powi(5)) - b / (6.0 * r.powi(4))));
    }
    for _ in 0..60 {
        let (k, k1, k2) = start.residual(chi, t);
        let root = (16.0 * k1 * k1 - 20.0 * k * k2).abs().sqrt();
        let step = 5.0 * k / (k1 + root.copysign(k1));
        if !step.is_finite() {
            return f64::NAN;
        }
        chi -= step;
        let size = step.abs();
        if size <= 1e-7 * chi.abs() {
            return chi;
        }
    }
    f64::NAN
}

/// Kepler's flow over `t` of the relative position `r0` and the velocity `v0` under `μ`
/// (K1)–(K3), from the universal anomaly `chi` ([`universal_anomaly`] of their values): one
/// Newton step of Kepler's equation on `T`, then `f`, `g`, `ḟ`, `ġ`. Returns `(r, v)`.
#[inline]
pub fn kepler_flow<T: Scalar>(
    mu: T,
    r0: &[T; 3],
    v0: &[T; 3],
    t: f64,
    chi: f64,
) -> ([T; 3], [T; 3]) {
    let one = T::splat(1.0);
    let start = Start::new(mu, r0, v0);
    let tt = T::splat(t);
    let chi = T::splat(chi);
    let (k, k1, _) = start.residual(chi, tt);
    let chi = chi - k / k1;
    let z = start.alpha * chi * chi;
    let (c2, c3) = stumpff(z);
    let x2c2 = chi * chi * c2;
    let f1 = -x2c2 / start.r0; // f − 1
    let g = (start.sigma0 * x2c2 + start.r0 * chi * (one - z * c3)) / start.sqrt_mu;
    let r: [T; 3] = std::array::from_fn(|i| r0[i] + f1 * r0[i] + g * v0[i]);
    let rn = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let fd = start.sqrt_mu * chi * (z * c3 - one) / (rn * start.r0);
    let gd1 = -x2c2 / rn; // ġ − 1
    let v: [T; 3] = std::array::from_fn(|i| v0[i] + fd * r0[i] + gd1 * v0[i]);
    (r, v)
}

#[cfg(test)]
#[path = "kepler_tests.rs"]
mod tests;
