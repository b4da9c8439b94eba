//! The adaptive driver: DOP853 with its step-size controller and dense output onto the sample
//! times ([`run_adaptive`]), and the step clamps it shares with the lanes' adaptive driver
//! (`crate::lanes::drivers`). The fixed-step driver and what both share (the clock, the
//! counters, the output, the sampling) are the parent module's, [`crate::drivers`].

use super::*;

/// The smallest step from `t` (10 ulps of t), with `h_abs` clamped to it and to `max_step`:
/// the adaptive drivers' clamp before a step's trials.
#[inline(always)]
pub(crate) fn clamp_step(t: f64, h_abs: &mut f64, max_step: f64) -> f64 {
    let min_step = 10.0 * (next_up(t) - t).abs();
    if *h_abs > max_step {
        *h_abs = max_step;
    } else if *h_abs < min_step {
        *h_abs = min_step;
    }
    min_step
}

/// A trial step from `t` of length `h_abs` cut at `t_end`: its end and signed length
/// `(t_new, h)`, with `h_abs = |h|`; `None` when `h_abs` is below `min_step`.
#[inline(always)]
pub(crate) fn trial_step(t: f64, h_abs: &mut f64, min_step: f64, t_end: f64) -> Option<(f64, f64)> {
    if *h_abs < min_step {
        return None;
    }
    let mut t_new = t + *h_abs;
    if t_new > t_end {
        t_new = t_end;
    }
    let h = t_new - t;
    *h_abs = h.abs();
    Some((t_new, h))
}

/// The state of a step: `(t, z, f)`, the time, the state and its derivative.
type StepStart<'a> = (f64, &'a [f64], &'a [f64]);

/// What every step of one call of [`run_adaptive`] reads: the system, its controller and its
/// sampling. (The buffers the steps write are the call's own locals, handed to each helper
/// as slices: distinct allocations, which the compiler then knows do not overlap, so that
/// the stages' and the dense output's loops vectorise.)
struct Adaptive<'a, S: ?Sized> {
    sys: &'a S,
    control: &'a Control,
    sampling: &'a Sampling<'a>,
}

impl<S: VectorField + ?Sized> Adaptive<'_, S> {
    /// The first call of a run: `f` at `(t, z)`, the samples at `t`, and the first step size
    /// (`h_abs` when given, else `control.first_step`, else [`initial_step_size`], with the
    /// buffers `ytmp` and `ftmp`).
    #[inline(always)]
    fn start(
        &self,
        (t, z, f): (f64, &[f64], &mut [f64]),
        h_abs: f64,
        out: &mut Output,
        c: &mut Counters,
        (ytmp, ftmp): (&mut [f64], &mut [f64]),
    ) -> f64 {
        let (sys, control) = (self.sys, self.control);
        sys.rhs(t, z, f);
        c.n_fev += 1;
        c.samples_at_start(self.sampling.t_eval, t, |i, ti| out.store(i, ti, z));
        if h_abs != 0.0 {
            return h_abs;
        }
        if control.first_step > 0.0 {
            return control.first_step;
        }
        c.n_fev += 1;
        initial_step_size(sys, t, z, f, self.sampling.t_end, 7.0, control, ytmp, ftmp)
    }

    /// One accepted DOP853 step from `(t, z, f)`: trial steps ([`clamp_step`],
    /// [`trial_step`]) until the error norm is below 1 (or a callback failed), `h_abs` scaled
    /// by the controller after each ([`step_size_factor`]) and each rejection counted; then
    /// the step's end put back on the constraints (its derivative anew) and the step counted.
    /// Returns `(t_new, h)`, with the end in `z_new`, its derivative in `f_new` and the stages
    /// in `kk` (`ytmp` their scratch); else sets `status` to what stops the run: the step
    /// size fell below 10 ulps of t, or a callback failed.
    #[inline(always)]
    fn step(
        &self,
        (t, z, f): StepStart,
        h_abs: &mut f64,
        (kk, ytmp, z_new, f_new): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
        c: &mut Counters,
        status: &mut Status,
    ) -> Option<(f64, f64)> {
        let (sys, control) = (self.sys, self.control);
        let min_step = clamp_step(t, h_abs, control.max_step);
        let mut rejected = false;
        let (t_new, h) = loop {
            let Some((t_new, h)) = trial_step(t, h_abs, min_step, self.sampling.t_end) else {
                *status = Status::StepTooSmall;
                return None;
            };
            dop853_step(sys, t, z, f, h, kk, ytmp, z_new, f_new);
            c.n_fev += DOP853_STAGES as u64;
            let (rtol, atol) = (control.rtol, control.atol);
            let err = dop853_error_norm(kk, sys.dim(), sys.error_blocks(), h, z, z_new, rtol, atol);
            *h_abs *= step_size_factor(err, 7.0, rejected, control);
            if err < 1.0 || sys.failed() {
                break (t_new, h);
            }
            rejected = true;
            c.n_rejected += 1;
        };
        if sys.failed() {
            *status = Status::CallbackFailed;
            return None;
        }
        if sys.project(t_new, z_new) {
            sys.rhs(t_new, z_new, f_new);
            c.n_fev += 1;
        }
        c.n_steps += 1;
        Some((t_new, h))
    }

    /// A watching observer's look at the accepted step from `z` to `t_new` (the state within
    /// it: the dense output, projected): a terminal event's zero.
    #[inline(always)]
    fn watch<O: Observer>(
        &self,
        observer: &mut O,
        dense: &mut Dense,
        z: &[f64],
        t_new: f64,
    ) -> Option<f64> {
        if !O::WATCHES {
            return None;
        }
        let (sys, t, z_new) = (self.sys, dense.step.0, dense.ends.0);
        let at = &mut |s: f64, out: &mut [f64]| dense.at(sys, z, s, out);
        observer.watch(t, z, t_new, z_new, at)
    }

    /// The samples after the accepted step from `z` to `t_new`: with sample times, those due
    /// by its end or by an event's zero `ended` in it, the step's end itself and the dense
    /// output elsewhere (`sample` its buffer), and true once the last is written; without,
    /// the step's end when due ([`Counters::step_due`]). (Written without a closure of the
    /// dense output, whose buffers then stay distinct to the compiler.)
    #[inline(always)]
    fn samples(
        &self,
        (c, out): (&mut Counters, &mut Output),
        dense: &mut Dense,
        (z, t_new, ended): (&[f64], f64, Option<f64>),
        sample: &mut [f64],
    ) -> bool {
        let (sampling, z_new) = (self.sampling, dense.ends.0);
        if sampling.t_eval.is_empty() {
            if let Some(i) = c.step_due(sampling, t_new, ended.is_some()) {
                out.store(i, t_new, z_new);
            }
            return false;
        }
        while let Some((i, ti)) = c.next_due(sampling.t_eval, ended.unwrap_or(t_new)) {
            if ti == t_new {
                out.store(i, ti, z_new);
            } else {
                dense.at(self.sys, z, ti, sample);
                out.store(i, ti, sample);
            }
        }
        c.next_sample >= sampling.t_eval.len()
    }

    /// Leave `(z, f)` at a terminal event's zero `tz` in the accepted step that ends at
    /// `t_new`: the dense output there, projected, and its derivative anew; or the step's end
    /// when `tz` is it. Returns the evaluations it made (1 or 0).
    #[inline(always)]
    fn settle_at_zero(
        &self,
        dense: &mut Dense,
        (t_new, tz): (f64, f64),
        (z, f): (&mut [f64], &mut [f64]),
        sample: &mut [f64],
    ) -> u64 {
        if tz < t_new {
            dense.at(self.sys, z, tz, sample);
            z.copy_from_slice(sample);
            self.sys.rhs(tz, z, f);
            return 1;
        }
        z.copy_from_slice(dense.ends.0);
        f.copy_from_slice(dense.ends.1);
        0
    }
}

/// The dense output of an accepted step `(t, h)` of [`run_adaptive`] to its `ends` (the
/// state and its derivative at `t + h`): [`dop853_dense`] on the step's stages `kk` (`ytmp`
/// its scratch) into the interpolant `fd`, made on first use (`ready`) at the cost of three
/// more evaluations, added to `evals`.
struct Dense<'w> {
    step: (f64, f64),
    ends: (&'w [f64], &'w [f64]),
    kk: &'w mut [f64],
    ytmp: &'w mut [f64],
    fd: &'w mut [f64],
    ready: bool,
    evals: &'w mut u64,
}

impl<'w> Dense<'w> {
    /// The dense output of the step `(t, h)` to `ends`, not made yet.
    #[inline(always)]
    fn new(
        step: (f64, f64),
        ends: (&'w [f64], &'w [f64]),
        (kk, ytmp, fd): (&'w mut [f64], &'w mut [f64], &'w mut [f64]),
        evals: &'w mut u64,
    ) -> Self {
        Dense {
            step,
            ends,
            kk,
            ytmp,
            fd,
            ready: false,
            evals,
        }
    }

    /// The state at `s` within the step from `z`, projected onto the constraints, into
    /// `out`.
    #[inline(always)]
    fn at<S: VectorField + ?Sized>(&mut self, sys: &S, z: &[f64], s: f64, out: &mut [f64]) {
        let ((t, h), (z_new, f_new)) = (self.step, self.ends);
        if !self.ready {
            dop853_dense(sys, t, h, z, z_new, f_new, self.kk, self.ytmp, self.fd);
            *self.evals += (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
            self.ready = true;
        }
        dop853_interpolate(self.fd, z, (s - t) / h, out);
        sys.project(s, out);
    }
}

/// The buffers of one call of [`run_adaptive`] for a state of `n` numbers: the stages, the
/// interpolant, the scratch of a stage, the step's end and its derivative, a sample.
#[inline(always)]
fn adaptive_buffers(n: usize) -> [Vec<f64>; 6] {
    let stages = vec![0.0; DOP853_STAGES_EXTENDED * n];
    let interpolant = vec![0.0; DOP853_INTERPOLATOR_POWER * n];
    [
        stages,
        interpolant,
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    ]
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
    let cx = Adaptive {
        sys,
        control,
        sampling,
    };
    let [mut kk, mut fd, mut ytmp, mut znew, mut fnew, mut sample] = adaptive_buffers(sys.dim());
    let (mut t, mut h_abs, mut c, mut evals) = (clock.t, clock.h, *counters, 0);
    if c.n_fev == 0 {
        h_abs = cx.start((t, z, f), h_abs, out, &mut c, (&mut ytmp, &mut fnew));
    }
    let mut status = first_status(sampling, t, &c);
    if sys.failed() {
        status = Status::CallbackFailed;
    }
    let mut taken: u64 = 0;
    while status == Status::Running && taken < max_steps {
        if sampling.t_eval.is_empty() && c.n_out >= out.capacity() {
            status = Status::OutputFull;
            break;
        }
        let work = (&mut kk[..], &mut ytmp[..], &mut znew[..], &mut fnew[..]);
        let Some((t_new, h)) = cx.step((t, z, f), &mut h_abs, work, &mut c, &mut status) else {
            break;
        };
        taken += 1;
        observer.observe(0, t, z, t_new, &znew);
        if !all_finite(&znew) {
            z.copy_from_slice(&znew);
            t = t_new;
            status = Status::NonFinite;
            break;
        }
        let buffers = (&mut kk[..], &mut ytmp[..], &mut fd[..]);
        let mut dense = Dense::new((t, h), (&znew, &fnew), buffers, &mut evals);
        let ended = cx.watch(observer, &mut dense, z, t_new);
        if O::WATCHES && observer.watch_failed() {
            status = Status::CallbackFailed;
            break;
        }
        if cx.samples((&mut c, out), &mut dense, (z, t_new, ended), &mut sample) {
            status = Status::Finished;
        }
        if let Some(tz) = ended {
            c.n_fev += cx.settle_at_zero(&mut dense, (t_new, tz), (z, f), &mut sample);
            t = tz;
            status = Status::Terminated;
            break;
        }
        z.copy_from_slice(&znew);
        f.copy_from_slice(&fnew);
        t = t_new;
        if t >= sampling.t_end {
            status = Status::Finished;
        }
        if sys.failed() {
            status = Status::CallbackFailed;
        }
    }
    c.n_fev += evals;
    clock.t = t;
    clock.h = h_abs;
    *counters = c;
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
