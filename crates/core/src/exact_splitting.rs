//! Exact-flow splitting (`docs/theory.md`, "Exact-flow splitting"): a body under forces
//! advanced by compositions of two flows, each solved exactly — the torque-free motion (the
//! closed form of [`crate::torque_free`], eqs (20)–(33)) and the kick of the forces at a fixed
//! attitude and position (`π += h τ`, `V += h F/M`).
//!
//! A composition is data ([`Composition`], the tables in [`crate::tableaux`]): the flows'
//! and the kicks' fractions of the step, alternating. For forces that depend on the time, the
//! position and the attitude only, the Hamiltonian splits as `H = T(π) + V(R, Q)` with
//! `{V, {V, {V, T}}} = 0`, so the Runge–Kutta–Nyström compositions of Blanes & Moan (2002)
//! apply; their error for a torque of size ε is O(ε hᵖ) (Celledoni, Fassò, Säfström & Zanna
//! 2008, *SIAM J. Sci. Comput.* 30(4), §5). Torque-free, every composition is the exact flow
//! (its flows compose to one), to round-off at any step.
//!
//! A free body under one central gravity drifts its centre of mass along Kepler's exact flow
//! ([`crate::kepler`]) and is kicked by the rest of the forces (the gravity-gradient terms and
//! any other), the splitting of Wisdom & Holman (1991): the error is then set by the gradient
//! terms alone (`docs/theory.md`, (S5)).
//!
//! The free flow is the closed form itself ([`crate::torque_free::Regime`] for ω,
//! [`crate::torque_free::attitude_at`] for Q, [`crate::torque_free::motion_at`]: one evaluation per sub-step from the sub-step's
//! own ω and Q): every branch of the exact solution (symmetric bodies, nearly symmetric ones,
//! the separatrix, fixed points) is the flow's. A body whose mass lies on a line (a zero
//! moment, which the closed form does not take) turns by the symmetric rotor's flow
//! ([`crate::rigid::free_rotor_symmetric`], exact for it).

use crate::drivers::FixedMethod;
use crate::dual::Dual;
use crate::forces::{central_point_force, Force};
use crate::freebody::euler_jacobian;
use crate::inertia::{symmetry_code, SYMMETRY_RTOL};
use crate::isa::Isa;
use crate::kepler::{kepler_flow, universal_anomaly};
use crate::layout::{Body, FORCE_PARAMS, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::linalg::expm;
use crate::real::{Real, Scalar};
use crate::rigid::free_rotor_symmetric;
use crate::so3::{Mat3, Vec3};
use crate::steppers::{hold_pivot, kick_by, momentum_to_velocity, velocity_to_momentum};
use crate::system::RigidStructure;
use crate::torque_free::{fixed_point_attitude, FIXED};
use crate::torque_free::{
    motion_at, motion_from_start, precession_attitude, precession_momentum, AttitudeSetup,
    ExactTangent, Radicals, Regime, ThirdKindStart, DIRECTIONS,
};

/// A composition of free flows and kicks, as fractions of the step: `kick_first` (the
/// "BAB" form) runs `kicks[0], flows[0], kicks[1], …, flows[m−1], kicks[m]`; otherwise
/// ("ABA") `flows[0], kicks[0], …, kicks[m−1], flows[m]`. Each list sums to one.
#[derive(Clone, Copy, Debug)]
pub struct Composition<'a> {
    pub kick_first: bool,
    pub flows: &'a [f64],
    pub kicks: &'a [f64],
}

impl<'a> Composition<'a> {
    /// The composition, checked: finite fractions, one more kick than flows (BAB) or one more
    /// flow than kicks (ABA), each list summing to one (to 1e-12); the error names the rule.
    pub fn new(kick_first: bool, flows: &'a [f64], kicks: &'a [f64]) -> Result<Self, String> {
        let (nf, nk) = (flows.len(), kicks.len());
        let shape_ok = nf >= 1
            && if kick_first {
                nk == nf + 1
            } else {
                nf == nk + 1
            };
        if !shape_ok {
            return Err(format!(
                "a composition needs at least one flow and {} (found {nf} flows, {nk} kicks)",
                if kick_first {
                    "one more kick than flows, kick first"
                } else {
                    "one more flow than kicks, flow first"
                }
            ));
        }
        for (what, list) in [("flows", flows), ("kicks", kicks)] {
            if let Some(k) = list.iter().position(|x| !x.is_finite()) {
                return Err(format!("`{what}[{k}]` must be finite, found {}", list[k]));
            }
            let sum: f64 = list.iter().sum();
            if (sum - 1.0).abs() > 1e-12 {
                return Err(format!("the {what} must sum to 1, found {sum}"));
            }
        }
        Ok(Composition {
            kick_first,
            flows,
            kicks,
        })
    }

    /// Kicks per step: the force evaluations of a step.
    pub fn kicks_per_step(&self) -> u64 {
        self.kicks.iter().filter(|&&b| b != 0.0).count() as u64
    }
}

/// The exact torque-free flow of one body on the momentum state `[R, V, Q, π]`: what the
/// closed form needs of the body, made once, and the motion the last flow was part of.
///
/// A flow starts a motion from the sub-step's own ω = π/I and Q (the regime and the attitude
/// setup of [`crate::torque_free`]). When the state it is handed is the one the previous flow
/// left (no kick moved it: no forces, or a force with no torque on a free body's rotation),
/// it goes on along that motion instead, at the time covered since it began: the whole steps
/// since (summed compensated) and the part of this step. So a torque-free run is the closed
/// form at the run's time, to round-off, at any step and after any number of steps: a memo
/// of the same function.
#[derive(Clone, Copy, Debug)]
pub struct FreeFlow {
    /// The instruction set of the flow's copy ([`evaluate_with`]), chosen once.
    isa: Isa,
    radicals: Radicals,
    symmetry: u8,
    /// All mass on a line (a zero moment): the symmetric rotor's flow.
    line: bool,
    motion: Option<Motion>,
}

/// A torque-free motion under way: its start (ω, Q, and the time into its first step at
/// which it began), the whole steps covered since (`steps + carry`, Neumaier's compensated
/// sum, with a step that has ended still `pending`) and the `(Q, π)` it left last. What the
/// closed form needs of the start (the regime, the frame, the start of `Π(u) − Π(u0)`) is made
/// when first needed ([`FreeFlow::evaluate`]): a flow made in lanes
/// ([`crate::torque_free::free_flows_in_lanes`]) needs none, and a flow one by one that goes on
/// along the motion makes it from the same start.
#[derive(Clone, Copy, Debug)]
struct Motion {
    /// What the closed form needs of the start, once `ready`.
    setup: Setup,
    ready: bool,
    w0: Vec3,
    q0: Mat3,
    began: f64,
    steps: f64,
    carry: f64,
    pending: f64,
    left: [f64; 12],
}

/// The closed form's setup of a motion ([`start_motion`]).
#[derive(Clone, Copy, Debug, Default)]
struct Setup {
    reg: Regime,
    att: AttitudeSetup,
    /// `Π(u) − Π(u0)` from the reductions (elliptic motions off the separatrix).
    start: Option<ThirdKindStart>,
}

impl FreeFlow {
    pub fn new(body: &Body) -> FreeFlow {
        FreeFlow {
            isa: Isa::widest_up_to(Isa::Avx2),
            radicals: Radicals::new(body.moments),
            symmetry: symmetry_code(body.moments, SYMMETRY_RTOL),
            line: body.moments[0] == 0.0,
            motion: None,
        }
    }

    /// Whether the flows of this body may run in lanes
    /// ([`crate::lanes::BlockExactSplitting`]): three distinct moments.
    pub fn takes_lanes(&self) -> bool {
        !self.line && self.symmetry == 0
    }

    /// The body's [`Radicals`].
    pub fn radicals(&self) -> &Radicals {
        &self.radicals
    }

    /// `z` advanced in place by the torque-free motion over `d`, a flow that ends `within`
    /// into its step of `h` (`within == h`: the step's last flow): π and Q by the closed form
    /// and, for a free body, its centre of mass by [`translate`] (Kepler's flow about the
    /// centre of `orbit`, or `R += d V`).
    #[inline]
    pub fn advance(
        &mut self,
        body: &Body,
        orbit: Option<&Force>,
        z: &mut [f64],
        d: f64,
        within: f64,
        h: f64,
    ) {
        if self.line {
            free_rotor_symmetric(body, z, d);
        } else {
            let t = self.plan(body, z, d, within);
            let (w, q) = self.evaluate(body.moments, t);
            self.finish(body, z, w, &q, within, h);
        }
        translate(body, orbit.map(|f| &f.p), z, d, |x| x);
    }

    /// The motion a flow from `z` over `d`, ending `within` into its step, follows, and the
    /// time into it at which the flow ends: a new motion from `z`'s own ω = π/I and Q, or,
    /// when `z` is the `(Q, π)` the last flow left (no kick moved it), that flow's motion with
    /// the steps it has covered summed (compensated). Its start is [`FreeFlow::start`].
    #[inline]
    pub fn plan(&mut self, body: &Body, z: &[f64], d: f64, within: f64) -> f64 {
        // in place: a motion is some hundred bytes, and a copy of it a call to `memcpy`
        match self.motion.as_mut() {
            Some(m) if m.left[..] == z[Q_AT..STATE_SIZE] => {
                let (s, x) = (m.steps, m.pending);
                let sum = s + x;
                m.carry += if s.abs() >= x.abs() {
                    (s - sum) + x
                } else {
                    (x - sum) + s
                };
                m.steps = sum;
                m.pending = 0.0;
                m.time(within)
            }
            Some(m) => {
                let (w0, q0) = flow_start(body, z);
                m.restart(w0, q0, within - d);
                m.time(within)
            }
            None => {
                let (w0, q0) = flow_start(body, z);
                let m = self.motion.insert(Motion::at(w0, q0, within - d));
                m.time(within)
            }
        }
    }

    /// The start (ω, Q) of the motion [`FreeFlow::plan`] chose.
    #[inline]
    pub fn start(&self) -> (Vec3, Mat3) {
        let m = self.motion.as_ref().expect("a flow planned");
        (m.w0, m.q0)
    }

    /// `(ω(t), Q(t))` of the planned motion by the closed form, its setup made when first
    /// needed (a motion planned for the lanes has none until a flow runs it here). It runs in
    /// a copy compiled for AVX2 + FMA where the CPU has them ([`evaluate_with`], the set
    /// chosen when the flow was made), as the drivers do: the elliptic functions' roundings
    /// and fused multiply-adds are then instructions, not library calls, with the same
    /// numbers.
    #[inline]
    pub fn evaluate(&mut self, moments: Vec3, t: f64) -> (Vec3, Mat3) {
        let m = self.motion.as_mut().expect("a flow planned");
        evaluate_with(self.isa, moments, &self.radicals, self.symmetry, m, t)
    }

    /// The planned motion's ω and Q at the end of its flow, `(w, q)` (here, or from the lanes:
    /// [`crate::torque_free::free_flows_in_lanes`]), written into `z` (π = Iω) and kept as
    /// what the motion left, the step's end noted for the next flow.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn finish(&mut self, body: &Body, z: &mut [f64], w: Vec3, q: &Mat3, within: f64, h: f64) {
        for k in 0..3 {
            z[OMEGA_AT + k] = body.moments[k] * w[k];
        }
        for r in 0..3 {
            z[Q_AT + 3 * r..Q_AT + 3 * r + 3].copy_from_slice(&q[r]);
        }
        let m = self.motion.as_mut().expect("a flow planned");
        m.left.copy_from_slice(&z[Q_AT..STATE_SIZE]);
        if within == h {
            // the step has ended: the next flow is in the next step
            m.pending = h;
        }
    }
}

/// The start of a flow from the momentum state `z`: `ω = π/I` and `Q`.
#[inline]
pub fn flow_start(body: &Body, z: &[f64]) -> (Vec3, Mat3) {
    // written out: `array::map`'s closures were calls of their own, at every flow
    let inv = body.inv_moments;
    let w0 = [
        z[OMEGA_AT] * inv[0],
        z[OMEGA_AT + 1] * inv[1],
        z[OMEGA_AT + 2] * inv[2],
    ];
    let q = &z[Q_AT..Q_AT + 9];
    let q0: Mat3 = [[q[0], q[1], q[2]], [q[3], q[4], q[5]], [q[6], q[7], q[8]]];
    (w0, q0)
}

impl Motion {
    fn at(w0: Vec3, q0: Mat3, began: f64) -> Motion {
        Motion {
            setup: Setup::default(),
            ready: false,
            w0,
            q0,
            began,
            steps: 0.0,
            carry: 0.0,
            pending: 0.0,
            left: [0.0; 12],
        }
    }

    /// [`Motion::at`] over `self`, in place: its setup to be made again, what it left kept
    /// ([`FreeFlow::finish`] writes it).
    #[inline(always)]
    fn restart(&mut self, w0: Vec3, q0: Mat3, began: f64) {
        self.ready = false;
        self.w0 = w0;
        self.q0 = q0;
        self.began = began;
        self.steps = 0.0;
        self.carry = 0.0;
        self.pending = 0.0;
    }

    /// The time into the motion at which a flow ending `within` into its step is evaluated:
    /// `steps + ((within − began) + carry)`.
    #[inline]
    fn time(&self, within: f64) -> f64 {
        self.steps + ((within - self.began) + self.carry)
    }
}

crate::multiversion! {
    /// [`evaluate`] in the copy for the widest instruction set up to AVX2 the CPU runs. The
    /// flows call `evaluate_with` with the set their [`FreeFlow`] chose once: asking again at
    /// every flow was three calls of its own.
    #[allow(dead_code)]
    fn evaluate_native, evaluate_with [] (
        moments: Vec3,
        radicals: &Radicals,
        symmetry: u8,
        m: &mut Motion,
        t: f64,
    ) -> (Vec3, Mat3) where [] => evaluate, up to Avx2;
}

/// `(ω(t), Q(t))` of the motion `m` ([`FreeFlow::evaluate`]), its setup made when first needed.
#[inline(always)]
fn evaluate(
    moments: Vec3,
    radicals: &Radicals,
    symmetry: u8,
    m: &mut Motion,
    t: f64,
) -> (Vec3, Mat3) {
    let (w0, q0) = (m.w0, m.q0);
    // not `get_or_insert_with`: its closure would be a function of its own, compiled for the
    // baseline
    if !m.ready {
        m.setup.fill(moments, radicals, symmetry, w0, &q0);
        m.ready = true;
    }
    let setup = &mut m.setup;
    match setup.start.as_mut() {
        Some(start) => motion_from_start(moments, &setup.reg, &setup.att, start, t),
        None => motion_at(moments, &setup.reg, &setup.att, w0, &q0, t),
    }
}

impl Setup {
    /// The setup of the motion from `w0`, `q0`, written over `self` in place (a copy of it
    /// was a call to `memcpy` at every flow).
    #[inline(always)]
    fn fill(&mut self, moments: Vec3, radicals: &Radicals, symmetry: u8, w0: Vec3, q0: &Mat3) {
        self.reg.fill(moments, radicals, symmetry, w0);
        let (att, start) = start_motion(moments, &self.reg, w0, q0);
        self.att = att;
        self.start = start;
    }
}

/// A free body's centre of mass moved over a flow of `d`: Kepler's flow about the centre of
/// the central gravity `orbit` (its parameter row: `μ`, the centre), else `R += d V`; about a
/// pivot `R` and `V` follow the attitude the flow reached ([`hold_pivot`]), where the next
/// kick's forces act. On `f64` or on dual numbers ([`kepler_flow`] takes one Newton step on
/// them from the values' universal anomaly).
#[inline]
pub fn translate<T: Scalar>(
    body: &Body<T>,
    orbit: Option<&[T; FORCE_PARAMS]>,
    z: &mut [T],
    d: f64,
    value: impl Fn(T) -> f64,
) {
    if body.has_pivot {
        hold_pivot(body, z);
        return;
    }
    match orbit {
        Some(p) => {
            let r0 = [z[R_AT] - p[1], z[R_AT + 1] - p[2], z[R_AT + 2] - p[3]];
            let v0 = [z[V_AT], z[V_AT + 1], z[V_AT + 2]];
            let chi = universal_anomaly(value(p[0]), &r0.map(&value), &v0.map(&value), d);
            let (r, v) = kepler_flow(p[0], &r0, &v0, d, chi);
            for k in 0..3 {
                z[R_AT + k] = p[1 + k] + r[k];
                z[V_AT + k] = v[k];
            }
        }
        None => {
            for k in 0..3 {
                z[R_AT + k] = z[R_AT + k] + T::splat(d) * z[V_AT + k];
            }
        }
    }
}

/// What a motion from `ω(0) = w0`, `Q(0) = q0` with regime `reg` needs for its attitude:
/// for the elliptic motions whose `Π(u)` comes from the reduction, the frame alone
/// ([`AttitudeSetup::frame`]) and the start of `Π(u) − Π(u0)` ([`ThirdKindStart`]: no
/// `Π(u0)` reduction, `Π(n|m)` only if the flow leaves its half period); otherwise the whole
/// [`AttitudeSetup`] (eqs (20)–(33); `docs/theory.md` §5).
#[inline(always)]
fn start_motion(
    moments: Vec3,
    reg: &Regime,
    w0: Vec3,
    q0: &Mat3,
) -> (AttitudeSetup, Option<ThirdKindStart>) {
    if reg.is_elliptic() {
        let att = AttitudeSetup::frame(moments, reg, w0, q0);
        if let Some(start) = ThirdKindStart::new(reg, &att, w0) {
            return (att, Some(start));
        }
    }
    (AttitudeSetup::new(moments, reg, w0, q0), None)
}

/// The exact-flow splitting method with a composition: a [`FixedMethod`] on the momentum
/// state, as the splitting method ([`crate::drivers::Splitting`]); forces must depend on the
/// time, the position and the attitude only.
pub struct ExactSplitting<'a> {
    composition: Composition<'a>,
    flow: FreeFlow,
}

impl<'a> ExactSplitting<'a> {
    pub fn new(body: &Body, composition: Composition<'a>) -> Self {
        ExactSplitting {
            composition,
            flow: FreeFlow::new(body),
        }
    }
}

/// One sub-step of a composition ([`compose`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SubStep {
    /// The kicks' `k`-th fraction of the step, at the time `covered` the flows have reached.
    Kick { k: usize, covered: f64 },
    /// A free flow over `d`, ending `within` into the step.
    Flow { d: f64, within: f64 },
}

/// The sub-steps of one step of `c` of size `h`, in order (zero fractions skipped): what
/// [`exact_splitting_step`] and its derivative
/// ([`crate::sensitivity::SensitiveExactSplitting`]) both walk. The last flow covers what is
/// left of the step, so that the flows of a step cover it exactly (a table's fractions sum to
/// one only to round-off: FRB's to 1 − 2⁻⁵²).
#[inline(always)]
pub fn compose(c: &Composition, h: f64, mut sub: impl FnMut(SubStep)) {
    let mut covered = 0.0; // the time the flows have covered
    let offset = usize::from(c.kick_first);
    if c.kick_first && c.kicks[0] != 0.0 {
        sub(SubStep::Kick { k: 0, covered });
    }
    let last = c.flows.len() - 1;
    for (j, &a) in c.flows.iter().enumerate() {
        let d = if j == last { h - covered } else { a * h };
        let within = if j == last { h } else { covered + d };
        if d != 0.0 {
            sub(SubStep::Flow { d, within });
        }
        covered = within;
        let k = j + offset;
        if k < c.kicks.len() && c.kicks[k] != 0.0 {
            sub(SubStep::Kick { k, covered });
        }
    }
}

/// One step of a composition from `(t, z)` into `out`: the sub-steps in order ([`compose`]),
/// each kick at the time its flows have reached. A free body under one central gravity
/// ([`RigidStructure::orbit`]) drifts along Kepler's flow and is kicked by the rest of the
/// forces: the gravity-gradient terms and any other force (Wisdom & Holman 1991).
#[inline]
pub fn exact_splitting_step<S: RigidStructure + ?Sized>(
    sys: &S,
    flow: &mut FreeFlow,
    c: &Composition,
    t: f64,
    z: &[f64],
    h: f64,
    out: &mut [f64],
) {
    out[..STATE_SIZE].copy_from_slice(&z[..STATE_SIZE]);
    let body = *sys.body();
    let orbit = sys.orbit();
    compose(c, h, |sub| match sub {
        SubStep::Kick { k, covered } => {
            exact_kick(sys, orbit.as_ref(), t + covered, out, c.kicks[k] * h)
        }
        SubStep::Flow { d, within } => flow.advance(&body, orbit.as_ref(), out, d, within, h),
    });
    hold_pivot(&body, out);
}

/// A kick of the momentum state `z` over `dt` at time `t`: the wrench of the forces, less
/// the point-mass gravity of `orbit` when the drift solves the orbit ([`off_orbit`]).
#[inline]
pub fn exact_kick<S: RigidStructure + ?Sized>(
    sys: &S,
    orbit: Option<&Force>,
    t: f64,
    z: &mut [f64],
    dt: f64,
) {
    let body = sys.body();
    let y = momentum_to_velocity(sys, z);
    let mut w = sys.wrench(t, &y);
    if let Some(f) = orbit {
        let point = central_point_force(&f.p, body, &y);
        off_orbit(&mut w, &point);
    }
    kick_by(body, &w, z, dt);
}

/// The wrench `w` less the point-mass gravity `point` that the drift's Kepler flow carries:
/// what a kick gives when the drift solves the orbit ([`translate`]).
#[inline(always)]
pub fn off_orbit<T: Scalar>(w: &mut [T; 6], point: &[T; 3]) {
    for k in 0..3 {
        w[k] = w[k] - point[k];
    }
}

/// The exact free flow over `d` of the momentum state `z = [R, V, Q, π]` on dual numbers, the
/// principal moments of `body` carrying their own derivatives, by the branch the plain flow
/// takes ([`FreeFlow`]): for three distinct moments the closed form's exact derivatives
/// ([`ExactTangent`]: `∂ω(d)`, `∂Q(d)` along the moments and `ω0 = π/I`, `Q0` held) chained
/// with the directions' own, and `Q(d) = Q0 U` (`U = Q0ᵀ Q(d)`, the free motion is
/// left-invariant) for their turn of `Q0`; for a symmetric body its closed form itself
/// ([`precession_momentum`], [`precession_attitude`]) on the dual numbers. The centre of
/// mass is the caller's ([`translate`]). False where the derivatives are not formed: a fixed
/// point or the separatrix of an asymmetric body, and a symmetric body's moments moved apart
/// (the symmetric closed form has no derivative along one of its equal moments alone).
pub fn free_flow_tangent<const P: usize>(
    body: &Body<Dual<P>>,
    z: &mut [Dual<P>; STATE_SIZE],
    d: f64,
) -> bool {
    let moments = body.moments.map(|x| x.v);
    let symmetry = symmetry_code(moments, SYMMETRY_RTOL);
    if symmetry != 0 {
        // the plain flow's branch (Regime::with): oblate (and spherical) about e3 with I⊥ = I1,
        // prolate about e1 with I⊥ = I3
        let (s, pair, i_perp) = match symmetry {
            1 => (0, (1, 2), body.moments[2]),
            _ => (2, (0, 1), body.moments[0]),
        };
        let equal = |a: usize, b: usize| body.moments[a].d == body.moments[b].d;
        if !(equal(pair.0, pair.1) && (symmetry != 3 || equal(0, 2))) {
            return false;
        }
        let one = Dual::splat(1.0);
        let pi = [0, 1, 2].map(|k| z[OMEGA_AT + k]);
        let nu = (one / body.moments[s] - one / i_perp) * pi[s];
        let q0 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| z[Q_AT + 3 * r + c]));
        let t = Dual::splat(d);
        let pi_t = precession_momentum(s, nu, pi, t);
        let q = precession_attitude(s, i_perp, nu, pi, &q0, t);
        z[OMEGA_AT..OMEGA_AT + 3].copy_from_slice(&pi_t);
        for (r, row) in q.iter().enumerate() {
            z[Q_AT + 3 * r..Q_AT + 3 * r + 3].copy_from_slice(row);
        }
        return true;
    }
    let w0 = [0, 1, 2].map(|k| z[OMEGA_AT + k].v / moments[k]);
    let q0: Mat3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| z[Q_AT + 3 * r + c].v));
    let Ok(tangent) = ExactTangent::new(moments, w0) else {
        if Regime::new(moments, 0, w0).case == FIXED {
            fixed_point_tangent(body, z, d, w0, &q0);
            return true;
        }
        return false;
    };
    let (w, dw) = tangent.omega_at(d);
    let (q, dq) = tangent.attitude_at(&q0, d);
    let mut u = [[0.0; 3]; 3];
    for (r, ur) in u.iter_mut().enumerate() {
        for (c, x) in ur.iter_mut().enumerate() {
            *x = (0..3).map(|m| q0[m][r] * q[m][c]).sum();
        }
    }
    let mut out = *z;
    for l in 0..P {
        // the closed form's parameters' derivatives along direction l: the moments, ω0 = π/I
        let di = body.moments.map(|x| x.d[l]);
        let mut dp = [0.0; DIRECTIONS];
        for k in 0..3 {
            dp[k] = di[k];
            dp[3 + k] = (z[OMEGA_AT + k].d[l] - w0[k] * di[k]) / moments[k];
        }
        let along =
            |row: &[f64; DIRECTIONS]| -> f64 { row.iter().zip(&dp).map(|(a, b)| a * b).sum() };
        for i in 0..3 {
            out[OMEGA_AT + i].d[l] = di[i] * w[i] + moments[i] * along(&dw[i]);
        }
        for r in 0..3 {
            for c in 0..3 {
                let turned: f64 = (0..3).map(|m| z[Q_AT + 3 * r + m].d[l] * u[m][c]).sum();
                out[Q_AT + 3 * r + c].d[l] = turned + along(&dq[r][c]);
            }
        }
    }
    for k in 0..3 {
        out[OMEGA_AT + k].v = moments[k] * w[k];
    }
    for r in 0..3 {
        for c in 0..3 {
            out[Q_AT + 3 * r + c].v = q[r][c];
        }
    }
    *z = out;
    true
}

/// [`free_flow_tangent`] at a fixed point of an asymmetric body (ω0 on a principal axis, or
/// within [`crate::torque_free::NEAR_UNSTABLE_AXIS`] of the intermediate one, where the plain
/// flow is `ω = ω0`, `Q = Q0 exp(ω̂0 d)`): the motions about a steady spin, linearised
/// exactly. With `Q = Q_n (I + ε̂)` about the nominal `Q_n(t)`, `δω̇ = J δω` (Euler's Jacobian
/// at ω0, [`euler_jacobian`]) and `ε̇ = δω − ω0 × ε`, so `(δω, ε)(d) = exp(G d) (δω, ε)(0)`
/// ([`expm`]); the moments do not move a steady spin (ω0 stays a fixed point for any moments,
/// so `∂ω/∂I = 0` and `∂Q/∂I = 0`).
fn fixed_point_tangent<const P: usize>(
    body: &Body<Dual<P>>,
    z: &mut [Dual<P>; STATE_SIZE],
    d: f64,
    w0: Vec3,
    q0: &Mat3,
) {
    let moments = body.moments.map(|x| x.v);
    let inertia = [0, 1, 2].map(|r| [0, 1, 2].map(|c| if r == c { moments[r] } else { 0.0 }));
    let j = euler_jacobian(&inertia, w0).unwrap_or([[0.0; 3]; 3]);
    let mut g = [[0.0; 6]; 6];
    for r in 0..3 {
        for c in 0..3 {
            g[r][c] = j[r][c] * d;
        }
        g[3 + r][r] = d;
    }
    // −ω0 × ε
    let wx = [
        [0.0, w0[2], -w0[1]],
        [-w0[2], 0.0, w0[0]],
        [w0[1], -w0[0], 0.0],
    ];
    for r in 0..3 {
        for c in 0..3 {
            g[3 + r][3 + c] = wx[r][c] * d;
        }
    }
    let phi = expm(g);
    let q = fixed_point_attitude(q0, w0, d);
    let mut out = *z;
    for l in 0..P {
        let di = body.moments.map(|x| x.d[l]);
        let mut x = [0.0; 6];
        for k in 0..3 {
            x[k] = (z[OMEGA_AT + k].d[l] - w0[k] * di[k]) / moments[k];
        }
        // ε(0) = vee(Q0ᵀ δQ0)
        let dq = |r: usize, c: usize| z[Q_AT + 3 * r + c].d[l];
        let body_turn = |r: usize, c: usize| -> f64 { (0..3).map(|m| q0[m][r] * dq(m, c)).sum() };
        x[3] = 0.5 * (body_turn(2, 1) - body_turn(1, 2));
        x[4] = 0.5 * (body_turn(0, 2) - body_turn(2, 0));
        x[5] = 0.5 * (body_turn(1, 0) - body_turn(0, 1));
        let y: [f64; 6] = std::array::from_fn(|r| (0..6).map(|c| phi[r][c] * x[c]).sum());
        for i in 0..3 {
            out[OMEGA_AT + i].d[l] = di[i] * w0[i] + moments[i] * y[i];
        }
        // δQ = Q(d) ε̂(d)
        let e = [[0.0, -y[5], y[4]], [y[5], 0.0, -y[3]], [-y[4], y[3], 0.0]];
        for r in 0..3 {
            for c in 0..3 {
                out[Q_AT + 3 * r + c].d[l] = (0..3).map(|m| q[r][m] * e[m][c]).sum();
            }
        }
    }
    for r in 0..3 {
        for c in 0..3 {
            out[Q_AT + 3 * r + c].v = q[r][c];
        }
    }
    *z = out;
}

impl<S: RigidStructure + ?Sized> FixedMethod<S> for ExactSplitting<'_> {
    fn evals_per_step(&self) -> u64 {
        self.composition.kicks_per_step()
    }
    #[inline]
    fn step(&mut self, sys: &S, t: f64, z: &[f64], h: f64, out: &mut [f64]) {
        exact_splitting_step(sys, &mut self.flow, &self.composition, t, z, h, out);
    }
    fn init(&self, sys: &S, y: &[f64], z: &mut [f64]) {
        velocity_to_momentum(sys, y, z);
    }
    fn output(&self, sys: &S, z: &[f64], y: &mut [f64]) {
        y[..STATE_SIZE].copy_from_slice(&momentum_to_velocity(sys, z));
    }
}

#[cfg(test)]
#[path = "exact_splitting_tests.rs"]
mod tests;
