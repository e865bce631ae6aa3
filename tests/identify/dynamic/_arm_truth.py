"""A small truth generator for whole-arm identification, independent of ``fricid.sim``.

The arm follows a smooth multi-sine reference exactly (no controller, no integrator): the
torque is the model's inverse dynamics along it plus each joint's friction law
(``fricid.models``) plus Gaussian noise; the logged position is the reference quantised to
``counts`` per revolution, the logged velocity its finite differences.
"""

from __future__ import annotations

import numpy as np

from fricid.models import get_model
from fricid.samples import RobotLog

#: A Coulomb-viscous law per direction for each joint of the double pendulum.
CV_LAWS = [
    ("coulomb_viscous_asym", {"f_c_pos": 0.5, "beta_pos": 0.3, "f_c_neg": 0.4, "beta_neg": 0.2}),
    ("coulomb_viscous_asym", {"f_c_pos": 0.7, "beta_pos": 0.3, "f_c_neg": 0.4, "beta_neg": 0.3}),
]

#: Harmonics of the reference's fundamental.
HARMONICS = (1, 2, 3, 5, 7)


def reference(model, duration, rate, seed, *, f0=0.1, speed=1.0, hold=()):
    """(t, q, dq, ddq): a multi-sine per joint, about ``speed`` rad/s RMS, centred in the
    joint's range; joints in ``hold`` stay at their centre."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(duration * rate)) / rate
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    centre, half = (lo + hi) / 2, (hi - lo) / 2
    n = model.n
    q = np.tile(centre, (t.size, 1))
    dq = np.zeros_like(q)
    ddq = np.zeros_like(q)
    for j in range(n):
        if j in hold:
            continue
        w = 2 * np.pi * f0 * np.array(HARMONICS)
        phase = rng.uniform(0, 2 * np.pi, w.size)
        amp = 1.0 / w  # equal velocity amplitude per harmonic
        arg = np.outer(t, w) + phase
        v = np.cos(arg) @ (amp * w)
        scale = speed / np.sqrt(np.mean(v**2))
        pos = np.sin(arg) @ amp * scale
        top = np.max(np.abs(pos))
        if top > 0.6 * half[j]:  # keep within the range: slower there
            scale *= 0.6 * half[j] / top
        q[:, j] = centre[j] + np.sin(arg) @ amp * scale
        dq[:, j] = np.cos(arg) @ (amp * w) * scale
        ddq[:, j] = -np.sin(arg) @ (amp * w**2) * scale
    return t, q, dq, ddq


def friction_torque(laws, dq, load=None):
    """Each joint's friction ``laws[j] = (family, {name: value})`` at velocities ``dq`` (and
    load torques ``load``, same shape, for the load families; default 0)."""
    out = np.zeros_like(dq)
    load = np.zeros_like(dq) if load is None else load
    for j, (family, values) in enumerate(laws):
        m = get_model(family)
        theta = np.array([values[p] for p in m.param_names])
        X = np.column_stack([dq[:, j], load[:, j], np.full(len(dq), 25.0)])
        out[:, j] = m.predict(theta, X)
    return out


def make_log(
    model,
    laws,
    *,
    duration=20.0,
    rate=1000.0,
    seed=0,
    counts=2**17,
    noise=0.05,
    hold=(),
    speed=1.0,
    source="truth",
    trajectory=None,
):
    """A :class:`RobotLog` of the arm along its reference (module notes), or along
    ``trajectory = (t, q, dq, ddq)`` when given (``duration``, ``rate``, ``speed``, ``hold``
    then unused)."""
    if trajectory is None:
        trajectory = reference(model, duration, rate, seed, speed=speed, hold=hold)
    t, q, dq, ddq = trajectory
    rate = 1.0 / float(np.median(np.diff(t)))
    rng = np.random.default_rng(seed + 10_000)
    tau = model.inverse_dynamics(q, dq, ddq) + friction_torque(laws, dq, _load(model, laws, q))
    tau = tau + rng.normal(0.0, 1.0, tau.shape) * np.broadcast_to(noise, (model.n,))
    step = 2 * np.pi / counts
    pos = np.round(q / step) * step
    vel = np.gradient(pos, axis=0) * rate
    return RobotLog(
        time=t, joints=model.joints, position=pos, velocity=vel, torque=tau, source=source
    )


def _load(model, laws, q):
    """The load torque of the load laws (``msk``): the arm's gravity torque at ``q`` (as
    the BAS-RBFNN paper's eq. 7 defines the load), None when no law needs it."""
    return model.gravity_torque(q) if any(f.startswith("msk") for f, _ in laws) else None


def load_law(rng, scale=1.0):
    """A joint-load law per direction (``msk_asym`` without a Stribeck rise: ``f_s = f_c``,
    ``f_sk = f_ck``), different between directions: Coulomb 0.2-0.6 N m plus 1-4 % of the
    gravity torque."""
    values = {}
    for d in ("_pos", "_neg"):
        f_c, f_ck = scale * rng.uniform(0.2, 0.6), rng.uniform(0.01, 0.04)
        values |= {f"f_c{d}": f_c, f"f_s{d}": f_c, f"f_ck{d}": f_ck, f"f_sk{d}": f_ck}
        values |= {f"v_s{d}": 0.1, f"xi{d}": 1.0, f"beta{d}": scale * rng.uniform(0.1, 0.6)}
    return "msk_asym", values


def stribeck_law(rng, scale=1.0):
    """A Stribeck law per direction, different between directions (``stribeck_asym``)."""
    values = {}
    for d in ("_pos", "_neg"):
        tau_c = scale * rng.uniform(0.3, 1.0)
        values |= {
            f"tau_c{d}": tau_c,
            f"tau_s{d}": tau_c * rng.uniform(1.3, 1.8),
            f"w_s{d}": rng.uniform(0.03, 0.12),
            f"tau_v{d}": scale * rng.uniform(0.1, 0.6),
            f"delta{d}": rng.uniform(0.8, 2.0),
        }
    return "stribeck_asym", values


def make_pd_log(
    model,
    laws,
    *,
    duration=20.0,
    rate=1000.0,
    seed=0,
    counts=2**17,
    noise=0.05,
    disturbance=0.05,
    bandwidth=10.0,
    substeps=4,
    source="truth-pd",
    trajectory=None,
    inertia=None,
):
    """A :class:`RobotLog` of the arm tracking its reference in closed loop: a PD of
    ``bandwidth`` Hz on the quantised position plus the model's inverse dynamics along the
    reference as feed-forward (friction not compensated), a white torque ``disturbance``
    [N m] acting on the arm, integrated semi-implicitly at ``substeps`` times the log's rate;
    the logged torque is the command plus ``noise``. The gains are for ``inertia`` per joint
    (default the mean diagonal of the mass matrix along the reference; ``"free"``: the least
    inertia each joint meets with the others free, ``1 / (M^-1)_jj``, which a Panda whose
    joints 1 and 3 align needs: with the diagonal's its loop diverges there)."""
    if trajectory is None:
        trajectory = reference(model, duration, rate, seed)
    t, q_r, dq_r, ddq_r = trajectory
    rate = 1.0 / float(np.median(np.diff(t)))
    rng = np.random.default_rng(seed + 20_000)
    ff = model.inverse_dynamics(q_r, dq_r, ddq_r)
    M = model.mass_matrix(q_r[:: max(len(t) // 200, 1)])
    if inertia == "free":
        m = 1.0 / np.diagonal(np.linalg.inv(M), axis1=1, axis2=2).max(axis=0)
    else:
        m = np.diagonal(M[::10], axis1=1, axis2=2).mean(axis=0)
    w = 2 * np.pi * bandwidth
    kp, kd = m * w**2, 2 * 0.7 * w * m
    step = 2 * np.pi / counts
    h = 1.0 / (rate * substeps)
    q, dq = q_r[0].copy(), dq_r[0].copy()
    pos = np.empty_like(q_r)
    tau_log = np.empty_like(q_r)
    q_prev = np.round(q / step) * step
    for k in range(len(t)):
        q_meas = np.round(q / step) * step
        v_meas = (q_meas - q_prev) * rate if k else dq_r[0]
        q_prev = q_meas
        tau = ff[k] + kp * (q_r[k] - q_meas) + kd * (dq_r[k] - v_meas)
        pos[k], tau_log[k] = q_meas, tau
        for _ in range(substeps):
            fr = friction_torque(laws, dq[None, :], _load(model, laws, q[None, :]))[0]
            dist = rng.normal(0.0, disturbance * np.sqrt(substeps), model.n)
            acc = model.forward_dynamics(q[None, :], dq[None, :], (tau - fr + dist)[None, :])[0]
            dq = dq + h * acc
            q = q + h * dq
    tau_log = tau_log + rng.normal(0.0, noise, tau_log.shape)
    vel = np.gradient(pos, axis=0) * rate
    return RobotLog(
        time=t, joints=model.joints, position=pos, velocity=vel, torque=tau_log, source=source
    )


def lugre_torque(law, dq, rate, substeps=20):
    """LuGre friction ``law`` (a mapping of ``fricid.models.lugre.PARAM_NAMES``) along the
    velocity ``dq`` (n,) sampled at ``rate``, at each sample instant: its own integrator,
    implicit Euler on the bristle state at ``substeps`` steps per period with the velocity
    interpolated linearly (not fricid's exact exponential period means)."""
    s0, s1, s2 = law["sigma_0"], law["sigma_1"], law["sigma_2"]
    tau_c, tau_s, w_s, delta = law["tau_c"], law["tau_s"], law["w_s"], law["delta"]
    h = 1.0 / (rate * substeps)
    frac = (np.arange(1, substeps + 1) / substeps)[None, :]
    v = (dq[:-1, None] * (1 - frac) + dq[1:, None] * frac).ravel()
    v = np.concatenate([dq[:1], v])
    g = tau_c + (tau_s - tau_c) * np.exp(-((np.abs(v) / w_s) ** delta))
    a = s0 * np.abs(v) / g
    z = np.empty(v.size)
    z[0] = np.sign(v[0]) * g[0] / s0
    for k in range(1, v.size):  # z_k = z_{k-1} + h (v_k - a_k z_k)
        z[k] = (z[k - 1] + h * v[k]) / (1.0 + h * a[k])
    dz = v - a * z
    F = s0 * z + s1 * dz + s2 * v
    return F[::substeps]


def make_lugre_log(model, laws, lugre_laws, **kwargs):
    """:func:`make_log` with the joints in ``lugre_laws`` (index -> LuGre law) given LuGre
    friction by :func:`lugre_torque` along the exact reference velocity instead of their
    entry in ``laws``."""
    rate = kwargs.get("rate", 1000.0)
    traj = kwargs.pop("trajectory", None)
    if traj is None:
        traj = reference(
            model, kwargs.get("duration", 20.0), rate, kwargs.get("seed", 0),
            speed=kwargs.get("speed", 1.0), hold=kwargs.get("hold", ()),
        )  # fmt: skip
    log = make_log(model, laws, trajectory=traj, **kwargs)
    dq = traj[2]
    tau = np.array(log.torque, dtype=float)
    for j, law in lugre_laws.items():
        f = friction_torque(laws, dq)[:, j]
        tau[:, j] += lugre_torque(law, dq[:, j], rate) - f
    return RobotLog(
        time=log.time, joints=log.joints, position=log.position, velocity=log.velocity,
        torque=tau, source=log.source,
    )  # fmt: skip
