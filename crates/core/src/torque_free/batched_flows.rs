//! The exact-flow splittings' free flows of many motions of one body at once, in SIMD lanes
//! ([`free_flows_in_lanes`]): each lane starts a torque-free motion from its own ω and Q and
//! follows it for a time, as [`crate::exact_splitting::FreeFlow`] does for one body with
//! [`Regime::with`](super::Regime::with), [`AttitudeSetup::frame`](super::AttitudeSetup::frame),
//! [`ThirdKindStart`](super::ThirdKindStart) and [`motion_from_start`](super::motion_from_start),
//! by the same generic formulas in the same order, so that each plain lane is bit for bit its
//! single run (`docs/theory.md` §5, (S6); eqs (20)–(33)).

use super::attitude::{invariable_frame_with, psi_terms, EllipticMotion};
use super::batched_omegas::{times_pow2, LaneMotion};
use super::{jacobi_omega, Radicals};
use crate::elliptic::{ellippi_excess_complete, parity, reduce_quarter, third_kind_excess};
use crate::invariants::principal_invariants;
use crate::real::{Mask, Real, Wide, WideMask};
use crate::so3::Vec3;

crate::multiversion! {
    /// The free flows of `N` motions of a body with three distinct sorted `moments` (its
    /// [`Radicals`]) from the sorted-frame ω `w` and attitude `q0` (rows, sorted frame → space)
    /// over the time `t` each: `(ω(t), Q(t), plain)`. A lane is `plain` where its motion is the
    /// plain elliptic case the lanes of [`exact_omegas`](super::exact_omegas) take (off the
    /// fixed points, the separatrix and its neighbourhood, extreme scales) and its sums of
    /// squares need no `hypot`; the other lanes' values are meaningless, and their flows are
    /// the caller's to take one at a time.
    /// The instruction set is chosen at run time (AVX-512, AVX2, the baseline), as in
    /// [`crate::lanes`].
    pub fn free_flows_in_lanes, free_flows_in_lanes_with [const N: usize] (
        moments: Vec3,
        radicals: &Radicals,
        w: [Wide<N>; 3],
        q0: &[[Wide<N>; 3]; 3],
        t: Wide<N>,
    ) -> ([Wide<N>; 3], [[Wide<N>; 3]; 3], WideMask<N>) where [] => free_flows_any::<N>, up to Avx512;
}

/// [`free_flows_in_lanes`]' body, inlined into each target's copy of it.
#[inline(always)]
fn free_flows_any<const N: usize>(
    moments: Vec3,
    radicals: &Radicals,
    w: [Wide<N>; 3],
    q0: &[[Wide<N>; 3]; 3],
    t: Wide<N>,
) -> ([Wide<N>; 3], [[Wide<N>; 3]; 3], WideMask<N>) {
    let c = Wide::<N>::splat;
    let im = moments.map(c);
    // the regime: the Jacobi form, K, u0 ([`Regime::with`]) and |L| of the scaled ω
    // filled in place (`LaneMotion::new` moved its 12 kB of AGM sequences three times)
    let mut lm = LaneMotion::default();
    let mut plain = lm.fill(moments, radicals, w);
    let x = w.map(|wk| times_pow2(wk, -lm.e));
    let momentum = times_pow2(principal_invariants(im, x).1, lm.e);
    for l in 0..N {
        plain.and_lane(l, momentum.0[l].is_normal());
    }
    // the frame ([`AttitudeSetup::frame`]): ψ's terms about either pole, the invariable frame
    let pi0 = [im[0] * w[0], im[1] * w[1], im[2] * w[2]];
    let about3 = psi_terms(true, im, momentum, lm.lam);
    let about1 = psi_terms(false, im, momentum, lm.lam);
    let pick = |a: Wide<N>, b: Wide<N>| Wide::select(lm.e3, a, b);
    let (iq, n, psi_pi) = (
        pick(about3.1, about1.1),
        pick(about3.2, about1.2),
        pick(about3.3, about1.3),
    );
    let p0 = invariable_frame_with(lm.e3, pi0, |r, k| q0[r][k], &mut plain);
    // the start of Π(u) − Π(u0) ([`ThirdKindStart::new`]): the Jacobi functions of u0 from ω
    let f = |i: usize| w[i] / lm.sa[i];
    let (sn0, cn0, dn0) = (f(1), pick(f(0), f(2)), pick(f(2), f(0)));
    let two_k = c(2.0) * lm.quarter;
    let start_p = (lm.u0 / two_k).round_ties_even();
    let start_par = parity(start_p);
    let x0 = third_kind_excess(n, start_par * sn0, start_par * cn0, dn0);
    // the motion at t ([`motion_from_start`])
    let u = lm.u0 + lm.lam * t;
    let (sn, cn, dn, p, _) = reduce_quarter(u, lm.rm1, lm.quarter, &lm.agm);
    let omega = jacobi_omega(lm.e3, lm.sa, sn, cn, dn);
    let par = parity(p);
    // Π(u) − Π(u0) less its first-kind part λt, which ψ takes exactly
    let g = third_kind_excess(n, par * sn, par * cn, dn) - x0;
    let crossed = p.unequal(start_p);
    let mut big_pi = g;
    if crossed.any() {
        // the lanes whose flow left its half period: Π(n|m) − K, each its own
        let mut pc = [0.0; N];
        for (l, x) in pc.iter_mut().enumerate() {
            if crossed.get(l) && plain.get(l) {
                *x = ellippi_excess_complete(n.0[l], lm.m.0[l], lm.m1.0[l], lm.quarter.0[l]);
            }
        }
        big_pi = Wide::select(crossed, g + c(2.0) * (p - start_p) * Wide(pc), g);
    }
    let motion = EllipticMotion {
        sa: lm.sa,
        e3: lm.e3,
        n,
        pi_complete: c(0.0),
        pi_u0: c(0.0),
        psi_pi,
        momentum,
        i_other: iq,
        p0,
    };
    let q = motion.attitude_with_excess(im, t, omega, big_pi, &mut plain);
    (omega, q, plain)
}
