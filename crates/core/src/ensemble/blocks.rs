//! Blocks of an ensemble's members in SIMD lanes (`docs/ensembles.md`): up to
//! [`LANES`] members stepped together ([`crate::lanes`]), each lane bit for bit its member's
//! single run. Which methods run in lanes ([`in_lanes`]), which systems a block's lanes run
//! ([`LaneSystems`]: free bodies, one built-in force compiled in, the same force kinds in
//! every lane, or any forces in scalar code), and each block's run, its samples and summaries
//! ([`run_lanes`]); a block that cannot run in lanes, or whose run fails, runs member by
//! member.

use std::sync::atomic::{AtomicBool, Ordering};

use super::{finish_member, principal, run_member, Member, MemberSummary, Method, Schedule};
use crate::drivers::{is_rk4, Counters, FixedMethod, Status};
use crate::exact_splitting::Composition;
use crate::lanes::{
    block_state, lane_samples, run_block, run_block_dop853, Block, BlockAdaptiveRun,
    BlockExactSplitting, BlockFlips, BlockRk4, BlockRk4Stages, BlockRkmk4, BlockRkmk4Stages,
    BlockRun, BlockSplitting, BlockSplittingStages, LaneRates, LANES,
};
use crate::layout::STATE_SIZE;
use crate::rigid::State;
use crate::steppers::Control;
use crate::system::{RigidStructure, VectorField};
use crate::systems::{OneForce, Rigid, SameForces, TorqueFree, MAX_SAME_FORCES};

/// The methods whose blocks of members run in lanes: RK4 and DOP853 (each lane its own
/// steps), RKMK with RK4's tableau, the splitting method and the exact-flow splittings (their
/// free flows in SIMD lanes, [`BlockExactSplitting`]: every system has them). A block runs in lanes when its
/// members' systems have the method there ([`lane_systems`]); else member by member.
pub(super) fn in_lanes(method: &Method) -> bool {
    match method {
        Method::Rk4 | Method::Splitting | Method::Dop853(_) | Method::ExactSplitting(_) => true,
        Method::Rkmk(tab) => is_rk4(tab),
        _ => false,
    }
}

/// The kind of system a block's lanes run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum LaneSystems {
    /// Free bodies without forces ([`TorqueFree`]).
    Free,
    /// Every member under the same single built-in force kind (its code; 0: none) and all free
    /// or all about a pivot: a [`OneForce`] whose kind is compiled in, for the kinds
    /// [`one_force_lanes`] compiles (uniform and central gravity, and a pivot alone).
    One(i64, bool),
    /// Anything else: each force for the whole block at once when every lane has the same
    /// force kinds ([`SameForces`], every method in lanes), else [`Rigid`] in scalar code
    /// (RK4 and DOP853 in lanes; RKMK4 and splitting member by member).
    Forces,
}

/// Which [`LaneSystems`] a block's members need.
pub(super) fn lane_systems(block: &[Member]) -> LaneSystems {
    let pivot = block[0].body.has_pivot;
    let kind = |m: &Member| match m.forces {
        [] => Some(0),
        [f] => Some(f.kind as i64),
        _ => None,
    };
    let k = kind(&block[0]);
    let uniform = block
        .iter()
        .all(|m| m.body.has_pivot == pivot && kind(m) == k);
    match (uniform, k, pivot) {
        (true, Some(0), false) => LaneSystems::Free,
        (true, Some(k @ (0..=2)), pivot) => LaneSystems::One(k, pivot),
        _ => LaneSystems::Forces,
    }
}

/// How a block's lanes ran: one status for a fixed-step method (the block steps together),
/// one per lane for DOP853 (one per block of [`LANES`] members, so its size does not matter).
#[allow(clippy::large_enum_variant)]
enum LanesRun {
    Fixed(BlockRun),
    Adaptive(BlockAdaptiveRun),
}

impl LanesRun {
    fn flips(&self) -> Option<&BlockFlips> {
        match self {
            LanesRun::Fixed(r) => r.flips.as_ref(),
            LanesRun::Adaptive(r) => r.flips.as_ref(),
        }
    }
    /// Lane `l`'s status and counters.
    fn lane(&self, l: usize) -> (Status, &Counters) {
        match self {
            LanesRun::Fixed(r) => (r.status, &r.counters),
            LanesRun::Adaptive(r) => (r.status[l], &r.counters[l]),
        }
    }
    /// A fixed-step block that did not finish cleanly (a member's state not finite).
    fn failed(&self) -> bool {
        match self {
            LanesRun::Fixed(r) => !matches!(r.status, Status::Finished | Status::Running),
            LanesRun::Adaptive(_) => false,
        }
    }
}

/// A block of lanes run with the schedule's method ([`in_lanes`]), for systems whose lanes
/// have every method ([`TorqueFree`], [`OneForce`]).
fn run_block_with<'a, S: LaneRates + Sync, const SHARED: bool>(
    block: &Block<'a, S, SHARED>,
    schedule: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> LanesRun
where
    BlockRkmk4: FixedMethod<Block<'a, S, SHARED>>,
    BlockSplitting: FixedMethod<Block<'a, S, SHARED>>,
{
    let s = schedule;
    match s.method {
        Method::Dop853(control) => adaptive_block(block, &control, s, z, samples, stop),
        Method::Rkmk(_) => fixed_block(block, BlockRkmk4, s, z, samples, stop),
        Method::Splitting => fixed_block(block, BlockSplitting, s, z, samples, stop),
        Method::ExactSplitting(c) => exact_block(block, c, s, z, samples, stop),
        _ => fixed_block(block, BlockRk4, s, z, samples, stop),
    }
}

/// A block run with the fixed-step `method` ([`run_block`]) on the schedule's times.
fn fixed_block<'a, S, M, const SHARED: bool>(
    block: &Block<'a, S, SHARED>,
    method: M,
    s: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> LanesRun
where
    S: RigidStructure + Sync,
    M: FixedMethod<Block<'a, S, SHARED>> + Copy,
{
    let (t0, t1, dt, t_eval, flips) = (s.t0, s.t1, s.dt, s.t_eval, s.flips);
    LanesRun::Fixed(run_block(
        block, method, t0, t1, dt, t_eval, flips, z, samples, stop,
    ))
}

/// A block run with an exact-flow splitting's composition `c` ([`BlockExactSplitting`]).
fn exact_block<S: RigidStructure + Sync, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    c: Composition,
    s: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> LanesRun {
    let method = BlockExactSplitting::new(block, c);
    fixed_block(block, method, s, z, samples, stop)
}

/// A block run with DOP853 ([`run_block_dop853`]) on the schedule's times.
fn adaptive_block<S: LaneRates + VectorField + Sync, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    control: &Control,
    s: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> LanesRun {
    let (t0, t1, t_eval, flips) = (s.t0, s.t1, s.t_eval, s.flips);
    LanesRun::Adaptive(run_block_dop853(
        block, control, t0, t1, t_eval, flips, z, samples, stop,
    ))
}

/// A block of bodies under one force of kind `K` ([`OneForce`]) in lanes, with the
/// schedule's method; `None` when a member's system is not `K`'s.
fn run_one_force_block<const K: i64, const PIVOT: bool>(
    members: &[Member],
    schedule: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> Option<LanesRun> {
    let systems = (0..LANES)
        .map(|l| {
            let m = &members[l.min(members.len() - 1)];
            OneForce::<K, PIVOT>::new(m.body, m.forces)
        })
        .collect::<Option<Vec<_>>>()?;
    let block = Block::<_, false> { systems: &systems };
    Some(run_block_with(&block, schedule, z, samples, stop))
}

/// [`run_one_force_block`] for the kinds compiled in lanes: uniform gravity (1) and central
/// gravity (2), free or about a pivot, and a pivot with no force (0). Each kind is a copy of
/// every method's time loop for every instruction set, so the list is kept to the forces
/// ensembles meet most (a heavy top, a satellite in orbit); the others run as [`Rigid`].
fn one_force_lanes(
    kind: i64,
    pivot: bool,
    members: &[Member],
    schedule: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> Option<LanesRun> {
    let (m, s) = (members, schedule);
    match (kind, pivot) {
        (0, true) => run_one_force_block::<0, true>(m, s, z, samples, stop),
        (1, false) => run_one_force_block::<1, false>(m, s, z, samples, stop),
        (1, true) => run_one_force_block::<1, true>(m, s, z, samples, stop),
        (2, false) => run_one_force_block::<2, false>(m, s, z, samples, stop),
        (2, true) => run_one_force_block::<2, true>(m, s, z, samples, stop),
        _ => None,
    }
}

/// A block of bodies under any built-in forces: as [`SameForces`] when every lane has the same
/// force kinds in the same order (at most [`MAX_SAME_FORCES`]), with every method
/// [`in_lanes`] runs; else as [`Rigid`] (scalar code in the lanes) with RK4 and DOP853, and
/// `None` for the other methods.
fn run_rigid_block(
    members: &[Member],
    schedule: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> Option<LanesRun> {
    let rigid = rigid_systems(members);
    let same_kinds = |r: &Rigid| {
        r.body.has_pivot == rigid[0].body.has_pivot
            && r.forces.len() == rigid[0].forces.len()
            && r.forces
                .iter()
                .zip(&rigid[0].forces)
                .all(|(a, b)| a.kind == b.kind)
    };
    if rigid[0].forces.len() <= MAX_SAME_FORCES && rigid.iter().all(same_kinds) {
        // every lane under the same force kinds: each force for the whole block at once
        return if rigid[0].body.has_pivot {
            same_forces_block::<true>(&rigid, schedule, z, samples, stop)
        } else {
            same_forces_block::<false>(&rigid, schedule, z, samples, stop)
        };
    }
    let block = Block::<_, false> { systems: &rigid };
    let s = schedule;
    match s.method {
        Method::Dop853(control) => Some(adaptive_block(&block, &control, s, z, samples, stop)),
        Method::Rk4 => Some(fixed_block(&block, BlockRk4, s, z, samples, stop)),
        Method::ExactSplitting(c) => Some(exact_block(&block, c, s, z, samples, stop)),
        _ => None,
    }
}

/// A block whose bodies all have the same force kinds in the same order and the pivot flag
/// `PIVOT` ([`SameForces`]): RK4, RKMK4 and the splitting method with their stages or kicks
/// across the block ([`BlockRk4Stages`], [`BlockRkmk4Stages`], [`BlockSplittingStages`]) and
/// DOP853 in lanes, each force evaluated for every lane at once; other methods `None`.
fn same_forces_block<const PIVOT: bool>(
    rigid: &[Rigid],
    schedule: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> Option<LanesRun> {
    let systems: Vec<SameForces<PIVOT>> =
        rigid.iter().map(SameForces::new).collect::<Option<_>>()?;
    let same = |s: &SameForces<PIVOT>| s.body == systems[0].body && s.forces == systems[0].forces;
    Some(if systems.iter().all(same) {
        // one body and one set of forces for every lane: their numbers broadcast
        forces_in_lanes(
            &Block::<_, true> {
                systems: &systems[..1],
            },
            schedule,
            z,
            samples,
            stop,
        )?
    } else {
        forces_in_lanes(
            &Block::<_, false> { systems: &systems },
            schedule,
            z,
            samples,
            stop,
        )?
    })
}

/// [`same_forces_block`]'s run of a block.
fn forces_in_lanes<const PIVOT: bool, const SHARED: bool>(
    block: &Block<'_, SameForces<PIVOT>, SHARED>,
    schedule: &Schedule,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> Option<LanesRun> {
    let s = schedule;
    match s.method {
        Method::Dop853(control) => Some(adaptive_block(block, &control, s, z, samples, stop)),
        Method::Rk4 => Some(fixed_block(block, BlockRk4Stages, s, z, samples, stop)),
        // RK4's tableau ([`in_lanes`])
        Method::Rkmk(_) => Some(fixed_block(block, BlockRkmk4Stages, s, z, samples, stop)),
        Method::Splitting => Some(fixed_block(
            block,
            BlockSplittingStages,
            s,
            z,
            samples,
            stop,
        )),
        Method::ExactSplitting(c) => Some(exact_block(block, c, s, z, samples, stop)),
        _ => None,
    }
}

/// Members run one at a time (their samples, finals and summaries as [`run_lanes`]'s).
fn one_by_one(
    schedule: &Schedule,
    block: &[Member],
    samples: &mut [f64],
    finals: &mut [f64],
    summaries: &mut [MemberSummary],
    stop: &AtomicBool,
) {
    let per = schedule.t_eval.len() * STATE_SIZE;
    for (i, member) in block.iter().enumerate() {
        let y = &mut samples[i * per..(i + 1) * per];
        summaries[i] = run_member(schedule, member, y, stop);
        finals[i * STATE_SIZE..(i + 1) * STATE_SIZE].copy_from_slice(&y[per - STATE_SIZE..]);
    }
}

/// The torque-free systems of a block's lanes, and whether they are shared: one system when
/// every member has the same body, else one per lane (the last member padding the block).
fn free_systems(block: &[Member]) -> (Vec<TorqueFree>, bool) {
    let shared = block.iter().all(|m| m.body == block[0].body);
    let lanes = if shared { 1 } else { LANES };
    let sys = (0..lanes)
        .map(|l| TorqueFree::new(block[l.min(block.len() - 1)].body))
        .collect();
    (sys, shared)
}

/// Up to [`LANES`] members in one block of lanes ([`in_lanes`]'s methods, [`lane_systems`]'
/// systems): their samples into `samples` (members · n · 18, body frame), final states into
/// `finals`, summaries into `summaries`. A fixed-step block that does not finish cleanly (a
/// member's state not finite) runs again member by member, so that each gets its own status
/// at its own step.
pub(super) fn run_lanes(
    schedule: &Schedule,
    block: &[Member],
    samples: &mut [f64],
    finals: &mut [f64],
    summaries: &mut [MemberSummary],
    stop: &AtomicBool,
) {
    let n = schedule.t_eval.len();
    let per = n * STATE_SIZE;
    if stop.load(Ordering::Relaxed) {
        samples.fill(f64::NAN);
        finals.fill(f64::NAN);
        summaries.fill(MemberSummary::default());
        return;
    }
    if block.len() < LANES / 4 {
        // a few members: their own runs (the same results) waste no lanes
        one_by_one(schedule, block, samples, finals, summaries, stop);
        return;
    }
    let z0: Vec<State> = block.iter().map(|m| principal(&m.axes, &m.y0)).collect();
    let mut z = block_state(&z0);
    let mut lanes = vec![0.0; n * STATE_SIZE * LANES];
    let systems = lane_systems(block);
    let run = match systems {
        LaneSystems::Free => {
            let (sys, shared) = free_systems(block);
            Some(if shared {
                let b = Block::<_, true> { systems: &sys };
                run_block_with(&b, schedule, &mut z, &mut lanes, stop)
            } else {
                let b = Block::<_, false> { systems: &sys };
                run_block_with(&b, schedule, &mut z, &mut lanes, stop)
            })
        }
        LaneSystems::One(kind, pivot) => {
            one_force_lanes(kind, pivot, block, schedule, &mut z, &mut lanes, stop)
                .or_else(|| run_rigid_block(block, schedule, &mut z, &mut lanes, stop))
        }
        LaneSystems::Forces => run_rigid_block(block, schedule, &mut z, &mut lanes, stop),
    };
    let run = match run {
        Some(run) if !run.failed() => run,
        // not in lanes, or a member failed: every member alone, each with its own status
        _ => return one_by_one(schedule, block, samples, finals, summaries, stop),
    };
    let rigid = (systems != LaneSystems::Free).then(|| rigid_systems(block));
    finish_lanes(
        block,
        &lanes,
        run.flips(),
        per,
        samples,
        finals,
        summaries,
        |l, m, f, y| {
            let (status, k) = run.lane(l);
            match &rigid {
                None => finish_member(schedule, m, status, k, f, y, |_, _| 0.0),
                Some(r) => finish_member(schedule, m, status, k, f, y, |t, z| r[l].potential(t, z)),
            }
        },
    );
}

/// The lanes' systems of a block under forces (lanes past the last member repeat it).
fn rigid_systems(block: &[Member]) -> Vec<Rigid> {
    (0..LANES)
        .map(|l| {
            let m = &block[l.min(block.len() - 1)];
            Rigid::new(m.body, m.forces.to_vec(), m.axes, None)
        })
        .collect()
}

/// Each lane's samples out of the block's `lanes` into `samples` (members · n · 18), its
/// summary (`summary(lane, member, flips, its samples)`: [`finish_member`] with the lane's run)
/// and its final state.
#[allow(clippy::too_many_arguments)]
fn finish_lanes(
    block: &[Member],
    lanes: &[f64],
    flips: Option<&BlockFlips>,
    per: usize,
    samples: &mut [f64],
    finals: &mut [f64],
    summaries: &mut [MemberSummary],
    summary: impl Fn(usize, &Member, Option<(f64, f64, f64)>, &mut [f64]) -> MemberSummary,
) {
    for (l, member) in block.iter().enumerate() {
        let y = &mut samples[l * per..(l + 1) * per];
        lane_samples(lanes, l, y);
        let f = flips.map(|f| (f.first[l], f.last[l], f.count[l]));
        summaries[l] = summary(l, member, f, y);
        finals[l * STATE_SIZE..(l + 1) * STATE_SIZE].copy_from_slice(&y[per - STATE_SIZE..]);
    }
}
