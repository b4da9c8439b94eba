//! Ensembles: many independent motions of one body (`docs/ensembles.md`), each an ordinary
//! run of the single-body systems and drivers, in parallel over the members.
//!
//! Nothing here is a formula of its own. A member is a [`Member`]: its body's parameters
//! (its own inertia, or the body every member shares), its principal axes, its built-in
//! forces and its body-frame initial state. [`run_member`] integrates it with the systems of
//! [`crate::systems`] ([`TorqueFree`](crate::systems::TorqueFree) without forces or pivot,
//! [`Rigid`](crate::systems::Rigid) otherwise) and the drivers of [`crate::drivers`]
//! ([`crate::drivers::run_fixed`] with any [`FixedMethod`](crate::drivers::FixedMethod),
//! [`run_adaptive`]), watching its flips with the
//! [`FlipObserver`](crate::observers::FlipObserver); [`run_members`] runs a chunk of members on
//! the current rayon pool. A member's arithmetic depends on nothing but its own data, so its
//! result is the same bit for bit whatever the chunking or the number of threads, and equal to
//! a single-body run of it.
//!
//! Every member gets its own [`Status`](crate::drivers::Status) (a member that fails gets NaN
//! samples and statistics; the others are untouched) and its own [`MemberSummary`]: the run's
//! counters, its flips, and the reductions over its samples of [`Drift`], streamed as the
//! member finishes, so that a caller that keeps only statistics never stores a trajectory (one
//! member's samples per thread at a time).
//!
//! Runs stop promptly when the caller raises a flag: the drivers are resumable and run
//! [`STEPS_PER_CALL`] steps between two looks at it.
//!
//! The files: `members.rs` (a member, its run, its drifts and summary) and `blocks.rs` (blocks
//! of [`LANES`] members in SIMD lanes, with the systems and methods each block runs); here the
//! schedule every member shares and the parallel run of a chunk.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::lanes::LANES;
use crate::layout::STATE_SIZE;

mod blocks;
mod members;

use blocks::{in_lanes, run_lanes};
pub use members::*;

pub use crate::drivers::STEPS_PER_CALL;

/// The method every member runs (DOP853: each member with its own step sizes).
pub use crate::spec::Method;

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
    /// Record the flips of every member ([`FlipObserver`](crate::observers::FlipObserver)).
    pub flips: bool,
    /// Steps each member may take; one that reaches it stops there with
    /// [`Status::Running`](crate::drivers::Status::Running) and NaN samples after it.
    pub max_steps: u64,
}

/// Run a chunk of members on the current rayon pool (`rayon::ThreadPool::install` picks
/// one). Per member `i`: its samples go to `samples[i · n · 18 ..]` (n · 18 each, body frame)
/// when given, else to one buffer per thread; its final state to `finals[i · 18 ..]`; its
/// summary to `summaries[i]`. Members not started when `stop` is raised keep the default
/// summary (status [`Status::Running`](crate::drivers::Status::Running): not run) and NaN
/// states.
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

#[cfg(test)]
#[path = "ensemble_tests.rs"]
mod tests;
