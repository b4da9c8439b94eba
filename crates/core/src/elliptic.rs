//! Jacobi elliptic functions and elliptic integrals that take `m1 = 1 − m` directly.
//!
//! Near the separatrix of the free rigid body `1 − m` can be 1e-14 or smaller, and forming `m`
//! first rounds most of its digits away; so the descending arithmetic–geometric-mean algorithm
//! (Abramowitz & Stegun 16.4; the recurrence of Cephes' `ellpj`) starts from `b₀ = √m1`, which
//! keeps every digit of `m1`.
//!
//! The integrals are Carlson's symmetric forms `R_F`, `R_J` and `R_C` by the duplication
//! algorithm (B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
//! *Numer. Algorithms* 10 (1995) 13–26; DLMF §19.36(i)). From them: the complete integral
//! `K(m) = R_F(0, m1, 1)` (DLMF 19.25.1) and the incomplete integrals of the first and third
//! kinds (DLMF 19.25.5, 19.25.14).
//!
//! The torque-free motion's own functions share one AGM sequence per parameter ([`Agm`]):
//! `K(m)`, the Jacobi functions (Bulirsch's `sncndn`) and the inverse of `(sn, cn)`
//! (Bulirsch's `el1`). They are generic over [`Real`], so that the same code evaluates one
//! motion (`f64`) or many in SIMD lanes ([`crate::real::Wide`]), bit for bit alike.

use crate::cmath;
use crate::dual::Dual;
use crate::real::{atan, py_max, sin_cos_small, Mask, Real};
use std::f64::consts::PI;

const EPS: f64 = 2.220446049250313e-16;
const MAX_ITER: usize = 64;

/// Below this `m1`, `|u| ≤ K/2` is evaluated by one ascending Landen step and the hyperbolic
/// expansion (neglected terms O(m1³)); above it the AGM's relative error, ~eps·K/m1^¼, is
/// below 3e-14.
pub const NEAR_ONE: f64 = 1e-5;

/// Below this `m1` the third-kind integral in u uses the separatrix forms (see
/// [`third_kind_u`]).
pub const TINY_M1: f64 = 1e-32;

/// Carlson's stopping rule for a relative error below `r = 2⁻⁵³`: `(3r)^(-1/6)` (R_F).
const RF_FACTOR: f64 = 379.82022430228585;
/// The same for R_J: `(r/4)^(-1/6)`.
const RJ_FACTOR: f64 = 574.7005687343988;

/// `(sn, cn, dn, am)` of one argument `u` by the descending AGM (A&S 16.4), with `m1 = 1 − m`
/// given separately (it carries the precision when `m` is close to 1). `am` is the amplitude φ
/// (continuous, `sn = sin φ`). At `m1 = 0` the separatrix limit (tanh, sech, sech, the
/// Gudermannian); at `m = 0` the circular functions.
pub fn jacobi_agm(u: f64, m: f64, m1: f64) -> (f64, f64, f64, f64) {
    if m1 <= 0.0 {
        let sech = 1.0 / u.cosh();
        return (u.tanh(), sech, sech, 2.0 * (0.5 * u).tanh().atan());
    }
    if m <= 0.0 {
        return (u.sin(), u.cos(), 1.0, u);
    }
    let mut a = [0.0f64; MAX_ITER + 1];
    let mut c = [0.0f64; MAX_ITER + 1];
    a[0] = 1.0;
    c[0] = m.sqrt();
    let mut b = m1.sqrt();
    let mut i = 0usize;
    while (c[i] / a[i]).abs() > EPS && i < MAX_ITER {
        let a_prev = a[i];
        a[i + 1] = 0.5 * (a_prev + b);
        c[i + 1] = 0.5 * (a_prev - b);
        b = (a_prev * b).sqrt();
        i += 1;
    }
    let mut phi = 2f64.powi(i as i32) * a[i] * u;
    while i > 0 {
        phi = 0.5 * ((c[i] * phi.sin() / a[i]).asin() + phi);
        i -= 1;
    }
    let sn = phi.sin();
    let cn = phi.cos();
    let dn = (cn * cn + m1 * sn * sn).sqrt(); // = √(1 − m sn²) without cancellation; dn > 0
    (sn, cn, dn, phi)
}

/// `(sn, cn, dn)` for `m1 ≪ 1` and `|u| ≤ K/2`, to round-off relative to each value.
///
/// One ascending Landen transformation (A&S 16.14.2–4) maps `m` to `μ` with complement
/// `μ1 = r²`, `r = (1 − √m)/(1 + √m) = m1/(1 + √m)²` (no cancellation); for parameter `μ` the
/// first-order hyperbolic expansion (A&S 16.15.1–3) is exact to O(μ1² e^{4|w|}), i.e. O(m1³)
/// on |u| ≤ K/2. Then `sn = (1 + r) sn_μ cn_μ / dn_μ`, `cn = (1 + r)/μ · (dn_μ² − r)/dn_μ`,
/// `dn = (1 − r)/μ · (dn_μ² + r)/dn_μ`.
pub fn jacobi_near_one(u: f64, m: f64, m1: f64) -> (f64, f64, f64) {
    let q = 1.0 + m.sqrt();
    let r = m1 / (q * q);
    let mu1 = r * r;
    let mu = 1.0 - mu1;
    let w = u / (1.0 + r);
    let t = w.tanh();
    let s = 1.0 / w.cosh();
    // sinh·cosh·sech² = tanh and sinh·cosh·tanh·sech = tanh²/sech: no overflow for large w
    let sn_mu = t + 0.25 * mu1 * (t - w * s * s);
    let cn_mu = s - 0.25 * mu1 * (t * t / s - w * t * s);
    let dn_mu = s + 0.25 * mu1 * (t * t / s + w * t * s);
    let sn = (1.0 + r) * sn_mu * cn_mu / dn_mu;
    let cn = (1.0 + r) / mu * (dn_mu * dn_mu - r) / dn_mu;
    let dn = (1.0 - r) / mu * (dn_mu * dn_mu + r) / dn_mu;
    (sn, cn, dn)
}

/// Bulirsch's stopping rule: the AGM's last difference below `√eps` of its mean (the error
/// of the next step, quadratic, is then below eps).
const BULIRSCH_CA: f64 = 1.4901161193847656e-8;

/// Levels the AGM sequence may hold: from `m1 = 1e-300` (the smallest the solution uses) it
/// needs 10.
const AGM_LEVELS: usize = 16;

/// The descending arithmetic–geometric-mean sequence of `(1, √m1)` (A&S 17.6), once per
/// parameter: the complete integral `K = π / (2 AGM(1, √m1))` (DLMF 19.8.5) and the Jacobi
/// functions of any argument ([`Agm::sncndn`]) share it. Generic over [`Real`]: one sequence
/// per lane, each as long as its own parameter needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Agm<T: Real = f64> {
    /// The means `a_i` and geometric means `√(a_i b_i)` of each level.
    em: [T; AGM_LEVELS],
    en: [T; AGM_LEVELS],
    /// The lanes that use each level.
    live: [T::Mask; AGM_LEVELS],
    /// The last level any lane uses.
    top: usize,
    /// The final mean.
    mean: T,
}

impl<T: Real> Agm<T> {
    /// The sequence for `0 < m1 ≤ 1`, to Bulirsch's stopping rule (the last difference below
    /// `√eps` of the mean: the next, quadratic, step is then exact to eps). In lanes, a lane
    /// whose sequence has ended keeps its values while the others go on.
    #[inline(always)]
    pub fn new(m1: T) -> Agm<T> {
        let mut g = Agm::<T>::default();
        g.fill(m1);
        g
    }

    /// [`Agm::new`] written over `self` in place (the exact-flow splittings' free flow makes
    /// one at every flow, into the regime it keeps: a sequence made elsewhere and moved there
    /// was a call to `memcpy`). The levels above the last one used keep what they held: no
    /// reader goes past `top`.
    #[inline(always)]
    pub fn fill(&mut self, m1: T) {
        let g = self;
        let mut a = T::splat(1.0);
        let mut emc = m1;
        let mut c = T::splat(1.0);
        let mut going = T::Mask::splat(true);
        for i in 0..AGM_LEVELS {
            g.top = i;
            g.live[i] = going;
            g.em[i] = a;
            emc = T::select(going, emc.sqrt(), emc);
            g.en[i] = emc;
            c = T::select(going, T::splat(0.5) * (a + emc), c);
            going = going & !(a - emc).abs().le(T::splat(BULIRSCH_CA) * a);
            if !going.any() {
                break;
            }
            emc = T::select(going, emc * a, emc);
            a = T::select(going, c, a);
        }
        g.mean = c;
    }

    /// `K(m) = π / (2 AGM(1, √m1))`.
    #[inline(always)]
    pub fn quarter(&self) -> T {
        T::splat(PI) / (T::splat(2.0) * self.mean)
    }

    /// `F(φ | m)` for `0 ≤ φ ≤ π/2` from `y = cot φ ≥ 0` (`∞` at φ = 0), on this sequence:
    /// Bulirsch's procedure `el1` (Bulirsch 1965, *Numer. Math.* 7, 78–90), whose means are
    /// this sequence's scaled by `2^i` at level `i` (so that it is written here in the
    /// sequence's own scale, exactly): `y ← (y − a_i b_i / y)/2` on each level, `l` counting
    /// the branches of the arctangent, and `F = (atan(AGM/y) + π l) / (2^(n+1) AGM)` after
    /// the last level `n`. One division per level and one arctangent ([`atan`]): no inverse
    /// sine, no square root (the sequence is the one `K` and the Jacobi functions use).
    #[inline(always)]
    pub fn first_kind_cot(&self, y: T) -> T {
        let (zero, one, two) = (T::splat(0.0), T::splat(1.0), T::splat(2.0));
        let mut y = y;
        let mut branches = zero;
        let mut scale = one; // 2^(levels passed)
        for i in 0..=self.top {
            let live = self.live[i];
            let more = if i < self.top {
                self.live[i + 1]
            } else {
                T::Mask::splat(false)
            };
            let ab = self.em[i] * self.en[i];
            y = T::select(live, T::splat(0.5) * (y - ab / y), y);
            let crossed = T::select(y.lt(zero), one, zero);
            branches = T::select(
                live,
                T::select(more, two * branches, branches) + crossed,
                branches,
            );
            scale = T::select(live, two * scale, scale);
        }
        (atan(self.mean / y) + T::splat(PI) * branches) / (scale * self.mean)
    }

    /// `(sn, cn, dn)` of `u` for `0 < m < 1` by the descending Landen (Gauss) transformation
    /// in Bulirsch's form (R. Bulirsch, "Numerical calculation of elliptic integrals and
    /// elliptic functions", *Numer. Math.* 7 (1965) 78–90, procedure `sncndn`): one sine and
    /// one cosine of the scaled argument ([`sin_cos_small`]: `|AGM · u| ≤ π/4`), then rational
    /// steps back up the sequence (no inverse sine per level, unlike [`jacobi_agm`]). For
    /// |u| ≤ K/2 ([`jacobi_reduced`]).
    #[inline(always)]
    pub fn sncndn(&self, u: T) -> (T, T, T) {
        let one = T::splat(1.0);
        // sn = u (1 + O(u²)), cn = dn = 1 − O(u²): exact in double precision; the recurrence
        // below would overflow through cot(c u) for tiny u
        let tiny = u.abs().lt(T::splat(1e-9));
        if tiny.all() {
            return (u, one, one);
        }
        let mut c = self.mean;
        let mut dn = one;
        let (sn, cn) = sin_cos_small(c * u);
        let mut a = cn / sn;
        c = c * a;
        for ii in (0..=self.top).rev() {
            let live = self.live[ii];
            let b = self.em[ii];
            let a1 = a * c;
            let c1 = c * dn;
            dn = T::select(live, (self.en[ii] + a1) / (b + a1), dn);
            a = T::select(live, c1 / b, a);
            c = T::select(live, c1, c);
        }
        let r = one / (c * c + one).sqrt();
        let s = T::select(sn.ge(T::splat(0.0)), r, -r);
        // sn = 0 (only at u = 0) is its own result
        let nonzero = sn.unequal(T::splat(0.0)) & !tiny;
        (
            T::select(nonzero, s, T::select(tiny, u, sn)),
            T::select(nonzero, c * s, T::select(tiny, one, cn)),
            T::select(nonzero, dn, one),
        )
    }
}

/// `(sn, cn, dn)` of `u` for `0 < m < 1` ([`Agm::sncndn`] of a sequence made for it).
pub fn jacobi_bulirsch(u: f64, m1: f64) -> (f64, f64, f64) {
    Agm::new(m1).sncndn(u)
}

/// `(sn, cn, dn)` on |u| ≤ K/2: [`jacobi_near_one`] below [`NEAR_ONE`], the circular
/// functions at `m = 0`, else [`Agm::sncndn`] on the sequence `agm` of `m1`.
#[inline(always)]
fn base(u: f64, m: f64, m1: f64, agm: &Agm) -> (f64, f64, f64) {
    if m1 < NEAR_ONE {
        return jacobi_near_one(u, m, m1);
    }
    if m <= 0.0 {
        return u.sin_cos().into_tuple(1.0);
    }
    agm.sncndn(u)
}

trait WithDn {
    fn into_tuple(self, dn: f64) -> (f64, f64, f64);
}

impl WithDn for (f64, f64) {
    #[inline(always)]
    fn into_tuple(self, dn: f64) -> (f64, f64, f64) {
        (self.0, self.1, dn)
    }
}

/// `(sn, cn, dn, p, v)`: the Jacobi functions of `u` with small `cn`, `dn` kept to relative
/// precision, and the reduction `u = 2pK + v` (|v| ≤ K); `k = K(m)`.
///
/// Near odd multiples of the quarter period K (where `sn ≈ ±1`), the amplitude computed by the
/// AGM rounds to ±π/2 and `cn`, `dn` lose all relative precision — exactly where the free body
/// lingers near its unstable axis. So for |v| > K/2 the quarter-period shift `x = K − |v|`:
/// `sn v = ±cd x`, `cn v = √m1 sd x`, `dn v = √m1 nd x` (DLMF 22.4.3), with
/// `sn(u) = (−1)^p sn v`, `cn(u) = (−1)^p cn v`, `dn(u) = dn v`. `K = inf` (m = 1) leaves `u`
/// unreduced.
pub fn jacobi_reduced(u: f64, m: f64, m1: f64, k: f64) -> (f64, f64, f64, f64, f64) {
    let agm = if m1 >= NEAR_ONE && m > 0.0 {
        Agm::new(m1)
    } else {
        Agm::default()
    };
    jacobi_reduced_with(u, m, m1, k, &agm)
}

/// [`jacobi_reduced`] with the AGM sequence of `m1` made once ([`Agm::new`]; unused below
/// [`NEAR_ONE`] and at `m = 0`): the form for many arguments of one parameter. Always
/// inlined, so that a caller's instruction set is its own (the exact splittings' AVX2 flow).
#[inline(always)]
pub fn jacobi_reduced_with(
    u: f64,
    m: f64,
    m1: f64,
    k: f64,
    agm: &Agm,
) -> (f64, f64, f64, f64, f64) {
    if k.is_infinite() {
        let (sn, cn, dn, _) = jacobi_agm(u, m, m1);
        return (sn, cn, dn, 0.0, u);
    }
    reduce_quarter(u, m1.sqrt(), k, &Base { m, m1, agm })
}

/// The Jacobi functions on |v| ≤ K/2 that the quarter-period reduction ([`reduce_quarter`])
/// starts from.
pub trait HalfQuarter<T: Real> {
    /// `(sn v, cn v, dn v)` for |v| ≤ K/2.
    fn sncndn(&self, v: T) -> (T, T, T);
}

impl<T: Real> HalfQuarter<T> for Agm<T> {
    #[inline(always)]
    fn sncndn(&self, v: T) -> (T, T, T) {
        Agm::sncndn(self, v)
    }
}

/// [`base`] as a [`HalfQuarter`].
struct Base<'a> {
    m: f64,
    m1: f64,
    agm: &'a Agm,
}

impl HalfQuarter<f64> for Base<'_> {
    #[inline(always)]
    fn sncndn(&self, v: f64) -> (f64, f64, f64) {
        base(v, self.m, self.m1, self.agm)
    }
}

/// The quarter-period reduction of [`jacobi_reduced`] for finite `k = K(m)`, with
/// `rm1 = √m1` and `base` the Jacobi functions on |v| ≤ K/2: `(sn, cn, dn, p, v)` with
/// `u = 2pK + v`, |v| ≤ K. Generic over [`Real`] (`base` is evaluated once, on `K − |v|`
/// or on `v`).
#[inline(always)]
pub fn reduce_quarter<T: Real>(u: T, rm1: T, k: T, base: &impl HalfQuarter<T>) -> (T, T, T, T, T) {
    let two_k = T::splat(2.0) * k;
    let p = (u / two_k).round_ties_even();
    let v = u - two_k * p;
    let shift = v.abs().gt(T::splat(0.5) * k);
    let (sx, cx, dx) = base.sncndn(T::select(shift, k - v.abs(), v));
    let sn = T::select(shift, T::splat(1.0).copysign(v) * cx / dx, sx);
    let cn = T::select(shift, rm1 * sx / dx, cx);
    let dn = T::select(shift, rm1 / dx, dx);
    let parity = parity(p);
    (parity * sn, parity * cn, dn, p, v)
}

/// `(−1)^p` for an integer `p` (exact below 2⁵³): the sign [`reduce_quarter`] gives `sn` and
/// `cn` of `u = 2pK + v` from those of `v`, so that `sn v = (−1)^p sn u`, exactly.
#[inline(always)]
pub fn parity<T: Real>(p: T) -> T {
    let half = T::splat(0.5) * p;
    let even = (half - half.trunc()).equal(T::splat(0.0));
    T::select(even, T::splat(1.0), T::splat(-1.0))
}

// ------------------------------------------------------------------------- Carlson's forms

/// `R_F(x, y, z) = ½ ∫₀^∞ dt / √((t + x)(t + y)(t + z))` for `x, y, z ≥ 0`, at most one zero
/// (DLMF 19.16.1), by duplication (Carlson 1995, algorithm 1; DLMF 19.36.1). Generic over
/// [`Real`]: in lanes, each lane stops duplicating where its own run stops.
#[inline(always)]
pub fn carlson_rf<T: Real>(x: T, y: T, z: T) -> T {
    let (mut x, mut y, mut z) = (x, y, z);
    let quarter = T::splat(0.25);
    let a0 = (x + y + z) / T::splat(3.0);
    let q = T::splat(RF_FACTOR) * py_max(py_max((a0 - x).abs(), (a0 - y).abs()), (a0 - z).abs());
    let dx = a0 - x;
    let dy = a0 - y;
    let mut a = a0;
    let mut scale = T::splat(1.0); // 4^-n
    loop {
        let going = (scale * q).ge(a.abs()) & scale.gt(T::splat(0.0));
        if !going.any() {
            break;
        }
        let sx = x.sqrt();
        let sy = y.sqrt();
        let sz = z.sqrt();
        let lam = sx * sy + sx * sz + sy * sz;
        a = T::select(going, quarter * (a + lam), a);
        x = T::select(going, quarter * (x + lam), x);
        y = T::select(going, quarter * (y + lam), y);
        z = T::select(going, quarter * (z + lam), z);
        scale = T::select(going, scale * quarter, scale);
    }
    let xx = dx * scale / a;
    let yy = dy * scale / a;
    let zz = -(xx + yy);
    let e2 = xx * yy - zz * zz;
    let e3 = xx * yy * zz;
    let c = T::splat;
    (c(1.0) - e2 / c(10.0) + e3 / c(14.0) + e2 * e2 / c(24.0) - c(3.0) * e2 * e3 / c(44.0))
        / a.sqrt()
}

/// `R_J(x, y, z, p) = 3/2 ∫₀^∞ dt / ((t + p) √((t + x)(t + y)(t + z)))` for `x, y, z ≥ 0` (at
/// most one zero) and `p > 0` (DLMF 19.16.2), by duplication (Carlson 1995, algorithm 3;
/// DLMF 19.36.1), with `R_C(1, 1 + e)` in its cancellation-free form ([`carlson_rc1p`]).
pub fn carlson_rj(x: f64, y: f64, z: f64, p: f64) -> f64 {
    carlson_rj_by::<f64, Libm>(x, y, z, p)
}

/// `R_C(1, 1 + e)` in the form Carlson's duplication for `R_J` takes (`carlson_rj_by`,
/// [`third_kind_from_roots`]): a type rather than a closure, so that the form is inlined into
/// each instruction set's copy of the lanes' code (a closure the compiler leaves out of line
/// is compiled for the baseline alone).
pub trait RcOnePlus<T> {
    fn rc1p(e: T) -> T;
}

/// [`carlson_rc1p`]: libm's `atan` and `atanh`, any `e > −1`.
pub struct Libm;

impl RcOnePlus<f64> for Libm {
    #[inline(always)]
    fn rc1p(e: f64) -> f64 {
        carlson_rc1p(e)
    }
}

/// `rc1p_above`: `e ≥ 0`, generic over [`Real`].
pub struct Above;

impl<T: Real> RcOnePlus<T> for Above {
    #[inline(always)]
    fn rc1p(e: T) -> T {
        rc1p_above(e)
    }
}

/// [`rc1p_dual`]: on dual numbers.
pub struct OnDuals;

impl<const P: usize> RcOnePlus<Dual<P>> for OnDuals {
    #[inline(always)]
    fn rc1p(e: Dual<P>) -> Dual<P> {
        rc1p_dual(e)
    }
}

/// [`carlson_rj`] where `p ≥ max(x, y, z)` (so that every `R_C(1, 1 + e)` of the duplication
/// has `e ≥ 0`: `atan(√e)/√e`, with [`atan`]), generic over [`Real`]: the form of the
/// third-kind integral `Π(n; ·)` with `n ≤ 0` that the attitude of a free body needs
/// ([`third_kind_excess_reduced`]), in lanes each lane duplicating until its own run stops (DLMF
/// 19.36.1, Carlson 1995, algorithm 3).
#[inline(always)]
pub fn carlson_rj_above<T: Real>(x: T, y: T, z: T, p: T) -> T {
    carlson_rj_by::<T, Above>(x, y, z, p)
}

/// Below this `e`, [`rc1p_above`] sums the series of `atan(√e)/√e`.
const RC_SERIES: f64 = 1e-3;

/// `R_C(1, 1 + e) = atan(√e)/√e` for `e ≥ 0` (DLMF 19.2.19), 1 at `e = 0`. Below
/// [`RC_SERIES`], as the duplication's terms soon are (`e` falls by about 64 a step), its
/// series `Σ (−e)^j/(2j + 1)` to `e⁶`: the first term left out, `e⁷/15 < 7e-23`, is far below
/// round-off, and no square root, division or arctangent is taken. Lanes with some `e` above
/// take both forms and select.
#[inline(always)]
fn rc1p_above<T: Real>(e: T) -> T {
    let c = T::splat;
    let small = e.lt(c(RC_SERIES));
    if small.all() {
        return rc1p_series(e);
    }
    let r = e.sqrt();
    let full = T::select(e.gt(c(0.0)), atan(r) / r, c(1.0));
    T::select(small, rc1p_series(e), full)
}

/// [`rc1p_above`]'s series in `e` (a function, not a closure: the compiler left the closure
/// out of line, compiled for the baseline, where the lanes ran it in SSE2).
#[inline(always)]
fn rc1p_series<T: Real>(e: T) -> T {
    let c = T::splat;
    let mut s = c(1.0 / 13.0);
    for j in (0..6).rev() {
        s = c(1.0 / (2 * j + 1) as f64) - e * s;
    }
    s
}

/// Carlson's duplication for `R_J` (DLMF 19.36.1, Carlson 1995, algorithm 3), generic over
/// [`Real`], with `R_C(1, 1 + e)` by `R` ([`RcOnePlus`]): each lane duplicates until its own run stops.
#[inline(always)]
pub(crate) fn carlson_rj_by<T: Real, R: RcOnePlus<T>>(x: T, y: T, z: T, p: T) -> T {
    let c = T::splat;
    let (mut x, mut y, mut z, mut p) = (x, y, z, p);
    let a0 = (x + y + z + c(2.0) * p) / c(5.0);
    let q = c(RJ_FACTOR)
        * py_max(
            py_max(py_max((a0 - x).abs(), (a0 - y).abs()), (a0 - z).abs()),
            (a0 - p).abs(),
        );
    let delta = (p - x) * (p - y) * (p - z);
    let dx = a0 - x;
    let dy = a0 - y;
    let dz = a0 - z;
    let mut a = a0;
    let mut scale = c(1.0); // 4^-m
    let mut total = c(0.0);
    let quarter = c(0.25);
    loop {
        let going = (scale * q).ge(a.abs()) & scale.gt(c(0.0));
        if !going.any() {
            break;
        }
        let sx = x.sqrt();
        let sy = y.sqrt();
        let sz = z.sqrt();
        let sp = p.sqrt();
        let lam = sx * sy + sx * sz + sy * sz;
        let d = (sp + sx) * (sp + sy) * (sp + sz);
        let e = scale * scale * scale * delta / (d * d);
        total = T::select(going, total + scale * R::rc1p(e) / d, total);
        a = T::select(going, quarter * (a + lam), a);
        x = T::select(going, quarter * (x + lam), x);
        y = T::select(going, quarter * (y + lam), y);
        z = T::select(going, quarter * (z + lam), z);
        p = T::select(going, quarter * (p + lam), p);
        scale = T::select(going, scale * quarter, scale);
    }
    let xx = dx * scale / a;
    let yy = dy * scale / a;
    let zz = dz * scale / a;
    let pp = c(-0.5) * (xx + yy + zz);
    let e2 = xx * yy + xx * zz + yy * zz - c(3.0) * pp * pp;
    let e3 = xx * yy * zz + c(2.0) * e2 * pp + c(4.0) * pp * pp * pp;
    let e4 = (c(2.0) * xx * yy * zz + e2 * pp + c(3.0) * pp * pp * pp) * pp;
    let e5 = xx * yy * zz * pp * pp;
    let series = c(1.0) - c(3.0) * e2 / c(14.0) + e3 / c(6.0) + c(9.0) * e2 * e2 / c(88.0)
        - c(3.0) * e4 / c(22.0)
        - c(9.0) * e2 * e3 / c(52.0)
        + c(3.0) * e5 / c(26.0);
    scale * series / (a * a.sqrt()) + c(6.0) * total
}

/// `R_C(1, 1 + e)` for `e > −1` (DLMF 19.2.17–19): `atan(√e)/√e` for e > 0,
/// `atanh(√−e)/√−e` for e < 0, 1 at 0 — accurate for small |e|, where `R_C(x, y)` with
/// `y → x` cancels.
pub fn carlson_rc1p(e: f64) -> f64 {
    if e > 0.0 {
        let r = e.sqrt();
        return r.atan() / r;
    }
    if e < 0.0 {
        let r = (-e).sqrt();
        return cmath::atanh(r) / r;
    }
    1.0
}

// ------------------------------------------------------------------------- integrals in (m, m1)

/// The complete integral of the first kind `K(m) = R_F(0, m1, 1)` (DLMF 19.25.1) from the
/// complementary parameter `m1 = 1 − m`; `inf` at `m1 = 0`.
pub fn ellipk_m1(m1: f64) -> f64 {
    if m1 <= 0.0 {
        return f64::INFINITY;
    }
    Agm::new(m1).quarter()
}

/// `φ = jπ + r` with `r ∈ [−π/2, π/2]`: `(j, r)`.
#[inline]
fn reduce_angle(phi: f64) -> (f64, f64) {
    let j = (phi / PI).round_ties_even();
    (j, phi - j * PI)
}

/// The incomplete integral of the first kind `F(φ | m)` for any real `φ`:
/// `sin r · R_F(cos²r, cos²r + m1 sin²r, 1) + 2jK` with `φ = jπ + r`, |r| ≤ π/2
/// (DLMF 19.25.5; the second argument `Δ² = 1 − m sin²r` formed without cancellation).
pub fn ellipf(phi: f64, _m: f64, m1: f64) -> f64 {
    let (j, r) = reduce_angle(phi);
    let s = r.sin();
    let c = r.cos();
    let mut value = s * carlson_rf(c * c, c * c + m1 * s * s, 1.0);
    if j != 0.0 {
        value += 2.0 * j * ellipk_m1(m1);
    }
    value
}

/// The complete integral of the third kind
/// `Π(n | m) = R_F(0, m1, 1) + (n/3) R_J(0, m1, 1, 1 − n)` for `n < 1` (DLMF 19.25.2); below
/// `n = −1`, where that form cancels, [`third_kind_negative`].
pub fn ellippi_complete(n: f64, m: f64, m1: f64) -> f64 {
    if n < -1.0 {
        let [x, y] = third_kind_negative::<f64, Libm>(-n, 1.0, 1.0, 0.0, m1.sqrt(), m);
        return x + y;
    }
    carlson_rf(0.0, m1, 1.0) + n / 3.0 * carlson_rj(0.0, m1, 1.0, 1.0 - n)
}

/// `Π(n|m) − K(m)`, what the complete integral of the third kind adds to that of the first
/// kind: `(n/3) R_J(0, m1, 1, 1 − n)` for `n ≥ −1` (DLMF 19.25.2, no `K` formed, so that it
/// keeps its digits as `n → 0`: a nearly symmetric body's `n ~ (I2 − I1)`), else
/// [`ellippi_complete`] less `k`, the quarter period given (nothing cancels there).
pub fn ellippi_excess_complete(n: f64, m: f64, m1: f64, k: f64) -> f64 {
    if n < -1.0 {
        return ellippi_complete(n, m, m1) - k;
    }
    n / 3.0 * carlson_rj(0.0, m1, 1.0, 1.0 - n)
}

/// The incomplete integral of the third kind
/// `Π(n; φ | m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ))` for `n < 1` and any real φ:
/// `s R_F(c², Δ², 1) + (n/3) s³ R_J(c², Δ², 1, 1 − n s²)` on |φ| ≤ π/2 (DLMF 19.25.14),
/// extended by `Π(n; φ + jπ) = Π(n; φ) + 2jΠ(n)`; below `n = −1`, where that form cancels,
/// [`third_kind_negative`].
pub fn ellippi(n: f64, phi: f64, m: f64, m1: f64) -> f64 {
    let (j, r) = reduce_angle(phi);
    let s = r.sin();
    let c = r.cos();
    let c2 = c * c;
    let d2 = c2 + m1 * s * s;
    let mut value = if n < -1.0 {
        let [x, y] = third_kind_negative::<f64, Libm>(-n, 1.0, s, c, d2.sqrt(), m);
        x + y
    } else {
        s * carlson_rf(c2, d2, 1.0) + n / 3.0 * s * s * s * carlson_rj(c2, d2, 1.0, 1.0 - n * s * s)
    };
    if j != 0.0 {
        value += 2.0 * j * ellippi_complete(n, m, m1);
    }
    value
}

/// The argument `u` in (−2K, 2K] with `sn u = s`, `cn u = c` (`s² + c² = 1`).
///
/// [`first_kind_in_period`] with `cot = |c/s|`; on the separatrix (`m1 = 0`) `sn = tanh u`,
/// `cn = sech u`: `u = asinh(s/c)`.
pub fn first_kind_from_sn_cn(s: f64, c: f64, _m: f64, m1: f64) -> f64 {
    if m1 == 0.0 {
        if c > 0.0 {
            return cmath::asinh(s / c);
        }
        return f64::INFINITY.copysign(s);
    }
    let agm = Agm::new(m1);
    first_kind_in_period((c / s).abs(), s, c, &agm, agm.quarter())
}

/// The argument `u` in (−2K, 2K] with `sn u` of the sign of `s` and `cn u` of the sign of
/// `c`, and `|cn u / sn u| = cot` (`m1 > 0`; `agm` the sequence of `m1`, `k = K(m)`):
/// `u = ±F(φ)` with `cot φ = cot`, φ ∈ [0, π/2] ([`Agm::first_kind_cot`]) for `c ≥ 0`, and
/// `sign(s)·2K ∓ F(φ)` for `c < 0`. No angle is formed, so a tiny `cn` keeps its digits (an
/// `atan2` would round the amplitude to ±π/2). Generic over [`Real`].
#[inline(always)]
pub fn first_kind_in_period<T: Real>(cot: T, s: T, c: T, agm: &Agm<T>, k: T) -> T {
    let r = agm.first_kind_cot(cot).copysign(s);
    let sign = T::select(s.ge(T::splat(0.0)), T::splat(1.0), T::splat(-1.0));
    T::select(c.ge(T::splat(0.0)), r, sign * T::splat(2.0) * k - r)
}

/// `∫₀^u du/(1 − n tanh²u)` (m = 1, sn = tanh) for `n < 1`: with ν = −n,
/// `u/(1 + ν) + √ν/(1 + ν) · atan(√ν tanh u)` (ν ≥ 0), and for 0 < n < 1
/// `u/(1 − n) − √n/(1 − n) · atanh(√n tanh u)`.
pub fn third_kind_separatrix(n: f64, u: f64) -> f64 {
    if n <= 0.0 {
        let nu = -n;
        let r = nu.sqrt();
        return u / (1.0 + nu) + r / (1.0 + nu) * (r * u.tanh()).atan();
    }
    let r = n.sqrt();
    u / (1.0 - n) - r / (1.0 - n) * cmath::atanh(r * u.tanh())
}

/// `Π(n; am u | m) − u` for `n ≤ 0` from the quarter-period reduction `u = 2pK + v` of its
/// argument ([`reduce_quarter`]): `s = sn v`, `c = cn v ≥ 0`, `d = dn v` and `p`, with
/// `Π(n|m) − K` given ([`ellippi_excess_complete`]): `X(v) + 2p (Π(n|m) − K)`, where
/// `X(v) = (n/3) s³ R_J(c², d², 1, 1 − n s²)` (DLMF 19.25.14, whose first-kind part
/// `s R_F(c², d², 1) = F(am v)` is `v` itself for |v| ≤ K). Left out, the first-kind part
/// `u` is known exactly (`u − u0 = λt`), so ψ does not take it from a difference of rounded
/// arguments, which ψ's factor `1/λ` had magnified. Generic over [`Real`] (the attitude of
/// free bodies in lanes); the reduction is the one ω(t) already made.
#[inline(always)]
pub fn third_kind_excess_reduced<T: Real>(n: T, s: T, c: T, d: T, p: T, excess: T) -> T {
    let k = T::splat;
    let x = third_kind_excess(n, s, c, d);
    T::select(p.unequal(k(0.0)), x + k(2.0) * p * excess, x)
}

/// `X(v) = (n/3) s³ R_J(c², d², 1, 1 − n s²)` from `s = sn v`, `c = cn v ≥ 0`, `d = dn v`
/// (|v| ≤ K, `n ≤ 0`): what the reduced integral of the third kind `G(v)`
/// ([`third_kind_excess_reduced`]) adds to its first-kind part `s R_F(c², d², 1) = F(am v) = v`
/// (DLMF 19.25.14 and 19.25.5), so that `Π(u) − Π(u0) = (u − u0) + X(v) − X(v0)` within a half
/// period. Generic over [`Real`].
#[inline(always)]
pub fn third_kind_excess<T: Real>(n: T, s: T, c: T, d: T) -> T {
    let k = T::splat;
    n / k(3.0) * s * s * s * carlson_rj_above(c * c, d * d, k(1.0), k(1.0) - n * s * s)
}

/// `R_F(c², d², 1)` and `R_J(c², d², 1, p)` (`c, d ≥ 0`, `p > 0`) with the first duplication
/// step taken on the square roots `c`, `d`, `1` and `√p` themselves: `R_F(x, y, z) =
/// R_F(x₁, y₁, z₁)` and `R_J(x, y, z, p) = R_J(x₁, y₁, z₁, p₁)/4 + 6 R_C(1, 1 + δ/d₀²)/d₀`, with
/// `x₁ = (x + λ)/4`, …, `λ = √x√y + √y√z + √z√x`, `δ = (p − x)(p − y)(p − z)`,
/// `d₀ = (√p + √x)(√p + √y)(√p + √z)` (DLMF 19.26.18; the first step of Carlson 1995,
/// algorithm 3). Generic over [`Real`], with `R_C(1, 1 + e)` by `R` ([`RcOnePlus`]). On dual
/// numbers no argument is then zero where it is differentiated: `cn v = 0` at `v = ±K` carries
/// its derivative in `c`, which `√(c²)` would lose (0/0).
#[inline(always)]
pub fn carlson_rf_rj_from_roots<T: Real, R: RcOnePlus<T>>(c: T, d: T, p: T) -> (T, T) {
    let k = T::splat;
    let one = k(1.0);
    let (c2, d2) = (c * c, d * d);
    let sp = p.sqrt();
    let lam = c * d + c + d;
    let q = k(0.25);
    let (x1, y1, z1, p1) = (
        q * (c2 + lam),
        q * (d2 + lam),
        q * (one + lam),
        q * (p + lam),
    );
    let d0 = (sp + c) * (sp + d) * (sp + one);
    let delta = (p - c2) * (p - d2) * (p - one);
    let rj = q * carlson_rj_by::<T, R>(x1, y1, z1, p1) + k(6.0) * R::rc1p(delta / (d0 * d0)) / d0;
    (carlson_rf(x1, y1, z1), rj)
}

/// The reduced integral of the third kind `G = s R_F(c², d², 1) + (n/3) s³ R_J(c², d², 1, 1 − n s²)` (n < 1,
/// `c ≥ 0`) by [`carlson_rf_rj_from_roots`].
pub fn third_kind_from_roots<T: Real, R: RcOnePlus<T>>(n: T, s: T, c: T, d: T) -> T {
    third_kind_with_p::<T, R>(n, s, c, d, T::splat(1.0) - n * s * s)
}

/// [`third_kind_from_roots`] less its first-kind part `s R_F(c², d², 1) = F(am v) = v`:
/// `X(v) = (n/3) s³ R_J(c², d², 1, 1 − n s²)` by [`carlson_rf_rj_from_roots`] (the closed
/// form's derivatives on dual numbers, which take `u − u0 = λt` apart, exactly; at `s = 1`,
/// `c = 0`, `d = √m1`, `Π(n|m) − K`).
pub fn third_kind_excess_from_roots<T: Real, R: RcOnePlus<T>>(n: T, s: T, c: T, d: T) -> T {
    let (_, rj) = carlson_rf_rj_from_roots::<T, R>(c, d, T::splat(1.0) - n * s * s);
    n / T::splat(3.0) * s * s * s * rj
}

/// [`third_kind_from_roots`] with `p = 1 − n s²` given: where `n → 1` and `s → ±1` it is small,
/// and a caller that knows it as a sum of positive numbers (the heavy top's `(1 − u)/(1 − u₁)`)
/// keeps the digits `1 − n s²` would lose.
#[inline(always)]
pub fn third_kind_with_p<T: Real, R: RcOnePlus<T>>(n: T, s: T, c: T, d: T, p: T) -> T {
    let (rf, rj) = carlson_rf_rj_from_roots::<T, R>(c, d, p);
    s * rf + n / T::splat(3.0) * s * s * s * rj
}

/// `Π(n; φ | m)` for a negative `n = −p/q` (`p > 0`, `q ≥ 0`) as `q X + √q Y`, from
/// `s = sin φ`, `c = cos φ ≥ 0` and `d = √(1 − m s²)` (|φ| ≤ π/2):
///
/// ```text
///     X = (m / 3p) s³ R_J(c², d², 1, 1 + (m q/p) s²),
///     Y = atan2(s h, c d √q) / h,      h² = p + (1 + m) q + m q²/p.
/// ```
///
/// This is DLMF 19.7.9, `Π(φ, n) + Π(φ, m/n) = F(φ) + √c₀ R_C((c₀ − 1)(c₀ − m), (c₀ − n)(c₀ − m/n))`
/// (`c₀ = csc²φ`), with `F(φ) − Π(φ, m/n) = −(m/3n) s³ R_J(…)` (DLMF 19.25.14) and `R_C(x, y) =
/// atan(√((y − x)/x))/√(y − x)` (DLMF 19.2.18), where `y − x = s⁻² h²/q` exactly. Both parts are
/// positive for `s > 0`: where `n ≪ −1` the direct form `s R_F + (n/3) s³ R_J` cancels to
/// `O(|n|^−½)` and loses `√|n|` of its relative accuracy (1e-9 at `n = −1e13`), and `q → 0`
/// (`n → −∞`) is a step `±π/(2h)` in `√q Y` (the heavy top passing through the hanging
/// vertical, `q = 1 + u₁`). The complete integral is `s = 1`, `c = 0`, `d = √m1`:
/// `X = (m/3p) R_J(0, m1, 1, 1 + m q/p)`, `Y = π/(2h)`. Generic over [`Real`] (the heavy top's
/// derivatives); `atan2(y, x) = 2 atan(y/(r + x))` for `x ≥ 0`, `r = √(x² + y²)`, 0 at `r = 0`.
#[inline(always)]
pub fn third_kind_negative<T: Real, R: RcOnePlus<T>>(p: T, q: T, s: T, c: T, d: T, m: T) -> [T; 2] {
    let k = T::splat;
    let mq_p = m * q / p;
    let (_, rj) = carlson_rf_rj_from_roots::<T, R>(c, d, k(1.0) + mq_p * s * s);
    let x = m / (k(3.0) * p) * s * s * s * rj;
    let h = (p + (k(1.0) + m) * q + mq_p * q).sqrt();
    [x, atan2_right(s * h, c * d * q.sqrt()) / h]
}

/// `atan2(y, x)` for `x ≥ 0`, generic over [`Real`]: `2 atan(y/(r + x))`, `r = √(x² + y²)`
/// (no division by a vanishing `x`), and 0 at `r = 0`.
#[inline(always)]
pub fn atan2_right<T: Real>(y: T, x: T) -> T {
    let k = T::splat;
    let r = (x * x + y * y).sqrt();
    T::select(r.gt(k(0.0)), k(2.0) * atan(y / (r + x)), k(0.0))
}

/// `∫₀^u du' / (1 − n sn²u')  (= Π(n; am u | m))` for `n < 1`, accurate for every u;
/// `k = K(m)`.
///
/// `u = 2pK + v` with |v| ≤ K: the integral is `2p Π(n|m) + G(v)`, with
/// `G(v) = s R_F(c², d², 1) + (n/3) s³ R_J(c², d², 1, 1 − n s²)` from `s = sn v`,
/// `c = cn v ≥ 0`, `d = dn v` taken from [`jacobi_reduced`] (accurate near v = ±K, where the
/// free body lingers by its unstable axis). For `m1 <` [`TINY_M1`], `sn(v|m) = tanh v + O(√m1)`
/// on |v| ≤ K/2 and `cd ≈ 1` beyond, so there `G` is the separatrix form, and
/// `Π(n|m) − (K − |v|)/(1 − n)` up to K, both exact to O(√m1) < 1e-16.
pub fn third_kind_u(n: f64, u: f64, m: f64, m1: f64, k: f64) -> f64 {
    if m1 == 0.0 {
        return third_kind_separatrix(n, u);
    }
    let (_, _, _, p, v) = jacobi_reduced(u, m, m1, k);
    let mut g = if m1 < TINY_M1 {
        if v.abs() <= 0.5 * k {
            third_kind_separatrix(n, v)
        } else {
            1f64.copysign(v) * (ellippi_complete(n, m, m1) - (k - v.abs()) / (1.0 - n))
        }
    } else {
        let (s, c, d, _, _) = jacobi_reduced(v, m, m1, k);
        let c2 = c * c;
        let d2 = d * d;
        s * carlson_rf(c2, d2, 1.0) + n / 3.0 * s * s * s * carlson_rj(c2, d2, 1.0, 1.0 - n * s * s)
    };
    if p != 0.0 {
        g += 2.0 * p * ellippi_complete(n, m, m1);
    }
    g
}

// ------------------------------------------------------------------- on dual numbers

/// `∂F(am u | m)/∂m` at fixed amplitude within the half period `n = round(u / 2K)` of `u`, from
/// `(sn, cn, dn)` of `u`: `(−1)^n (sn³/6) R_D(cn², 1, dn²)` (differentiating
/// `F = sin φ R_F(cos²φ, 1 − m sin²φ, 1)`, DLMF 19.25.5, with `∂R_F/∂z = −R_D/6`, on
/// |φ| ≤ π/2): Carlson's form, with no cancellation as `m → 0` or `m → 1`. The whole
/// derivative adds `2n ∂K/∂m` (`F(φ + nπ) = F(φ) + 2nK`, `∂K/∂m = R_D(0, 1, m1)/6`), which
/// [`jacobi_dual`] adds for the half periods its caller does not carry.
pub fn first_kind_dm_reduced(sn: f64, cn: f64, dn: f64, n: f64) -> f64 {
    let sign = if n.rem_euclid(2.0) == 0.0 { 1.0 } else { -1.0 };
    let (c2, d2) = (cn * cn, dn * dn);
    sign * sn * sn * sn / 6.0 * carlson_rj(c2, 1.0, d2, d2)
}

/// `(sn u, cn u, dn u)` of a dual `u` and parameter `m` (`m1 = 1 − m`, `k = K(m)`,
/// `∂K/∂m = k_m`, `agm` the sequence of `m1`), with their derivatives: in `u` (DLMF
/// 22.13.1–3) and, at fixed `u`, in `m` through the amplitude,
/// `∂am/∂m = −dn ∂F(φ|m)/∂m` ([`first_kind_dm_reduced`] and `2n ∂K/∂m`); and the reduction's `p`
/// (`u = 2pK + v`, |v| ≤ K, [`jacobi_reduced_with`]).
///
/// `carried` half periods of `u` have their `2 carried ∂K/∂m` left out of `u`'s own
/// derivatives by the caller, and are left out here too: `u = u0 + λt` with `u0` in its
/// half period `n0` then differentiates `2(n − n0) ∂K/∂m`, not `2n ∂K/∂m` twice over, which
/// near the separatrix (`∂K/∂m ~ 1/m1`) had cancelled to `ε/m1`.
#[allow(clippy::type_complexity)]
#[allow(clippy::too_many_arguments)]
pub fn jacobi_dual<const P: usize>(
    u: Dual<P>,
    m: Dual<P>,
    m1: f64,
    k: f64,
    k_m: f64,
    agm: &Agm,
    carried: f64,
) -> (Dual<P>, Dual<P>, Dual<P>, f64) {
    let (sn, cn, dn, p, _) = jacobi_reduced_with(u.v, m.v, m1, k, agm);
    let n = (u.v / (2.0 * k)).round();
    let am_m = -dn * (first_kind_dm_reduced(sn, cn, dn, n) + 2.0 * (n - carried) * k_m);
    let dual = |v: f64, du: f64, dm: f64| {
        let mut out = Dual::new(v, [0.0; P]);
        for j in 0..P {
            out.d[j] = du * u.d[j] + dm * m.d[j];
        }
        out
    };
    (
        dual(sn, cn * dn, cn * am_m),
        dual(cn, -sn * dn, -sn * am_m),
        dual(
            dn,
            -m.v * sn * cn,
            -(sn * sn + 2.0 * m.v * sn * cn * am_m) / (2.0 * dn),
        ),
        p,
    )
}

/// `R_C(1, 1 + e)` on dual numbers (e > −1, [`carlson_rc1p`]'s value) with its derivative
/// `(1/(1 + e) − R_C)/(2e)`, or for |e| < 0.1 the series
/// `Σ_{k≥1} (−1)^k k e^{k−1}/(2k + 1)`, where that difference cancels (the later `e` of a
/// duplication are tiny, `4^{−3j}` times the first): the `R_C` that
/// [`third_kind_from_roots`] takes on dual numbers.
pub fn rc1p_dual<const P: usize>(e: Dual<P>) -> Dual<P> {
    let v = carlson_rc1p(e.v);
    let slope = if e.v.abs() < 0.1 {
        (1..=18).rev().fold(0.0, |acc, k| {
            let k = k as f64;
            let sign = if k % 2.0 == 0.0 { 1.0 } else { -1.0 };
            acc * e.v + sign * k / (2.0 * k + 1.0)
        })
    } else {
        (1.0 / (1.0 + e.v) - v) / (2.0 * e.v)
    };
    Dual::new(v, e.d.map(|x| x * slope))
}

#[cfg(test)]
#[path = "elliptic_tests.rs"]
mod tests;
