//! Events inside the time loop: functions `g(t, y)` of the state whose zeros are located
//! along a run, with `solve_ivp`'s contract (`terminal`, `direction`).
//!
//! After every step from `(t0, y0)` to `(t1, y1)` a driver hands [`Watch`] (an
//! [`Observer`]) a way to reach the state at any time of the step (the adaptive method's
//! dense output, projected onto the constraints; a fixed-step method's step restarted from
//! `t0` with a shorter length: the integrator's own accuracy either way). The watch:
//!
//! 1. evaluates the events at the step's end, and at points within it no further apart than
//!    `spacing` (so that a long adaptive step does not hide two zeros from a detection grid
//!    that a user asked to be fine);
//! 2. takes a sign change of an event between two such points, in its direction (both values
//!    finite and different; rising: `a < 0 ≤ b`, falling: `a > 0 ≥ b`), as a zero in between;
//! 3. locates the zero by Brent's method ([`brent`]) on the state reached within the step,
//!    and logs the event, the time and the state ([`Crossing`]);
//! 4. ends the run at the earliest zero of a terminal event: the driver leaves the state at
//!    that time and returns [`crate::drivers::Status::Terminated`]. Zeros logged past it in
//!    the same interval are dropped (they did not happen).
//!
//! Zeros closer together than the detection spacing can be missed (two zeros in one interval
//! leave no sign change).

use crate::observers::Observer;

/// Values of a run's events.
pub trait EventFunctions {
    /// How many events.
    fn count(&self) -> usize;
    /// Event `k` at `(t, y)`; `None` when a call out of the engine (a user callback) failed.
    fn value(&self, k: usize, t: f64, y: &[f64]) -> Option<f64>;
    /// Every event at `(t, y)` into `out` (`count()`); false when a callback failed.
    fn values(&self, t: f64, y: &[f64], out: &mut [f64]) -> bool {
        for (k, o) in out.iter_mut().enumerate() {
            match self.value(k, t, y) {
                Some(v) => *o = v,
                None => return false,
            }
        }
        true
    }
}

/// A zero of event `event` at time `t`, with the state `y` there.
#[derive(Clone, Debug, PartialEq)]
pub struct Crossing {
    pub event: usize,
    pub t: f64,
    pub y: Vec<f64>,
}

/// True when `a → b` is a zero in `direction` (> 0 rising, < 0 falling, 0 both): both
/// finite, different, and rising `a < 0 ≤ b` or falling `a > 0 ≥ b`.
#[inline]
pub fn crosses(a: f64, b: f64, direction: f64) -> bool {
    if !(a.is_finite() && b.is_finite()) || a == b {
        return false;
    }
    let rising = a < 0.0 && b >= 0.0;
    let falling = a > 0.0 && b <= 0.0;
    if direction > 0.0 {
        rising
    } else if direction < 0.0 {
        falling
    } else {
        rising || falling
    }
}

/// A zero of `f` in `[xa, xb]`, given `(xa, fa)` and `(xb, fb)` with `f(xa) = fa` and
/// `f(xb) = fb` of different signs, by
/// Brent's method (R. P. Brent, *Algorithms for Minimization without Derivatives*, 1973,
/// ch. 4: inverse quadratic interpolation, the secant and bisection, the bracket kept). The
/// iteration stops when the bracket is narrower than `xtol + rtol·|x|`, after `max_iter`
/// evaluations, or at an exact zero; SciPy's `brentq` makes the same choices step for step.
pub fn brent(
    mut f: impl FnMut(f64) -> f64,
    (xa, fa): (f64, f64),
    (xb, fb): (f64, f64),
    xtol: f64,
    rtol: f64,
    max_iter: usize,
) -> f64 {
    let (mut xpre, mut xcur, mut fpre, mut fcur) = (xa, xb, fa, fb);
    let (mut xblk, mut fblk, mut spre, mut scur) = (0.0, 0.0, 0.0, 0.0);
    if fpre == 0.0 {
        return xpre;
    }
    if fcur == 0.0 {
        return xcur;
    }
    for _ in 0..max_iter {
        if fpre != 0.0 && fcur != 0.0 && fpre.is_sign_negative() != fcur.is_sign_negative() {
            xblk = xpre;
            fblk = fpre;
            spre = xcur - xpre;
            scur = spre;
        }
        if fblk.abs() < fcur.abs() {
            xpre = xcur;
            xcur = xblk;
            xblk = xpre;
            fpre = fcur;
            fcur = fblk;
            fblk = fpre;
        }
        let delta = (xtol + rtol * xcur.abs()) / 2.0;
        let sbis = (xblk - xcur) / 2.0;
        if fcur == 0.0 || sbis.abs() < delta {
            return xcur;
        }
        if spre.abs() > delta && fcur.abs() < fpre.abs() {
            let stry = if xpre == xblk {
                // the secant
                -fcur * (xcur - xpre) / (fcur - fpre)
            } else {
                // inverse quadratic interpolation
                let dpre = (fpre - fcur) / (xpre - xcur);
                let dblk = (fblk - fcur) / (xblk - xcur);
                -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            };
            if 2.0 * stry.abs() < spre.abs().min(3.0 * sbis.abs() - delta) {
                spre = scur;
                scur = stry;
            } else {
                spre = sbis;
                scur = sbis;
            }
        } else {
            spre = sbis;
            scur = sbis;
        }
        xpre = xcur;
        fpre = fcur;
        xcur += if scur.abs() > delta {
            scur
        } else if sbis > 0.0 {
            delta
        } else {
            -delta
        };
        fcur = f(xcur);
    }
    xcur
}

/// Brent's iterations at most, per zero.
pub const MAX_ITER: usize = 100;

/// The events of a run as an [`Observer`] that locates their zeros (see the module's
/// documentation). `log` holds the zeros found, in time order per interval; `failed` is set
/// when an event's callback failed (the driver then stops with
/// [`crate::drivers::Status::CallbackFailed`]).
pub struct Watch<'a, E: EventFunctions + ?Sized> {
    pub functions: &'a E,
    /// Per event: end the run at its first zero.
    pub terminal: &'a [bool],
    /// Per event: > 0 rising zeros only, < 0 falling only, 0 both.
    pub direction: &'a [f64],
    /// The largest distance between two detection points (∞: the step ends only).
    pub spacing: f64,
    pub log: Vec<Crossing>,
    pub failed: bool,
    /// The events at time `g0_at`, the start of the next interval (valid when `known`).
    g0: Vec<f64>,
    g0_at: f64,
    g1: Vec<f64>,
    known: bool,
    ya: Vec<f64>,
    yb: Vec<f64>,
    yz: Vec<f64>,
}

impl<'a, E: EventFunctions + ?Sized> Watch<'a, E> {
    /// A watch of `functions` on states of length `dim`. `terminal` and `direction` hold one
    /// entry per event (checked by the caller).
    pub fn new(
        functions: &'a E,
        terminal: &'a [bool],
        direction: &'a [f64],
        spacing: f64,
        dim: usize,
    ) -> Self {
        let n = functions.count();
        Watch {
            functions,
            terminal,
            direction,
            spacing,
            log: Vec::new(),
            failed: false,
            g0: vec![0.0; n],
            g0_at: f64::NAN,
            g1: vec![0.0; n],
            known: false,
            ya: vec![0.0; dim],
            yb: vec![0.0; dim],
            yz: vec![0.0; dim],
        }
    }

    /// Detection points in a step of length `h`: enough that none are further apart than
    /// `spacing` (at most 10⁶).
    fn pieces(&self, h: f64) -> usize {
        if self.spacing.is_finite() && self.spacing > 0.0 && h > self.spacing {
            (h / self.spacing).ceil().min(1e6) as usize
        } else {
            1
        }
    }

    /// The events at the start `t0` of a step, `y0` there, in `g0`: those of the last step's
    /// end, unless a driver replays steps from an earlier state (what was logged after `t0`
    /// is then dropped, to be found again). False when a callback failed.
    #[inline(always)]
    fn start_at(&mut self, t0: f64, y0: &[f64]) -> bool {
        if self.known && t0 != self.g0_at {
            // a driver replaying steps from an earlier state (to pin a non-finite state to
            // its step): what was found after it is found again
            self.log.retain(|c| c.t <= t0);
            self.known = false;
        }
        if !self.known {
            if !self.functions.values(t0, y0, &mut self.g0) {
                self.failed = true;
                return false;
            }
            self.known = true;
        }
        true
    }

    /// Detection point `j` of `pieces` in the step from `t0` to `(t1, y1)` (step 1 of the
    /// module's documentation): its time, the state there in `yb` (reached within the step,
    /// or the step's end) and the events there in `g1`; `None` when a callback failed.
    #[inline(always)]
    fn point(
        &mut self,
        j: usize,
        pieces: usize,
        t0: f64,
        (t1, y1): (f64, &[f64]),
        at: &mut dyn FnMut(f64, &mut [f64]),
    ) -> Option<f64> {
        let sb = if j == pieces {
            self.yb.copy_from_slice(y1);
            t1
        } else {
            let s = t0 + (t1 - t0) * (j as f64 / pieces as f64);
            at(s, &mut self.yb);
            s
        };
        if !self.functions.values(sb, &self.yb, &mut self.g1) {
            self.failed = true;
            return None;
        }
        Some(sb)
    }

    /// The zeros between the detection points `sa` and `sb` (steps 2 and 3 of the module's
    /// documentation): each event whose values there (`g0`, `g1`) cross in its direction,
    /// located by [`brent`] and logged with its state. Returns the earliest zero of a
    /// terminal event; `failed` is set when a callback failed.
    #[inline(always)]
    fn zeros_between(
        &mut self,
        sa: f64,
        sb: f64,
        at: &mut dyn FnMut(f64, &mut [f64]),
    ) -> Option<f64> {
        let mut stop: Option<f64> = None;
        for k in 0..self.functions.count() {
            let (ga, gb) = (self.g0[k], self.g1[k]);
            if !crosses(ga, gb, self.direction[k]) {
                continue;
            }
            let Some(tz) = self.locate(k, (sa, ga), (sb, gb), at) else {
                self.failed = true;
                return None;
            };
            let y = if tz == sa {
                self.ya.clone()
            } else if tz == sb {
                self.yb.clone()
            } else {
                at(tz, &mut self.yz);
                self.yz.clone()
            };
            self.log.push(Crossing { event: k, t: tz, y });
            if self.terminal[k] && stop.map_or(true, |s| tz < s) {
                stop = Some(tz);
            }
        }
        stop
    }

    /// Event `k`'s zero between `(sa, ga)` and `(sb, gb)` by [`brent`], on the state reached
    /// within the step; `None` when a callback failed.
    #[inline]
    fn locate(
        &mut self,
        k: usize,
        (sa, ga): (f64, f64),
        (sb, gb): (f64, f64),
        at: &mut dyn FnMut(f64, &mut [f64]),
    ) -> Option<f64> {
        let (functions, yz) = (self.functions, &mut self.yz);
        let mut failed = false;
        let tz = brent(
            |s| {
                at(s, yz);
                functions.value(k, s, yz).unwrap_or_else(|| {
                    failed = true;
                    f64::NAN
                })
            },
            (sa, ga),
            (sb, gb),
            1e-14 * sb.abs().max(1.0),
            4.0 * f64::EPSILON,
            MAX_ITER,
        );
        (!failed).then_some(tz)
    }

    /// The zeros logged since `first` put in time order, those after a terminal zero `stop`
    /// dropped first (step 4 of the module's documentation: they did not happen).
    #[inline(always)]
    fn settle_log(&mut self, first: usize, stop: Option<f64>) {
        if let Some(ts) = stop {
            let mut i = first;
            while i < self.log.len() {
                if self.log[i].t > ts {
                    self.log.remove(i);
                } else {
                    i += 1;
                }
            }
        }
        self.log[first..].sort_by(|a, b| a.t.total_cmp(&b.t));
    }
}

impl<E: EventFunctions + ?Sized> Observer for Watch<'_, E> {
    const WATCHES: bool = true;

    #[inline(always)]
    fn observe(&mut self, _: usize, _: f64, _: &[f64], _: f64, _: &[f64]) {}

    fn watch(
        &mut self,
        t0: f64,
        y0: &[f64],
        t1: f64,
        y1: &[f64],
        at: &mut dyn FnMut(f64, &mut [f64]),
    ) -> Option<f64> {
        if self.functions.count() == 0 || self.failed || !self.start_at(t0, y0) {
            return None;
        }
        let pieces = self.pieces(t1 - t0);
        let mut sa = t0;
        self.ya.copy_from_slice(y0);
        for j in 1..=pieces {
            let sb = self.point(j, pieces, t0, (t1, y1), at)?;
            let first = self.log.len();
            let stop = self.zeros_between(sa, sb, at);
            if self.failed {
                return None;
            }
            self.settle_log(first, stop);
            if stop.is_some() {
                return stop;
            }
            std::mem::swap(&mut self.g0, &mut self.g1);
            std::mem::swap(&mut self.ya, &mut self.yb);
            sa = sb;
        }
        self.g0_at = t1;
        None
    }

    fn watch_failed(&self) -> bool {
        self.failed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_textbook_zeros() {
        // x³ − 2x − 5 = 0: Wallis's equation, x = 2.0945514815423265...
        // (Whittaker & Robinson, The Calculus of Observations, §44)
        let f = |x: f64| x * x * x - 2.0 * x - 5.0;
        let x = brent(
            f,
            (2.0, f(2.0)),
            (3.0, f(3.0)),
            1e-15,
            4.0 * f64::EPSILON,
            100,
        );
        assert!((x - 2.094_551_481_542_326_5).abs() < 2e-15, "{x}");
        // cos x = x (the Dottie number 0.7390851332151607)
        let g = |x: f64| x.cos() - x;
        let x = brent(
            g,
            (0.0, g(0.0)),
            (1.0, g(1.0)),
            1e-15,
            4.0 * f64::EPSILON,
            100,
        );
        assert!((x - 0.739_085_133_215_160_7).abs() < 2e-15, "{x}");
        // an exact zero at an end is returned as it is
        assert_eq!(brent(|x| x, (0.0, 0.0), (1.0, 1.0), 1e-15, 0.0, 100), 0.0);
    }

    #[test]
    fn crossings_follow_the_direction_and_skip_non_finite_values() {
        assert!(crosses(-1.0, 1.0, 1.0) && !crosses(-1.0, 1.0, -1.0));
        assert!(crosses(1.0, -1.0, -1.0) && !crosses(1.0, -1.0, 1.0));
        assert!(crosses(-1.0, 0.0, 0.0) && !crosses(0.0, 1.0, 0.0));
        assert!(!crosses(f64::NAN, 1.0, 0.0) && !crosses(-1.0, f64::INFINITY, 0.0));
        assert!(!crosses(0.0, 0.0, 0.0));
    }

    /// sin t and cos 3t as the states of a trivial run (the state at t is exact), watched in
    /// steps of 0.7 with points no further apart than 0.05: every zero, in its direction, to
    /// round-off; a terminal event ends the watch at its first zero and drops later ones.
    struct Trig;
    impl EventFunctions for Trig {
        fn count(&self) -> usize {
            2
        }
        fn value(&self, k: usize, _: f64, y: &[f64]) -> Option<f64> {
            Some(y[k])
        }
    }

    fn state(t: f64, out: &mut [f64]) {
        out[0] = t.sin();
        out[1] = (3.0 * t).cos();
    }

    fn watch_run(w: &mut Watch<Trig>, t_end: f64, h: f64) -> Option<f64> {
        let (mut t, mut y0, mut y1) = (0.0, vec![0.0; 2], vec![0.0; 2]);
        state(t, &mut y0);
        while t < t_end {
            let t1 = (t + h).min(t_end);
            state(t1, &mut y1);
            if let Some(tz) = w.watch(t, &y0, t1, &y1, &mut state) {
                return Some(tz);
            }
            t = t1;
            std::mem::swap(&mut y0, &mut y1);
        }
        None
    }

    #[test]
    fn the_watch_finds_every_zero_in_its_direction() {
        let pi = std::f64::consts::PI;
        for direction in [0.0, 1.0, -1.0] {
            let dirs = [direction, direction];
            let terminal = [false, false];
            let mut w = Watch::new(&Trig, &terminal, &dirs, 0.05, 2);
            assert_eq!(watch_run(&mut w, 10.0, 0.7), None);
            let found = |k: usize| -> Vec<f64> {
                w.log.iter().filter(|c| c.event == k).map(|c| c.t).collect()
            };
            // sin falls at odd multiples of π; cos 3t falls at π/6 + 2jπ/3
            let sin: Vec<f64> = (1..4).map(|j| j as f64 * pi).collect();
            let cos: Vec<f64> = (0..10).map(|j| pi / 6.0 + j as f64 * pi / 3.0).collect();
            let pick = |z: &[f64], parity: usize| -> Vec<f64> {
                z.iter()
                    .enumerate()
                    .filter(|(i, _)| direction == 0.0 || i % 2 == parity)
                    .map(|(_, &x)| x)
                    .collect()
            };
            let (p_sin, p_cos) = if direction > 0.0 { (1, 1) } else { (0, 0) };
            for (got, want) in [(found(0), pick(&sin, p_sin)), (found(1), pick(&cos, p_cos))] {
                assert_eq!(got.len(), want.len(), "{direction} {got:?} {want:?}");
                for (a, b) in got.iter().zip(&want) {
                    assert!((a - b).abs() < 1e-13, "{a} {b}");
                }
            }
            // each logged state is the state at its time
            for c in &w.log {
                let mut y = [0.0; 2];
                state(c.t, &mut y);
                assert_eq!(c.y, y);
            }
        }
        // cos 3t terminal: the run ends at π/6 and sin's zeros after it are not logged
        let dirs = [0.0, 0.0];
        let terminal = [false, true];
        let mut w = Watch::new(&Trig, &terminal, &dirs, f64::INFINITY, 2);
        let tz = watch_run(&mut w, 10.0, 0.7).unwrap();
        assert!((tz - std::f64::consts::FRAC_PI_6).abs() < 1e-14);
        assert_eq!(w.log.len(), 1);
    }

    /// A driver that replays steps from an earlier state (the fixed-step driver pinning a
    /// non-finite state to its step) finds each zero once.
    #[test]
    fn replayed_steps_log_their_zeros_once() {
        let (dirs, terminal) = ([0.0, 0.0], [false, false]);
        let mut w = Watch::new(&Trig, &terminal, &dirs, f64::INFINITY, 2);
        watch_run(&mut w, 4.0, 0.5);
        let once = w.log.clone();
        // replay from t = 0 over the same steps
        watch_run(&mut w, 4.0, 0.5);
        assert_eq!(w.log, once);
        assert_eq!(once.len(), 1 + 4); // sin: π; cos 3t: π/6, π/2, 5π/6, 7π/6
    }

    /// With points only at the step ends, two zeros inside one step leave no sign change;
    /// the detection spacing finds them.
    #[test]
    fn the_spacing_finds_zeros_a_long_step_hides() {
        let (dirs, terminal) = ([0.0, 0.0], [false, false]);
        let mut coarse = Watch::new(&Trig, &terminal, &dirs, f64::INFINITY, 2);
        watch_run(&mut coarse, 7.0, 7.0);
        let mut fine = Watch::new(&Trig, &terminal, &dirs, 0.1, 2);
        watch_run(&mut fine, 7.0, 7.0);
        assert!(coarse.log.len() < 3, "{}", coarse.log.len());
        assert_eq!(fine.log.len(), 2 + 7); // sin: π, 2π; cos 3t: seven zeros below 7
    }
}
