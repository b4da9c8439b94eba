//! Members in lanes: [`LANES`] members of an ensemble stepped together, structure of arrays,
//! the member loop innermost, so that the compiler turns each step into vector instructions
//! (8 members per instruction with AVX-512, 4 with AVX2, 2 with SSE2 or NEON).
//!
//! Nothing here is a formula. A block's state holds component `c` of lane `l` at
//! `c · LANES + l`; a step gathers each lane's state, runs the *same* scalar step as a single
//! run ([`rk4_rigid_step`](crate::steppers::rk4_rigid_step) on the lane's system,
//! constrained), and scatters it back. Floating point in Rust is never contracted or
//! reassociated, so a lane computes bit for bit what a single run of its member computes,
//! whatever instruction set runs it.
//!
//! The instruction set is chosen at run time ([`run_block`]): the block's whole time loop is
//! compiled once per target (AVX-512, AVX2 + FMA, the baseline) and the best one the CPU
//! offers runs, so one wheel serves every x86-64 machine (ARM's NEON is its baseline).
//!
//! The files: here a block, its state and its rates across lanes ([`LaneRates`]);
//! `steppers.rs` the fixed-step methods on a block ([`BlockRk4`], [`BlockRk4Stages`],
//! [`BlockRkmk4`], [`BlockRkmk4Stages`], [`BlockSplitting`], [`BlockSplittingStages`],
//! [`BlockExactSplitting`]);
//! `drivers.rs` a block's time loops ([`run_block`], [`run_block_dop853`]) and its flips.

use crate::forces::one_force_wrench;
use crate::layout::{Body, STATE_SIZE};
use crate::rigid::State;
use crate::rigid::{rigid_rates, shift_torque_to_pivot};
use crate::system::{RigidStructure, VectorField};
use crate::systems::{OneForce, Rigid, SameForces, TorqueFree, MAX_SAME_FORCES};

mod drivers;
mod steppers;

pub use drivers::*;
pub use steppers::*;

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
    pub(super) fn lane(&self, l: usize) -> &S {
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
pub(super) fn block(z: &[f64]) -> &BlockState {
    z[..STATE_SIZE * LANES].try_into().expect("a block's state")
}

#[inline(always)]
pub(super) fn block_mut(z: &mut [f64]) -> &mut BlockState {
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
pub(super) fn scatter(y: &State, l: usize, z: &mut BlockState) {
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

/// Lane `i` of `N` components of `W` lanes, structure of arrays (component `c` at
/// `c · W + i`).
#[inline(always)]
pub(super) fn lane_of<const N: usize, const W: usize>(z: &[f64], i: usize) -> [f64; N] {
    let z = &z[..N * W];
    let mut y = [0.0; N];
    for c in 0..N {
        y[c] = z[c * W + i % W];
    }
    y
}

#[inline(always)]
pub(super) fn set_lane_of<const N: usize, const W: usize>(y: &[f64; N], i: usize, z: &mut [f64]) {
    let z = &mut z[..N * W];
    for c in 0..N {
        z[c * W + i % W] = y[c];
    }
}

/// Lane `i` of `W` lanes' states.
#[inline(always)]
pub(super) fn gather_of<const W: usize>(z: &[f64], i: usize) -> State {
    lane_of::<STATE_SIZE, W>(z, i)
}

#[inline(always)]
pub(super) fn scatter_of<const W: usize>(y: &State, i: usize, z: &mut [f64]) {
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
pub(super) fn lane_body<S: LaneRates, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    l: usize,
) -> Body {
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
#[path = "lanes_tests.rs"]
mod tests;
