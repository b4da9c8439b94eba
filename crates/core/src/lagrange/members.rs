//! Runs of a constrained system (`docs/lagrange.md`): one member ([`run_member`]) and members
//! in parallel on the current rayon pool ([`run_members`]), each a run of [`Lagrangian`] with
//! the drivers' one path ([`crate::run::Run`]); with one-sided constraints
//! ([`run_member_with`]) the run goes in phases, each ended where a multiplier falls through
//! zero ([`LagrangeEvents`], [`Source::Release`]) and the released constraint leaves the
//! system.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::{
    Constant, Inputs, LagrangeEvents, Lagrangian, Model, NoCallbacks, Source, Stabilization,
};
use crate::drivers::{Clock, Counters, Output, Sampling, Status};
use crate::events::Watch;
use crate::observers::{NoObserver, Observer};
use crate::run::Run;
use crate::spec::RunSpec;
use crate::system::VectorField;

/// The method of a run: DOP853 or an explicit tableau (RK4 as its tableau); the methods that
/// need a rigid body's structure are refused at the boundary ([`crate::spec::RunSpec::check_for`]).
pub use crate::spec::Method;

/// How a member's run ended, with its counters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemberRun {
    pub status: Status,
    pub n_steps: u64,
    pub n_fev: u64,
}

/// The one-sided constraints of a run: their indices among the model's constraints, and the
/// detection grid's number of points (`event_resolution`): a phase from `ta` detects releases
/// at points no further apart than `(t1 − ta)/(resolution − 1)` ([`crate::events::Watch`]).
#[derive(Clone, Copy, Debug)]
pub struct OneSided<'a> {
    pub constraints: &'a [usize],
    pub resolution: usize,
}

impl OneSided<'_> {
    /// No one-sided constraint.
    pub const NONE: OneSided<'static> = OneSided {
        constraints: &[],
        resolution: 2,
    };
}

/// Integrate one member: parameters `p`, constant inputs `u`, initial state `y0` (2n), its
/// samples at `t_eval` into `samples` (len(t_eval) · 2n; NaN when the run fails). A run that
/// takes `max_steps` steps before its end stops there, with the status
/// [`Status::Running`] (NaN samples), as one stopped by `stop`.
#[allow(clippy::too_many_arguments)]
pub fn run_member(
    model: &Model,
    p: &[f64],
    u: &[f64],
    y0: &[f64],
    stabilization: Stabilization,
    method: Method,
    t0: f64,
    t1: f64,
    dt: f64,
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
) -> MemberRun {
    let span = (t0, t1, dt);
    run_member_with(
        model,
        p,
        u,
        y0,
        stabilization,
        method,
        span,
        t_eval,
        samples,
        max_steps,
        stop,
        OneSided::NONE,
        &mut [],
    )
}

/// [`run_member`] with one-sided constraints: the run goes in phases, as a single run of the
/// Python package does. In each, the multiplier of every one-sided constraint in play is
/// watched ([`LagrangeEvents`], [`Source::Release`]); where one falls through zero the phase
/// ends at that instant (located inside the time loop), the constraint leaves the system and
/// the next phase starts there afresh (a new step-size choice, the samples from there on), at
/// most `max_steps` steps each. `releases` (one per one-sided constraint) gets the release
/// times, NaN for a constraint that held. `span` is `(t0, t1, dt)`.
#[allow(clippy::too_many_arguments)]
pub fn run_member_with(
    model: &Model,
    p: &[f64],
    u: &[f64],
    y0: &[f64],
    stabilization: Stabilization,
    method: Method,
    span: (f64, f64, f64),
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
    one_sided: OneSided,
    releases: &mut [f64],
) -> MemberRun {
    let (t0, t1, dt) = span;
    releases.fill(f64::NAN);
    let s = model.shape;
    if one_sided.constraints.iter().any(|&c| c >= s.m) {
        return failed_member(samples);
    }
    let dim = 2 * s.n;
    let mut times = vec![0.0; t_eval.len()];
    let mut z = y0.to_vec();
    let mut active = vec![true; s.m];
    let (mut ta, mut written) = (t0, 0usize);
    let (mut n_steps, mut n_fev) = (0u64, 0u64);
    let status = loop {
        let mask = (!active.iter().all(|&a| a)).then(|| active.clone());
        let Ok(sys) = Lagrangian::new(model, p, Constant(u), stabilization, mask) else {
            return failed_member(samples);
        };
        let out = Output {
            t: &mut times[written..],
            y: &mut samples[written * dim..],
        };
        let sampling = Sampling {
            t_end: t1,
            t_eval: &t_eval[written..],
            every: u64::MAX,
        };
        let mut phase = Phase::new((method, dt, max_steps), stop, ta);
        let watched = one_sided.in_play(&active);
        let (status, released) = if watched.is_empty() {
            (
                phase.run(&sys, &mut NoObserver, &mut z, sampling, out),
                None,
            )
        } else {
            let spacing = (t1 - ta) / (one_sided.resolution.max(2) - 1) as f64;
            phase.run_releasing(&sys, &watched, spacing, &mut z, sampling, out)
        };
        if let Some(c) = released {
            active[c] = false;
            if let Some(slot) = one_sided.constraints.iter().position(|&k| k == c) {
                releases[slot] = phase.clock.t;
            }
        }
        n_steps += phase.counters.n_steps;
        n_fev += phase.counters.n_fev;
        written += phase.counters.n_out;
        ta = phase.clock.t;
        if status != Status::Terminated {
            break status;
        }
    };
    if status != Status::Finished {
        samples.fill(f64::NAN);
    }
    MemberRun {
        status,
        n_steps,
        n_fev,
    }
}

/// A member that cannot run (a one-sided constraint out of range, a system that cannot be
/// made): NaN samples, no steps.
fn failed_member(samples: &mut [f64]) -> MemberRun {
    samples.fill(f64::NAN);
    MemberRun {
        status: Status::NonFinite,
        n_steps: 0,
        n_fev: 0,
    }
}

impl OneSided<'_> {
    /// The releases to watch: those of the one-sided constraints still in play (`active`).
    fn in_play(&self, active: &[bool]) -> Vec<Source> {
        self.constraints
            .iter()
            .filter(|&&c| active[c])
            .map(|&c| Source::Release(c))
            .collect()
    }
}

/// One phase of a member's run: the run's method, step and step budget `max_steps`, the stop
/// flag, and the phase's clock and counters (fresh at its start).
struct Phase<'s> {
    method: Method<'s>,
    dt: f64,
    max_steps: u64,
    stop: &'s AtomicBool,
    clock: Clock,
    counters: Counters,
}

impl<'s> Phase<'s> {
    /// A phase from `ta`.
    fn new((method, dt, max_steps): (Method<'s>, f64, u64), stop: &'s AtomicBool, ta: f64) -> Self {
        Phase {
            method,
            dt,
            max_steps,
            stop,
            clock: Clock { t: ta, h: 0.0 },
            counters: Counters::default(),
        }
    }

    /// Run the phase to its end (or a terminal event, `max_steps` steps, `stop`): the
    /// members' one runner, [`Run::to_end`].
    fn run<S: VectorField, O: Observer>(
        &mut self,
        sys: &S,
        observer: &mut O,
        z: &mut [f64],
        sampling: Sampling,
        out: Output,
    ) -> Status {
        let mut f = vec![0.0; sys.dim()];
        let max_steps = self.max_steps;
        let mut run = Run {
            spec: RunSpec {
                method: self.method,
                dt: self.dt,
                sampling,
                max_steps,
            },
            clock: &mut self.clock,
            z,
            f: &mut f,
            out,
            counters: &mut self.counters,
        };
        run.to_end(self.stop, |run, steps| run.chunk(sys, observer, steps))
    }

    /// Run the phase watching the releases `watched` ([`LagrangeEvents`]: the multipliers of
    /// the one-sided constraints in play) at detection points no further apart than
    /// `spacing`: where a multiplier falls through zero the phase ends there
    /// ([`Status::Terminated`]), and that constraint is returned with the status.
    fn run_releasing<I: Inputs>(
        &mut self,
        sys: &Lagrangian<'_, I>,
        watched: &[Source],
        spacing: f64,
        z: &mut [f64],
        sampling: Sampling,
        out: Output,
    ) -> (Status, Option<usize>) {
        let events =
            LagrangeEvents::new(sys, watched, None, NoCallbacks).expect("constraints in play");
        let terminal = vec![true; watched.len()];
        let direction = vec![-1.0; watched.len()];
        let mut watch = Watch::new(&events, &terminal, &direction, spacing, sys.dim());
        let status = self.run(sys, &mut watch, z, sampling, out);
        if status != Status::Terminated {
            return (status, None);
        }
        let t = self.clock.t;
        let last = watch.log.iter().rev().find(|c| c.t == t).map(|c| c.event);
        match last.map(|e| watched[e]) {
            Some(Source::Release(c)) => (status, Some(c)),
            _ => (status, None),
        }
    }
}

/// Run members `P` (members · np), `U` (members · nu), `Y0` (members · 2n) in parallel on the
/// current rayon pool; member `i`'s samples into `samples[i]` (len(t_eval) · 2n). Each member
/// depends on its own data only, so its result is the same bit for bit whatever the chunking
/// or the number of threads, and equal to a single run of it.
#[allow(clippy::too_many_arguments)]
pub fn run_members(
    model: &Model,
    params: &[f64],
    inputs: &[f64],
    y0: &[f64],
    stabilization: Stabilization,
    method: Method,
    t0: f64,
    t1: f64,
    dt: f64,
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
) -> Vec<MemberRun> {
    let span = (t0, t1, dt);
    run_members_with(
        model,
        (params, inputs, y0),
        stabilization,
        method,
        span,
        t_eval,
        samples,
        max_steps,
        stop,
        OneSided::NONE,
        &mut [],
    )
}

/// [`run_members`] with one-sided constraints ([`run_member_with`]): `data` is
/// `(P, U, Y0)`; member `i`'s release times go to `releases[i]` (one per one-sided
/// constraint).
#[allow(clippy::too_many_arguments)]
pub fn run_members_with(
    model: &Model,
    data: (&[f64], &[f64], &[f64]),
    stabilization: Stabilization,
    method: Method,
    span: (f64, f64, f64),
    t_eval: &[f64],
    samples: &mut [f64],
    max_steps: u64,
    stop: &AtomicBool,
    one_sided: OneSided,
    releases: &mut [f64],
) -> Vec<MemberRun> {
    let (params, inputs, y0) = data;
    let s = model.shape;
    let dim = 2 * s.n;
    let per = t_eval.len() * dim;
    let k = one_sided.constraints.len();
    let members = samples.len() / per.max(1);
    // without one-sided constraints, a slot per member that nothing reads
    let mut none = vec![0.0; if k == 0 { members } else { 0 }];
    let releases = if k == 0 { &mut none[..] } else { releases };
    samples
        .par_chunks_mut(per.max(1))
        .zip(releases.par_chunks_mut(k.max(1)))
        .enumerate()
        .map(|(i, (rows, released))| {
            if stop.load(Ordering::Relaxed) {
                rows.fill(f64::NAN);
                released.fill(f64::NAN);
                return MemberRun {
                    status: Status::Running,
                    n_steps: 0,
                    n_fev: 0,
                };
            }
            run_member_with(
                model,
                &params[i * s.np..(i + 1) * s.np],
                &inputs[i * s.nu..(i + 1) * s.nu],
                &y0[i * dim..(i + 1) * dim],
                stabilization,
                method,
                span,
                t_eval,
                rows,
                max_steps,
                stop,
                one_sided,
                &mut released[..k],
            )
        })
        .collect()
}
