//! A run in progress: its [`RunSpec`] and the buffers it advances (clock, state, the adaptive
//! method's derivative, samples, counters), and one chunk of it. Every driver of the crate
//! goes through here: the bindings' single runs (a call, in chunks between looks for an
//! interrupt), an ensemble's member (chunks between looks at the stop flag) and a constrained
//! system's phase; the method's stepper comes from the registry's one table
//! ([`crate::spec::Method::on_rigid`], [`crate::spec::Method::on_field`]).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::drivers::is_rk4;
use crate::drivers::{
    run_adaptive, run_fixed_native, Clock, Counters, FixedMethod, Output, Status, STEPS_PER_CALL,
};
use crate::observers::Observer;
use crate::sensitivity::{
    Sensitive, SensitiveExactSplitting, SensitiveRegisters, SensitiveSplitting,
};
use crate::spec::{Method, RunSpec, UseMethod};
use crate::steppers::Control;
use crate::system::{RigidStructure, VectorField};

/// A run's spec and the buffers it advances, borrowed for a call.
pub struct Run<'a> {
    pub spec: RunSpec<'a>,
    /// The time and the adaptive method's next step.
    pub clock: &'a mut Clock,
    /// The state (n): the system's between calls ([`Run::enter`], [`Run::leave`]).
    pub z: &'a mut [f64],
    /// The adaptive method's derivative at `z` (n), kept between calls.
    pub f: &'a mut [f64],
    pub out: Output<'a>,
    pub counters: &'a mut Counters,
}

impl Run<'_> {
    /// At most `steps` steps of a rigid body's run (`sys`), with any method; `obs` watches
    /// them.
    pub fn chunk_rigid<S, O>(&mut self, sys: &S, obs: &mut O, steps: u64) -> Status
    where
        S: RigidStructure + ?Sized,
        O: Observer,
    {
        let method = self.spec.method;
        method.on_rigid(
            sys,
            Chunk {
                run: self,
                sys,
                obs,
                steps,
            },
        )
    }

    /// At most `steps` steps of a run of any vector field (`sys`): the adaptive method or an
    /// explicit tableau. A method that needs a rigid body was refused when the run was built
    /// ([`RunSpec::check_for`]); here it fails the call.
    pub fn chunk<S, O>(&mut self, sys: &S, obs: &mut O, steps: u64) -> Status
    where
        S: VectorField + ?Sized,
        O: Observer,
    {
        let method = self.spec.method;
        method
            .on_field(
                sys,
                Chunk {
                    run: self,
                    sys,
                    obs,
                    steps,
                },
            )
            .unwrap_or(Status::CallbackFailed)
    }

    /// At most `steps` steps of a rigid body's run with its forward sensitivities (`sys`):
    /// RK4, RKMK4 and the splitting method as the derivatives of their discrete steps
    /// ([`SensitiveRegisters`], [`SensitiveSplitting`], [`SensitiveExactSplitting`]: enter and
    /// leave with [`Run::convert_sensitive`]), the methods of any vector field on the
    /// augmented system ([`Run::chunk`]).
    pub fn chunk_sensitive<O: Observer>(
        &mut self,
        sys: &Sensitive<'_>,
        obs: &mut O,
        steps: u64,
    ) -> Status {
        match self.spec.method {
            Method::Rkmk(tab) if is_rk4(&tab) => Chunk {
                run: self,
                sys,
                obs,
                steps,
            }
            .fixed(SensitiveRegisters::<true>), // RKMK4
            Method::Rk4 => Chunk {
                run: self,
                sys,
                obs,
                steps,
            }
            .fixed(SensitiveRegisters::<false>), // RK4
            Method::Splitting => Chunk {
                run: self,
                sys,
                obs,
                steps,
            }
            .fixed(SensitiveSplitting),
            Method::ExactSplitting(composition) => Chunk {
                run: self,
                sys,
                obs,
                steps,
            }
            .fixed(SensitiveExactSplitting { composition }),
            Method::Erk(_) | Method::Dop853(_) => self.chunk(sys, obs, steps),
            _ => Status::CallbackFailed,
        }
    }

    /// The method's own state from the system's in `z` at the start of a call of a run with
    /// sensitivities (`enter`), or back at its end: the splitting method's momenta and their
    /// derivatives (the exact-flow splittings' too); nothing for the others.
    pub fn convert_sensitive(&mut self, sys: &Sensitive<'_>, enter: bool) {
        if let Method::Splitting | Method::ExactSplitting(_) = self.spec.method {
            let from = self.z.to_vec();
            if enter {
                SensitiveSplitting.init(sys, &from, self.z);
            } else {
                SensitiveSplitting.output(sys, &from, self.z);
            }
        }
    }

    /// Run to the end (or a terminal event, or a failure), a chunk of at most
    /// [`STEPS_PER_CALL`] steps at a time (`chunk`: [`Run::chunk_rigid`] or [`Run::chunk`] of
    /// the caller's system and observer), looking at `stop` between chunks. A run that spends
    /// its step budget (`spec.max_steps`) stops there and stays [`Status::Running`], as one
    /// stopped by `stop` does. Every member of an ensemble runs through here: a rigid body's
    /// (`crate::ensemble`) and each phase of a constrained system's (`crate::lagrange`).
    pub fn to_end(
        &mut self,
        stop: &AtomicBool,
        mut chunk: impl FnMut(&mut Self, u64) -> Status,
    ) -> Status {
        let budget = self.spec.max_steps;
        loop {
            let left = budget.saturating_sub(self.counters.n_steps);
            if left == 0 {
                return Status::Running;
            }
            let status = chunk(self, STEPS_PER_CALL.min(left));
            if status != Status::Running || stop.load(Ordering::Relaxed) {
                return status;
            }
        }
    }

    /// The method's own state from the system's in `z`, at the start of a call of a rigid
    /// body's run (the splitting method's momenta; the identity for the others).
    pub fn enter<S: RigidStructure + ?Sized>(&mut self, sys: &S) {
        let method = self.spec.method;
        method.on_rigid(
            sys,
            Convert {
                sys,
                z: self.z,
                enter: true,
            },
        );
    }

    /// The system's state from the method's in `z`, at the end of a call ([`Run::enter`]).
    pub fn leave<S: RigidStructure + ?Sized>(&mut self, sys: &S) {
        let method = self.spec.method;
        method.on_rigid(
            sys,
            Convert {
                sys,
                z: self.z,
                enter: false,
            },
        );
    }
}

/// One chunk of a run with the stepper the table built.
struct Chunk<'r, 'a, S: ?Sized, O> {
    run: &'r mut Run<'a>,
    sys: &'r S,
    obs: &'r mut O,
    steps: u64,
}

impl<S: VectorField + ?Sized, O: Observer> UseMethod<S> for Chunk<'_, '_, S, O> {
    type Output = Status;

    fn fixed<M: FixedMethod<S> + Send>(self, mut method: M) -> Status {
        let r = self.run;
        run_fixed_native(
            self.sys,
            &mut method,
            self.obs,
            r.clock,
            r.z,
            r.spec.dt,
            &r.spec.sampling,
            &mut r.out,
            r.counters,
            self.steps,
        )
    }

    fn adaptive(self, control: Control) -> Status {
        let r = self.run;
        run_adaptive(
            self.sys,
            self.obs,
            r.clock,
            r.z,
            r.f,
            &control,
            &r.spec.sampling,
            &mut r.out,
            r.counters,
            self.steps,
        )
    }
}

/// Between the system's state and the method's ([`FixedMethod::init`], [`FixedMethod::output`]).
struct Convert<'r, S: ?Sized> {
    sys: &'r S,
    z: &'r mut [f64],
    enter: bool,
}

impl<S: VectorField + ?Sized> UseMethod<S> for Convert<'_, S> {
    type Output = ();

    fn fixed<M: FixedMethod<S> + Send>(self, method: M) {
        let from = self.z.to_vec();
        if self.enter {
            method.init(self.sys, &from, self.z);
        } else {
            method.output(self.sys, &from, self.z);
        }
    }

    fn adaptive(self, _control: Control) {}
}
