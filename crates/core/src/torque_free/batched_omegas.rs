//! ω(t) of many torque-free motions at once, body frame (`docs/theory.md` §1, eqs (20)–(33);
//! `docs/torque_free.md`): [`exact_omegas`] and the polhode families, periods and flip
//! intervals ([`families`]). Bodies with three distinct moments run [`WIDTH`] members at a time
//! in SIMD lanes ([`omegas_in_lanes`]: structure of arrays, the member loop innermost, the
//! instruction set chosen at run time), each lane computing bit for bit what its single run
//! ([`Regime::omega_at`]) computes; the members off the plain elliptic case run one by one.

use rayon::prelude::*;

use super::{
    jacobi_omega, polhode_radii, JacobiForm, Radicals, Regime, AROUND_E1, AROUND_E3,
    NEAR_UNSTABLE_AXIS,
};
use crate::elliptic::{first_kind_in_period, reduce_quarter, Agm, NEAR_ONE};
use crate::real::{py_max, Mask, Real, Wide, WideMask, WIDTH};
use crate::so3::{Mat3, Vec3};

/// `Sᵀ ω`: body-frame ω in the sorted principal frame. A component smaller than the largest
/// times 2⁻¹⁰²² (subnormal once ω is scaled to its largest component: zero to round-off) is
/// flushed to a zero of its sign, so that the closed forms never work with the few digits a
/// subnormal carries (ω = (2.2e-313, 0, 0.125) gave an attitude 3e-11 off the rotation about
/// e3 it is to round-off).
#[inline(always)]
pub(super) fn to_sorted<T: Real>(s: &Mat3, w: [T; 3]) -> [T; 3] {
    let c = T::splat;
    let v = [
        c(s[0][0]) * w[0] + c(s[1][0]) * w[1] + c(s[2][0]) * w[2],
        c(s[0][1]) * w[0] + c(s[1][1]) * w[1] + c(s[2][1]) * w[2],
        c(s[0][2]) * w[0] + c(s[1][2]) * w[1] + c(s[2][2]) * w[2],
    ];
    let floor = py_max(py_max(v[0].abs(), v[1].abs()), v[2].abs()) * c(f64::MIN_POSITIVE);
    v.map(|x| T::select(x.abs().lt(floor), c(0.0).copysign(x), x))
}

/// `S v`: sorted-frame `v` in the body frame.
#[inline(always)]
fn from_sorted<T: Real>(s: &Mat3, v: [T; 3]) -> [T; 3] {
    let c = T::splat;
    [
        c(s[0][0]) * v[0] + c(s[0][1]) * v[1] + c(s[0][2]) * v[2],
        c(s[1][0]) * v[0] + c(s[1][1]) * v[1] + c(s[1][2]) * v[2],
        c(s[2][0]) * v[0] + c(s[2][1]) * v[1] + c(s[2][2]) * v[2],
    ]
}

/// Below this many evaluations (members × times) the batched functions run on one thread.
pub(super) const PARALLEL_MIN: usize = 4096;

/// The regime of the motion from body-frame ω `w`, for a body with sorted moments `moments`
/// and sorted axes `s` (columns, body coordinates).
pub fn regime_of(moments: Vec3, s: &Mat3, symmetry: u8, w: Vec3) -> Regime {
    Regime::new(moments, symmetry, to_sorted(s, w))
}

/// ω(t), body frame, of the torque-free motions from the body-frame ω `ws` at the times `ts`
/// (from t = 0), into `out` (`ws.len() · ts.len()` vectors, member-major). One pass per member:
/// the regime, then every time. Bodies with three distinct moments run [`WIDTH`] members at a
/// time in SIMD lanes ([`omegas_in_lanes`]), each lane computing bit for bit what its single
/// run computes; blocks of members are shared among rayon's threads.
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
    let block = |ws: &[Vec3], out: &mut [Vec3]| {
        if symmetry == 0 {
            omegas_in_lanes::<WIDTH>(moments, s, &radicals, ws, ts, out);
        } else {
            for (w, o) in ws.iter().zip(out.chunks_mut(n)) {
                omegas_one_by_one(moments, s, &radicals, symmetry, *w, ts, o);
            }
        }
    };
    if ws.len() > 1 && ws.len() * n >= PARALLEL_MIN {
        ws.par_chunks(LANES_BLOCK)
            .zip(out.par_chunks_mut(n * LANES_BLOCK))
            .for_each(|(w, o)| block(w, o));
    } else {
        block(ws, out);
    }
}

/// Members per rayon task of [`exact_omegas`].
const LANES_BLOCK: usize = 256;

/// ω(t) (body frame) of one member at the times `ts`: its [`Regime`], then every time.
#[inline]
pub(super) fn omegas_one_by_one(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    symmetry: u8,
    w: Vec3,
    ts: &[f64],
    out: &mut [Vec3],
) {
    let ws = to_sorted(s, w);
    let reg = Regime::with(moments, radicals, symmetry, ws);
    for (o, &t) in out.iter_mut().zip(ts) {
        *o = from_sorted(s, reg.omega_at(moments, ws, t));
    }
}

/// What ω(t) needs of [`WIDTH`] motions in lanes (a body with three distinct moments): the
/// [`Regime`]'s elliptic fields, with `rm1 = √m1` and `sa = σ α`.
#[derive(Default)]
pub(super) struct LaneMotion<const N: usize> {
    pub(super) u0: Wide<N>,
    pub(super) lam: Wide<N>,
    pub(super) rm1: Wide<N>,
    pub(super) quarter: Wide<N>,
    pub(super) sa: [Wide<N>; 3],
    pub(super) e3: WideMask<N>,
    pub(super) agm: Agm<Wide<N>>,
    /// The parameter and its complement, and the exponent `e` of ω's scale (`ω = 2^e x`).
    pub(super) m: Wide<N>,
    pub(super) m1: Wide<N>,
    pub(super) e: Wide<N>,
}

/// `x` times `2^e` for integer `e` in [−1022, 1023] (a power of two made from its bits).
#[inline(always)]
pub(super) fn times_pow2<const N: usize>(x: Wide<N>, e: Wide<N>) -> Wide<N> {
    let mut p = [0.0; N];
    for l in 0..N {
        p[l] = f64::from_bits(((e.0[l] as i64 + 1023) as u64) << 52);
    }
    x * Wide(p)
}

impl<const N: usize> LaneMotion<N> {
    /// The motions from the sorted-frame ω `w`, and the lanes where they are what
    /// [`Regime::with`] makes ("plain": a normal scale, off the fixed points, `m1 ≥`
    /// [`NEAR_ONE`], `m > 0`, every sum of squares safe, normal amplitudes). The other lanes'
    /// values are meaningless; they are evaluated one at a time.
    #[inline(always)]
    pub(super) fn new(
        moments: Vec3,
        radicals: &Radicals,
        w: [Wide<N>; 3],
    ) -> (LaneMotion<N>, WideMask<N>) {
        let mut motion = LaneMotion::default();
        let plain = motion.fill(moments, radicals, w);
        (motion, plain)
    }

    /// [`LaneMotion::new`] written over `self` in place, its plain lanes returned: the AGM
    /// sequences of `N` lanes are some 12 kB, and a motion made elsewhere and moved (from
    /// [`Agm::new`], into the motion, out of `new`) was three copies of them at every flow
    /// in lanes.
    #[inline(always)]
    pub(super) fn fill(
        &mut self,
        moments: Vec3,
        radicals: &Radicals,
        w: [Wide<N>; 3],
    ) -> WideMask<N> {
        let c = Wide::<N>::splat;
        let big = py_max(py_max(w[0].abs(), w[1].abs()), w[2].abs());
        // frexp's exponent of a normal `big` (ω scaled by 2^-e exactly, as `Regime::with`)
        let mut e = [0.0; N];
        let mut plain = WideMask::<N>::splat(true);
        for l in 0..N {
            let biased = (big.0[l].to_bits() >> 52) & 0x7ff;
            plain.and_lane(l, (1..=2044).contains(&biased));
            e[l] = biased as f64 - 1022.0;
        }
        let e = Wide(e);
        let x = [
            times_pow2(w[0], -e),
            times_pow2(w[1], -e),
            times_pow2(w[2], -e),
        ];
        // off the intermediate axis (`NEAR_UNSTABLE_AXIS`)
        plain = plain & py_max(x[0].abs(), x[2].abs()).gt(c(NEAR_UNSTABLE_AXIS) * x[1].abs());
        let radicals = radicals.splat::<Wide<N>>();
        let (q3, q1) = polhode_radii(&radicals, x, &mut plain);
        let f = JacobiForm::new(moments.map(c), &radicals, x, q3, q1);
        plain = plain & f.m1.ge(c(NEAR_ONE)) & f.m.gt(c(0.0));
        // benign values in the other lanes, where the loops below end at once
        let m1 = Wide::<N>::select(plain, f.m1, c(0.5));
        self.agm.fill(m1);
        let agm = &self.agm;
        let quarter = agm.quarter();
        let u0 = first_kind_in_period(f.cot0, f.sn0, f.cn0, agm, quarter);
        let alpha = [
            times_pow2(f.alpha[0], e),
            times_pow2(f.alpha[1], e),
            times_pow2(f.alpha[2], e),
        ];
        let lam = times_pow2(f.lam, e);
        for l in 0..N {
            let normal = alpha[0].0[l].is_normal()
                && alpha[1].0[l].is_normal()
                && alpha[2].0[l].is_normal()
                && lam.0[l].is_normal();
            plain.and_lane(l, normal);
        }
        let s2 = f.s1 * f.s3;
        self.u0 = u0;
        self.lam = lam;
        self.rm1 = m1.sqrt();
        self.quarter = quarter;
        self.sa = [f.s1 * alpha[0], s2 * alpha[1], f.s3 * alpha[2]];
        self.e3 = f.e3;
        self.m = f.m;
        self.m1 = m1;
        self.e = e;
        plain
    }

    /// ω(t) (sorted principal frame) in every lane: as [`Regime::omega_at`].
    #[inline(always)]
    fn omega_at(&self, t: Wide<N>) -> [Wide<N>; 3] {
        let u = self.u0 + self.lam * t;
        let (sn, cn, dn, _, _) = reduce_quarter(u, self.rm1, self.quarter, &self.agm);
        jacobi_omega(self.e3, self.sa, sn, cn, dn)
    }
}

crate::multiversion! {
    /// [`exact_omegas`] for a body with three distinct moments, [`WIDTH`] members at a time in
    /// SIMD lanes; a lane off the plain elliptic case ([`LaneMotion::new`]: fixed points, the
    /// separatrix and its neighbourhood `m1 <` [`NEAR_ONE`], extreme scales) is evaluated on its own.
    /// The instruction set is chosen at run time (AVX-512, AVX2, the baseline), as in
    /// [`crate::lanes`].
    pub fn omegas_in_lanes, omegas_in_lanes_with [const N: usize] (
        moments: Vec3,
        s: &Mat3,
        radicals: &Radicals,
        ws: &[Vec3],
        ts: &[f64],
        out: &mut [Vec3],
    ) -> () where [] => omegas_in_lanes_any::<N>, up to Avx512;
}

/// The lanes' loop, inlined into each target's copy of it: groups of `N` members in the
/// lanes; the members left over in one more group when they fill a quarter of it, else each
/// alone, its times in the lanes (or one by one when they are fewer than the lanes).
#[inline(always)]
pub(super) fn omegas_in_lanes_any<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    ws: &[Vec3],
    ts: &[f64],
    out: &mut [Vec3],
) {
    let n = ts.len();
    let whole = if ws.len() % N * 4 >= N {
        ws.len()
    } else {
        ws.len() / N * N
    };
    let (out_whole, out_rest) = out.split_at_mut(whole * n);
    for (wg, og) in ws[..whole].chunks(N).zip(out_whole.chunks_mut(N * n)) {
        members_in_lanes::<N>(moments, s, radicals, wg, ts, og);
    }
    for (w, o) in ws[whole..].iter().zip(out_rest.chunks_exact_mut(n)) {
        if n < N || !times_in_lanes::<N>(moments, s, radicals, *w, ts, o) {
            omegas_one_by_one(moments, s, radicals, 0, *w, ts, o);
        }
    }
}

/// ω (body frame) of up to `N` members `wg` at the times `ts`, one member per lane (lanes past
/// the last member repeat it, their results dropped); the members the lanes do not cover
/// ([`LaneMotion::new`]) one by one.
#[inline(always)]
fn members_in_lanes<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    wg: &[Vec3],
    ts: &[f64],
    og: &mut [Vec3],
) {
    let n = ts.len();
    let lanes = wg.len();
    // structure of arrays
    let mut w = [Wide::<N>::default(); 3];
    for l in 0..N {
        let v = wg[l.min(lanes - 1)];
        for c in 0..3 {
            w[c].0[l] = v[c];
        }
    }
    let (motion, plain) = LaneMotion::new(moments, radicals, to_sorted(s, w));
    for (j, &t) in ts.iter().enumerate() {
        let v = from_sorted(s, motion.omega_at(Wide::<N>::splat(t)));
        for l in 0..lanes {
            og[l * n + j] = [v[0].0[l], v[1].0[l], v[2].0[l]];
        }
    }
    for l in 0..lanes {
        if !plain.get(l) {
            omegas_one_by_one(
                moments,
                s,
                radicals,
                0,
                wg[l],
                ts,
                &mut og[l * n..(l + 1) * n],
            );
        }
    }
}

/// ω (body frame) of one member at the times `ts`, `N` times at once in the lanes (the member
/// in every lane); `false` (nothing written) where the member is not a plain lane
/// ([`LaneMotion::new`]).
#[inline(always)]
fn times_in_lanes<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    w: Vec3,
    ts: &[f64],
    out: &mut [Vec3],
) -> bool {
    let w = [Wide::splat(w[0]), Wide::splat(w[1]), Wide::splat(w[2])];
    let (motion, plain) = LaneMotion::<N>::new(moments, radicals, to_sorted(s, w));
    if !plain.get(0) {
        return false;
    }
    for (tc, oc) in ts.chunks(N).zip(out.chunks_mut(N)) {
        // lanes past the last time repeat it (their results dropped)
        let mut t = [0.0; N];
        for l in 0..N {
            t[l] = tc[l.min(tc.len() - 1)];
        }
        let v = from_sorted(s, motion.omega_at(Wide(t)));
        for (l, o) in oc.iter_mut().enumerate() {
            *o = [v[0].0[l], v[1].0[l], v[2].0[l]];
        }
    }
    true
}

/// What an ensemble asks of each motion without its time history: the polhode family (the
/// case code of [`Regime`]), the period of ω(t) ([`Regime::period`]) and the time between
/// flips ([`Regime::flip_interval`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Family {
    pub case: u8,
    pub period: f64,
    pub flip_interval: f64,
}

impl Family {
    /// The family, period and flip interval of a regime.
    pub fn of(reg: &Regime) -> Family {
        Family {
            case: reg.case,
            period: reg.period(),
            flip_interval: reg.flip_interval(),
        }
    }
}

/// [`Family`] of each torque-free motion from the body-frame ω `ws` into `out`: bodies with
/// three distinct moments [`WIDTH`] members at a time in SIMD lanes (the regime's elliptic
/// fields as [`LaneMotion::new`] makes them for ω(t): `4K/λ`, `2K/λ`, the pole), each lane
/// bit for bit its member's [`regime_of`]; the lanes off the plain elliptic case, and
/// symmetric bodies, one by one. Blocks of members are shared among rayon's threads.
pub fn families(moments: Vec3, s: &Mat3, symmetry: u8, ws: &[Vec3], out: &mut [Family]) {
    assert_eq!(out.len(), ws.len(), "families: `out` has the wrong length");
    let radicals = Radicals::new(moments);
    let block = |ws: &[Vec3], out: &mut [Family]| {
        if symmetry == 0 {
            families_in_lanes::<WIDTH>(moments, s, &radicals, ws, out);
        } else {
            for (w, o) in ws.iter().zip(out.iter_mut()) {
                *o = Family::of(&Regime::with(
                    moments,
                    &radicals,
                    symmetry,
                    to_sorted(s, *w),
                ));
            }
        }
    };
    if ws.len() >= PARALLEL_MIN {
        ws.par_chunks(FAMILY_BLOCK)
            .zip(out.par_chunks_mut(FAMILY_BLOCK))
            .for_each(|(w, o)| block(w, o));
    } else {
        block(ws, out);
    }
}

/// Members per rayon task of [`families`].
const FAMILY_BLOCK: usize = 4096;

crate::multiversion! {
    /// [`families`] of a body with three distinct moments in lanes, the instruction set chosen at
    /// run time (as [`omegas_in_lanes`]).
    pub(super) fn families_in_lanes, families_in_lanes_with [const N: usize] (
        moments: Vec3,
        s: &Mat3,
        radicals: &Radicals,
        ws: &[Vec3],
        out: &mut [Family],
    ) -> () where [] => families_in_lanes_any::<N>, up to Avx512;
}

/// Groups of `N` members in the lanes (lanes past the last member repeat it, their results
/// dropped); a lane off the plain case gets its member's own [`Regime`].
#[inline(always)]
fn families_in_lanes_any<const N: usize>(
    moments: Vec3,
    s: &Mat3,
    radicals: &Radicals,
    ws: &[Vec3],
    out: &mut [Family],
) {
    for (wg, og) in ws.chunks(N).zip(out.chunks_mut(N)) {
        let lanes = wg.len();
        let mut w = [Wide::<N>::default(); 3];
        for l in 0..N {
            let v = wg[l.min(lanes - 1)];
            for c in 0..3 {
                w[c].0[l] = v[c];
            }
        }
        let (motion, plain) = LaneMotion::new(moments, radicals, to_sorted(s, w));
        // the formulas of Regime::period and Regime::flip_interval, lane by lane
        let period = Wide::<N>::splat(4.0) * motion.quarter / motion.lam;
        let flip = Wide::<N>::splat(2.0) * motion.quarter / motion.lam;
        for (l, o) in og.iter_mut().enumerate() {
            *o = if plain.get(l) {
                Family {
                    case: if motion.e3.get(l) {
                        AROUND_E3
                    } else {
                        AROUND_E1
                    },
                    period: period.0[l],
                    flip_interval: flip.0[l],
                }
            } else {
                Family::of(&Regime::with(moments, radicals, 0, to_sorted(s, wg[l])))
            };
        }
    }
}
