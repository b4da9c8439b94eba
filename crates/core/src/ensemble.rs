//! Ensembles: many independent motions of one body (`docs/ensembles.md`), each an ordinary
//! run of the single-body systems and drivers, in parallel over the members.
//!
//! Nothing here is a formula of its own. A member is a [`Member`]: its body's parameters
//! (its own inertia, or the body every member shares), its principal axes, its built-in
//! forces and its body-frame initial state. [`run_member`] integrates it with the systems of
//! [`crate::systems`] ([`TorqueFree`] without forces or pivot, [`Rigid`] otherwise) and the
//! drivers of [`crate::drivers`] ([`crate::drivers::run_fixed`] with any [`FixedMethod`], [`run_adaptive`]),
//! watching its flips with the [`FlipObserver`]; [`run_members`] runs a chunk of members on
//! the current rayon pool. A member's arithmetic depends on nothing but its own data, so its
//! result is the same bit for bit whatever the chunking or the number of threads, and equal to
//! a single-body run of it.
//!
//! Every member gets its own [`Status`] (a member that fails gets NaN samples and statistics;
//! the others are untouched) and its own [`MemberSummary`]: the run's counters, its flips,
//! and the reductions over its samples of [`Drift`], streamed as the member finishes, so that
//! a caller that keeps only statistics never stores a trajectory (one member's samples per
//! thread at a time).
//!
//! Runs stop promptly when the caller raises a flag: the drivers are resumable and run
//! [`STEPS_PER_CALL`] steps between two looks at it.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::drivers::{is_rk4, Clock, Counters, FixedMethod, Output, Sampling, Status};
use crate::forces::Force;
use crate::inertia::{parallel_axis, principal_decomposition};
use crate::invariants::{angular_momentum_body, kinetic_energy};
use crate::lanes::{
    block_state, lane_samples, run_block, run_block_dop853, Block, BlockAdaptiveRun, BlockFlips,
    BlockRk4, BlockRk4Stages, BlockRkmk4, BlockRkmk4Stages, BlockRun, BlockSplitting,
    BlockSplittingStages, LaneRates, LANES,
};
use crate::layout::{Body, BODY_SIZE, OMEGA_AT, Q_AT, STATE_SIZE, V_AT};
use crate::observers::{FlipObserver, NoObserver, Observer};
use crate::rigid::{
    body_parameters, orthogonality_error, pivot_point, state_from_principal, state_to_principal,
    State,
};
use crate::so3::{Mat3, Vec3};
use crate::steppers::Control;
use crate::system::{RigidStructure, VectorField};
use crate::systems::{OneForce, Rigid, SameForces, TorqueFree, MAX_SAME_FORCES};

pub use crate::drivers::STEPS_PER_CALL;

use crate::run::Run;
/// The method every member runs (DOP853: each member with its own step sizes).
pub use crate::spec::Method;
use crate::spec::RunSpec;

/// What every member shares: the method, the time span and the sample times.
#[derive(Clone, Copy, Debug)]
pub struct Schedule<'a> {
    pub method: Method<'a>,
    pub t0: f64,
    pub t1: f64,
    /// Step of the fixed-step methods (unused by DOP853).
    pub dt: f64,
    /// Sample times, increasing, within `[t0, t1]` (at least one).
    pub t_eval: &'a [f64],
    /// Record the flips of every member ([`FlipObserver`]).
    pub flips: bool,
}

/// One member of an ensemble.
#[derive(Clone, Debug)]
pub struct Member<'a> {
    /// Its body (principal frame of the inertia about the reference point), the pivot placed
    /// where its initial state puts it ([`Member::new`]).
    pub body: Body,
    /// Its principal axes (columns, body coordinates).
    pub axes: Mat3,
    /// Its inertia about the centre of mass, body frame (for the statistics).
    pub inertia: Mat3,
    /// Its built-in forces, lowered in its principal frame.
    pub forces: &'a [Force],
    /// Its initial state, body frame.
    pub y0: State,
}

impl<'a> Member<'a> {
    /// A member from its body (pivot not yet placed), axes, inertia, forces and body-frame
    /// initial state. About a pivot, the pivot is held where the initial state puts it,
    /// `P = R − Q c` ([`pivot_point`]).
    pub fn new(body: Body, axes: Mat3, inertia: Mat3, forces: &'a [Force], y0: State) -> Self {
        let mut body = body;
        if body.has_pivot {
            body.pivot = pivot_point(&body, &principal(&axes, &y0));
        }
        Member {
            body,
            axes,
            inertia,
            forces,
            y0,
        }
    }
}

/// The parameters and principal axes of a member with its own inertia about the centre of
/// mass (body frame), sharing the body's `mass` and centre of mass `c` (seen from the
/// reference point): `(parameters, axes, degenerate)`. About a pivot the inertia is moved
/// there by Huygens–Steiner ([`parallel_axis`]); then [`principal_decomposition`] and
/// [`body_parameters`], as for a single body.
pub fn member_body(
    mass: f64,
    inertia_com: &Mat3,
    c: Vec3,
    has_pivot: bool,
) -> ([f64; BODY_SIZE], Mat3, bool) {
    let about = if has_pivot {
        parallel_axis(inertia_com, mass, c)
    } else {
        *inertia_com
    };
    let (moments, axes) = principal_decomposition(&about);
    let (params, degenerate) = body_parameters(mass, moments, &axes, c, inertia_com, has_pivot);
    (params, axes, degenerate)
}

fn principal(axes: &Mat3, y: &State) -> State {
    let mut z = [0.0; STATE_SIZE];
    state_to_principal(axes, y, &mut z);
    z
}

/// The largest drifts over a member's samples relative to its initial state, accumulated one
/// sample at a time (the per-member statistics of `poinsot.ensemble`):
///
/// * energy: `max |E(t_k) − E(t0)| / |E(t0)|` (absolute where `E(t0) = 0`), `E = K + U`, K the
///   kinetic energy (12) ([`kinetic_energy`]) and U the potential of the built-in forces;
/// * momentum: `max |L(t_k) − L(t0)| / |L(t0)|` (absolute where `L(t0) = 0`), L the angular
///   momentum about the centre of mass in space, `Q A ω` (eq. (03), first term;
///   [`angular_momentum_body`] turned to space);
/// * orthogonality: `max |QᵀQ − I|` ([`orthogonality_error`]).
///
/// Samples are body-frame states (what the caller stores), A the inertia about the centre of
/// mass in the body frame. A NaN energy (a failed member) makes all three NaN.
#[derive(Clone, Copy, Debug)]
pub struct Drift {
    e0: f64,
    scale_e: f64,
    l0: Vec3,
    scale_l: f64,
    pub energy: f64,
    pub momentum: f64,
    pub orthogonality: f64,
    failed: bool,
}

/// `(E, L)` of a body-frame state: kinetic energy (12) plus the potential `u`, and `Q A ω`.
#[inline]
fn energy_momentum(inertia: &Mat3, mass: f64, y: &[f64], u: f64) -> (f64, Vec3) {
    let w = [y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]];
    let v = [y[V_AT], y[V_AT + 1], y[V_AT + 2]];
    let e = kinetic_energy(inertia, mass, w, v) + u;
    let p = angular_momentum_body(inertia, w);
    let q = Q_AT;
    let l =
        [0, 1, 2].map(|j| y[q + 3 * j] * p[0] + y[q + 3 * j + 1] * p[1] + y[q + 3 * j + 2] * p[2]);
    (e, l)
}

impl Drift {
    /// Start from the initial body-frame state `y0` with potential `u0`.
    pub fn new(inertia: &Mat3, mass: f64, y0: &[f64], u0: f64) -> Self {
        let (e0, l0) = energy_momentum(inertia, mass, y0, u0);
        let a = (l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]).sqrt();
        Drift {
            e0,
            scale_e: if e0 != 0.0 { e0.abs() } else { 1.0 },
            l0,
            scale_l: if a != 0.0 { a } else { 1.0 },
            energy: 0.0,
            momentum: 0.0,
            orthogonality: 0.0,
            failed: false,
        }
    }

    /// Take the body-frame sample `y` with potential `u` into account.
    pub fn add(&mut self, inertia: &Mat3, mass: f64, y: &[f64], u: f64) {
        if self.failed {
            return;
        }
        let (e, l) = energy_momentum(inertia, mass, y, u);
        let d = [l[0] - self.l0[0], l[1] - self.l0[1], l[2] - self.l0[2]];
        self.energy = self.energy.max((e - self.e0).abs() / self.scale_e);
        self.momentum = self
            .momentum
            .max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / self.scale_l);
        self.orthogonality = self.orthogonality.max(orthogonality_error(y));
        if e.is_nan() {
            self.fail();
        }
    }

    /// A member that failed: every drift NaN.
    pub fn fail(&mut self) {
        self.failed = true;
        self.energy = f64::NAN;
        self.momentum = f64::NAN;
        self.orthogonality = f64::NAN;
    }
}

/// What a member's run leaves besides its samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemberSummary {
    /// How its run ended ([`Status::Running`]: stopped by the caller, or never run).
    pub status: Status,
    pub n_steps: u64,
    pub n_fev: u64,
    /// Its drifts over the samples ([`Drift`]).
    pub energy: f64,
    pub momentum: f64,
    pub orthogonality: f64,
    /// Times of its first and last flips (NaN: none, or not recorded) and their count (−1
    /// when not recorded).
    pub first_flip: f64,
    pub last_flip: f64,
    pub flip_count: i64,
}

impl Default for MemberSummary {
    fn default() -> Self {
        MemberSummary {
            status: Status::Running,
            n_steps: 0,
            n_fev: 0,
            energy: f64::NAN,
            momentum: f64::NAN,
            orthogonality: f64::NAN,
            first_flip: f64::NAN,
            last_flip: f64::NAN,
            flip_count: -1,
        }
    }
}

/// Integrate one member: its samples at `schedule.t_eval` go to `samples` (n · 18, body
/// frame; NaN if the run fails), with its summary. The driver is called [`STEPS_PER_CALL`]
/// steps at a time until it ends or `stop` is raised.
pub fn run_member(
    schedule: &Schedule,
    member: &Member,
    samples: &mut [f64],
    stop: &AtomicBool,
) -> MemberSummary {
    let z0 = principal(&member.axes, &member.y0);
    if member.forces.is_empty() && !member.body.has_pivot {
        let sys = TorqueFree::new(member.body);
        member_on(schedule, member, &sys, &z0, samples, stop, |_, _| 0.0)
    } else {
        let sys: Rigid = Rigid::new(member.body, member.forces.to_vec(), member.axes, None);
        member_on(schedule, member, &sys, &z0, samples, stop, |t, z| {
            sys.potential(t, z)
        })
    }
}

fn member_on<S: RigidStructure, P: Fn(f64, &State) -> f64>(
    schedule: &Schedule,
    member: &Member,
    sys: &S,
    z0: &State,
    samples: &mut [f64],
    stop: &AtomicBool,
    potential: P,
) -> MemberSummary {
    let n = schedule.t_eval.len();
    assert_eq!(
        samples.len(),
        n * STATE_SIZE,
        "one member's samples: n · 18"
    );
    let mut first = [f64::NAN];
    let mut last = [f64::NAN];
    let mut count = [0.0];
    let (status, k) = if schedule.flips {
        let mut obs = FlipObserver {
            first: &mut first,
            last: &mut last,
            count: &mut count,
            offset: 0,
        };
        integrate(schedule, sys, z0, samples, &mut obs, stop)
    } else {
        integrate(schedule, sys, z0, samples, &mut NoObserver, stop)
    };
    let flips = schedule.flips.then_some((first[0], last[0], count[0]));
    finish_member(schedule, member, status, &k, flips, samples, potential)
}

/// A member's summary from its run (status, counters, flips `(first, last, count)` when
/// recorded) and its principal-frame samples, which are turned to the body frame in place
/// (NaN when the run did not finish), with the drifts of what the caller stores: the
/// potential of each stored sample is that of its principal-frame state.
fn finish_member<P: Fn(f64, &State) -> f64>(
    schedule: &Schedule,
    member: &Member,
    status: Status,
    k: &Counters,
    flips: Option<(f64, f64, f64)>,
    samples: &mut [f64],
    potential: P,
) -> MemberSummary {
    let mut out = MemberSummary {
        status,
        n_steps: k.n_steps,
        n_fev: k.n_fev,
        ..MemberSummary::default()
    };
    if let Some((first, last, count)) = flips {
        out.first_flip = first;
        out.last_flip = last;
        out.flip_count = count as i64;
    }
    if status != Status::Finished {
        samples.fill(f64::NAN);
        return out;
    }
    let z0 = principal(&member.axes, &member.y0);
    let (a, mass) = (&member.inertia, member.body.mass);
    let mut drift = Drift::new(a, mass, &member.y0, potential(schedule.t0, &z0));
    let mut y = [0.0; STATE_SIZE];
    for (row, &t) in samples.chunks_exact_mut(STATE_SIZE).zip(schedule.t_eval) {
        state_from_principal(&member.axes, row, &mut y);
        row.copy_from_slice(&y);
        drift.add(a, mass, &y, potential(t, &principal(&member.axes, &y)));
    }
    out.energy = drift.energy;
    out.momentum = drift.momentum;
    out.orthogonality = drift.orthogonality;
    out
}

/// The driver loop of one member: principal-frame samples into `samples`.
fn integrate<S: RigidStructure, O: Observer>(
    schedule: &Schedule,
    sys: &S,
    z0: &State,
    samples: &mut [f64],
    obs: &mut O,
    stop: &AtomicBool,
) -> (Status, Counters) {
    let n = schedule.t_eval.len();
    let mut times = vec![0.0; n];
    let mut clock = Clock {
        t: schedule.t0,
        h: 0.0,
    };
    let mut k = Counters::default();
    let mut z = *z0;
    let mut f = [0.0; STATE_SIZE];
    let mut run = Run {
        spec: RunSpec {
            method: schedule.method,
            dt: schedule.dt,
            sampling: Sampling {
                t_end: schedule.t1,
                t_eval: schedule.t_eval,
                every: u64::MAX,
            },
            max_steps: u64::MAX,
        },
        clock: &mut clock,
        z: &mut z,
        f: &mut f,
        out: Output {
            t: &mut times,
            y: samples,
        },
        counters: &mut k,
    };
    run.enter(sys);
    let status = resume(stop, || run.chunk_rigid(sys, obs, STEPS_PER_CALL));
    (status, k)
}

/// Call a resumable driver until it ends or `stop` is raised.
fn resume(stop: &AtomicBool, mut call: impl FnMut() -> Status) -> Status {
    loop {
        let status = call();
        if status != Status::Running || stop.load(Ordering::Relaxed) {
            return status;
        }
    }
}

/// Run a chunk of members on the current rayon pool (`rayon::ThreadPool::install` picks
/// one). Per member `i`: its samples go to `samples[i · n · 18 ..]` (n · 18 each, body frame)
/// when given, else to one buffer per thread; its final state to `finals[i · 18 ..]`; its
/// summary to `summaries[i]`. Members not started when `stop` is raised keep the default
/// summary (status [`Status::Running`]: not run) and NaN states.
pub fn run_members(
    schedule: &Schedule,
    members: &[Member],
    samples: Option<&mut [f64]>,
    finals: &mut [f64],
    summaries: &mut [MemberSummary],
    stop: &AtomicBool,
) {
    let per = schedule.t_eval.len() * STATE_SIZE;
    let m = members.len();
    assert_eq!(finals.len(), m * STATE_SIZE, "finals: m · 18");
    assert_eq!(summaries.len(), m, "summaries: m");
    if let Some(y) = &samples {
        assert_eq!(y.len(), m * per, "samples: m · n · 18");
    }
    if in_lanes(&schedule.method) {
        // RK4 and RKMK4: blocks of LANES members in SIMD lanes (crate::lanes), bit for bit the
        // single runs
        let blocks = finals
            .par_chunks_mut(STATE_SIZE * LANES)
            .zip(summaries.par_chunks_mut(LANES))
            .zip(members.par_chunks(LANES));
        match samples {
            Some(y) => {
                y.par_chunks_mut(per * LANES)
                    .zip(blocks)
                    .for_each(|(y, ((last, s), block))| {
                        run_lanes(schedule, block, y, last, s, stop);
                    })
            }
            None => blocks.for_each_init(
                || vec![0.0; per * LANES],
                |y, ((last, s), block)| {
                    run_lanes(schedule, block, &mut y[..per * block.len()], last, s, stop);
                },
            ),
        }
        return;
    }
    let one = |member: &Member, y: &mut [f64], last: &mut [f64], summary: &mut MemberSummary| {
        if stop.load(Ordering::Relaxed) {
            y.fill(f64::NAN);
            last.fill(f64::NAN);
            *summary = MemberSummary::default();
            return;
        }
        *summary = run_member(schedule, member, y, stop);
        last.copy_from_slice(&y[per - STATE_SIZE..]);
    };
    let rest = finals
        .par_chunks_mut(STATE_SIZE)
        .zip(summaries.par_iter_mut())
        .zip(members.par_iter());
    match samples {
        Some(y) => {
            y.par_chunks_mut(per)
                .zip(rest)
                .for_each(|(y, ((last, s), member))| one(member, y, last, s));
        }
        None => rest.for_each_init(
            || vec![0.0; per],
            |y, ((last, s), member)| one(member, y, last, s),
        ),
    }
}

/// The methods whose blocks of members run in lanes: RK4 and DOP853 (each lane its own
/// steps), RKMK with RK4's tableau and the splitting method. A block runs in lanes when its
/// members' systems have the method there ([`lane_systems`]); else member by member.
fn in_lanes(method: &Method) -> bool {
    match method {
        Method::Rk4 | Method::Splitting | Method::Dop853(_) => true,
        Method::Rkmk(tab) => is_rk4(tab),
        _ => false,
    }
}

/// The kind of system a block's lanes run.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LaneSystems {
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
fn lane_systems(block: &[Member]) -> LaneSystems {
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
fn run_lanes(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::{run_fixed_native, Rk4Rigid};
    use crate::forces::ForceKind;
    use crate::layout::FORCE_PARAMS;
    use crate::rigid::initial_state;
    use crate::steppers::Tableau;
    use crate::tableaux::{RK4_A, RK4_B, RK4_C};

    const CONTROL: Control = Control {
        rtol: 1e-10,
        atol: 1e-12,
        safety: 0.9,
        min_factor: 0.2,
        max_factor: 10.0,
        max_step: f64::INFINITY,
        first_step: 0.0,
    };

    fn rot(a: f64, b: f64) -> Mat3 {
        let (sa, ca) = a.sin_cos();
        let (sb, cb) = b.sin_cos();
        // rotation about z by a, then about x by b
        let rz = [[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]];
        let rx = [[1.0, 0.0, 0.0], [0.0, cb, -sb], [0.0, sb, cb]];
        crate::so3::matmul(&rz, &rx)
    }

    /// A body with a tilted inertia tensor, its members' initial states and bodies.
    fn members(n: usize, pivot: bool) -> (Vec<State>, [f64; BODY_SIZE], Mat3, Mat3) {
        let e = rot(0.3, 0.7);
        let d = [1.0, 2.0, 3.5];
        let mut a = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = (0..3).map(|k| e[i][k] * d[k] * e[j][k]).sum();
            }
        }
        let c = if pivot { [0.1, -0.2, 0.4] } else { [0.0; 3] };
        let (params, axes, _) = member_body(2.0, &a, c, pivot);
        let y0 = (0..n)
            .map(|i| {
                let s = i as f64;
                let w = [0.05 * s.sin(), 1.0 + 0.1 * s, 0.05 * s.cos()];
                initial_state(
                    &rot(0.2 * s, 0.1),
                    w,
                    None,
                    None,
                    [0.5, 0.0, 0.0],
                    c,
                    [0.0; 3],
                    pivot,
                    [0.0; 3],
                )
            })
            .collect();
        (y0, params, axes, a)
    }

    fn schedule<'a>(method: Method<'a>, t_eval: &'a [f64]) -> Schedule<'a> {
        Schedule {
            method,
            t0: 0.0,
            t1: *t_eval.last().unwrap(),
            dt: 1e-2,
            t_eval,
            flips: true,
        }
    }

    /// A member equals the single-body run of the same system and driver, bit for bit.
    #[test]
    fn a_member_is_a_single_body_run() {
        let (y0, params, axes, a) = members(3, false);
        let body = Body::from_slice(&params).unwrap();
        let t_eval: Vec<f64> = (0..=20).map(|k| 0.25 * k as f64).collect();
        let s = schedule(Method::Rk4, &t_eval);
        let member = Member::new(body, axes, a, &[], y0[2]);
        let mut samples = vec![0.0; t_eval.len() * STATE_SIZE];
        let summary = run_member(&s, &member, &mut samples, &AtomicBool::new(false));
        assert_eq!(summary.status, Status::Finished);
        // the single-body route: one call of the driver, no chunks, samples converted here
        let sys = TorqueFree::new(body);
        let mut z = principal(&axes, &y0[2]);
        let mut t_out = vec![0.0; t_eval.len()];
        let mut y_out = vec![0.0; t_eval.len() * STATE_SIZE];
        let mut k = Counters::default();
        let status = run_fixed_native(
            &sys,
            &mut Rk4Rigid,
            &mut NoObserver,
            &mut Clock { t: 0.0, h: 0.0 },
            &mut z,
            1e-2,
            &Sampling {
                t_end: 5.0,
                t_eval: &t_eval,
                every: 1,
            },
            &mut Output {
                t: &mut t_out,
                y: &mut y_out,
            },
            &mut k,
            u64::MAX,
        );
        assert_eq!(status, Status::Finished);
        assert_eq!(summary.n_steps, k.n_steps);
        assert_eq!(summary.n_fev, k.n_fev);
        for (row, got) in y_out
            .chunks_exact(STATE_SIZE)
            .zip(samples.chunks_exact(STATE_SIZE))
        {
            let mut y = [0.0; STATE_SIZE];
            state_from_principal(&axes, row, &mut y);
            assert_eq!(&y[..], got);
        }
    }

    /// RK4 and DOP853 members in SIMD lanes (DOP853: each lane its own step sizes, samples
    /// between steps from its dense output) equal their single runs bit for bit — samples,
    /// finals, counters, drifts and flips — with one shared body, with a body per member, under
    /// forces about a pivot (the state projected after each step and at each sample), in a
    /// partial block (padded lanes), and (RK4) with a member whose state stops being finite
    /// (the block then runs member by member, each with its own status).
    #[test]
    fn members_in_lanes_are_their_single_runs() {
        let t_eval: Vec<f64> = (0..=8).map(|k| 0.125 * k as f64).collect();
        for method in [
            Method::Rk4,
            Method::Dop853(CONTROL),
            Method::Rkmk(crate::steppers::RK4),
            Method::Splitting,
        ] {
            lanes_are_single_runs(method, &t_eval);
        }
    }

    /// A built-in force of `kind` with its first parameters `p`.
    fn force(kind: ForceKind, p: &[f64]) -> Force {
        let mut params = [0.0; FORCE_PARAMS];
        params[..p.len()].copy_from_slice(p);
        Force { kind, p: params }
    }

    /// The lanes' cases: whether the members turn about a pivot, and their forces. In
    /// lanes as [`OneForce`]: a pivot alone, uniform gravity free and about a pivot, central
    /// gravity with its gradient torque free and about a pivot; as [`Rigid`]: two forces
    /// (RK4 and DOP853; the other methods member by member), one force of a kind not compiled
    /// in lanes.
    fn forced_cases() -> Vec<(bool, Vec<Force>, LaneSystems)> {
        let gravity = force(ForceKind::Gravity, &[0.0, 0.0, -9.8]);
        let central = force(ForceKind::CentralGravity, &[40.0, -6.0, 1.0, 0.5, 1.0]);
        let drag = force(ForceKind::LinearDrag, &[0.3, 0.05]);
        // a damped tether from the body point (0.1, 0, 0) to (0, 0, 2), rest length 1
        let tether = force(
            ForceKind::Spring,
            &[0.1, 0.0, 0.0, 0.0, 0.0, 2.0, 5.0, 1.0, 0.2, 1.0],
        );
        let quadratic = force(ForceKind::QuadraticDrag, &[0.1, 0.02]);
        // a body-fixed force at the body point (0, 0.2, 0)
        let thrust = force(ForceKind::PointForce, &[0.0, 0.2, 0.0, 0.3, 0.0, 0.1, 1.0]);
        let couple = force(ForceKind::Torque, &[0.05, 0.0, 0.02, 0.0]);
        let body_couple = force(ForceKind::Torque, &[0.0, 0.1, 0.0, 1.0]);
        vec![
            (true, vec![], LaneSystems::One(0, true)),
            (false, vec![gravity], LaneSystems::One(1, false)),
            (true, vec![gravity], LaneSystems::One(1, true)),
            (false, vec![central], LaneSystems::One(2, false)),
            (true, vec![central], LaneSystems::One(2, true)),
            (true, vec![gravity, drag], LaneSystems::Forces),
            (false, vec![drag], LaneSystems::Forces),
            // every other kind, several at once: each force for the whole block at once
            (
                false,
                vec![tether, quadratic, thrust, couple],
                LaneSystems::Forces,
            ),
            (
                true,
                vec![body_couple, gravity, central],
                LaneSystems::Forces,
            ),
            // the last case: every other member has the forces in the other order, so the
            // block's kinds differ from lane to lane (each lane its own Rigid)
            (false, vec![drag, gravity], LaneSystems::Forces),
        ]
    }

    fn lanes_are_single_runs(method: Method, t_eval: &[f64]) {
        let dop853 = matches!(method, Method::Dop853(_));
        let s = schedule(method, t_eval);
        let stop = AtomicBool::new(false);
        let forced = forced_cases();
        let n = LANES + LANES / 2 + 3; // one full block, one partial
        for case in 0..3 + forced.len() {
            if dop853 && case == 2 {
                continue; // a state not finite from the start: the fixed-step methods' check
            }
            // 0: one shared body; 1: a body per member; 2: a member that cannot run; then
            // the forced cases
            let (pivot, forces, systems) = match case {
                0..=2 => (false, vec![], LaneSystems::Free),
                _ => forced[case - 3].clone(),
            };
            let (mut y0, params, axes, a) = members(n, pivot);
            if case == 2 {
                y0[LANES + 5][OMEGA_AT] = f64::INFINITY;
            }
            let body = Body::from_slice(&params).unwrap();
            let reversed: Vec<Force> = forces.iter().rev().copied().collect();
            let ms: Vec<Member> = (0..n)
                .map(|i| {
                    let mut b = body;
                    if case == 1 || case == 4 {
                        // a body per member: moments scaled
                        let f = 1.0 + 0.01 * i as f64;
                        b.moments = b.moments.map(|x| x * f);
                        b.inv_moments = b.inv_moments.map(|x| x / f);
                    }
                    let forces = if case == 2 + forced.len() && i % 2 == 1 {
                        &reversed
                    } else {
                        &forces
                    };
                    Member::new(b, axes, a, forces, y0[i])
                })
                .collect();
            assert_eq!(lane_systems(&ms[..LANES]), systems, "case {case}");
            let per = t_eval.len() * STATE_SIZE;
            let mut samples = vec![0.0; n * per];
            let mut finals = vec![0.0; n * STATE_SIZE];
            let mut sums = vec![MemberSummary::default(); n];
            run_members(&s, &ms, Some(&mut samples), &mut finals, &mut sums, &stop);
            for (i, m) in ms.iter().enumerate() {
                let mut one = vec![0.0; per];
                let single = run_member(&s, m, &mut one, &stop);
                let same =
                    |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                assert!(
                    one.iter()
                        .zip(&samples[i * per..(i + 1) * per])
                        .all(|(a, b)| same(*a, *b)),
                    "{method:?} case {case}, member {i}: samples"
                );
                let got = sums[i];
                assert_eq!(got.status, single.status, "case {case}, member {i}");
                assert_eq!(
                    got.status,
                    if case == 2 && i == LANES + 5 {
                        Status::NonFinite
                    } else {
                        Status::Finished
                    }
                );
                assert_eq!((got.n_steps, got.n_fev), (single.n_steps, single.n_fev));
                for (a, b) in [
                    (got.energy, single.energy),
                    (got.momentum, single.momentum),
                    (got.orthogonality, single.orthogonality),
                    (got.first_flip, single.first_flip),
                    (got.last_flip, single.last_flip),
                ] {
                    assert!(same(a, b), "case {case}, member {i}: {a} vs {b}");
                }
                assert_eq!(got.flip_count, single.flip_count);
            }
        }
    }

    /// Torque-free members keep their energy and |L| (each method to its error), Q stays
    /// orthogonal (to round-off for the Lie-group methods), and the drifts computed on the fly are those of the
    /// stored samples.
    #[test]
    fn torque_free_members_conserve_energy_and_momentum() {
        let (y0, params, axes, a) = members(16, false);
        let body = Body::from_slice(&params).unwrap();
        let ms: Vec<Member> = y0
            .iter()
            .map(|y| Member::new(body, axes, a, &[], *y))
            .collect();
        let t_eval: Vec<f64> = (0..=40).map(|k| 0.5 * k as f64).collect();
        let a_flat = RK4_A.concat();
        let tab = Tableau {
            a: &a_flat,
            b: &RK4_B,
            c: &RK4_C,
        };
        // (method, tolerance of the invariants, of QᵀQ = I: the Lie-group methods keep it)
        for (method, tol, tol_q) in [
            (Method::Rk4, 1e-6, 1e-6),
            (Method::Erk(tab), 1e-6, 1e-6),
            (Method::Rkmk(tab), 1e-6, 1e-13),
            (Method::Splitting, 1e-3, 1e-13),
            (Method::Dop853(CONTROL), 1e-8, 1e-8),
        ] {
            let s = schedule(method, &t_eval);
            let m = ms.len();
            let mut samples = vec![0.0; m * t_eval.len() * STATE_SIZE];
            let mut finals = vec![0.0; m * STATE_SIZE];
            let mut sums = vec![MemberSummary::default(); m];
            let stop = AtomicBool::new(false);
            run_members(&s, &ms, Some(&mut samples), &mut finals, &mut sums, &stop);
            for (i, sum) in sums.iter().enumerate() {
                assert_eq!(sum.status, Status::Finished, "{method:?}");
                assert!(sum.energy < tol && sum.momentum < tol, "{method:?} {sum:?}");
                assert!(sum.orthogonality < tol_q, "{method:?} {sum:?}");
                // the drifts again, from the stored samples by the invariants directly
                let w0 = [y0[i][15], y0[i][16], y0[i][17]];
                let e0 = crate::invariants::rotational_energy(&a, w0);
                let mut de: f64 = 0.0;
                for row in samples[i * t_eval.len() * STATE_SIZE..][..t_eval.len() * STATE_SIZE]
                    .chunks_exact(STATE_SIZE)
                {
                    let e = crate::invariants::rotational_energy(&a, [row[15], row[16], row[17]]);
                    de = de.max((e - e0).abs() / e0);
                }
                assert!((de - sum.energy).abs() <= 1e-15, "{de} {}", sum.energy);
                let last =
                    &samples[(i + 1) * t_eval.len() * STATE_SIZE - STATE_SIZE..][..STATE_SIZE];
                assert_eq!(&finals[i * STATE_SIZE..(i + 1) * STATE_SIZE], last);
            }
            // no samples stored: the same summaries and final states
            let mut finals2 = vec![0.0; m * STATE_SIZE];
            let mut sums2 = vec![MemberSummary::default(); m];
            run_members(&s, &ms, None, &mut finals2, &mut sums2, &stop);
            assert_eq!(finals, finals2, "{method:?}");
            assert_eq!(sums, sums2);
        }
    }

    /// Members near the intermediate axis flip (the tennis-racket effect); a steady spin
    /// about the largest axis never does.
    #[test]
    fn flips_are_counted_per_member() {
        let d = [1.0, 2.0, 3.0];
        let a = [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]];
        let (params, axes, _) = member_body(1.0, &a, [0.0; 3], false);
        let body = Body::from_slice(&params).unwrap();
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let y = |w: Vec3| {
            initial_state(
                &eye, w, None, None, [0.0; 3], [0.0; 3], [0.0; 3], false, [0.0; 3],
            )
        };
        let ms = [
            Member::new(body, axes, a, &[], y([1e-3, 1.0, 1e-3])),
            Member::new(body, axes, a, &[], y([0.0, 0.0, 1.0])),
        ];
        let t_eval = [60.0];
        let s = schedule(Method::Dop853(CONTROL), &t_eval);
        let mut finals = vec![0.0; 2 * STATE_SIZE];
        let mut sums = vec![MemberSummary::default(); 2];
        run_members(
            &s,
            &ms,
            None,
            &mut finals,
            &mut sums,
            &AtomicBool::new(false),
        );
        assert!(sums[0].flip_count >= 2, "{:?}", sums[0]);
        assert!(sums[0].first_flip > 0.0 && sums[0].last_flip > sums[0].first_flip);
        assert_eq!(sums[1].flip_count, 0);
        assert!(sums[1].first_flip.is_nan());
    }

    /// A member that overflows fails alone; its neighbours are unchanged, bit for bit.
    #[test]
    fn a_failing_member_gets_its_own_status() {
        let (mut y0, params, axes, a) = members(5, true);
        let body = Body::from_slice(&params).unwrap();
        let gravity = Force {
            kind: ForceKind::Gravity,
            p: {
                let mut p = [0.0; FORCE_PARAMS];
                p[2] = -9.8;
                p
            },
        };
        let forces = [gravity];
        let t_eval = [0.5, 1.0];
        let s = schedule(Method::Rk4, &t_eval);
        let run = |y0: &[State]| {
            let ms: Vec<Member> = y0
                .iter()
                .map(|y| Member::new(body, axes, a, &forces, *y))
                .collect();
            let mut finals = vec![0.0; y0.len() * STATE_SIZE];
            let mut sums = vec![MemberSummary::default(); y0.len()];
            run_members(
                &s,
                &ms,
                None,
                &mut finals,
                &mut sums,
                &AtomicBool::new(false),
            );
            (finals, sums)
        };
        let (good, good_sums) = run(&y0);
        y0[2][16] = 1e200;
        let (bad, bad_sums) = run(&y0);
        assert_eq!(bad_sums[2].status, Status::NonFinite);
        assert!(bad_sums[2].energy.is_nan());
        assert!(bad[2 * STATE_SIZE..3 * STATE_SIZE]
            .iter()
            .all(|x| x.is_nan()));
        for i in [0, 1, 3, 4] {
            assert_eq!(good_sums[i], bad_sums[i]);
            assert_eq!(
                good[i * STATE_SIZE..(i + 1) * STATE_SIZE],
                bad[i * STATE_SIZE..(i + 1) * STATE_SIZE]
            );
        }
        // about a pivot the pivot stays where the initial state put it
        let m = Member::new(body, axes, a, &forces, y0[0]);
        let z0 = principal(&axes, &y0[0]);
        assert_eq!(pivot_point(&m.body, &z0), m.body.pivot);
    }

    /// A raised stop flag: no member runs.
    #[test]
    fn a_raised_flag_stops_every_member() {
        let (y0, params, axes, a) = members(8, false);
        let body = Body::from_slice(&params).unwrap();
        let ms: Vec<Member> = y0
            .iter()
            .map(|y| Member::new(body, axes, a, &[], *y))
            .collect();
        let t_eval = [1e6];
        let s = schedule(Method::Rk4, &t_eval);
        let mut finals = vec![0.0; 8 * STATE_SIZE];
        let mut sums = vec![MemberSummary::default(); 8];
        run_members(
            &s,
            &ms,
            None,
            &mut finals,
            &mut sums,
            &AtomicBool::new(true),
        );
        assert!(sums.iter().all(|s| s.status == Status::Running));
    }
}
