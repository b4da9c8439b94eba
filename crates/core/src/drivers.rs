//! Time loops: the whole integration of a system in one call.
//!
//! A driver advances the solver's state until the end time, keeping only the samples asked
//! for, and returns a [`Status`]. It allocates its work space once per call and nothing per
//! step, and it is *resumable*: the time, the next step size and the state live in buffers the
//! caller owns ([`Clock`], [`Counters`]), and `max_steps` bounds the steps per call, so the
//! caller can report progress, grow an output buffer, check for an interrupt or stop between
//! calls, at no cost per step.
//!
//! Sampling (diffrax's `SaveAt`): with sample times `t_eval` (increasing), fixed-step methods
//! shorten a step to land on each sample and the adaptive method interpolates with its dense
//! output; without them, the start, every `save_every`-th step and the end are kept.

use crate::layout::{load, STATE_SIZE};
use crate::observers::Observer;
use crate::steppers::{
    dop853_dense, dop853_error_norm, dop853_interpolate, dop853_step, erk_step, initial_step_size,
    momentum_to_velocity, rk4_rigid_step, rkmk_step, step_size_factor, velocity_to_momentum,
    Control, Tableau,
};
use crate::system::{RigidStructure, VectorField};
use crate::tableaux::{DOP853_INTERPOLATOR_POWER, DOP853_STAGES, DOP853_STAGES_EXTENDED};

mod adaptive;
pub(crate) use adaptive::{clamp_step, trial_step};
pub use adaptive::{next_up, run_adaptive};

/// Steps a driver takes between two looks at a stop flag (an ensemble's, a resumable run's):
/// well under a millisecond of RK4, a few milliseconds of DOP853 for a rigid body.
pub const STEPS_PER_CALL: u64 = 4096;

/// How a call of a driver ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i64)]
pub enum Status {
    /// Stopped after `max_steps` steps; call again to continue.
    Running = 0,
    Finished = 1,
    /// The state became NaN or infinite (left in `z` for the diagnosis).
    NonFinite = 2,
    /// The adaptive step fell below 10 ulps of t.
    StepTooSmall = 3,
    /// No room for the next sample; grow the output and call again.
    OutputFull = 4,
    /// A call out of the engine (a user callback) failed; its error is kept by the caller.
    CallbackFailed = 5,
    /// A terminal event ended the run ([`crate::events::Watch`]): the time and the state are
    /// those of its zero.
    Terminated = 6,
}

/// Counters a run keeps between calls.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Samples written.
    pub n_out: usize,
    /// Index of the next sample time.
    pub next_sample: usize,
    pub n_steps: u64,
    pub n_fev: u64,
    pub n_rejected: u64,
}

impl Counters {
    /// The next sample due by `upto` (the time of `t_eval` at `next_sample`, when at most
    /// `upto`): its row and time, counted as written.
    #[inline(always)]
    pub(crate) fn next_due(&mut self, t_eval: &[f64], upto: f64) -> Option<(usize, f64)> {
        if self.next_sample < t_eval.len() && t_eval[self.next_sample] <= upto {
            let due = (self.n_out, t_eval[self.next_sample]);
            self.n_out += 1;
            self.next_sample += 1;
            Some(due)
        } else {
            None
        }
    }

    /// Without sample times: the row of the state after a step that ended at `t`, when it is
    /// due (every `every`-th step, and at the end, unless an event's zero ended the step:
    /// `ended`), counted as written.
    #[inline(always)]
    fn step_due(&mut self, sampling: &Sampling, t: f64, ended: bool) -> Option<usize> {
        if ended || !(self.n_steps % sampling.every.max(1) == 0 || t >= sampling.t_end) {
            return None;
        }
        self.n_out += 1;
        Some(self.n_out - 1)
    }

    /// Write the samples at a run's start `t` through `write(row, time)`: the sample times
    /// due by then, or (without sample times) the start itself.
    #[inline(always)]
    fn samples_at_start(&mut self, t_eval: &[f64], t: f64, mut write: impl FnMut(usize, f64)) {
        if t_eval.is_empty() {
            write(self.n_out, t);
            self.n_out += 1;
        }
        while let Some((i, ti)) = self.next_due(t_eval, t) {
            write(i, ti);
        }
    }
}

/// The current time and, for the adaptive method, the next step size (0 before the first).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Clock {
    pub t: f64,
    pub h: f64,
}

/// Where samples go: `t` (m) and `y` (m · n, row per sample).
pub struct Output<'a> {
    pub t: &'a mut [f64],
    pub y: &'a mut [f64],
}

impl Output<'_> {
    #[inline(always)]
    fn capacity(&self) -> usize {
        self.t.len()
    }

    /// Write sample `i`: the time `t` and the state `y` (a row).
    #[inline(always)]
    fn store(&mut self, i: usize, t: f64, y: &[f64]) {
        let n = y.len();
        self.t[i] = t;
        self.y[i * n..(i + 1) * n].copy_from_slice(y);
    }
}

/// What to save and until when.
#[derive(Clone, Copy, Debug)]
pub struct Sampling<'a> {
    pub t_end: f64,
    /// Sample times (increasing); empty: every `every`-th step.
    pub t_eval: &'a [f64],
    pub every: u64,
}

/// Fixed-step drivers check the state for non-finite values every this many steps (and
/// before saving a sample); a failure is then pinned to its exact step by replaying from the
/// last verified state.
pub const CHECK_EVERY: u64 = 32;

/// True when every entry is finite (`x − x` is 0 for finite x, NaN otherwise); the tests are
/// independent and OR-ed, so the compiler vectorises them.
#[inline(always)]
pub fn all_finite(z: &[f64]) -> bool {
    let mut bad = false;
    for &x in z {
        #[allow(clippy::eq_op)]
        {
            bad |= x - x != 0.0;
        }
    }
    !bad
}

/// A buffer of doubles that starts on a cache line (64 bytes).
pub struct Lines {
    lines: Vec<Line>,
    len: usize,
}

#[repr(C, align(64))]
#[derive(Clone, Copy)]
struct Line([f64; 8]);

impl Lines {
    pub fn zeros(len: usize) -> Self {
        Lines {
            lines: vec![Line([0.0; 8]); len.div_ceil(8)],
            len,
        }
    }
    pub fn from_slice(z: &[f64]) -> Self {
        let mut out = Self::zeros(z.len());
        out.copy_from_slice(z);
        out
    }
}

impl std::ops::Deref for Lines {
    type Target = [f64];
    #[inline(always)]
    fn deref(&self) -> &[f64] {
        // SAFETY: `Line` is `repr(C)` over `[f64; 8]`: the lines are `8 · lines.len() ≥ len`
        // contiguous, initialised doubles.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr() as *const f64, self.len) }
    }
}

impl std::ops::DerefMut for Lines {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as for `deref`, uniquely borrowed.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr() as *mut f64, self.len) }
    }
}

/// A fixed-step method as the fixed-step driver runs it.
pub trait FixedMethod<S: VectorField + ?Sized> {
    /// Evaluations of the vector field per step.
    fn evals_per_step(&self) -> u64;
    /// `out` = the state after a step of `h` from `(t, z)` (the method's own state), put back
    /// on the system's constraint.
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]);
    /// The method's state from the system's (identity but for the splitting method).
    fn init(&self, sys: &S, y: &[f64], z: &mut [f64]) {
        let _ = sys;
        z.copy_from_slice(y);
    }
    /// The system's state from the method's.
    fn output(&self, sys: &S, z: &[f64], y: &mut [f64]) {
        let _ = sys;
        y.copy_from_slice(z);
    }
}

/// Any explicit Runge–Kutta tableau, projected after each step.
pub struct Erk<'a> {
    tab: Tableau<'a>,
    k: Vec<f64>,
    ytmp: Vec<f64>,
}

impl<'a> Erk<'a> {
    pub fn new(tab: Tableau<'a>, n: usize) -> Self {
        Erk {
            tab,
            k: vec![0.0; tab.stages().max(1) * n],
            ytmp: vec![0.0; n],
        }
    }
}

impl<S: VectorField + ?Sized> FixedMethod<S> for Erk<'_> {
    fn evals_per_step(&self) -> u64 {
        self.tab.stages() as u64
    }
    #[inline(always)]
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        erk_step(sys, &self.tab, t, z, h, &mut self.k, &mut self.ytmp, out);
        sys.project(t + h, out);
    }
}

/// Classical RK4 on a rigid state in registers, constrained after each step.
pub struct Rk4Rigid;

impl<S: RigidStructure + ?Sized> FixedMethod<S> for Rk4Rigid {
    fn evals_per_step(&self) -> u64 {
        4
    }
    #[inline(always)]
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        let y1 = sys.constrain(t + h, rk4_rigid_step(sys, t, &load(z), h));
        out[..STATE_SIZE].copy_from_slice(&y1);
    }
}

/// Runge–Kutta–Munthe-Kaas with a tableau, projected after each step.
pub struct Rkmk<'a> {
    tab: Tableau<'a>,
    k: Vec<f64>,
    ytmp: Vec<f64>,
    kth: Vec<[f64; 3]>,
}

impl<'a> Rkmk<'a> {
    pub fn new(tab: Tableau<'a>, n: usize) -> Self {
        let s = tab.stages().max(1);
        Rkmk {
            tab,
            k: vec![0.0; s * n],
            ytmp: vec![0.0; n],
            kth: vec![[0.0; 3]; s],
        }
    }
}

impl<S: VectorField + ?Sized> FixedMethod<S> for Rkmk<'_> {
    fn evals_per_step(&self) -> u64 {
        self.tab.stages() as u64
    }
    #[inline(always)]
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        rkmk_step(
            sys,
            &self.tab,
            t,
            z,
            h,
            &mut self.k,
            &mut self.ytmp,
            &mut self.kth,
            out,
        );
        sys.project(t + h, out);
    }
}

/// Runge–Kutta–Munthe-Kaas on a rigid body: with the classical RK4 tableau, the step in
/// registers ([`RigidStructure::rkmk4`], the one the ensembles' lanes run), else the
/// generic [`Rkmk`].
pub struct RkmkRigid<'a> {
    generic: Rkmk<'a>,
    rk4: bool,
}

impl<'a> RkmkRigid<'a> {
    pub fn new(tab: Tableau<'a>) -> Self {
        RkmkRigid {
            rk4: is_rk4(&tab),
            generic: Rkmk::new(tab, STATE_SIZE),
        }
    }
}

/// Whether a tableau is the classical RK4's ([`crate::steppers::RK4`]).
pub fn is_rk4(tab: &Tableau) -> bool {
    let rk4 = crate::steppers::RK4;
    tab.a == rk4.a && tab.b == rk4.b && tab.c == rk4.c
}

impl<S: RigidStructure + ?Sized> FixedMethod<S> for RkmkRigid<'_> {
    fn evals_per_step(&self) -> u64 {
        FixedMethod::<S>::evals_per_step(&self.generic)
    }
    #[inline(always)]
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        if self.rk4 {
            out[..STATE_SIZE].copy_from_slice(&sys.rkmk4(t, &load(z), h));
            sys.project(t + h, out);
        } else {
            self.generic.step(sys, t, z, h, out);
        }
    }
}

/// The splitting method on the momentum state.
pub struct Splitting;

impl<S: RigidStructure + ?Sized> FixedMethod<S> for Splitting {
    fn evals_per_step(&self) -> u64 {
        2
    }
    #[inline(always)]
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        out[..STATE_SIZE].copy_from_slice(&sys.splitting(t, &load(z), h));
    }
    fn init(&self, sys: &S, y: &[f64], z: &mut [f64]) {
        velocity_to_momentum(sys, y, z);
    }
    fn output(&self, sys: &S, z: &[f64], y: &mut [f64]) {
        y[..STATE_SIZE].copy_from_slice(&momentum_to_velocity(sys, z));
    }
}

#[inline(always)]
fn save<S: VectorField + ?Sized, M: FixedMethod<S>>(
    m: &M,
    sys: &S,
    t: f64,
    z: &[f64],
    out: &mut Output,
    k: usize,
) {
    let n = z.len();
    out.t[k] = t;
    m.output(sys, z, &mut out.y[k * n..(k + 1) * n]);
}

crate::multiversion! {
    /// [`run_fixed`] in a copy compiled for AVX2 + FMA where the CPU has them (else the
    /// baseline), chosen at run time as the ensembles' lanes choose theirs
    /// ([`crate::lanes::run_block`]): a step written with fused multiply-adds
    /// ([`crate::systems::TorqueFree::rk4_points`]) then runs them in hardware. A single run is
    /// scalar code, so AVX-512 adds nothing (its copy measured 35 ns per torque-free RK4 step
    /// against 31). A fused multiply-add is rounded
    /// once wherever it runs (a baseline CPU computes it in software, slowly), so every copy
    /// gives the same numbers, and a single run equals its ensemble member bit for bit.
    pub fn run_fixed_native, run_fixed_native_with [S, M, O] (
        sys: &S,
        method: &mut M,
        observer: &mut O,
        clock: &mut Clock,
        z: &mut [f64],
        dt: f64,
        sampling: &Sampling,
        out: &mut Output,
        counters: &mut Counters,
        max_steps: u64,
    ) -> Status where [
        S: VectorField + ?Sized,
        M: FixedMethod<S>,
        O: Observer,
    ] => run_fixed, up to Avx2;
}

/// Integrate with a fixed-step method from `clock.t` to `sampling.t_end`, resumably.
///
/// `z` (n) is the method's state ([`FixedMethod::init`]) and is advanced in place; samples go
/// to `out`. Steps are `dt`, shortened to land exactly on every sample time and on the end.
///
/// Always inlined: a caller compiled for a wider instruction set (the ensembles' lanes,
/// [`crate::lanes`]) gets the whole loop, its steps included, in that instruction set.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn run_fixed<S, M, O>(
    sys: &S,
    method: &mut M,
    observer: &mut O,
    clock: &mut Clock,
    z: &mut [f64],
    dt: f64,
    sampling: &Sampling,
    out: &mut Output,
    counters: &mut Counters,
    max_steps: u64,
) -> Status
where
    S: VectorField + ?Sized,
    M: FixedMethod<S>,
    O: Observer,
{
    // the two state buffers swap roles every step; whole cache lines, so that vector loads
    // and stores of many states at once (crate::lanes) never straddle two
    let mut a = Lines::from_slice(z);
    let mut b = Lines::zeros(sys.dim());
    let mut checkpoint = Lines::from_slice(z); // the last state verified finite
    let (mut t, mut c) = (clock.t, *counters);
    if c.n_steps == 0 && c.n_out == 0 {
        fixed_samples(sys, method, (sampling, &mut c, out), &a, (t, t), false);
    }
    let mut status = first_status(sampling, t, &c);
    let mut taken: u64 = 0;
    let per_step = method.evals_per_step();
    let slack = dt * (1.0 + 1e-9);
    let mut exact = false;
    while status == Status::Running && taken < max_steps {
        if sampling.t_eval.is_empty() && c.n_out >= out.capacity() {
            status = Status::OutputFull;
            break;
        }
        let plan = Plan::new(sampling, &c, t, (dt, slack), exact, max_steps - taken);
        let t_checked = t;
        checkpoint.copy_from_slice(&a);
        let (done, ended) = take_steps(sys, method, observer, &mut a, &mut b, &mut t, plan);
        let verdict = verdict(sys, observer, &a, exact);
        if verdict == Verdict::Replay {
            // replay from the last verified state one checked step at a time, to report the
            // exact step where the state stopped being finite
            a.copy_from_slice(&checkpoint);
            t = t_checked;
            exact = true;
            continue;
        }
        c.n_steps += done;
        c.n_fev += done * per_step;
        if let Verdict::Stop(s) = verdict {
            status = s;
            break;
        }
        taken += done;
        let upto = t + 1e-12 * t.abs().max(1.0);
        let to = (sampling, &mut c, &mut *out);
        if fixed_samples(sys, method, to, &a, (t, upto), ended.is_some()) || t >= sampling.t_end {
            status = Status::Finished;
        }
        if ended.is_some() {
            status = Status::Terminated;
        }
    }
    z.copy_from_slice(&a);
    clock.t = t;
    *counters = c;
    status
}

/// A call's status before its first step: finished when `t` is at the end or every sample
/// time is written.
#[inline(always)]
fn first_status(sampling: &Sampling, t: f64, c: &Counters) -> Status {
    let n_eval = sampling.t_eval.len();
    if t >= sampling.t_end || (n_eval > 0 && c.next_sample >= n_eval) {
        Status::Finished
    } else {
        Status::Running
    }
}

/// [`run_fixed`]'s next run of steps: `run` whole steps of `dt`, then (`planned` > `run`) one
/// step onto `target`, the next sample time or the end.
#[derive(Clone, Copy)]
struct Plan {
    dt: f64,
    target: f64,
    run: u64,
    planned: u64,
}

impl Plan {
    /// The run of steps from `t` (`slack`: how far short of the target a whole step still
    /// goes): at most [`CHECK_EVERY`] steps (1 while replaying them one checked step at a
    /// time: `exact`) before the next look at the state, at most the `left` steps of the
    /// call and, without sample times, the steps to the next `every`-th.
    #[inline(always)]
    fn new(
        sampling: &Sampling,
        c: &Counters,
        t: f64,
        (dt, slack): (f64, f64),
        exact: bool,
        left: u64,
    ) -> Plan {
        let use_eval = !sampling.t_eval.is_empty();
        let target = if use_eval {
            sampling.t_eval[c.next_sample]
        } else {
            sampling.t_end
        };
        let mut budget = (if exact { 1 } else { CHECK_EVERY }).min(left);
        if !use_eval {
            let every = sampling.every.max(1);
            budget = budget.min(every - c.n_steps % every);
        }
        let (mut run, mut tt) = (0u64, t);
        while run < budget && target - tt > slack {
            tt += dt;
            run += 1;
        }
        let planned = if run < budget { run + 1 } else { run };
        Plan {
            dt,
            target,
            run,
            planned,
        }
    }
}

/// Take the planned steps from `(t, a)` ([`Plan`]), each observed; `a` and `t` follow them
/// (`b` is each step's scratch). Stops at a terminal event's zero (the state left there, its
/// time returned) or when the watch's callback failed. Returns the steps taken.
#[inline(always)]
fn take_steps<S, M, O>(
    sys: &S,
    method: &mut M,
    observer: &mut O,
    a: &mut Lines,
    b: &mut Lines,
    t: &mut f64,
    plan: Plan,
) -> (u64, Option<f64>)
where
    S: VectorField + ?Sized,
    M: FixedMethod<S>,
    O: Observer,
{
    let mut done = 0;
    while done < plan.planned {
        let whole = done < plan.run;
        let h = if whole { plan.dt } else { plan.target - *t };
        method.step(sys, *t, a, h, b);
        observer.observe(0, *t, a, *t + h, b);
        let t1 = if whole { *t + h } else { plan.target };
        done += 1;
        if O::WATCHES {
            if let Some(tz) = watch_step(sys, method, observer, a, b, *t, t1) {
                std::mem::swap(a, b);
                *t = tz;
                return (done, Some(tz));
            }
            if observer.watch_failed() {
                break;
            }
        }
        std::mem::swap(a, b);
        *t = t1;
    }
    (done, None)
}

/// A watching observer's look at the fixed step from `(t, a)` to `(t1, b)` (the state within
/// it: the step from `t`, shortened): a terminal event's zero `tz`, with `b` the step
/// retaken onto it.
#[inline(always)]
fn watch_step<S, M, O>(
    sys: &S,
    method: &mut M,
    observer: &mut O,
    a: &[f64],
    b: &mut [f64],
    t: f64,
    t1: f64,
) -> Option<f64>
where
    S: VectorField + ?Sized,
    M: FixedMethod<S>,
    O: Observer,
{
    let at = &mut |s: f64, out: &mut [f64]| method.step(sys, t, a, s - t, out);
    let tz = observer.watch(t, a, t1, b, at)?;
    if tz < t1 {
        method.step(sys, t, a, tz - t, b);
    }
    Some(tz)
}

/// What [`run_fixed`]'s checks after a run of steps say.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Verdict {
    Go,
    /// Replay the steps from the last verified state, one checked step at a time.
    Replay,
    Stop(Status),
}

/// The checks after a run of steps ending in `a`: a failed callback stops the run; a state no
/// longer finite stops it after a single checked step (`exact`: this is where it stopped
/// being finite), and has the steps replayed after several.
#[inline(always)]
fn verdict<S, O>(sys: &S, observer: &O, a: &[f64], exact: bool) -> Verdict
where
    S: VectorField + ?Sized,
    O: Observer,
{
    if sys.failed() || observer.watch_failed() {
        return Verdict::Stop(Status::CallbackFailed);
    }
    if !all_finite(a) {
        return if exact {
            Verdict::Stop(Status::NonFinite)
        } else {
            Verdict::Replay
        };
    }
    Verdict::Go
}

/// The samples after a fixed step that ended at `t` in the state `a` (and at a run's start,
/// where `upto` is `t`): with sample times, those due by `upto`, and true once the last is
/// written; without, the state at `t` when due ([`Counters::step_due`]; `ended`: an event's
/// zero ended the step). (Calls of [`save`], not a closure: always inlined, in the caller's
/// instruction set.)
#[inline(always)]
fn fixed_samples<S: VectorField + ?Sized, M: FixedMethod<S>>(
    sys: &S,
    method: &M,
    (sampling, c, out): (&Sampling, &mut Counters, &mut Output),
    a: &[f64],
    (t, upto): (f64, f64),
    ended: bool,
) -> bool {
    if sampling.t_eval.is_empty() {
        if let Some(i) = c.step_due(sampling, t, ended) {
            save(method, sys, t, a, out, i);
        }
        return false;
    }
    while let Some((i, ti)) = c.next_due(sampling.t_eval, upto) {
        save(method, sys, ti, a, out, i);
    }
    c.next_sample >= sampling.t_eval.len()
}

#[cfg(test)]
#[path = "drivers_tests.rs"]
mod tests;
