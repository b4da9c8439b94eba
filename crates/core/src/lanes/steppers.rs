//! The fixed-step methods on a block of [`LANES`] members (`docs/ensembles.md`): classical
//! RK4 ([`BlockRk4`], [`BlockRk4Stages`]), Runge–Kutta–Munthe-Kaas with RK4's tableau
//! ([`BlockRkmk4`], [`BlockRkmk4Stages`]), the splitting method ([`BlockSplitting`],
//! [`BlockSplittingStages`]) and the exact-flow splittings ([`BlockExactSplitting`], their
//! free flows in SIMD lanes), each lane the *same* scalar step as a single run of its member
//! ([`crate::steppers`]), so bit for bit that run: lane by lane, or with the stages (kicks)
//! formed across [`STAGE_LANES`] lanes at a time where the rates vectorise across lanes.

use super::{
    at, block, block_mut, gather, gather_of, lane_body, lane_of, scatter, scatter_of, set_lane_of,
    Block, BlockState, LaneRates, LANES,
};
use crate::drivers::FixedMethod;
use crate::exact_splitting::{compose, exact_kick, translate, Composition, FreeFlow, SubStep};
use crate::forces::Force;
use crate::layout::STATE_SIZE;
use crate::real::{Real, Wide, WIDTH};
use crate::rigid::State;
use crate::steppers::{
    drift, hold_pivot, kick_by, momentum_to_velocity, rk4_rigid_step, rkmk4_carry,
    rkmk4_first_carry, rkmk4_last, rkmk4_point, velocity_of, velocity_to_momentum, Rkmk4Carry,
    RKMK4_CARRY,
};
use crate::system::RigidStructure;
use crate::systems::{OneForce, TorqueFree, ANY_ROTOR, SYMMETRIC, TRIAXIAL};
use crate::tableaux::RK4_C;
use crate::torque_free::free_flows_in_lanes;

/// Classical RK4 on every lane, each a single run's [`rk4_rigid_step`] constrained after the
/// step (as [`crate::drivers::Rk4Rigid`]). Each method writes its lane loop out: folded into
/// one helper taking the step as a closure, LLVM stopped vectorising them (RK4 ensembles
/// ran 60× slower).
#[derive(Clone, Copy, Default)]
pub struct BlockRk4;

impl<S: RigidStructure, const SHARED: bool> FixedMethod<Block<'_, S, SHARED>> for BlockRk4 {
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(&mut self, sys: &Block<'_, S, SHARED>, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        let (z, out) = (block(z), block_mut(out));
        for l in 0..LANES {
            let s = sys.lane(l);
            let y1 = s.constrain(t + h, rk4_rigid_step(s, t, &gather(z, l), h));
            scatter(&y1, l, out);
        }
    }
}

/// Lanes a [`BlockRk4Stages`] step forms its stages for at a time: their states, stages and
/// sums stay in the L1 cache (the whole block's did not: 96 KiB).
const STAGE_LANES: usize = 32;
const _: () = assert!(LANES % STAGE_LANES == 0, "a block is whole stage groups");

/// Classical RK4 on every lane with the stages formed across [`STAGE_LANES`] lanes at a time,
/// one stage after the other (each stage's rates by [`LaneRates::rates_in_lanes`]), then
/// each lane constrained: the operations of [`crate::steppers::rk4_registers`] in its order
/// (`y + a k` for the stage points, `y + h/6 (k1 + 2 k2 + 2 k3 + k4)` summed left to right),
/// so each lane is bit for bit its single run's RK4 step (as [`crate::drivers::Rk4Rigid`])
/// for a system that keeps the default [`RigidStructure::rk4`]. For bodies under several
/// forces ([`SameForces`](crate::systems::SameForces)), whose rates vectorise across lanes but
/// not within one lane's step.
#[derive(Clone, Copy, Default)]
pub struct BlockRk4Stages;

impl<S: LaneRates, const SHARED: bool> FixedMethod<Block<'_, S, SHARED>> for BlockRk4Stages {
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(&mut self, sys: &Block<'_, S, SHARED>, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        const W: usize = STAGE_LANES;
        const N: usize = STATE_SIZE * W;
        let (z, out) = (block(z), block_mut(out));
        let half = 0.5 * h;
        let c = h / 6.0;
        let mut zs = [0.0; N];
        let mut k = [0.0; N];
        let mut y = [0.0; N];
        let mut sum = [0.0; N];
        let pivot = (0..LANES).any(|l| sys.lane(l).body().has_pivot);
        for first in (0..LANES).step_by(W) {
            for c in 0..STATE_SIZE {
                zs[c * W..(c + 1) * W].copy_from_slice(&z[at(c, first)..at(c, first) + W]);
            }
            S::rates_in_lanes(sys, first, &[t; W], &zs, &mut k);
            for i in 0..N {
                sum[i] = k[i];
                y[i] = zs[i] + half * k[i];
            }
            S::rates_in_lanes(sys, first, &[t + half; W], &y, &mut k);
            for i in 0..N {
                sum[i] += 2.0 * k[i];
                y[i] = zs[i] + half * k[i];
            }
            S::rates_in_lanes(sys, first, &[t + half; W], &y, &mut k);
            for i in 0..N {
                sum[i] += 2.0 * k[i];
                y[i] = zs[i] + h * k[i];
            }
            S::rates_in_lanes(sys, first, &[t + h; W], &y, &mut k);
            for i in 0..N {
                y[i] = zs[i] + c * (sum[i] + k[i]);
            }
            if pivot {
                for i in 0..W {
                    let y1 = sys.lane(first + i).constrain(t + h, gather_of::<W>(&y, i));
                    scatter_of::<W>(&y1, i, &mut y);
                }
            }
            for c in 0..STATE_SIZE {
                out[at(c, first)..at(c, first) + W].copy_from_slice(&y[c * W..(c + 1) * W]);
            }
        }
    }
}

/// A group of [`STAGE_LANES`] lanes from lane `first` of a block's state `z`, copied into
/// `zs` (18 · W, structure of arrays).
#[inline(always)]
fn load_group<const W: usize>(z: &BlockState, first: usize, zs: &mut [f64]) {
    for c in 0..STATE_SIZE {
        zs[c * W..(c + 1) * W].copy_from_slice(&z[at(c, first)..at(c, first) + W]);
    }
}

/// [`load_group`]'s inverse: the group's lanes written back into a block's state.
#[inline(always)]
fn store_group<const W: usize>(zs: &[f64], first: usize, z: &mut BlockState) {
    for c in 0..STATE_SIZE {
        z[at(c, first)..at(c, first) + W].copy_from_slice(&zs[c * W..(c + 1) * W]);
    }
}

/// Lane `l` of an RKMK4 carry stored for `W` lanes.
#[inline(always)]
fn take<const W: usize>(c: &[f64], l: usize) -> Rkmk4Carry {
    lane_of::<RKMK4_CARRY, W>(c, l)
}

#[inline(always)]
fn put<const W: usize>(x: &Rkmk4Carry, l: usize, c: &mut [f64]) {
    set_lane_of::<RKMK4_CARRY, W>(x, l, c)
}

/// Runge–Kutta–Munthe-Kaas with RK4's tableau on every lane, the stages formed across
/// [`STAGE_LANES`] lanes at a time: each stage's points and `kθ` lane by lane
/// ([`rkmk4_point`]), the rates of all of them at once ([`LaneRates::rates_in_lanes`]), then
/// the carries ([`rkmk4_carry`]); the step's end ([`rkmk4_last`]) and each lane constrained.
/// The pieces of [`crate::steppers::rkmk4_registers`] in its order, so each lane is bit for
/// bit its single run's step (as [`crate::drivers::RkmkRigid`]) for a system that keeps the
/// default [`RigidStructure::rkmk4`]. For bodies under forces ([`OneForce`],
/// [`SameForces`](crate::systems::SameForces)); under one force a little faster than the same
/// stages across the whole block of [`LANES`] (whose carries outgrow the L1 cache).
#[derive(Clone, Copy, Default)]
pub struct BlockRkmk4Stages;

impl<S: LaneRates, const SHARED: bool> FixedMethod<Block<'_, S, SHARED>> for BlockRkmk4Stages {
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(&mut self, sys: &Block<'_, S, SHARED>, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        const W: usize = STAGE_LANES;
        const N: usize = STATE_SIZE * W;
        let (z, out) = (block(z), block_mut(out));
        let mut zs = [0.0; N];
        let mut ys = [0.0; N];
        let mut k = [0.0; N];
        let mut kt = [[0.0; 3]; W];
        let mut c = [0.0; RKMK4_CARRY * W];
        for first in (0..LANES).step_by(W) {
            load_group::<W>(z, first, &mut zs);
            S::rates_in_lanes(sys, first, &[t + RK4_C[0] * h; W], &zs, &mut k);
            for i in 0..W {
                let carry = rkmk4_first_carry(&gather_of::<W>(&zs, i), &gather_of::<W>(&k, i));
                put::<W>(&carry, i, &mut c);
            }
            macro_rules! stage {
                ($i:literal) => {
                    for i in 0..W {
                        let (p, kti) =
                            rkmk4_point::<$i, f64>(&gather_of::<W>(&zs, i), h, &take::<W>(&c, i));
                        scatter_of::<W>(&p, i, &mut ys);
                        kt[i] = kti;
                    }
                    S::rates_in_lanes(sys, first, &[t + RK4_C[$i] * h; W], &ys, &mut k);
                    for i in 0..W {
                        let prev = take::<W>(&c, i);
                        let carry =
                            rkmk4_carry::<$i, f64>(&gather_of::<W>(&k, i), &kt[i], Some(&prev));
                        put::<W>(&carry, i, &mut c);
                    }
                };
            }
            stage!(1);
            stage!(2);
            stage!(3);
            for i in 0..W {
                let y1 = rkmk4_last(&gather_of::<W>(&zs, i), h, &take::<W>(&c, i));
                let y1 = sys.lane(first + i).constrain(t + h, y1);
                scatter_of::<W>(&y1, i, &mut ys);
            }
            store_group::<W>(&ys, first, out);
        }
    }
}

/// The splitting method on every lane, its kicks formed across [`STAGE_LANES`] lanes at a
/// time: each lane's velocity state, the wrench of all of them at once
/// ([`LaneRates::wrench_in_lanes`]), then each lane's kick ([`kick_by`]); the drift
/// ([`drift`], the free rotor's branch named when every lane takes the same) and the pivot
/// ([`hold_pivot`]) lane by lane. The pieces of [`crate::steppers::splitting_step`] in its
/// order, so each lane is bit for bit its single run's step for a system that keeps the
/// default [`RigidStructure::splitting`]. For bodies under several forces
/// ([`SameForces`](crate::systems::SameForces)).
#[derive(Clone, Copy, Default)]
pub struct BlockSplittingStages;

impl<S: LaneRates, const SHARED: bool> FixedMethod<Block<'_, S, SHARED>> for BlockSplittingStages {
    fn evals_per_step(&self) -> u64 {
        2
    }
    #[inline(always)]
    fn step(&mut self, sys: &Block<'_, S, SHARED>, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        let lanes = if SHARED { 1 } else { LANES };
        if (0..lanes).all(|l| sys.lane(l).body().rotor < 0) {
            splitting_stages::<S, SHARED, TRIAXIAL>(sys, t, block(z), h, block_mut(out));
        } else if (0..lanes).all(|l| sys.lane(l).body().rotor >= 0) {
            splitting_stages::<S, SHARED, SYMMETRIC>(sys, t, block(z), h, block_mut(out));
        } else {
            splitting_stages::<S, SHARED, ANY_ROTOR>(sys, t, block(z), h, block_mut(out));
        }
    }
    fn init(&self, sys: &Block<'_, S, SHARED>, y: &[f64], z: &mut [f64]) {
        to_momentum(sys, y, z);
    }
    fn output(&self, sys: &Block<'_, S, SHARED>, z: &[f64], y: &mut [f64]) {
        to_velocity(sys, z, y);
    }
}

/// [`BlockSplittingStages`]' step with the free rotor's branch `ROTOR`.
#[inline(always)]
fn splitting_stages<S: LaneRates, const SHARED: bool, const ROTOR: u8>(
    sys: &Block<'_, S, SHARED>,
    t: f64,
    z: &BlockState,
    h: f64,
    out: &mut BlockState,
) {
    const W: usize = STAGE_LANES;
    let mut zs = [0.0; STATE_SIZE * W];
    let pivot = S::PIVOT.unwrap_or(true);
    for first in (0..LANES).step_by(W) {
        load_group::<W>(z, first, &mut zs);
        kick_in_lanes::<S, SHARED>(sys, first, t, &mut zs, 0.5 * h);
        for i in 0..W {
            let mut x = gather_of::<W>(&zs, i);
            drift::<ROTOR, f64>(&lane_body(sys, first + i), &mut x, h);
            scatter_of::<W>(&x, i, &mut zs);
        }
        kick_in_lanes::<S, SHARED>(sys, first, t + h, &mut zs, 0.5 * h);
        if pivot {
            for i in 0..W {
                let mut x = gather_of::<W>(&zs, i);
                hold_pivot(&lane_body(sys, first + i), &mut x);
                scatter_of::<W>(&x, i, &mut zs);
            }
        }
        store_group::<W>(&zs, first, out);
    }
}

/// The splitting method's kick by the forces over `h` ([`kick_by`]) on [`STAGE_LANES`] lanes'
/// momentum states `z` from lane `first` on, at time `t`, their wrench formed across the
/// lanes.
#[inline(always)]
fn kick_in_lanes<S: LaneRates, const SHARED: bool>(
    sys: &Block<'_, S, SHARED>,
    first: usize,
    t: f64,
    z: &mut [f64],
    h: f64,
) {
    const W: usize = STAGE_LANES;
    let mut y = [0.0; STATE_SIZE * W];
    for i in 0..W {
        let v = velocity_of(&lane_body(sys, first + i), &gather_of::<W>(z, i));
        scatter_of::<W>(&v, i, &mut y);
    }
    let mut w = [[0.0; W]; 6];
    S::wrench_in_lanes(sys, first, &[t; W], &y, &mut w);
    for i in 0..W {
        let mut x = gather_of::<W>(z, i);
        let wl = [w[0][i], w[1][i], w[2][i], w[3][i], w[4][i], w[5][i]];
        kick_by(&lane_body(sys, first + i), &wl, &mut x, h);
        scatter_of::<W>(&x, i, z);
    }
}

/// Runge–Kutta–Munthe-Kaas with the classical RK4 tableau on every lane, each its single
/// run's [`RigidStructure::rkmk4`] constrained after the step (as
/// [`crate::drivers::RkmkRigid`]). Free bodies run [`TorqueFree::rkmk4_step`] lane by lane,
/// whose exponentials' sines and cosines are polynomials ([`crate::real::sin_cos`]); under
/// one force ([`OneForce`]) the stages are formed across [`STAGE_LANES`] lanes at a time
/// ([`BlockRkmk4Stages`]; one lane's whole step, four exponentials and four evaluations of
/// the rates, is too long a loop to run in vector instructions). Either way the lanes run in
/// vector instructions.
#[derive(Clone, Copy, Default)]
pub struct BlockRkmk4;

impl<const SHARED: bool> FixedMethod<Block<'_, TorqueFree, SHARED>> for BlockRkmk4 {
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(
        &mut self,
        sys: &Block<'_, TorqueFree, SHARED>,
        t: f64,
        z: &[f64],
        h: f64,
        out: &mut [f64],
    ) {
        let (z, out) = (block(z), block_mut(out));
        for l in 0..LANES {
            scatter(&sys.lane(l).rkmk4(t, &gather(z, l), h), l, out);
        }
    }
}

impl<const K: i64, const PIVOT: bool, const SHARED: bool>
    FixedMethod<Block<'_, OneForce<K, PIVOT>, SHARED>> for BlockRkmk4
{
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(
        &mut self,
        sys: &Block<'_, OneForce<K, PIVOT>, SHARED>,
        t: f64,
        z: &[f64],
        h: f64,
        out: &mut [f64],
    ) {
        BlockRkmk4Stages.step(sys, t, z, h, out)
    }
}

/// The splitting method (kick–drift–kick, [`crate::drivers::Splitting`]) on every lane, each
/// its single run's step on the lane's momentum state: for free bodies the drift alone
/// ([`TorqueFree::splitting_free`]), whose free rotor turns by [`crate::real::sin_cos`]; under
/// one force [`crate::steppers::splitting_step`] on a [`OneForce`]. The block enters the
/// momentum state once ([`FixedMethod::init`]) and leaves it at every sample, so the lanes
/// run in vector instructions.
#[derive(Clone, Copy, Default)]
pub struct BlockSplitting;

impl<const SHARED: bool> FixedMethod<Block<'_, TorqueFree, SHARED>> for BlockSplitting {
    fn evals_per_step(&self) -> u64 {
        2
    }
    #[inline(always)]
    fn step(
        &mut self,
        sys: &Block<'_, TorqueFree, SHARED>,
        _t: f64,
        z: &[f64],
        h: f64,
        out: &mut [f64],
    ) {
        let (z, out) = (block(z), block_mut(out));
        // the rotor's kind chosen once for a shared body, so that the lane loop has no branch
        let rotor = sys.lane(0).body.rotor;
        if SHARED && rotor < 0 {
            for l in 0..LANES {
                let z1 = sys.lane(l).splitting_free::<TRIAXIAL>(&gather(z, l), h);
                scatter(&z1, l, out);
            }
        } else if SHARED {
            for l in 0..LANES {
                let z1 = sys.lane(l).splitting_free::<SYMMETRIC>(&gather(z, l), h);
                scatter(&z1, l, out);
            }
        } else {
            for l in 0..LANES {
                let z1 = sys.lane(l).splitting_free::<ANY_ROTOR>(&gather(z, l), h);
                scatter(&z1, l, out);
            }
        }
    }
    fn init(&self, sys: &Block<'_, TorqueFree, SHARED>, y: &[f64], z: &mut [f64]) {
        to_momentum(sys, y, z);
    }
    fn output(&self, sys: &Block<'_, TorqueFree, SHARED>, z: &[f64], y: &mut [f64]) {
        to_velocity(sys, z, y);
    }
}

impl<const K: i64, const PIVOT: bool, const SHARED: bool>
    FixedMethod<Block<'_, OneForce<K, PIVOT>, SHARED>> for BlockSplitting
{
    fn evals_per_step(&self) -> u64 {
        2
    }
    #[inline(always)]
    fn step(
        &mut self,
        sys: &Block<'_, OneForce<K, PIVOT>, SHARED>,
        t: f64,
        z: &[f64],
        h: f64,
        out: &mut [f64],
    ) {
        let (z, out) = (block(z), block_mut(out));
        // the free rotor's branch named when every lane takes the same, so that the lane loop
        // has none
        let lanes = if SHARED { 1 } else { LANES };
        let triaxial = (0..lanes).all(|l| sys.lane(l).body.rotor < 0);
        let symmetric = (0..lanes).all(|l| sys.lane(l).body.rotor >= 0);
        if triaxial {
            for l in 0..LANES {
                let z1 = sys.lane(l).splitting_rotor::<TRIAXIAL>(t, &gather(z, l), h);
                scatter(&z1, l, out);
            }
        } else if symmetric {
            for l in 0..LANES {
                let z1 = sys
                    .lane(l)
                    .splitting_rotor::<SYMMETRIC>(t, &gather(z, l), h);
                scatter(&z1, l, out);
            }
        } else {
            for l in 0..LANES {
                scatter(&sys.lane(l).splitting(t, &gather(z, l), h), l, out);
            }
        }
    }
    fn init(&self, sys: &Block<'_, OneForce<K, PIVOT>, SHARED>, y: &[f64], z: &mut [f64]) {
        to_momentum(sys, y, z);
    }
    fn output(&self, sys: &Block<'_, OneForce<K, PIVOT>, SHARED>, z: &[f64], y: &mut [f64]) {
        to_velocity(sys, z, y);
    }
}

/// Every lane's momentum state `z` from its state `y` ([`velocity_to_momentum`]).
fn to_momentum<S: RigidStructure, const SHARED: bool>(
    sys: &Block<'_, S, SHARED>,
    y: &[f64],
    z: &mut [f64],
) {
    let (y, z) = (block(y), block_mut(z));
    for l in 0..LANES {
        let mut m = [0.0; STATE_SIZE];
        velocity_to_momentum(sys.lane(l), &gather(y, l), &mut m);
        scatter(&m, l, z);
    }
}

/// Every lane's state `y` from its momentum state `z` ([`momentum_to_velocity`]).
fn to_velocity<S: RigidStructure, const SHARED: bool>(
    sys: &Block<'_, S, SHARED>,
    z: &[f64],
    y: &mut [f64],
) {
    let (z, y) = (block(z), block_mut(y));
    for l in 0..LANES {
        scatter(&momentum_to_velocity(sys.lane(l), &gather(z, l)), l, y);
    }
}

/// The exact-flow splittings ([`crate::exact_splitting`]) on every lane, each lane its single
/// run's [`exact_splitting_step`](crate::exact_splitting::exact_splitting_step) bit for bit:
/// the sub-steps of the composition in order, each kick lane by lane
/// ([`exact_kick`]), each free flow for the whole block at once where every lane's body is the
/// same with three distinct moments — [`WIDTH`] lanes at a time in SIMD lanes
/// ([`free_flows_in_lanes`]), each lane along the motion its single run follows
/// ([`FreeFlow::plan`]: a new one, or its last one gone on from its start), one by one
/// ([`FreeFlow::evaluate`]) for the lanes off the plain elliptic case — and lane by lane
/// otherwise.
#[derive(Clone, Copy)]
pub struct BlockExactSplitting<'c> {
    composition: Composition<'c>,
    flows: [FreeFlow; LANES],
    /// Every lane's body the same, with three distinct moments: the flows in lanes.
    in_lanes: bool,
}

impl<'c> BlockExactSplitting<'c> {
    pub fn new<S: RigidStructure, const SHARED: bool>(
        sys: &Block<'_, S, SHARED>,
        composition: Composition<'c>,
    ) -> Self {
        let flows: [FreeFlow; LANES] = std::array::from_fn(|l| FreeFlow::new(sys.lane(l).body()));
        let moments = sys.lane(0).body().moments;
        let in_lanes =
            flows[0].takes_lanes() && (0..LANES).all(|l| sys.lane(l).body().moments == moments);
        BlockExactSplitting {
            composition,
            flows,
            in_lanes,
        }
    }

    /// Every lane's free flow over `d`, ending `within` into its step of `h`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn flows<S: RigidStructure, const SHARED: bool>(
        &mut self,
        sys: &Block<'_, S, SHARED>,
        orbits: &[Option<Force>; LANES],
        states: &mut [State; LANES],
        d: f64,
        within: f64,
        h: f64,
    ) {
        if !self.in_lanes {
            for (l, z) in states.iter_mut().enumerate() {
                self.flows[l].advance(sys.lane(l).body(), orbits[l].as_ref(), z, d, within, h);
            }
            return;
        }
        let moments = sys.lane(0).body().moments;
        for g in (0..LANES).step_by(WIDTH) {
            // each lane's motion (a new one, or its last one gone on) and the time into it
            let mut t = Wide::<WIDTH>::splat(0.0);
            let mut w = [Wide::<WIDTH>::splat(0.0); 3];
            let mut q = [[Wide::<WIDTH>::splat(0.0); 3]; 3];
            for j in 0..WIDTH {
                let l = g + j;
                t.0[j] = self.flows[l].plan(sys.lane(l).body(), &states[l], d, within);
                let (w0, q0) = self.flows[l].start();
                for k in 0..3 {
                    w[k].0[j] = w0[k];
                    for c in 0..3 {
                        q[k][c].0[j] = q0[k][c];
                    }
                }
            }
            let (wt, qt, plain) = free_flows_in_lanes(moments, self.flows[g].radicals(), w, &q, t);
            for j in 0..WIDTH {
                let l = g + j;
                let (body, flow) = (sys.lane(l).body(), &mut self.flows[l]);
                let (wl, ql) = if plain.get(j) {
                    // written out: `array::map` took `wt` and `qt` (3 kB) by value, a call and
                    // a copy for every lane
                    let wl = [wt[0].0[j], wt[1].0[j], wt[2].0[j]];
                    let mut ql = [[0.0; 3]; 3];
                    for (row, from) in ql.iter_mut().zip(&qt) {
                        *row = [from[0].0[j], from[1].0[j], from[2].0[j]];
                    }
                    (wl, ql)
                } else {
                    flow.evaluate(moments, t.0[j])
                };
                flow.finish(body, &mut states[l], wl, &ql, within, h);
                translate(
                    body,
                    orbits[l].as_ref().map(|f| &f.p),
                    &mut states[l],
                    d,
                    |x| x,
                );
            }
        }
    }
}

impl<S: RigidStructure, const SHARED: bool> FixedMethod<Block<'_, S, SHARED>>
    for BlockExactSplitting<'_>
{
    fn evals_per_step(&self) -> u64 {
        self.composition.kicks_per_step()
    }
    #[inline(always)]
    fn step(&mut self, sys: &Block<'_, S, SHARED>, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        let z = block(z);
        let mut states: [State; LANES] = std::array::from_fn(|l| gather(z, l));
        let orbits: [Option<Force>; LANES] = std::array::from_fn(|l| sys.lane(l).orbit());
        let c = self.composition;
        compose(&c, h, |sub| match sub {
            SubStep::Kick { k, covered } => {
                for (l, z) in states.iter_mut().enumerate() {
                    exact_kick(
                        sys.lane(l),
                        orbits[l].as_ref(),
                        t + covered,
                        z,
                        c.kicks[k] * h,
                    );
                }
            }
            SubStep::Flow { d, within } => self.flows(sys, &orbits, &mut states, d, within, h),
        });
        let out = block_mut(out);
        for (l, z) in states.iter_mut().enumerate() {
            hold_pivot(sys.lane(l).body(), z);
            scatter(z, l, out);
        }
    }
    fn init(&self, sys: &Block<'_, S, SHARED>, y: &[f64], z: &mut [f64]) {
        to_momentum(sys, y, z);
    }
    fn output(&self, sys: &Block<'_, S, SHARED>, z: &[f64], y: &mut [f64]) {
        to_velocity(sys, z, y);
    }
}
