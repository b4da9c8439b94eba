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
    let n = sys.dim();
    let t_eval = sampling.t_eval;
    let t_end = sampling.t_end;
    let save_every = sampling.every.max(1);
    // the two state buffers swap roles every step; whole cache lines, so that vector loads
    // and stores of many states at once (crate::lanes) never straddle two
    let mut a = Lines::from_slice(z);
    let mut b = Lines::zeros(n);
    let mut checkpoint = Lines::from_slice(z); // the last state verified finite
    let n_eval = t_eval.len();
    let use_eval = n_eval > 0;
    let mut t = clock.t;
    let mut nout = counters.n_out;
    let mut k = counters.next_sample;
    let mut nsteps = counters.n_steps;
    let mut nfev = counters.n_fev;
    if nsteps == 0 && nout == 0 {
        if use_eval {
            while k < n_eval && t_eval[k] <= t {
                save(method, sys, t_eval[k], &a, out, nout);
                nout += 1;
                k += 1;
            }
        } else {
            save(method, sys, t, &a, out, nout);
            nout += 1;
        }
    }
    let mut status = Status::Running;
    if t >= t_end || (use_eval && k >= n_eval) {
        status = Status::Finished;
    }
    let mut taken: u64 = 0;
    let per_step = method.evals_per_step();
    let slack = dt * (1.0 + 1e-9);
    let mut exact = false;
    while status == Status::Running && taken < max_steps {
        if !use_eval && nout >= out.capacity() {
            status = Status::OutputFull;
            break;
        }
        // plan: `run` whole steps of dt, then (`lands`) one step onto the target; the run ends
        // early at a finiteness check, at `max_steps` or at a `save_every` sample
        let target = if use_eval { t_eval[k] } else { t_end };
        let mut budget = (if exact { 1 } else { CHECK_EVERY }).min(max_steps - taken);
        if !use_eval {
            budget = budget.min(save_every - nsteps % save_every);
        }
        let mut run = 0u64;
        let mut tt = t;
        while run < budget && target - tt > slack {
            tt += dt;
            run += 1;
        }
        let lands = run < budget;
        let t_checked = t;
        checkpoint.copy_from_slice(&a);
        let planned = if lands { run + 1 } else { run };
        let mut done = 0;
        let mut ended = None;
        while done < planned {
            let i = done;
            let h = if i < run { dt } else { target - t };
            method.step(sys, t, &a, h, &mut b);
            observer.observe(0, t, &a, t + h, &b);
            let t1 = if i < run { t + h } else { target };
            done += 1;
            if O::WATCHES {
                // the state within the step: the step from t, shortened
                let (ta, za) = (t, &a);
                let at = &mut |s: f64, out: &mut [f64]| method.step(sys, ta, za, s - ta, out);
                if let Some(tz) = observer.watch(t, &a, t1, &b, at) {
                    if tz < t1 {
                        method.step(sys, t, &a, tz - t, &mut b);
                    }
                    std::mem::swap(&mut a, &mut b);
                    t = tz;
                    ended = Some(tz);
                    break;
                }
                if observer.watch_failed() {
                    break;
                }
            }
            std::mem::swap(&mut a, &mut b);
            t = t1;
        }
        if sys.failed() || observer.watch_failed() {
            nsteps += done;
            nfev += done * per_step;
            status = Status::CallbackFailed;
            break;
        }
        if !all_finite(&a) {
            if exact {
                // a replayed single step: this is where it stopped being finite
                nsteps += done;
                nfev += done * per_step;
                status = Status::NonFinite;
                break;
            }
            // replay from the last verified state one checked step at a time, to report the
            // exact step where the state stopped being finite
            a.copy_from_slice(&checkpoint);
            t = t_checked;
            exact = true;
            continue;
        }
        nsteps += done;
        taken += done;
        nfev += done * per_step;
        if use_eval {
            let tol = 1e-12 * t.abs().max(1.0);
            while k < n_eval && t_eval[k] <= t + tol {
                save(method, sys, t_eval[k], &a, out, nout);
                nout += 1;
                k += 1;
            }
            if k >= n_eval {
                status = Status::Finished;
            }
        } else if ended.is_none() && (nsteps % save_every == 0 || t >= t_end) {
            save(method, sys, t, &a, out, nout);
            nout += 1;
        }
        if t >= t_end {
            status = Status::Finished;
        }
        if ended.is_some() {
            status = Status::Terminated;
        }
    }
    z.copy_from_slice(&a);
    clock.t = t;
    counters.n_out = nout;
    counters.next_sample = k;
    counters.n_steps = nsteps;
    counters.n_fev = nfev;
    status
}

/// Integrate with adaptive Dormand–Prince 8(5,3) from `clock.t` to `sampling.t_end`,
/// resumably.
///
/// `z` (n) and its derivative `f` (n, kept between calls: first-same-as-last) are advanced
/// in place; `clock.h` is the next step
/// size (0 before the first step: chosen by [`initial_step_size`], or `control.first_step`).
/// Constrained systems are projected after every step and at every interpolated sample.
#[allow(clippy::too_many_arguments)]
pub fn run_adaptive<S, O>(
    sys: &S,
    observer: &mut O,
    clock: &mut Clock,
    z: &mut [f64],
    f: &mut [f64],
    control: &Control,
    sampling: &Sampling,
    out: &mut Output,
    counters: &mut Counters,
    max_steps: u64,
) -> Status
where
    S: VectorField + ?Sized,
    O: Observer,
{
    let n = sys.dim();
    let t_eval = sampling.t_eval;
    let t_end = sampling.t_end;
    let save_every = sampling.every.max(1);
    let mut kk = vec![0.0; DOP853_STAGES_EXTENDED * n];
    let mut fd = vec![0.0; DOP853_INTERPOLATOR_POWER * n];
    let mut ytmp = vec![0.0; n];
    let mut znew = vec![0.0; n];
    let mut fnew = vec![0.0; n];
    let mut sample = vec![0.0; n];
    let (rtol, atol, max_step) = (control.rtol, control.atol, control.max_step);
    let n_eval = t_eval.len();
    let use_eval = n_eval > 0;
    let mut t = clock.t;
    let mut h_abs = clock.h;
    let mut nout = counters.n_out;
    let mut k = counters.next_sample;
    let mut nsteps = counters.n_steps;
    let mut nfev = counters.n_fev;
    let mut nrej = counters.n_rejected;
    let store = |out: &mut Output, i: usize, t: f64, y: &[f64]| {
        out.t[i] = t;
        out.y[i * n..(i + 1) * n].copy_from_slice(y);
    };
    if nfev == 0 {
        sys.rhs(t, z, f);
        nfev += 1;
        if use_eval {
            while k < n_eval && t_eval[k] <= t {
                store(out, nout, t_eval[k], z);
                nout += 1;
                k += 1;
            }
        } else {
            store(out, nout, t, z);
            nout += 1;
        }
        if h_abs == 0.0 {
            if control.first_step > 0.0 {
                h_abs = control.first_step;
            } else {
                h_abs = initial_step_size(sys, t, z, f, t_end, 7.0, control, &mut ytmp, &mut fnew);
                nfev += 1;
            }
        }
    }
    let mut status = Status::Running;
    if t >= t_end || (use_eval && k >= n_eval) {
        status = Status::Finished;
    }
    if sys.failed() {
        status = Status::CallbackFailed;
    }
    let mut taken: u64 = 0;
    while status == Status::Running && taken < max_steps {
        if !use_eval && nout >= out.capacity() {
            status = Status::OutputFull;
            break;
        }
        let min_step = 10.0 * (next_up(t) - t).abs();
        if h_abs > max_step {
            h_abs = max_step;
        } else if h_abs < min_step {
            h_abs = min_step;
        }
        let mut rejected = false;
        let mut t_new;
        let mut h;
        loop {
            if h_abs < min_step {
                status = Status::StepTooSmall;
                t_new = t;
                h = 0.0;
                break;
            }
            t_new = t + h_abs;
            if t_new > t_end {
                t_new = t_end;
            }
            h = t_new - t;
            h_abs = h.abs();
            dop853_step(sys, t, z, f, h, &mut kk, &mut ytmp, &mut znew, &mut fnew);
            nfev += DOP853_STAGES as u64;
            let err = dop853_error_norm(&kk, n, h, z, &znew, rtol, atol);
            h_abs *= step_size_factor(err, 7.0, rejected, control);
            if err < 1.0 || sys.failed() {
                break;
            }
            rejected = true;
            nrej += 1;
        }
        if status != Status::Running {
            break;
        }
        if sys.failed() {
            status = Status::CallbackFailed;
            break;
        }
        if sys.project(t_new, &mut znew) {
            sys.rhs(t_new, &znew, &mut fnew);
            nfev += 1;
        }
        nsteps += 1;
        taken += 1;
        observer.observe(0, t, z, t_new, &znew);
        if !all_finite(&znew) {
            z.copy_from_slice(&znew);
            t = t_new;
            status = Status::NonFinite;
            break;
        }
        let mut dense = false;
        let mut ended = None;
        if O::WATCHES {
            // the state within the step: the dense output, projected
            let extra = (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
            let (za, zb, fb) = (&*z, &znew, &fnew);
            let at = &mut |s: f64, out: &mut [f64]| {
                if !dense {
                    dop853_dense(sys, t, h, za, zb, fb, &mut kk, &mut ytmp, &mut fd);
                    nfev += extra;
                    dense = true;
                }
                dop853_interpolate(&fd, za, (s - t) / h, out);
                sys.project(s, out);
            };
            ended = observer.watch(t, za, t_new, zb, at);
            if observer.watch_failed() {
                status = Status::CallbackFailed;
                break;
            }
        }
        let t_stop = ended.unwrap_or(t_new);
        if use_eval {
            while k < n_eval && t_eval[k] <= t_stop {
                if t_eval[k] == t_new {
                    store(out, nout, t_new, &znew);
                } else {
                    if !dense {
                        dop853_dense(sys, t, h, z, &znew, &fnew, &mut kk, &mut ytmp, &mut fd);
                        nfev += (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
                        dense = true;
                    }
                    dop853_interpolate(&fd, z, (t_eval[k] - t) / h, &mut sample);
                    sys.project(t_eval[k], &mut sample);
                    store(out, nout, t_eval[k], &sample);
                }
                nout += 1;
                k += 1;
            }
            if k >= n_eval {
                status = Status::Finished;
            }
        } else if ended.is_none() && (nsteps % save_every == 0 || t_new >= t_end) {
            store(out, nout, t_new, &znew);
            nout += 1;
        }
        if let Some(tz) = ended {
            if tz < t_new {
                if !dense {
                    dop853_dense(sys, t, h, z, &znew, &fnew, &mut kk, &mut ytmp, &mut fd);
                    nfev += (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
                }
                dop853_interpolate(&fd, z, (tz - t) / h, &mut sample);
                sys.project(tz, &mut sample);
                z.copy_from_slice(&sample);
                sys.rhs(tz, z, f);
                nfev += 1;
            } else {
                z.copy_from_slice(&znew);
                f.copy_from_slice(&fnew);
            }
            t = tz;
            status = Status::Terminated;
            break;
        }
        z.copy_from_slice(&znew);
        f.copy_from_slice(&fnew);
        t = t_new;
        if t >= t_end {
            status = Status::Finished;
        }
        if sys.failed() {
            status = Status::CallbackFailed;
        }
    }
    clock.t = t;
    clock.h = h_abs;
    counters.n_out = nout;
    counters.next_sample = k;
    counters.n_steps = nsteps;
    counters.n_fev = nfev;
    counters.n_rejected = nrej;
    status
}

/// The next float above `x` (NumPy's `nextafter(x, inf)`).
#[inline(always)]
pub fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    f64::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
}

#[cfg(test)]
#[path = "drivers_tests.rs"]
mod tests;
