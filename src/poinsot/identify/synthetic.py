"""Synthetic throws made by poinsot itself: the logs that the tests, the docs and the example
identify.

The body (:func:`logger_block`) is a 70 × 60 × 30 mm block with a 45 × 40 × 25 mm logger fixed
on top, turned on it; the sensor frame is the logger's. A throw (:func:`synthetic_throw`)
tumbles it freely for ``duration`` seconds, sampled at ``rate``:

* without a rotor, ω(t) is the exact torque-free solution
  (:meth:`poinsot.torquefree.FreeRigidBody.exact_omega`, Jacobi elliptic functions);
* with the logger's flywheel (``J = 1.7·10⁻⁶ kg m²``, spun from 200 up to 1300 rad/s over
  0.2 s and back by a raised-cosine profile) ω(t) is the gyrostat integrated by the compiled
  core on a rotor speed sampled 8 times finer than the log, with RK4 steps of an eighth of the
  log's interval;

then the gyro reads ω + bias + white noise, clipped at the saturation level. With ``accel``
the accelerometer reads the specific force of its point, ``ω̇ × p + ω × (ω × p) + b`` plus
noise, and with ``hand`` the log also holds the throw from the hand (0.3 s before) and the
catch (0.3 s after), where the accelerometer feels gravity and the hand.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._bindings import identify as core_identify
from .._bindings import inertia as core_inertia

__all__ = [
    "SAMPLE_LOG",
    "SAMPLE_PHONE",
    "SyntheticThrow",
    "logger_block",
    "rotor_profile",
    "sample_log_text",
    "synthetic_throw",
]

#: The example body's parts: (size [m], mass [kg]).
BLOCK = ((0.070, 0.060, 0.030), 0.20)
LOGGER = ((0.045, 0.040, 0.025), 0.06)
#: The logger's centre on the block (block frame) [m] and its turn about the block's z [deg].
LOGGER_OFFSET = (0.012, -0.008, 0.0275)
LOGGER_TURN_DEG = 25.0
#: The accelerometer's position in the logger (logger frame) [m].
IMU_OFFSET = (0.010, 0.005, -0.004)
#: The flywheel: axial inertia [kg m²], axis (sensor frame), speeds [rad/s], ramp time [s].
ROTOR_INERTIA = 1.7e-6
ROTOR_AXIS = (0.0, 0.0, 1.0)
ROTOR_SPEEDS = (200.0, 1300.0)
ROTOR_RAMP = 0.2
STANDARD_GRAVITY = 9.80665
#: Log before the release and after the catch, with ``hand`` [s].
HAND_TIME = 0.3


def logger_block():
    """The example body in its sensor frame and the accelerometer's position.

    Returns
    -------
    body : RigidBody
        The block with the logger, centre of mass at the origin, in the logger's (sensor)
        frame.
    imu_position : ndarray (3,)
        The accelerometer's position from the centre of mass, sensor frame [m].

    Examples
    --------
    >>> body, p = logger_block()
    >>> round(body.mass, 3), body.symmetry
    (0.26, 'asymmetric')
    >>> (body.principal_moments * 1e7).round().tolist()  # g cm²
    [1184.0, 1494.0, 1770.0]
    """
    from ..bodies import RigidBody
    from ..rotation import matrix_from_rotvec

    (bs, bm), (ls, lm) = BLOCK, LOGGER
    turn = matrix_from_rotvec([0.0, 0.0, np.radians(LOGGER_TURN_DEG)])
    block = RigidBody.box(bm, bs)
    logger = RigidBody.box(lm, ls, position=LOGGER_OFFSET, orientation=turn)
    whole = RigidBody.compose([block, logger])
    com = whole.center_of_mass
    imu = np.asarray(LOGGER_OFFSET) + turn @ np.asarray(IMU_OFFSET) - com
    # the sensor frame is the logger's: components v_s = turnᵀ v_block
    body = RigidBody(whole.mass, turn.T @ whole.inertia @ turn)
    return body, turn.T @ imu


def rotor_profile(tau, duration: float = 0.5, speeds=ROTOR_SPEEDS, ramp: float = ROTOR_RAMP):
    """The flywheel's speed and its rate at the flight times ``tau`` [s]: ``speeds[0]``, then
    a raised-cosine spin-up to ``speeds[1]`` over ``ramp`` seconds and back down over
    ``ramp``, centred in ``[0, duration]``.

    Returns
    -------
    speed, rate : ndarray, ndarray
        [rad/s], [rad/s²].

    Examples
    --------
    >>> s, r = rotor_profile(np.array([0.0, 0.25, 0.5]))
    >>> s.tolist(), r.round(9).tolist()
    ([200.0, 1300.0, 200.0], [0.0, 0.0, 0.0])
    """
    tau = np.asarray(tau, dtype=float)
    lo, hi = speeds
    r = min(ramp, duration / 2)
    t0 = max(0.0, (duration - 2 * r) / 2)
    a = 0.5 * (hi - lo)
    x = np.clip((tau - t0) / r, 0.0, 2.0)  # 0 … 1 up, 1 … 2 down
    speed = lo + a * (1.0 - np.cos(np.pi * x))
    inside = (tau > t0) & (tau < t0 + 2 * r)
    rate = np.where(inside, a * np.pi / r * np.sin(np.pi * x), 0.0)
    return speed, rate


@dataclass(frozen=True, eq=False)
class SyntheticThrow:
    """A synthetic log and the truth behind it (SI units, sensor frame).

    Attributes
    ----------
    t, omega : ndarray (n,), (n, 3)
        The log: times and gyro readings (noise, bias, saturation).
    rotor_speed : ndarray (n,) or None
        The flywheel's speed readings [rad/s].
    accel : ndarray (n, 3) or None
        Accelerometer readings [m/s²].
    omega_true : ndarray (n, 3)
        The body's ω without the sensor's errors.
    window : (float, float)
        The true free flight (release, catch) [s].
    inertia : ndarray (3, 3)
        The body's inertia about its centre of mass [kg m²]; ``principal_moments``, ``axes``,
        ``ratios`` from it.
    rotor_axis, rotor_inertia, lever_arm, gyro_bias, accel_bias, noise, saturation
        The rest of the truth.
    """

    t: np.ndarray
    omega: np.ndarray
    rotor_speed: np.ndarray | None
    accel: np.ndarray | None
    omega_true: np.ndarray
    window: tuple
    inertia: np.ndarray
    principal_moments: np.ndarray
    axes: np.ndarray
    ratios: np.ndarray
    rotor_axis: np.ndarray | None
    rotor_inertia: float | None
    lever_arm: np.ndarray
    gyro_bias: np.ndarray
    accel_bias: np.ndarray
    noise: float
    saturation: float | None

    def kwargs(self, *, rotor_inertia_known: bool = True, rotor: bool = True) -> dict:
        """The keyword arguments of :func:`poinsot.identify.identify` for this log: the rotor
        (its inertia only when ``rotor_inertia_known``; nothing with ``rotor=False``) and the
        accelerometer."""
        kw = {}
        if rotor and self.rotor_speed is not None:
            kw["rotor_speed"] = self.rotor_speed
            kw["rotor_axis"] = self.rotor_axis
            if rotor_inertia_known:
                kw["rotor_inertia"] = self.rotor_inertia
        if self.accel is not None:
            kw["accel"] = self.accel
        return kw

    def axis_errors_deg(self, axes) -> np.ndarray:
        """The angle [deg] between each column of ``axes`` and the true axis (signs free)."""
        c = np.abs(np.sum(np.asarray(axes) * self.axes, axis=0)).clip(max=1.0)
        return np.degrees(np.arccos(c))


def _direction(rng, axes):
    """A random unit ω direction away from every principal axis (each principal component at
    least 0.3 in size), sensor frame."""
    while True:
        u = rng.standard_normal(3)
        u /= np.linalg.norm(u)
        if np.all(np.abs(u) >= 0.3):
            return axes @ u


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _motion(body, moments, axes, a, J, rotor, tau, dt, duration, rotor_speeds):
    """ω(t) at the flight times ``tau`` as a function of ω0: the exact torque-free motion, or
    the gyrostat with the flywheel (inertia ``J``, axis ``a``) integrated by the core."""
    from ..torquefree import FreeRigidBody
    from .output_error import gyrostat_run

    def motion(w0):
        if not rotor:
            return FreeRigidBody.from_body(body).exact_omega(w0, tau)
        fine = dt / 8 * np.arange(8 * (len(tau) - 1) + 1)
        speed, _ = rotor_profile(fine, duration, rotor_speeds)
        return core_identify.gyrostat_omegas(moments[None], axes[None], np.array([J]), w0[None],
                                             gyrostat_run(tau, dt / 8), fine, speed,
                                             a)[0]  # fmt: skip

    return motion


def _within_max_spin(motion, w0, given: bool, max_spin: float):
    """``(ω0, ω(t))`` with a random ``ω0`` (not ``given``) scaled down until ``|ω(t)|`` stays
    within ``max_spin`` (exact for torque-free motion; three tries)."""
    w = motion(w0)
    for _ in range(3):  # |ω| up to max_spin: scale ω0 (exact for torque-free motion)
        top = np.abs(w).max()
        if given or top <= max_spin:
            break
        w0 = w0 * (0.995 * max_spin / top)
        w = motion(w0)
    return w0, w


def _flight_specific_force(moments, axes, w, J, a, speed, speed_rate, p):
    """The specific force ``ω̇ × p + ω × (ω × p)`` (n, 3) of the accelerometer at ``p`` in
    flight, with the flywheel's momentum ``J speed a`` and its rate."""
    h = J * speed[:, None] * a
    h_dot = J * speed_rate[:, None] * a
    wd = core_identify.gyrostat_omega_dot(moments, axes, w, h, h_dot)
    return core_identify.point_acceleration_matrices(w, wd) @ p  # ω̇ × p + ω × (ω × p)


def _with_hand(rng, tau, dt, rate, w0, w, f, speed):
    """The log with the throw from the hand before and the catch after the flight:
    ``(t, window, ω, specific force, rotor speed)``."""
    m = round(HAND_TIME * rate)
    pre = -dt * np.arange(m, 0, -1)
    post = tau[-1] + dt * np.arange(1, m + 1)
    up = rng.standard_normal(3)
    up /= np.linalg.norm(up)
    s_pre = _smoothstep((pre + 0.12) / 0.12)  # the wind-up: 0 → 1 over the last 0.12 s
    s_post = 1.0 - _smoothstep((post - tau[-1]) / 0.05)  # the catch stops it in 0.05 s
    w_pre = s_pre[:, None] * w0
    w_post = s_post[:, None] * w[-1]
    push = np.sin(np.pi * np.clip((pre + 0.12) / 0.12, 0, 1))[:, None] * 25.0 * up
    jolt = np.exp(-(post - tau[-1]) / 0.02)[:, None] * 30.0 * rng.standard_normal(3)
    f_pre = STANDARD_GRAVITY * up + push
    f_post = STANDARD_GRAVITY * up + jolt
    t = np.concatenate([pre, tau, post]) + HAND_TIME
    window = (HAND_TIME, HAND_TIME + float(tau[-1]))
    w_true = np.concatenate([w_pre, w, w_post])
    f = np.concatenate([f_pre, f, f_post])
    rotor_read = np.concatenate([np.full(m, speed[0]), speed, np.full(m, speed[-1])])
    return t, window, w_true, f, rotor_read


def synthetic_throw(
    *,
    rotor: bool = True,
    duration: float = 0.5,
    rate: float = 4000.0,
    omega0=None,
    spin: float = 25.0,
    max_spin: float = 30.0,
    noise: float = 0.02,
    bias: float = 0.01,
    saturation: float | None = 35.0,
    rotor_inertia: float = ROTOR_INERTIA,
    rotor_axis=ROTOR_AXIS,
    rotor_speeds=ROTOR_SPEEDS,
    rotor_noise: float = 0.0,
    accel: bool = False,
    accel_noise: float = 0.05,
    accel_bias: float = 0.1,
    hand: bool = False,
    body=None,
    imu_position=None,
    seed=None,
) -> SyntheticThrow:
    """A synthetic throw of the example body (or ``body``), made by poinsot.

    Parameters
    ----------
    rotor : bool
        With the logger's flywheel spinning up and down (a gyrostat), or torque-free.
    duration, rate : float
        Free flight [s] and sampling rate [Hz].
    omega0 : array_like (3,), optional
        ω at release [rad/s], sensor frame; default ``spin`` times a random direction away
        from the principal axes, scaled down if ``|ω(t)|`` would exceed ``max_spin``.
    noise, bias : float
        The gyro's white noise (standard deviation) and the size of each component of its bias
        (random signs) [rad/s].
    saturation : float or None
        The gyro's range [rad/s]: readings are clipped there.
    rotor_inertia, rotor_axis, rotor_speeds : float, array_like (3,), (float, float)
        The flywheel [kg m²], its unit axis (sensor frame), its low and high speeds [rad/s].
    rotor_noise : float
        White noise on the rotor speed readings [rad/s].
    accel, accel_noise, accel_bias : bool, float, float
        Log the accelerometer, its noise [m/s²] and the size of its bias components.
    hand : bool
        Add the throw from the hand before and the catch after the flight (0.3 s each).
    body, imu_position : RigidBody, array_like (3,), optional
        Another body (its frame is the sensor frame; its inertia about the centre of mass is
        used) and the accelerometer's position from its centre of mass [m].
    seed : int or numpy Generator, optional

    Returns
    -------
    SyntheticThrow

    Examples
    --------
    >>> throw = synthetic_throw(seed=1)
    >>> throw.t.shape, throw.omega.shape, throw.window
    ((2001,), (2001, 3), (0.0, 0.5))
    >>> bool(np.abs(throw.omega_true).max() <= 30.0), throw.rotor_speed.max().round(6)
    (True, np.float64(1300.0))
    """
    rng = np.random.default_rng(seed)
    if body is None:
        body, p_default = logger_block()
    else:
        p_default = np.zeros(3)
    p = p_default if imu_position is None else np.asarray(imu_position, dtype=float)
    inertia = np.array(body.inertia, dtype=float)
    moments, axes = (np.asarray(x) for x in core_inertia.principal_decomposition(inertia))
    a = np.asarray(rotor_axis, dtype=float)
    a = a / np.linalg.norm(a)
    dt = 1.0 / rate
    n = round(duration * rate) + 1
    tau = dt * np.arange(n)
    w0 = spin * _direction(rng, axes) if omega0 is None else np.asarray(omega0, dtype=float)
    J = rotor_inertia if rotor else 0.0
    motion = _motion(body, moments, axes, a, J, rotor, tau, dt, duration, rotor_speeds)
    w0, w = _within_max_spin(motion, w0, omega0 is not None, max_spin)
    speed, speed_rate = rotor_profile(tau, duration, rotor_speeds)
    f = _flight_specific_force(moments, axes, w, J, a, speed, speed_rate, p)
    b_gyro = bias * rng.choice([-1.0, 1.0], 3)
    b_acc = accel_bias * rng.choice([-1.0, 1.0], 3)
    t = tau
    w_true = w
    rotor_read = speed
    window = (0.0, float(tau[-1]))
    if hand:
        t, window, w_true, f, rotor_read = _with_hand(rng, tau, dt, rate, w0, w, f, speed)
    readings = w_true + b_gyro + noise * rng.standard_normal(w_true.shape)
    if saturation is not None:
        readings = np.clip(readings, -saturation, saturation)
    acc = f + b_acc + accel_noise * rng.standard_normal(f.shape) if accel else None
    if rotor_noise > 0:
        rotor_read = rotor_read + rotor_noise * rng.standard_normal(rotor_read.shape)
    return SyntheticThrow(
        t=t,
        omega=readings,
        rotor_speed=rotor_read if rotor else None,
        accel=acc,
        omega_true=w_true,
        window=window,
        inertia=inertia,
        principal_moments=moments,
        axes=axes,
        ratios=moments[:2] / moments[2],
        rotor_axis=a if rotor else None,
        rotor_inertia=float(rotor_inertia) if rotor else None,
        lever_arm=p,
        gyro_bias=b_gyro,
        accel_bias=b_acc,
        noise=float(noise),
        saturation=saturation,
    )


#: The sample log that ships with poinsot (``poinsot examples --data gyro.csv``): its file name,
#: and how :func:`sample_log_text` makes it.
SAMPLE_LOG = "gyro.csv"
#: The sample's phone: a 190 g box of 71.5 × 147 × 7.8 mm whose principal axes are turned
#: 3° (about the sensor's (1, 1, 0) direction) from the sensor's axes: a sensor mounted a
#: little askew.
SAMPLE_PHONE = {"mass": 0.19, "size": (0.0715, 0.147, 0.0078), "misalignment_deg": 3.0}


def sample_log_text() -> str:
    """The sample gyro log, as phyphox exports it (``"Time (s)","Gyroscope x (rad/s)",…``):
    a **synthetic** throw made by :func:`synthetic_throw`, not a measurement. The phone of
    :data:`SAMPLE_PHONE`, thrown from the hand (0.3 s of wind-up), 0.5 s of free flight from
    t = 0.3 s, caught (0.3 s), logged at 200 Hz with white noise 0.005 rad/s, a bias of
    0.01 rad/s per axis and a 35 rad/s range. The file ``identify/samples/gyro.csv`` is this
    text (a test keeps the two equal).

    Examples
    --------
    >>> sample_log_text().splitlines()[0].split(",")[:2]
    ['"Time (s)"', '"Gyroscope x (rad/s)"']
    """
    from ..bodies import RigidBody
    from ..rotation import matrix_from_rotvec

    p = SAMPLE_PHONE
    turn = np.radians(p["misalignment_deg"]) * np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    phone = RigidBody.box(p["mass"], p["size"], orientation=matrix_from_rotvec(turn))
    throw = synthetic_throw(rotor=False, body=phone, rate=200.0, noise=0.005, bias=0.01,
                            saturation=35.0, hand=True, spin=20.0, seed=2026)  # fmt: skip
    rows = ["\"Time (s)\",\"Gyroscope x (rad/s)\",\"Gyroscope y (rad/s)\","
            "\"Gyroscope z (rad/s)\",\"Absolute (rad/s)\""]  # fmt: skip
    for t, w in zip(throw.t, throw.omega, strict=True):
        values = (t, *w, float(np.sqrt(w @ w)))
        rows.append(",".join(f"{v:.9E}" for v in values))
    return "\n".join(rows) + "\n"
