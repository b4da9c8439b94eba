//! Members in lanes: [`LANES`] members of an ensemble stepped together, structure of arrays,
//! the member loop innermost, so that the compiler turns each step into vector instructions
//! (8 members per instruction with AVX-512, 4 with AVX2, 2 with SSE2 or NEON).
//!
//! Nothing here is a formula. A block's state holds component `c` of lane `l` at
//! `c · LANES + l`; a step gathers each lane's state, runs the *same* scalar step as a single
//! run ([`rk4_rigid_step`] on the lane's system, constrained), and scatters it back. Floating
//! point in Rust is never contracted or reassociated, so a lane computes bit for bit what a
//! single run of its member computes, whatever instruction set runs it.
//!
//! The instruction set is chosen at run time ([`run_block`]): the block's whole time loop is
//! compiled once per target (AVX-512, AVX2 + FMA, the baseline) and the best one the CPU
//! offers runs, so one wheel serves every x86-64 machine (ARM's NEON is its baseline).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::drivers::{next_up, run_fixed, Clock, Counters, FixedMethod, Output, Sampling, Status};
use crate::forces::one_force_wrench;
use crate::layout::{Body, OMEGA_AT, STATE_SIZE};
use crate::observers::Observer;
use crate::rigid::State;
use crate::rigid::{rigid_rates, shift_torque_to_pivot};
use crate::steppers::{
    dop853_dense, dop853_interpolate, drift, hold_pivot, initial_step_size, kick_by,
    momentum_to_velocity, rk4_rigid_step, rkmk4_carry, rkmk4_first_carry, rkmk4_last, rkmk4_point,
    step_size_factor, velocity_of, velocity_to_momentum, Control, Rkmk4Carry, RKMK4_CARRY,
};
use crate::system::{RigidStructure, VectorField};
use crate::systems::{
    OneForce, Rigid, SameForces, TorqueFree, ANY_ROTOR, MAX_SAME_FORCES, SYMMETRIC, TRIAXIAL,
};
use crate::tableaux::{
    DOP853_A, DOP853_C, DOP853_E3, DOP853_E5, DOP853_INTERPOLATOR_POWER, DOP853_STAGES,
    DOP853_STAGES_EXTENDED, RK4_C,
};

/// Members per block: eight vectors of AVX-512 doubles (sixteen of AVX2), a state of 9 KiB.
/// The fixed-step driver keeps two states and a checkpoint, 27 KiB, inside a 32 KiB L1 data
/// cache; with 128 lanes (54 KiB) the torque-free RK4 ensemble of `speed_ensemble` ran 9 %
/// slower on an AVX2 machine (AMD EPYC, same run, best of 12: 0.505 s against 0.586 s).
pub const LANES: usize = 64;

/// Component `c` of lane `l` in a block's state.
#[inline(always)]
pub fn at(c: usize, l: usize) -> usize {
    c * LANES + l
}

/// [`LANES`] rigid-body systems stepped together: one system shared by every lane
/// (`SHARED`: a body every member shares, its parameters broadcast), or one per lane.
pub struct Block<'a, S, const SHARED: bool> {
    pub systems: &'a [S],
}

impl<S: RigidStructure, const SHARED: bool> Block<'_, S, SHARED> {
    #[inline(always)]
    fn lane(&self, l: usize) -> &S {
        if SHARED {
            &self.systems[0]
        } else {
            &self.systems[l]
        }
    }
}

/// A block's state: 18 components of [`LANES`] lanes each.
pub type BlockState = [f64; STATE_SIZE * LANES];

/// The block state of a slice (its length checked once, so that no index in the lanes'
/// loops needs a check of its own).
#[inline(always)]
fn block(z: &[f64]) -> &BlockState {
    z[..STATE_SIZE * LANES].try_into().expect("a block's state")
}

#[inline(always)]
fn block_mut(z: &mut [f64]) -> &mut BlockState {
    (&mut z[..STATE_SIZE * LANES])
        .try_into()
        .expect("a block's state")
}

/// Lane `l` of a block's state.
#[inline(always)]
pub fn gather(z: &BlockState, l: usize) -> State {
    lane_of::<STATE_SIZE, LANES>(z, l)
}

#[inline(always)]
fn scatter(y: &State, l: usize, z: &mut BlockState) {
    set_lane_of::<STATE_SIZE, LANES>(y, l, z)
}

impl<S: RigidStructure, const SHARED: bool> VectorField for Block<'_, S, SHARED> {
    fn dim(&self) -> usize {
        STATE_SIZE * LANES
    }
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let (y, out) = (block(y), block_mut(out));
        for l in 0..LANES {
            scatter(&self.lane(l).rates(t, &gather(y, l)), l, out);
        }
    }
    fn project(&self, t: f64, y: &mut [f64]) -> bool {
        let y = block_mut(y);
        let mut any = false;
        for l in 0..LANES {
            let s = self.lane(l);
            let c = s.constrain(t, gather(y, l));
            scatter(&c, l, y);
            any |= s.body().has_pivot;
        }
        any
    }
    fn failed(&self) -> bool {
        (0..if SHARED { 1 } else { LANES }).any(|l| self.lane(l).failed())
    }
}

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

/// Lane `i` of `N` components of `W` lanes, structure of arrays (component `c` at
/// `c · W + i`).
#[inline(always)]
fn lane_of<const N: usize, const W: usize>(z: &[f64], i: usize) -> [f64; N] {
    let z = &z[..N * W];
    let mut y = [0.0; N];
    for c in 0..N {
        y[c] = z[c * W + i % W];
    }
    y
}

#[inline(always)]
fn set_lane_of<const N: usize, const W: usize>(y: &[f64; N], i: usize, z: &mut [f64]) {
    let z = &mut z[..N * W];
    for c in 0..N {
        z[c * W + i % W] = y[c];
    }
}

/// Lane `i` of `W` lanes' states.
#[inline(always)]
fn gather_of<const W: usize>(z: &[f64], i: usize) -> State {
    lane_of::<STATE_SIZE, W>(z, i)
}

#[inline(always)]
fn scatter_of<const W: usize>(y: &State, i: usize, z: &mut [f64]) {
    set_lane_of::<STATE_SIZE, W>(y, i, z)
}

/// The rates and the wrench of `W` lanes of a block from lane `first` on, each at its own
/// time `t[i]`, the states `y` and rates `k` (18 · W) component by component: by default lane
/// by lane, the lane's own [`RigidStructure::rates`] and [`RigidStructure::wrench`]; a system
/// whose lanes can share the work says how.
pub trait LaneRates: RigidStructure + Sized {
    /// The pivot flag of every lane's body when the system's type fixes it (so that a loop
    /// across lanes has no branch on it), else `None`.
    const PIVOT: Option<bool> = None;

    #[inline(always)]
    fn rates_in_lanes<const SHARED: bool, const W: usize>(
        block: &Block<'_, Self, SHARED>,
        first: usize,
        t: &[f64; W],
        y: &[f64],
        k: &mut [f64],
    ) {
        for i in 0..W {
            let r = block.lane(first + i).rates(t[i], &gather_of::<W>(y, i));
            scatter_of::<W>(&r, i, k);
        }
    }

    /// The wrench `(F, τ)` of each lane, component-major (`w[c][i]`).
    #[inline(always)]
    fn wrench_in_lanes<const SHARED: bool, const W: usize>(
        block: &Block<'_, Self, SHARED>,
        first: usize,
        t: &[f64; W],
        y: &[f64],
        w: &mut [[f64; W]; 6],
    ) {
        for i in 0..W {
            let v = block.lane(first + i).wrench(t[i], &gather_of::<W>(y, i));
            for c in 0..6 {
                w[c][i] = v[c];
            }
        }
    }
}

/// Lane `l`'s body, its pivot flag the system's constant where it has one
/// ([`LaneRates::PIVOT`]).
#[inline(always)]
fn lane_body<S: LaneRates, const SHARED: bool>(block: &Block<'_, S, SHARED>, l: usize) -> Body {
    let mut body = *block.lane(l).body();
    if let Some(p) = S::PIVOT {
        body.has_pivot = p;
    }
    body
}

impl LaneRates for TorqueFree {}
impl<const K: i64, const PIVOT: bool> LaneRates for OneForce<K, PIVOT> {
    const PIVOT: Option<bool> = Some(PIVOT);
}
impl LaneRates for Rigid {}

impl<const PIVOT: bool> LaneRates for SameForces<PIVOT> {
    const PIVOT: Option<bool> = Some(PIVOT);

    /// Each lane's rates from its wrench ([`LaneRates::wrench_in_lanes`]), as
    /// [`SameForces::rates`] forms them.
    #[inline(always)]
    fn rates_in_lanes<const SHARED: bool, const W: usize>(
        block: &Block<'_, Self, SHARED>,
        first: usize,
        t: &[f64; W],
        y: &[f64],
        k: &mut [f64],
    ) {
        let mut w = [[0.0; W]; 6];
        Self::wrench_in_lanes(block, first, t, y, &mut w);
        for i in 0..W {
            let body = lane_body(block, first + i);
            let wl = [w[0][i], w[1][i], w[2][i], w[3][i], w[4][i], w[5][i]];
            let r = rigid_rates(&body, &gather_of::<W>(y, i), wl);
            scatter_of::<W>(&r, i, k);
        }
    }

    /// Each force for every lane before the next (its kind the same in every lane, named at
    /// compile time: [`one_force_wrench`]), summed per lane in the forces' order from zero as
    /// [`crate::forces::total_wrench`] sums them; then each lane's torque moved to its pivot
    /// ([`shift_torque_to_pivot`]), as [`SameForces::wrench`] does. Bit for bit the lane by
    /// lane wrench.
    #[inline(always)]
    fn wrench_in_lanes<const SHARED: bool, const W: usize>(
        block: &Block<'_, Self, SHARED>,
        first: usize,
        t: &[f64; W],
        y: &[f64],
        w: &mut [[f64; W]; 6],
    ) {
        *w = [[0.0; W]; 6];
        for (j, f) in block.lane(0).forces().iter().enumerate() {
            // each arm its own call, inlined: the kind named at compile time
            match f.kind as i64 {
                1 => add_force::<1, PIVOT, SHARED, W>(block, j, first, t, y, w),
                2 => add_force::<2, PIVOT, SHARED, W>(block, j, first, t, y, w),
                3 => add_force::<3, PIVOT, SHARED, W>(block, j, first, t, y, w),
                4 => add_force::<4, PIVOT, SHARED, W>(block, j, first, t, y, w),
                5 => add_force::<5, PIVOT, SHARED, W>(block, j, first, t, y, w),
                6 => add_force::<6, PIVOT, SHARED, W>(block, j, first, t, y, w),
                _ => add_force::<7, PIVOT, SHARED, W>(block, j, first, t, y, w),
            }
        }
        for i in 0..W {
            let body = lane_body(block, first + i);
            let wl = [w[0][i], w[1][i], w[2][i], w[3][i], w[4][i], w[5][i]];
            let v = shift_torque_to_pivot(&body, &gather_of::<W>(y, i), wl);
            for c in 0..6 {
                w[c][i] = v[c];
            }
        }
    }
}

/// Force `j` (of kind `K` in every lane) added to the wrench `w` (component-major) of `W`
/// lanes from lane `first` on.
#[inline(always)]
fn add_force<const K: i64, const PIVOT: bool, const SHARED: bool, const W: usize>(
    block: &Block<'_, SameForces<PIVOT>, SHARED>,
    j: usize,
    first: usize,
    t: &[f64; W],
    y: &[f64],
    w: &mut [[f64; W]; 6],
) {
    let j = j.min(MAX_SAME_FORCES - 1);
    for i in 0..W {
        let s = block.lane(first + i);
        let v = one_force_wrench::<K>(&s.forces[j].p, &s.body, t[i], &gather_of::<W>(y, i));
        for c in 0..6 {
            w[c][i] += v[c];
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
/// forces ([`SameForces`]), whose rates vectorise across lanes but not within one lane's
/// step.
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
/// default [`RigidStructure::rkmk4`]. For bodies under forces ([`OneForce`], [`SameForces`]);
/// under one force a little faster than the same stages across the whole block of
/// [`LANES`] (whose carries outgrow the L1 cache).
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
                            rkmk4_point::<$i>(&gather_of::<W>(&zs, i), h, &take::<W>(&c, i));
                        scatter_of::<W>(&p, i, &mut ys);
                        kt[i] = kti;
                    }
                    S::rates_in_lanes(sys, first, &[t + RK4_C[$i] * h; W], &ys, &mut k);
                    for i in 0..W {
                        let prev = take::<W>(&c, i);
                        let carry = rkmk4_carry::<$i>(&gather_of::<W>(&k, i), &kt[i], Some(&prev));
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
/// default [`RigidStructure::splitting`]. For bodies under several forces ([`SameForces`]).
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
            drift::<ROTOR>(&lane_body(sys, first + i), &mut x, h);
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

/// The flips of every lane ([`crate::observers::FlipObserver`]'s rule, lane by lane): the
/// sign test runs on all lanes at once; the rare step with a flip records it lane by lane.
pub struct BlockFlips {
    pub first: [f64; LANES],
    pub last: [f64; LANES],
    pub count: [f64; LANES],
}

impl Default for BlockFlips {
    fn default() -> Self {
        BlockFlips {
            first: [f64::NAN; LANES],
            last: [f64::NAN; LANES],
            count: [0.0; LANES],
        }
    }
}

impl Observer for BlockFlips {
    #[inline(always)]
    fn observe(&mut self, _: usize, t0: f64, y0: &[f64], t1: f64, y1: &[f64]) {
        let (a, b) = (
            &y0[at(OMEGA_AT + 1, 0)..at(OMEGA_AT + 2, 0)],
            &y1[at(OMEGA_AT + 1, 0)..at(OMEGA_AT + 2, 0)],
        );
        // a flip has a · b ≤ 0, which one product and one compare per vector tell (the exact
        // rule below, four compares, runs for the rare step where some lane may have flipped:
        // a product of zero, an underflow, a flip)
        let mut any = false;
        for l in 0..LANES {
            any |= a[l] * b[l] <= 0.0;
        }
        if !any {
            return;
        }
        // the lanes that flipped take the new time, the others keep theirs: written without
        // branches, so that the whole block is a few vector instructions
        for l in 0..LANES {
            let (a, b) = (a[l], b[l]);
            let flip = (a < 0.0 && b >= 0.0) | (a > 0.0 && b <= 0.0);
            let t = t0 + (t1 - t0) * a / (a - b);
            let fresh = flip & (self.count[l] == 0.0);
            self.first[l] = if fresh { t } else { self.first[l] };
            self.last[l] = if flip { t } else { self.last[l] };
            self.count[l] += if flip { 1.0 } else { 0.0 };
        }
    }
}

/// Records nothing (a block without flips).
pub struct NoFlips;

impl Observer for NoFlips {
    #[inline(always)]
    fn observe(&mut self, _: usize, _: f64, _: &[f64], _: f64, _: &[f64]) {}
}

/// What a block's run leaves: its status, counters and (when watched) flips.
pub struct BlockRun {
    pub status: Status,
    pub counters: Counters,
    pub flips: Option<BlockFlips>,
}

crate::multiversion! {
    /// Integrate a block with a fixed-step `method` ([`BlockRk4`], [`BlockRkmk4`]) from `t0` to
    /// `t1` in steps of `dt`, landing on every time of
    /// `t_eval`: `z` (18 · LANES) the initial states, advanced in place; `samples`
    /// (len(t_eval) · 18 · LANES) the block's states at the sample times. The driver is the
    /// single runs' [`run_fixed`], resumed [`crate::drivers::STEPS_PER_CALL`] steps at a time
    /// until it ends or `stop` is raised.
    pub fn run_block, run_block_with [
        'a,
        S: RigidStructure + Sync,
        M: FixedMethod<Block<'a, S, SHARED>> + Copy,
        const SHARED: bool,
    ] (
        block: &Block<'a, S, SHARED>,
        method: M,
        t0: f64,
        t1: f64,
        dt: f64,
        t_eval: &[f64],
        flips: bool,
        z: &mut [f64],
        samples: &mut [f64],
        stop: &AtomicBool,
    ) -> BlockRun where [] => run_block_any, up to Avx512;
}

/// The block's time loop, inlined into each target's copy of it.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn run_block_any<
    'a,
    S: RigidStructure + Sync,
    M: FixedMethod<Block<'a, S, SHARED>> + Copy,
    const SHARED: bool,
>(
    block: &Block<'a, S, SHARED>,
    method: M,
    t0: f64,
    t1: f64,
    dt: f64,
    t_eval: &[f64],
    flips: bool,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> BlockRun {
    let mut times = vec![0.0; t_eval.len()];
    let mut out = Output {
        t: &mut times,
        y: samples,
    };
    let sampling = Sampling {
        t_end: t1,
        t_eval,
        every: u64::MAX,
    };
    let mut clock = Clock { t: t0, h: 0.0 };
    let mut k = Counters::default();
    let mut obs = BlockFlips::default();
    let mut method = method;
    // the method's own state (the splitting method's momenta), once per run
    let y0 = z.to_vec();
    method.init(block, &y0, z);
    let status = loop {
        let s = if flips {
            run_fixed(
                block,
                &mut method,
                &mut obs,
                &mut clock,
                z,
                dt,
                &sampling,
                &mut out,
                &mut k,
                crate::drivers::STEPS_PER_CALL,
            )
        } else {
            run_fixed(
                block,
                &mut method,
                &mut NoFlips,
                &mut clock,
                z,
                dt,
                &sampling,
                &mut out,
                &mut k,
                crate::drivers::STEPS_PER_CALL,
            )
        };
        if s != Status::Running || stop.load(Ordering::Relaxed) {
            break s;
        }
    };
    BlockRun {
        status,
        counters: k,
        flips: flips.then_some(obs),
    }
}

/// What a block's adaptive run leaves: each lane's status and counters (every lane its own
/// steps), and (when watched) the flips.
pub struct BlockAdaptiveRun {
    pub status: [Status; LANES],
    pub counters: [Counters; LANES],
    pub flips: Option<BlockFlips>,
}

crate::multiversion! {
    /// Adaptive Dormand–Prince 8(5,3) on every lane (free bodies, or built-in forces and a pivot),
    /// each lane with its own step sizes, bit for bit its single run ([`crate::drivers::run_adaptive`]): the lanes step in lock
    /// step, one trial step (accepted or rejected) per lane per round. The twelve stages and the
    /// error norms run for all lanes at once (structure of arrays, each lane's step size its own);
    /// the controller, the flips, the samples (dense output where a sample falls inside a step)
    /// and the checks run lane by lane, with the single run's own functions. `z` (18 · LANES) the
    /// initial states, advanced in place; `samples` (len(t_eval) · 18 · LANES). The instruction
    /// set is chosen at run time, as [`run_block`].
    pub fn run_block_dop853, run_block_dop853_with [
        S: LaneRates + VectorField,
        const SHARED: bool,
    ] (
        block: &Block<'_, S, SHARED>,
        control: &Control,
        t0: f64,
        t1: f64,
        t_eval: &[f64],
        flips: bool,
        z: &mut [f64],
        samples: &mut [f64],
        stop: &AtomicBool,
    ) -> BlockAdaptiveRun where [] => dop853_any, up to Avx512;
}

/// The stages of one DOP853 trial step on every lane, as [`dop853_step`] computes them for
/// one: `k` (16 · 18 · LANES) holds the stages (row 0 the lanes' `f`), `z_new` the 8th-order
/// solutions; then each lane's error norm ([`dop853_error_norm`]'s sums, in its order).
#[inline(always)]
fn dop853_stages<S: LaneRates + VectorField, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    t: &[f64; LANES],
    h: &[f64; LANES],
    z: &BlockState,
    k: &mut [f64],
    z_new: &mut BlockState,
) {
    let row = STATE_SIZE * LANES;
    let mut ytmp = [0.0; STATE_SIZE * LANES];
    for st in 1..=DOP853_STAGES {
        for c in 0..STATE_SIZE {
            // the sum over the stages in their order, each lane's own
            let mut acc = [0.0; LANES];
            for (m, a) in DOP853_A[st][..st].iter().enumerate() {
                let km = &k[m * row + at(c, 0)..m * row + at(c, 0) + LANES];
                for l in 0..LANES {
                    acc[l] += a * km[l];
                }
            }
            for l in 0..LANES {
                ytmp[at(c, l)] = z[at(c, l)] + h[l] * acc[l];
            }
        }
        if st == DOP853_STAGES {
            z_new.copy_from_slice(&ytmp);
        }
        let kr: &mut BlockState = (&mut k[st * row..(st + 1) * row])
            .try_into()
            .expect("a stage");
        let mut ts = [0.0; LANES];
        for l in 0..LANES {
            ts[l] = t[l] + DOP853_C[st] * h[l];
        }
        S::rates_in_lanes(block, 0, &ts, &ytmp, kr);
    }
}

/// Each lane's error norm of the last trial step ([`dop853_error_norm`], its sums in its
/// order).
#[inline(always)]
fn dop853_errors(
    k: &[f64],
    h: &[f64; LANES],
    z: &BlockState,
    z_new: &BlockState,
    control: &Control,
) -> [f64; LANES] {
    let row = STATE_SIZE * LANES;
    let (rtol, atol) = (control.rtol, control.atol);
    let mut e5 = [0.0; LANES];
    let mut e3 = [0.0; LANES];
    for c in 0..STATE_SIZE {
        let mut a5 = [0.0; LANES];
        let mut a3 = [0.0; LANES];
        for s in 0..=DOP853_STAGES {
            let ks = &k[s * row + at(c, 0)..s * row + at(c, 0) + LANES];
            for l in 0..LANES {
                a5[l] += DOP853_E5[s] * ks[l];
                a3[l] += DOP853_E3[s] * ks[l];
            }
        }
        for l in 0..LANES {
            let i = at(c, l);
            let scale = atol + z[i].abs().max(z_new[i].abs()) * rtol;
            let (b5, b3) = (a5[l] / scale, a3[l] / scale);
            e5[l] += b5 * b5;
            e3[l] += b3 * b3;
        }
    }
    let mut err = [0.0; LANES];
    for l in 0..LANES {
        err[l] = if e5[l] == 0.0 && e3[l] == 0.0 {
            0.0
        } else {
            h[l].abs() * e5[l] / ((e5[l] + 0.01 * e3[l]) * STATE_SIZE as f64).sqrt()
        };
    }
    err
}

/// The lanes' adaptive loop, inlined into each target's copy of it: the single run's
/// [`crate::drivers::run_adaptive`] lane by lane, the stages and error norms in lanes.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn dop853_any<S: LaneRates + VectorField, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    control: &Control,
    t0: f64,
    t1: f64,
    t_eval: &[f64],
    flips: bool,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> BlockAdaptiveRun {
    let n = STATE_SIZE;
    let row = STATE_SIZE * LANES;
    let n_eval = t_eval.len();
    let z = block_mut(z);
    let mut k = vec![0.0; DOP853_STAGES_EXTENDED * row];
    let mut z_new = vec![0.0; row];
    let mut f = vec![0.0; row];
    let mut obs = BlockFlips::default();
    let mut status = [Status::Running; LANES];
    let mut counters = [Counters::default(); LANES];
    let mut t = [t0; LANES];
    let mut h_abs = [0.0; LANES];
    let mut h = [0.0; LANES];
    let mut t_new = [t0; LANES];
    let mut min_step = [0.0; LANES];
    let mut rejected = [false; LANES];
    let mut fresh = [true; LANES]; // the lane's next trial starts a step
    let (mut ytmp, mut fnew) = ([0.0; STATE_SIZE], [0.0; STATE_SIZE]);
    let store = |samples: &mut [f64], i: usize, y: &State, l: usize| {
        let r: &mut BlockState = (&mut samples[i * row..(i + 1) * row])
            .try_into()
            .expect("a sample");
        scatter(y, l, r);
    };
    // each lane's start: f, the samples at t0, the first step
    for l in 0..LANES {
        let sys = block.lane(l);
        let y = gather(z, l);
        let fl = sys.rates(t0, &y);
        scatter(&fl, l, block_mut(&mut f));
        let c = &mut counters[l];
        c.n_fev = 1;
        while c.next_sample < n_eval && t_eval[c.next_sample] <= t0 {
            store(samples, c.n_out, &y, l);
            c.n_out += 1;
            c.next_sample += 1;
        }
        h_abs[l] = if control.first_step > 0.0 {
            control.first_step
        } else {
            c.n_fev += 1;
            initial_step_size(sys, t0, &y, &fl, t1, 7.0, control, &mut ytmp, &mut fnew)
        };
        if t0 >= t1 || c.next_sample >= n_eval {
            status[l] = Status::Finished;
        }
    }
    let mut rounds: u64 = 0;
    while status.contains(&Status::Running) {
        rounds += 1;
        if rounds % crate::drivers::STEPS_PER_CALL == 0 && stop.load(Ordering::Relaxed) {
            break;
        }
        // each running lane's trial step size (the single run's clamps and checks)
        for l in 0..LANES {
            h[l] = 0.0;
            if status[l] != Status::Running {
                continue;
            }
            if fresh[l] {
                min_step[l] = 10.0 * (next_up(t[l]) - t[l]).abs();
                if h_abs[l] > control.max_step {
                    h_abs[l] = control.max_step;
                } else if h_abs[l] < min_step[l] {
                    h_abs[l] = min_step[l];
                }
                rejected[l] = false;
                fresh[l] = false;
            }
            if h_abs[l] < min_step[l] {
                status[l] = Status::StepTooSmall;
                continue;
            }
            t_new[l] = t[l] + h_abs[l];
            if t_new[l] > t1 {
                t_new[l] = t1;
            }
            h[l] = t_new[l] - t[l];
            h_abs[l] = h[l].abs();
        }
        k[..row].copy_from_slice(&f);
        let zn: &mut BlockState = (&mut z_new[..]).try_into().expect("a block");
        dop853_stages(block, &t, &h, z, &mut k, zn);
        let err = dop853_errors(&k, &h, z, zn, control);
        // each lane: accept or retry; an accepted step observed, sampled and taken
        let zn: &BlockState = (&z_new[..]).try_into().expect("a block");
        for l in 0..LANES {
            if status[l] != Status::Running {
                continue;
            }
            let c = &mut counters[l];
            c.n_fev += DOP853_STAGES as u64;
            h_abs[l] *= step_size_factor(err[l], 7.0, rejected[l], control);
            let accepted = err[l] < 1.0;
            if !accepted {
                // rejected (a NaN norm too, as the single run's `err < 1` test)
                rejected[l] = true;
                c.n_rejected += 1;
                continue;
            }
            fresh[l] = true;
            let sys = block.lane(l);
            let y0 = gather(z, l);
            let mut y1 = gather(zn, l);
            let mut f1: State = [0.0; STATE_SIZE];
            for cc in 0..n {
                f1[cc] = k[DOP853_STAGES * row + at(cc, l)];
            }
            if sys.project(t_new[l], &mut y1) {
                // about a pivot: the state put back on the constraint, its derivative anew
                sys.rhs(t_new[l], &y1, &mut f1);
                c.n_fev += 1;
            }
            c.n_steps += 1;
            if flips {
                let mut one = crate::observers::FlipObserver {
                    first: &mut obs.first,
                    last: &mut obs.last,
                    count: &mut obs.count,
                    offset: 0,
                };
                one.observe(l, t[l], &y0, t_new[l], &y1);
            }
            let y1_finite = y1.iter().all(|x| x.is_finite());
            if !y1_finite {
                scatter(&y1, l, z);
                t[l] = t_new[l];
                status[l] = Status::NonFinite;
                continue;
            }
            let mut dense: Option<[f64; DOP853_INTERPOLATOR_POWER * STATE_SIZE]> = None;
            while c.next_sample < n_eval && t_eval[c.next_sample] <= t_new[l] {
                let te = t_eval[c.next_sample];
                if te == t_new[l] {
                    store(samples, c.n_out, &y1, l);
                } else {
                    let fd = dense.get_or_insert_with(|| {
                        // the lane's stages, three more, and the interpolant (the single
                        // run's dop853_dense on the lane's numbers)
                        let mut kl = [0.0; DOP853_STAGES_EXTENDED * STATE_SIZE];
                        for s in 0..=DOP853_STAGES {
                            for cc in 0..n {
                                kl[s * n + cc] = k[s * row + at(cc, l)];
                            }
                        }
                        let mut fd = [0.0; DOP853_INTERPOLATOR_POWER * STATE_SIZE];
                        dop853_dense(sys, t[l], h[l], &y0, &y1, &f1, &mut kl, &mut ytmp, &mut fd);
                        c.n_fev += (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
                        fd
                    });
                    let mut sample = [0.0; STATE_SIZE];
                    dop853_interpolate(fd, &y0, (te - t[l]) / h[l], &mut sample);
                    sys.project(te, &mut sample);
                    store(samples, c.n_out, &sample, l);
                }
                c.n_out += 1;
                c.next_sample += 1;
            }
            if c.next_sample >= n_eval {
                status[l] = Status::Finished;
            }
            scatter(&y1, l, z);
            scatter(&f1, l, block_mut(&mut f));
            t[l] = t_new[l];
            if t[l] >= t1 {
                status[l] = Status::Finished;
            }
        }
    }
    BlockAdaptiveRun {
        status,
        counters,
        flips: flips.then_some(obs),
    }
}

/// Lane `l`'s samples (len(t_eval) · 18) out of a block's (len(t_eval) · 18 · LANES).
pub fn lane_samples(samples: &[f64], l: usize, out: &mut [f64]) {
    for (row, block_row) in out
        .chunks_exact_mut(STATE_SIZE)
        .zip(samples.chunks_exact(STATE_SIZE * LANES))
    {
        row.copy_from_slice(&gather(block(block_row), l));
    }
}

/// A block's initial state from its members' (principal frame; lanes past the last member
/// repeat it, and their results are dropped).
pub fn block_state(states: &[State]) -> Vec<f64> {
    let mut z = vec![0.0; STATE_SIZE * LANES];
    for l in 0..LANES {
        scatter(&states[l.min(states.len() - 1)], l, block_mut(&mut z));
    }
    z
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::{run_fixed_native, Rk4Rigid};
    use crate::isa::Isa;
    use crate::layout::{Body, Q_AT};
    use crate::observers::NoObserver;
    use crate::systems::TorqueFree;

    /// The torque-free RK4 step's fused multiply-adds round once on every instruction set:
    /// the block's AVX-512, AVX2 + FMA and baseline copies (fma in software) give the same
    /// numbers, and so do the single runs' baseline and native loops, lane for member.
    #[test]
    fn every_instruction_set_gives_the_same_numbers() {
        same_numbers_everywhere(BlockRk4, || Rk4Rigid);
    }

    /// RKMK4 and the splitting method in lanes (sines and cosines by polynomials, no fused
    /// operations): every copy and every single run gives the same numbers, lane for member
    /// (the splitting method's samples leave its momentum state).
    #[test]
    fn rkmk4_and_splitting_lanes_are_their_single_runs() {
        use crate::drivers::{RkmkRigid, Splitting};
        same_numbers_everywhere(BlockRkmk4, || RkmkRigid::new(crate::steppers::RK4));
        same_numbers_everywhere(BlockSplitting, || Splitting);
    }

    fn same_numbers_everywhere<M, N>(method: M, single: impl Fn() -> N)
    where
        M: for<'a> FixedMethod<Block<'a, TorqueFree, true>> + Copy,
        N: FixedMethod<TorqueFree>,
    {
        let moments = [1.0, 2.0, 3.5];
        let a = [0, 1, 2].map(|r| [0, 1, 2].map(|c| if r == c { moments[r] } else { 0.0 }));
        let body = Body::from_slice(&Body::vector(
            2.0, moments, [0.0; 3], &a, [0.0; 3], false, -1,
        ))
        .unwrap();
        let sys = [TorqueFree::new(body)];
        let block = Block::<_, true> { systems: &sys };
        let states: Vec<State> = (0..LANES)
            .map(|l| {
                let s = l as f64;
                let mut y = [0.0; STATE_SIZE];
                y[Q_AT] = 1.0;
                y[Q_AT + 4] = 1.0;
                y[Q_AT + 8] = 1.0;
                y[OMEGA_AT..].copy_from_slice(&[0.05 * s.sin(), 1.0 + 0.01 * s, 0.05 * s.cos()]);
                y[3] = 0.1 * s;
                y
            })
            .collect();
        let t_eval = [0.0, 0.37, 2.0];
        let (t0, t1, dt) = (0.0, 2.0, 1e-2);
        let stop = AtomicBool::new(false);
        let run = |f: &dyn Fn(&mut [f64], &mut [f64])| {
            let mut z = block_state(&states);
            let mut samples = vec![0.0; t_eval.len() * STATE_SIZE * LANES];
            f(&mut z, &mut samples);
            samples
        };
        let mut copies: Vec<(&str, Vec<f64>)> = vec![(
            "dispatched",
            run(&|z, y| {
                run_block(&block, method, t0, t1, dt, &t_eval, true, z, y, &stop);
            }),
        )];
        for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
            let got = run(&|z, y| {
                run_block_with(isa, &block, method, t0, t1, dt, &t_eval, true, z, y, &stop);
            });
            copies.push((isa.name(), got));
        }
        let want = &copies[0].1;
        assert!(want.iter().all(|x| x.is_finite()));
        for (name, got) in &copies {
            assert!(
                got.iter()
                    .zip(want)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{name}"
            );
        }
        // each lane is its member's single run, with the baseline loop and the native one
        for l in [0, 1, LANES / 2 + 13, LANES - 1] {
            for native in [false, true] {
                let mut m = single();
                let mut z = [0.0; STATE_SIZE];
                m.init(&sys[0], &states[l], &mut z);
                let mut t_out = vec![0.0; t_eval.len()];
                let mut y_out = vec![0.0; t_eval.len() * STATE_SIZE];
                let sampling = Sampling {
                    t_end: t1,
                    t_eval: &t_eval,
                    every: 1,
                };
                let mut out = Output {
                    t: &mut t_out,
                    y: &mut y_out,
                };
                let run = if native { run_fixed_native } else { run_fixed };
                let status = run(
                    &sys[0],
                    &mut m,
                    &mut NoObserver,
                    &mut Clock { t: t0, h: 0.0 },
                    &mut z,
                    dt,
                    &sampling,
                    &mut out,
                    &mut Counters::default(),
                    u64::MAX,
                );
                assert_eq!(status, Status::Finished);
                let mut lane = vec![0.0; t_eval.len() * STATE_SIZE];
                lane_samples(want, l, &mut lane);
                assert!(
                    lane.iter()
                        .zip(&y_out)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "lane {l}, native {native}"
                );
            }
        }
    }
}
