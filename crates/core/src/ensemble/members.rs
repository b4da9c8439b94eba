//! One member of an ensemble (`docs/ensembles.md`): its body, axes, forces and initial state
//! ([`Member`], [`member_body`]), its run with the single-body systems and drivers
//! ([`run_member`]), and what it leaves besides its samples ([`MemberSummary`]): the counters,
//! the flips, and its largest drifts of the energy (kinetic energy (12) plus the potential),
//! of the angular momentum (eq. (03)) and of the orthogonality of `Q` ([`Drift`]).

use std::sync::atomic::AtomicBool;

use super::Schedule;
use crate::drivers::{Clock, Counters, Output, Sampling, Status};
use crate::forces::Force;
use crate::inertia::{parallel_axis, principal_decomposition};
use crate::invariants::{angular_momentum_body, kinetic_energy};
use crate::layout::{Body, BODY_SIZE, OMEGA_AT, Q_AT, STATE_SIZE, V_AT};
use crate::observers::{FlipObserver, NoObserver, Observer};
use crate::rigid::{
    body_parameters, orthogonality_error, pivot_point, state_from_principal, state_to_principal,
    State,
};
use crate::run::Run;
use crate::so3::{Mat3, Vec3};
use crate::spec::RunSpec;
use crate::system::RigidStructure;
use crate::systems::{Rigid, TorqueFree};

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

pub(super) fn principal(axes: &Mat3, y: &State) -> State {
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
/// frame; NaN if the run fails), with its summary. It runs through the members' one runner,
/// [`crate::run::Run::to_end`], until it ends, spends its step budget or `stop` is raised.
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
pub(super) fn finish_member<P: Fn(f64, &State) -> f64>(
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
            max_steps: schedule.max_steps,
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
    let status = run.to_end(stop, |run, steps| run.chunk_rigid(sys, obs, steps));
    (status, k)
}
