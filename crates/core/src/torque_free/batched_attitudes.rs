//! `Q(t)` of many torque-free motions at once, body frame (`docs/theory.md` §1,
//! eqs (20)–(33); `docs/torque_free.md`): [`exact_attitudes`]. Bodies with three distinct
//! moments run [`WIDTH`] members at a time in SIMD lanes ([`attitudes_in_lanes`]): the
//! attitude's formulas ([`EllipticMotion`]: `Π(u)` from the reduction of `u` that ω(t) makes,
//! by Carlson's `R_F` and `R_J` with a polynomial `atan`; θ and φ as ratios of the body
//! momentum's components; ψ's sine and cosine by [`crate::real::sin_cos`]), each lane bit for
//! bit its single run ([`attitude_at`]). Members off the plain elliptic case (fixed points,
//! the separatrix and `m1 <` [`NEAR_ONE`], extreme scales, symmetric bodies) run one by one.

use rayon::prelude::*;

use super::{
    attitude_at, reduced_third_kind, to_sorted, AttitudeSetup, EllipticMotion, Regime, PARALLEL_MIN,
};
use crate::elliptic::{reduce_quarter, Agm, NEAR_ONE};
use crate::real::{Mask, Real, Wide, WideMask, WIDTH};
use crate::so3::{matmul, Mat3, Vec3};

/// `Q Sᵀ`: an attitude with the sorted principal frame as body frame, turned to the body frame.
#[inline(always)]
fn sorted_to_body<T: Real>(qs: &[[T; 3]; 3], s: &Mat3) -> [[T; 3]; 3] {
    let c = T::splat;
    qs.map(|row| [0, 1, 2].map(|k| row[0] * c(s[k][0]) + row[1] * c(s[k][1]) + row[2] * c(s[k][2])))
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
pub(super) fn attitudes_one_by_one(
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
pub(super) fn plain_motion(
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
        let red = reduce_quarter(u, self.rm1, self.quarter, &self.agm);
        sorted_to_body(&motion.attitude(moments, t, red, plain), s)
    }
}

#[inline(always)]
fn lane_matrix<const N: usize>(q: &[[Wide<N>; 3]; 3], l: usize) -> Mat3 {
    q.map(|row| row.map(|x| x.0[l]))
}

crate::multiversion! {
    /// [`exact_attitudes`] of a body with three distinct moments in lanes, the instruction set
    /// chosen at run time (as [`omegas_in_lanes`](super::omegas_in_lanes)); `q0s` one per
    /// member or one shared.
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
