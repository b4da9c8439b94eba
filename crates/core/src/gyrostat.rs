//! A rigid body carrying a spinning symmetric rotor: the gyrostat (`docs/theory.md` §4).
//!
//! A rotor of axial inertia `J` spins at `ω_R(t)` relative to the body about the body-fixed
//! unit axis `a`; its momentum relative to the body is `h = J ω_R a`. With no external torque
//! about the centre of mass, the total angular momentum `L = I ω + h` is fixed in space, so in
//! body components
//!
//! ```text
//! L̇ = L × ω,    ω = I⁻¹ (L − h(t)),                                  (momentum form)
//! I ω̇ + ω × (I ω + h) + ḣ = 0,                                       (velocity form)
//! ```
//!
//! the second being Euler's equation (08) with the rotor's reaction torque
//! `τ = −ω × h − ḣ` ([`rotor_torque`]); `I` is the inertia of the whole body about the centre of
//! mass, rotor included. With `h = 0` both reduce to the torque-free Euler equation (20). The
//! velocity form needs `ḣ`, the momentum form only `h`, so a rotor speed known at samples and
//! interpolated linearly between them (a continuous `h`, a jumping `ḣ`) is integrated in the
//! momentum form.
//!
//! * [`rotor_torque`], [`gyrostat_omega_dot`]: the right-hand side of the velocity form;
//! * [`gyrostat_regressor`]: the same equation written as a linear map of the six entries of
//!   `I` and of `J`, the regressor of an equation-error fit (`poinsot.identify`);
//! * [`SampledRotor`] and [`Gyrostat`]: the momentum form as a [`VectorField`], stepped by the
//!   crate's drivers; [`gyrostat_omegas`] integrates it onto sample times with a run's spec;
//! * [`point_acceleration_matrix`]: what an accelerometer on the body reads in free flight, the
//!   lever-arm model that finds the flight in a log.

use crate::drivers::{Clock, Counters, Output, Status};
use crate::dual::Dual;
use crate::observers::NoObserver;
use crate::real::Real;
use crate::rigid::omega_dot_principal;
use crate::run::Run;
use crate::so3::{cross, cross_t, exp_so3, Mat3, Vec3};
use crate::spec::RunSpec;
use crate::system::VectorField;

/// `Eᵀ v`: the components along the columns of `axes` of a vector given in the body frame.
#[inline(always)]
pub fn to_principal<T: Real>(axes: &[[T; 3]; 3], v: [T; 3]) -> [T; 3] {
    [0, 1, 2].map(|k| axes[0][k] * v[0] + axes[1][k] * v[1] + axes[2][k] * v[2])
}

/// `E v`: the body-frame vector of principal components `v`.
#[inline(always)]
pub fn from_principal<T: Real>(axes: &[[T; 3]; 3], v: [T; 3]) -> [T; 3] {
    [0, 1, 2].map(|r| axes[r][0] * v[0] + axes[r][1] * v[1] + axes[r][2] * v[2])
}

/// The reaction torque of the rotor on the body, `τ = −ω × h − ḣ` (any frame, the same for
/// all three vectors): the gyroscopic torque of its momentum `h` carried round by the body,
/// and the torque that spins it up.
#[inline(always)]
pub fn rotor_torque(w: Vec3, h: Vec3, h_dot: Vec3) -> Vec3 {
    let c = cross(w, h);
    [-c[0] - h_dot[0], -c[1] - h_dot[1], -c[2] - h_dot[2]]
}

/// `ω̇` of the gyrostat, `I ω̇ + ω × (I ω + h) + ḣ = 0`, for the inertia
/// `I = E diag(moments) Eᵀ` (`axes` = E, columns the principal axes in body coordinates) and
/// `ω`, `h`, `ḣ` in body components: Euler's equation (27)–(29) in the principal frame with
/// the torque [`rotor_torque`]. A zero moment gives a zero rate about its axis (as
/// [`omega_dot_principal`]).
///
/// ```
/// use poinsot_core::gyrostat::gyrostat_omega_dot;
/// let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// // a sphere spinning about z whose rotor along x spins up: ω̇ = −ḣ/I
/// let wd = gyrostat_omega_dot([2.0; 3], &eye, [0.0, 0.0, 1.0], [0.0; 3], [4.0, 0.0, 0.0]);
/// assert_eq!(wd, [-2.0, 0.0, 0.0]);
/// ```
#[inline(always)]
pub fn gyrostat_omega_dot(moments: Vec3, axes: &Mat3, w: Vec3, h: Vec3, h_dot: Vec3) -> Vec3 {
    let inv = moments.map(|i| if i != 0.0 { 1.0 / i } else { 0.0 });
    let wp = to_principal(axes, w);
    let tau = to_principal(axes, rotor_torque(w, h, h_dot));
    from_principal(axes, omega_dot_principal(moments, inv, wp, tau))
}

/// The matrix `A = hat(ω̇) + hat(ω)²` with `A p = ω̇ × p + ω × (ω × p)`: the acceleration,
/// relative to the centre of mass, of the body point `p` (body frame, from the centre of mass)
/// of a body turning with `ω`, `ω̇`. In free flight the centre of mass falls with `g`, so an
/// accelerometer at `p` reads the specific force `f = A p` (plus its bias), linear in `p`.
///
/// ```
/// use poinsot_core::gyrostat::point_acceleration_matrix;
/// // spinning at 2 rad/s about z: a point 0.1 m out on x is pulled in at ω² r = 0.4 m/s²
/// let a = point_acceleration_matrix([0.0, 0.0, 2.0], [0.0; 3]);
/// assert_eq!([a[0][0] * 0.1, a[1][0] * 0.1, a[2][0] * 0.1], [-0.4, 0.0, 0.0]);
/// ```
#[inline]
pub fn point_acceleration_matrix(w: Vec3, w_dot: Vec3) -> Mat3 {
    let [x, y, z] = w;
    // hat(ω)² = ω ωᵀ − |ω|² 𝟙
    let n2 = x * x + y * y + z * z;
    let mut a = [
        [x * x - n2, x * y, x * z],
        [y * x, y * y - n2, y * z],
        [z * x, z * y, z * z - n2],
    ];
    let h = crate::so3::hat(w_dot);
    for r in 0..3 {
        for c in 0..3 {
            a[r][c] += h[r][c];
        }
    }
    a
}

/// Index of the symmetric entries in [`gyrostat_regressor`]'s columns 0–5:
/// `(I11, I22, I33, I12, I13, I23)` as `(row, column)` pairs.
pub const INERTIA_ENTRIES: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// The gyrostat equation as a linear map: the 3 × 7 matrix `Φ` with
/// `Φ θ = I ω̇ + ω × (I ω + J ω_R a) + J ω̇_R a` for
/// `θ = (I11, I22, I33, I12, I13, I23, J)` ([`INERTIA_ENTRIES`]): column `j < 6` is
/// `S_j ω̇ + ω × (S_j ω)` for the symmetric unit matrix `S_j` of entry j, column 6 is
/// `ω_R (ω × a) + ω̇_R a`. Along a motion of the gyrostat `Φ θ = 0`; an equation-error fit
/// solves it for θ from measured `ω`, `ω̇`, `ω_R`, `ω̇_R` (all body frame, `a` a unit vector).
///
/// ```
/// use poinsot_core::gyrostat::gyrostat_regressor;
/// // spinning about z with a rotor along x: column 6 is ω_R (ω × a) + ω̇_R a
/// let phi = gyrostat_regressor([0.0, 0.0, 2.0], [0.0; 3], 3.0, 0.5, [1.0, 0.0, 0.0]);
/// assert_eq!([phi[0][6], phi[1][6], phi[2][6]], [0.5, 6.0, 0.0]);
/// ```
#[inline]
pub fn gyrostat_regressor(
    w: Vec3,
    w_dot: Vec3,
    rotor_speed: f64,
    rotor_accel: f64,
    axis: Vec3,
) -> [[f64; 7]; 3] {
    let mut phi = [[0.0; 7]; 3];
    for (j, &(r, c)) in INERTIA_ENTRIES.iter().enumerate() {
        // S_j v has v[c] in row r and v[r] in row c (one entry on the diagonal)
        let mut s_wd = [0.0; 3];
        let mut s_w = [0.0; 3];
        s_wd[r] += w_dot[c];
        s_w[r] += w[c];
        if r != c {
            s_wd[c] += w_dot[r];
            s_w[c] += w[r];
        }
        let g = cross(w, s_w);
        for k in 0..3 {
            phi[k][j] = s_wd[k] + g[k];
        }
    }
    let g = cross(w, axis);
    for k in 0..3 {
        phi[k][6] = rotor_speed * g[k] + rotor_accel * axis[k];
    }
    phi
}

/// A rotor whose speed `ω_R` is known at increasing times `t` and linear between them
/// (constant before the first and after the last): `h(t) = J ω_R(t) a`.
#[derive(Clone, Copy, Debug)]
pub struct SampledRotor<'a> {
    pub t: &'a [f64],
    pub speed: &'a [f64],
    /// Unit axis, body frame.
    pub axis: Vec3,
    /// Axial moment of inertia `J`.
    pub inertia: f64,
}

impl SampledRotor<'_> {
    /// `ω_R(t)` by linear interpolation (0 for a rotor with no samples).
    #[inline(always)]
    pub fn speed_at(&self, t: f64) -> f64 {
        let (ts, s) = (self.t, self.speed);
        let n = ts.len().min(s.len());
        if n == 0 {
            return 0.0;
        }
        if t <= ts[0] {
            return s[0];
        }
        if t >= ts[n - 1] {
            return s[n - 1];
        }
        let k = ts[..n].partition_point(|&x| x <= t); // ts[k-1] <= t < ts[k]
        let (t0, t1) = (ts[k - 1], ts[k]);
        let f = (t - t0) / (t1 - t0);
        s[k - 1] + f * (s[k] - s[k - 1])
    }

    /// `h(t) = J ω_R(t) a`, body frame.
    #[inline(always)]
    pub fn momentum_at(&self, t: f64) -> Vec3 {
        let c = self.inertia * self.speed_at(t);
        self.axis.map(|x| c * x)
    }
}

/// The gyrostat in its momentum form, `L̇ = L × ω`, `ω = I⁻¹(L − h(t))`, as a [`VectorField`]
/// on the state `L` (3) in the principal frame of `I` (moments `moments`, axes `axes`). Its
/// numbers are `f64`, or dual numbers ([`GyrostatTangent`]) where a fit differentiates the
/// motion with respect to the moments, the axes, the rotor's inertia and ω0.
pub struct Gyrostat<'a, T = f64> {
    pub moments: [T; 3],
    inv_moments: [T; 3],
    pub axes: [[T; 3]; 3],
    pub rotor: SampledRotor<'a>,
    /// The rotor's axial inertia `J`.
    rotor_inertia: T,
    /// The rotor axis in the principal frame.
    axis_p: [T; 3],
}

impl<'a> Gyrostat<'a> {
    pub fn new(moments: Vec3, axes: Mat3, rotor: SampledRotor<'a>) -> Self {
        Gyrostat::with(moments, axes, rotor.inertia, rotor)
    }
}

impl<'a, T: Real> Gyrostat<'a, T> {
    /// The gyrostat of `moments` along `axes` whose rotor has the axial inertia
    /// `rotor_inertia` (`rotor`'s own is not read), in numbers of type `T`.
    pub fn with(
        moments: [T; 3],
        axes: [[T; 3]; 3],
        rotor_inertia: T,
        rotor: SampledRotor<'a>,
    ) -> Self {
        let zero = T::splat(0.0);
        Gyrostat {
            moments,
            inv_moments: moments.map(|i| T::select(i.unequal(zero), T::splat(1.0) / i, zero)),
            axis_p: to_principal(&axes, rotor.axis.map(T::splat)),
            axes,
            rotor,
            rotor_inertia,
        }
    }

    /// `h(t)` in the principal frame.
    #[inline(always)]
    fn momentum_p(&self, t: f64) -> [T; 3] {
        let c = self.rotor_inertia * T::splat(self.rotor.speed_at(t));
        self.axis_p.map(|x| c * x)
    }

    /// `ω = I⁻¹(L − h(t))`, principal frame, of the state `l` (principal frame).
    #[inline(always)]
    pub fn omega_principal(&self, t: f64, l: &[T]) -> [T; 3] {
        let h = self.momentum_p(t);
        [0, 1, 2].map(|k| self.inv_moments[k] * (l[k] - h[k]))
    }

    /// `L̇ = L × ω` of the state `l`.
    #[inline(always)]
    pub fn rates(&self, t: f64, l: &[T]) -> [T; 3] {
        cross_t([l[0], l[1], l[2]], self.omega_principal(t, l))
    }

    /// The state `L = I ω + h(t)` (principal frame) of the body-frame `ω`.
    pub fn state_of(&self, t: f64, w: [T; 3]) -> [T; 3] {
        let wp = to_principal(&self.axes, w);
        let h = self.momentum_p(t);
        [0, 1, 2].map(|k| self.moments[k] * wp[k] + h[k])
    }

    /// The body-frame `ω` of the state `l` at `t`.
    pub fn omega_of(&self, t: f64, l: &[T]) -> [T; 3] {
        from_principal(&self.axes, self.omega_principal(t, l))
    }
}

impl VectorField for Gyrostat<'_> {
    #[inline(always)]
    fn dim(&self) -> usize {
        3
    }
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        out[..3].copy_from_slice(&self.rates(t, y));
    }
}

/// Body-frame `ω` at the sample times `t = spec.sampling.t_eval` (n, increasing) of the
/// gyrostat with inertia `E diag(moments) Eᵀ` and rotor `rotor` (its speed sampled on its own
/// times), from `ω(t[0]) = omega0`: the momentum form run by the drivers' one path
/// ([`Run`]) with `spec`'s method (any method of a vector field: RK4, an explicit tableau,
/// DOP853), step and budget. Returns the driver's status ([`Status::Finished`], or the
/// failure with the samples not reached left as NaN).
pub fn gyrostat_omegas(
    moments: Vec3,
    axes: &Mat3,
    rotor: SampledRotor<'_>,
    omega0: Vec3,
    spec: &RunSpec,
    out: &mut [Vec3],
) -> Status {
    let t = spec.sampling.t_eval;
    let n = t.len();
    assert_eq!(out.len(), n, "gyrostat_omegas: `out` has the wrong length");
    if n == 0 {
        return Status::Finished;
    }
    let sys = Gyrostat::new(moments, *axes, rotor);
    let (out_y, reached, status) = run_onto(&sys, sys.state_of(t[0], omega0).to_vec(), spec);
    for (k, o) in out.iter_mut().enumerate() {
        *o = if k < reached {
            sys.omega_of(t[k], &out_y[3 * k..3 * k + 3])
        } else {
            [f64::NAN; 3]
        };
    }
    status
}

/// The run of `sys` from the state `z` onto the sample times of `spec` (its method, step and
/// budget; [`Run`]): the samples (`dim · n`, NaN where not reached), how many were reached,
/// and the driver's status.
fn run_onto<S: VectorField>(sys: &S, mut z: Vec<f64>, spec: &RunSpec) -> (Vec<f64>, usize, Status) {
    let t = spec.sampling.t_eval;
    let (n, dim) = (t.len(), sys.dim());
    let mut f = vec![0.0; dim];
    let mut out_t = vec![f64::NAN; n];
    let mut out_y = vec![f64::NAN; dim * n];
    let mut clock = Clock { t: t[0], h: 0.0 };
    let mut counters = Counters::default();
    let mut run = Run {
        spec: *spec,
        clock: &mut clock,
        z: &mut z,
        f: &mut f,
        out: Output {
            t: &mut out_t,
            y: &mut out_y,
        },
        counters: &mut counters,
    };
    let status = run.chunk(sys, &mut NoObserver, spec.max_steps);
    (out_y, counters.n_out, status)
}

/// The most directions a gyrostat fit differentiates along at once.
pub const GYRO_DIRECTIONS: usize = 16;

/// A number of a gyrostat fit's derivatives: its value and [`GYRO_DIRECTIONS`] derivatives.
pub type GyroDual = Dual<GYRO_DIRECTIONS>;

/// The gyrostat's momentum form with its forward sensitivities: the state `[L (3), S (3 × P,
/// row-major)]`, `S = ∂L/∂p`, advanced by the [`Gyrostat`]'s own rates on dual numbers (the
/// variational equations, no derivative written by hand; `crate::sensitivity`).
pub struct GyrostatTangent<'a> {
    pub gyrostat: Gyrostat<'a, GyroDual>,
    /// The number of directions `P` (at most [`GYRO_DIRECTIONS`]).
    pub p: usize,
}

impl GyrostatTangent<'_> {
    /// The state as dual numbers.
    #[inline(always)]
    fn lift(&self, y: &[f64]) -> [GyroDual; 3] {
        let p = self.p;
        [0, 1, 2].map(|i| {
            let mut x = GyroDual::splat(y[i]);
            x.d[..p].copy_from_slice(&y[3 + p * i..3 + p * (i + 1)]);
            x
        })
    }
}

impl VectorField for GyrostatTangent<'_> {
    #[inline(always)]
    fn dim(&self) -> usize {
        3 * (1 + self.p)
    }
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let p = self.p;
        let r = self.gyrostat.rates(t, &self.lift(y));
        for (i, x) in r.iter().enumerate() {
            out[i] = x.v;
            out[3 + p * i..3 + p * (i + 1)].copy_from_slice(&x.d[..p]);
        }
    }
}

/// The principal axes `E0 exp(δ̂)` of a fit's rotation vector `δ` (dual numbers: their
/// derivatives with respect to `δ` exact, through [`exp_so3`]).
pub fn turned_axes<T: Real>(e0: &Mat3, delta: [T; 3]) -> [[T; 3]; 3] {
    let r = exp_so3(delta);
    [0, 1, 2].map(|i| {
        [0, 1, 2].map(|j| (0..3).fold(T::splat(0.0), |acc, m| acc + T::splat(e0[i][m]) * r[m][j]))
    })
}

/// Body-frame `ω` and its derivatives at the sample times `spec.sampling.t_eval` (n) of the
/// gyrostat whose moments, axes `E0 exp(δ̂)`, rotor inertia and initial `ω0` are dual numbers
/// carrying `p` directions: [`gyrostat_omegas`] with the variational equations alongside
/// (the same method and steps). `out` receives `ω` with its derivatives (samples not reached
/// are NaN). Returns the driver's status.
#[allow(clippy::too_many_arguments)]
pub fn gyrostat_sensitivities(
    moments: [GyroDual; 3],
    e0: &Mat3,
    delta: [GyroDual; 3],
    rotor_inertia: GyroDual,
    rotor: SampledRotor<'_>,
    omega0: [GyroDual; 3],
    p: usize,
    spec: &RunSpec,
    out: &mut [[GyroDual; 3]],
) -> Status {
    let t = spec.sampling.t_eval;
    let n = t.len();
    assert!(
        p <= GYRO_DIRECTIONS && out.len() == n,
        "gyrostat_sensitivities: sizes"
    );
    if n == 0 {
        return Status::Finished;
    }
    let sys = GyrostatTangent {
        gyrostat: Gyrostat::with(moments, turned_axes(e0, delta), rotor_inertia, rotor),
        p,
    };
    let dim = sys.dim();
    let l0 = sys.gyrostat.state_of(t[0], omega0);
    let mut z = vec![0.0; dim];
    for (i, x) in l0.iter().enumerate() {
        z[i] = x.v;
        z[3 + p * i..3 + p * (i + 1)].copy_from_slice(&x.d[..p]);
    }
    let (out_y, reached, status) = run_onto(&sys, z, spec);
    for (k, o) in out.iter_mut().enumerate() {
        *o = if k < reached {
            let l = sys.lift(&out_y[dim * k..dim * (k + 1)]);
            sys.gyrostat.omega_of(t[k], &l)
        } else {
            [GyroDual::splat(f64::NAN); 3]
        };
    }
    status
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::Sampling;
    use crate::freebody::euler_omega_dot;
    use crate::inertia::principal_decomposition;
    use crate::invariants::{angular_momentum_body, rotational_energy};
    use crate::so3::{exp_so3, matmul};
    use crate::spec::Method;
    use crate::steppers::Control;
    use crate::torque_free::exact_omegas;

    /// A run onto the samples `t` with `method`: steps of at most `max_step` (≤ 0: one step
    /// per sample interval), as `poinsot.identify` builds it.
    fn onto<'a>(t: &'a [f64], max_step: f64, method: Method<'a>) -> RunSpec<'a> {
        let longest = t.windows(2).map(|p| p[1] - p[0]).fold(0.0, f64::max);
        let dt = if max_step > 0.0 {
            max_step
        } else {
            longest.max(f64::MIN_POSITIVE)
        };
        let span = t[t.len() - 1] - t[0];
        let steps = (span / dt).ceil() as u64 + 2 * t.len() as u64 + 16;
        let sampling = Sampling {
            t_end: t[t.len() - 1],
            t_eval: t,
            every: 1,
        };
        RunSpec::new(method, dt, sampling, steps).expect("a valid run")
    }

    /// RK4 onto the samples `t` (the fits' run).
    fn rk4_omegas(
        moments: Vec3,
        axes: &Mat3,
        rotor: SampledRotor<'_>,
        omega0: Vec3,
        t: &[f64],
        max_step: f64,
        out: &mut [Vec3],
    ) -> Status {
        gyrostat_omegas(
            moments,
            axes,
            rotor,
            omega0,
            &onto(t, max_step, Method::Rk4),
            out,
        )
    }

    fn body() -> (Vec3, Mat3, Mat3) {
        // principal moments and axes tilted away from the body frame, and the full tensor
        let moments = [1.3e-4, 2.1e-4, 2.9e-4];
        let axes = exp_so3([0.4, -0.7, 0.25]);
        let mut inertia = [[0.0; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                inertia[r][c] = (0..3).map(|k| axes[r][k] * moments[k] * axes[c][k]).sum();
            }
        }
        (moments, axes, inertia)
    }

    /// `x` with `A x = b` by Cramer's rule: a route independent of the principal frame.
    fn cramer(a: &Mat3, b: Vec3) -> Vec3 {
        let det = |m: &Mat3| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let d = det(a);
        [0, 1, 2].map(|c| {
            let mut m = *a;
            for r in 0..3 {
                m[r][c] = b[r];
            }
            det(&m) / d
        })
    }

    fn norm(v: Vec3) -> f64 {
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    /// A smooth spin-up and back, 200 → 1300 → 200 rad/s over [0.05, 0.45] s, and its rate.
    fn profile(t: f64) -> (f64, f64) {
        let (t0, t1) = (0.05, 0.45);
        if t <= t0 || t >= t1 {
            return (200.0, 0.0);
        }
        let p = 2.0 * std::f64::consts::PI / (t1 - t0);
        let x = p * (t - t0);
        (200.0 + 550.0 * (1.0 - x.cos()), 550.0 * p * x.sin())
    }

    #[test]
    fn velocity_form_matches_a_direct_solve_of_the_full_tensor() {
        let (moments, axes, inertia) = body();
        let w = [12.0, -7.5, 20.0];
        let h = [1.1e-3, -4.0e-4, 2.0e-3];
        let hd = [0.3, 0.05, -0.2];
        let got = gyrostat_omega_dot(moments, &axes, w, h, hd);
        let iw = angular_momentum_body(&inertia, w);
        let l = [iw[0] + h[0], iw[1] + h[1], iw[2] + h[2]];
        let c = cross(w, l);
        let want = cramer(&inertia, [-c[0] - hd[0], -c[1] - hd[1], -c[2] - hd[2]]);
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-10 * norm(want),
                "{got:?} {want:?}"
            );
        }
    }

    #[test]
    fn without_a_rotor_it_is_the_torque_free_euler_equation() {
        let (moments, axes, _) = body();
        let wp = [3.0, -1.0, 2.5];
        let w = from_principal(&axes, wp);
        let got = to_principal(
            &axes,
            gyrostat_omega_dot(moments, &axes, w, [0.0; 3], [0.0; 3]),
        );
        let want = euler_omega_dot(moments, wp);
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-12 * norm(want));
        }
    }

    #[test]
    fn the_regressor_is_the_equation_and_vanishes_on_a_motion() {
        let (moments, axes, inertia) = body();
        let (a, wr, wrd, j) = ([0.6, 0.0, 0.8], 900.0, 3.0e3, 1.7e-6);
        let w = [9.0, 4.0, -15.0];
        let h = a.map(|x| j * wr * x);
        let hd = a.map(|x| j * wrd * x);
        let theta = [
            inertia[0][0],
            inertia[1][1],
            inertia[2][2],
            inertia[0][1],
            inertia[0][2],
            inertia[1][2],
            j,
        ];
        // at an arbitrary ω̇, Φθ is the equation's left side
        let wd = [1.0, -2.0, 0.5];
        let phi = gyrostat_regressor(w, wd, wr, wrd, a);
        let iwd = angular_momentum_body(&inertia, wd);
        let iw = angular_momentum_body(&inertia, w);
        let c = cross(w, [iw[0] + h[0], iw[1] + h[1], iw[2] + h[2]]);
        for k in 0..3 {
            let lhs: f64 = (0..7).map(|m| phi[k][m] * theta[m]).sum();
            let want = iwd[k] + c[k] + hd[k];
            assert!(
                (lhs - want).abs() < 1e-12 * norm(c).max(1e-9),
                "{lhs} {want}"
            );
        }
        // at the gyrostat's ω̇ it vanishes
        let wd = gyrostat_omega_dot(moments, &axes, w, h, hd);
        let phi = gyrostat_regressor(w, wd, wr, wrd, a);
        for row in phi {
            let r: f64 = (0..7).map(|m| row[m] * theta[m]).sum();
            assert!(r.abs() < 1e-12 * norm(c), "{r}");
        }
    }

    #[test]
    fn a_constant_rotor_momentum_keeps_energy_and_total_momentum() {
        let (moments, axes, inertia) = body();
        let t: Vec<f64> = (0..=2000).map(|k| k as f64 * 2.5e-4).collect();
        let speed = vec![1000.0; t.len()];
        let rotor = SampledRotor {
            t: &t,
            speed: &speed,
            axis: [0.0, 0.6, 0.8],
            inertia: 1.7e-6,
        };
        let h = rotor.momentum_at(0.0);
        let mut out = vec![[0.0; 3]; t.len()];
        let status = rk4_omegas(moments, &axes, rotor, [20.0, 3.0, -9.0], &t, 0.0, &mut out);
        assert_eq!(status, Status::Finished);
        let l_norm = |w: Vec3| {
            let iw = angular_momentum_body(&inertia, w);
            norm([iw[0] + h[0], iw[1] + h[1], iw[2] + h[2]])
        };
        let (l0, e0) = (l_norm(out[0]), rotational_energy(&inertia, out[0]));
        let mut moved: f64 = 0.0;
        for &w in &out {
            assert!((l_norm(w) - l0).abs() < 1e-11 * l0);
            assert!((rotational_energy(&inertia, w) - e0).abs() < 1e-9 * e0);
            moved = moved.max(norm([w[0] - out[0][0], w[1] - out[0][1], w[2] - out[0][2]]));
        }
        assert!(moved > 1.0, "the motion must not be trivial");
    }

    #[test]
    fn the_integrated_motion_solves_the_velocity_form() {
        // momentum-form RK4 over a sampled spin-up, checked by central differences of ω(t)
        // against the velocity form with the profile's exact ḣ
        let (moments, axes, _) = body();
        let dt = 2.5e-4;
        let t: Vec<f64> = (0..=2000).map(|k| k as f64 * dt).collect();
        // the rotor sampled 16 times finer than the output, so that its linear interpolation
        // is below the check's resolution
        let tr: Vec<f64> = (0..=32000).map(|k| k as f64 * dt / 16.0).collect();
        let speed: Vec<f64> = tr.iter().map(|&x| profile(x).0).collect();
        let (axis, j) = ([0.0, 0.0, 1.0], 1.7e-6);
        let rotor = SampledRotor {
            t: &tr,
            speed: &speed,
            axis,
            inertia: j,
        };
        let mut out = vec![[0.0; 3]; t.len()];
        let status = rk4_omegas(
            moments,
            &axes,
            rotor,
            [10.0, -20.0, 5.0],
            &t,
            dt / 16.0,
            &mut out,
        );
        assert_eq!(status, Status::Finished);
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for k in 1..t.len() - 1 {
            let fd = [0, 1, 2].map(|i| (out[k + 1][i] - out[k - 1][i]) / (2.0 * dt));
            let (wr, wrd) = profile(t[k]);
            let h = axis.map(|x| j * wr * x);
            let hd = axis.map(|x| j * wrd * x);
            let wd = gyrostat_omega_dot(moments, &axes, out[k], h, hd);
            worst = worst.max(norm([fd[0] - wd[0], fd[1] - wd[1], fd[2] - wd[2]]));
            scale = scale.max(norm(wd));
        }
        // central differences err by dt²/6 |ω⃛|: about 1e-4 of |ω̇| here
        assert!(worst < 1e-3 * scale, "{worst} vs {scale}");
        assert!(scale > 100.0);
    }

    #[test]
    fn without_a_rotor_it_follows_the_exact_torque_free_motion() {
        let (moments, axes, _) = body();
        let t: Vec<f64> = (0..=2000).map(|k| k as f64 * 2.5e-4).collect();
        let rotor = SampledRotor {
            t: &[],
            speed: &[],
            axis: [1.0, 0.0, 0.0],
            inertia: 0.0,
        };
        let w0 = [14.0, 25.0, -6.0];
        let mut out = vec![[0.0; 3]; t.len()];
        rk4_omegas(moments, &axes, rotor, w0, &t, 0.0, &mut out);
        // the closed form (Jacobi elliptic functions) wants the axes right-handed and sorted
        let (m, s) = principal_decomposition(&{
            let d = [
                [moments[0], 0.0, 0.0],
                [0.0, moments[1], 0.0],
                [0.0, 0.0, moments[2]],
            ];
            let ad = matmul(&axes, &d);
            let mut at = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    at[r][c] = axes[c][r];
                }
            }
            matmul(&ad, &at)
        });
        let code = crate::inertia::symmetry_code(m, crate::inertia::SYMMETRY_RTOL);
        let mut exact = vec![[0.0; 3]; t.len()];
        exact_omegas(m, &s, code, &[w0], &t, &mut exact);
        let mut worst: f64 = 0.0;
        for (a, b) in out.iter().zip(&exact) {
            worst = worst.max(norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]]));
        }
        assert!(worst < 1e-8 * norm(w0), "{worst}");
    }

    #[test]
    fn rk4_is_fourth_order_on_the_gyrostat() {
        let (moments, axes, _) = body();
        let tr: Vec<f64> = (0..=400).map(|k| k as f64 * 1e-3).collect();
        let speed: Vec<f64> = tr.iter().map(|&x| 200.0 + 2000.0 * x).collect(); // linear: exact
        let rotor = SampledRotor {
            t: &tr,
            speed: &speed,
            axis: [0.0, 0.6, 0.8],
            inertia: 1.7e-6,
        };
        let t = [0.0, 0.4];
        let end = |h: f64| {
            let mut out = [[0.0; 3]; 2];
            rk4_omegas(moments, &axes, rotor, [10.0, -20.0, 5.0], &t, h, &mut out);
            out[1]
        };
        let reference = end(1e-5);
        let err = |h: f64| {
            let w = end(h);
            norm([0, 1, 2].map(|i| w[i] - reference[i]))
        };
        let (e1, e2) = (err(4e-3), err(2e-3));
        let order = (e1 / e2).log2();
        assert!(
            (order - 4.0).abs() < 0.3,
            "observed order {order} ({e1}, {e2})"
        );
    }

    #[test]
    fn the_point_acceleration_is_the_rigid_body_acceleration() {
        let (w, wd, p) = ([3.0, -1.5, 7.0], [20.0, 5.0, -11.0], [0.02, -0.013, 0.031]);
        let a = point_acceleration_matrix(w, wd);
        let ap: Vec3 = [0, 1, 2].map(|r| a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2]);
        let c1 = cross(wd, p);
        let c2 = cross(w, cross(w, p));
        for k in 0..3 {
            assert!((ap[k] - (c1[k] + c2[k])).abs() < 1e-14);
        }
    }

    #[test]
    fn linear_interpolation_of_the_rotor_speed() {
        let t = [0.0, 1.0, 3.0];
        let s = [10.0, 20.0, 0.0];
        let r = SampledRotor {
            t: &t,
            speed: &s,
            axis: [0.0, 0.0, 1.0],
            inertia: 2.0,
        };
        assert_eq!(r.speed_at(-1.0), 10.0);
        assert_eq!(r.speed_at(0.5), 15.0);
        assert_eq!(r.speed_at(1.0), 20.0);
        assert_eq!(r.speed_at(2.0), 10.0);
        assert_eq!(r.speed_at(5.0), 0.0);
        assert_eq!(r.momentum_at(0.5), [0.0, 0.0, 30.0]);
    }

    /// A rotor spun up from 200 to 1000 rad/s over 0.4 s, sampled every millisecond: its
    /// times and speeds.
    fn spin_up() -> (Vec<f64>, Vec<f64>) {
        let tr: Vec<f64> = (0..=400).map(|k| k as f64 * 1e-3).collect();
        let speed = tr.iter().map(|&x| 200.0 + 2000.0 * x).collect();
        (tr, speed)
    }

    /// The rotor of [`spin_up`]'s samples, about a tilted axis.
    fn spun_rotor<'a>(tr: &'a [f64], speed: &'a [f64]) -> SampledRotor<'a> {
        SampledRotor {
            t: tr,
            speed,
            axis: [0.0, 0.6, 0.8],
            inertia: 1.7e-6,
        }
    }

    #[test]
    fn the_run_takes_its_method_from_the_spec() {
        // the same motion by DOP853 at tight tolerances and by RK4 at a fine step
        let (moments, axes, _) = body();
        let (tr, speed) = spin_up();
        let rotor = spun_rotor(&tr, &speed);
        let t: Vec<f64> = (0..=40).map(|k| k as f64 * 1e-2).collect();
        let w0 = [10.0, -20.0, 5.0];
        let mut rk4 = vec![[0.0; 3]; t.len()];
        rk4_omegas(moments, &axes, rotor, w0, &t, 1e-5, &mut rk4);
        let control = Control::with_tolerances(1e-12, 1e-12);
        let mut dop = vec![[0.0; 3]; t.len()];
        let spec = onto(&t, 0.0, Method::Dop853(control));
        let status = gyrostat_omegas(moments, &axes, rotor, w0, &spec, &mut dop);
        assert_eq!(status, Status::Finished);
        for (a, b) in rk4.iter().zip(&dop) {
            let d = norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]]);
            assert!(d < 1e-9 * norm(w0), "{d}");
        }
        assert_ne!(rk4[t.len() - 1], dop[t.len() - 1]); // two routes, not one
    }

    #[test]
    fn the_sensitivities_carry_the_plain_motion_and_its_derivative() {
        // the value of the dual run is the plain run bit for bit; the derivative along ω0_y
        // agrees with central differences of plain runs
        let (moments, axes, _) = body();
        let (tr, speed) = spin_up();
        let rotor = spun_rotor(&tr, &speed);
        let t: Vec<f64> = (0..=40).map(|k| k as f64 * 1e-2).collect();
        let spec = onto(&t, 1e-4, Method::Rk4);
        let w0 = [10.0, -20.0, 5.0];
        let mut plain = vec![[0.0; 3]; t.len()];
        gyrostat_omegas(moments, &axes, rotor, w0, &spec, &mut plain);
        let lift = |v: Vec3| v.map(GyroDual::splat);
        let mut w = lift(w0);
        w[1].d[0] = 1.0;
        let mut dual = vec![[GyroDual::splat(0.0); 3]; t.len()];
        let status = gyrostat_sensitivities(
            lift(moments),
            &axes,
            lift([0.0; 3]),
            GyroDual::splat(rotor.inertia),
            rotor,
            w,
            1,
            &spec,
            &mut dual,
        );
        assert_eq!(status, Status::Finished);
        let h = 1e-4;
        let (mut up, mut down) = (vec![[0.0; 3]; t.len()], vec![[0.0; 3]; t.len()]);
        gyrostat_omegas(
            moments,
            &axes,
            rotor,
            [w0[0], w0[1] + h, w0[2]],
            &spec,
            &mut up,
        );
        gyrostat_omegas(
            moments,
            &axes,
            rotor,
            [w0[0], w0[1] - h, w0[2]],
            &spec,
            &mut down,
        );
        for k in 0..t.len() {
            for i in 0..3 {
                assert_eq!(dual[k][i].v.to_bits(), plain[k][i].to_bits(), "{k} {i}");
                let fd = (up[k][i] - down[k][i]) / (2.0 * h);
                assert!(
                    (dual[k][i].d[0] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                    "{k} {i}"
                );
            }
        }
    }
}
