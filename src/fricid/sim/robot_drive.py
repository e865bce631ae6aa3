"""The drive of :mod:`fricid.sim.robot`: the encoder, the velocity it reads, and its controller.

At the log's ``rate`` the controller reads the quantised position (an encoder of ``counts``
per revolution, :func:`quantise`) and the velocity by backward differences of it, low-pass
filtered (first order), and holds its command for one period. Its PD gains default to a
bandwidth and a damping ratio on the inertia each joint meets at the start
(:func:`default_gains`), lowered on a joint where the arm will pass configurations in which that
inertia is so small that the sampled loop would go unstable (:data:`STABLE_DAMPING`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..robot import RigidBodyModel

__all__ = [
    "CONTROLLERS",
    "MAX_RISE",
    "STABLE_DAMPING",
    "default_gains",
    "least_inertia",
    "quantise",
]

#: The drive's controllers (:mod:`fricid.sim.robot` module notes).
CONTROLLERS = ("pd", "torque", "none")

#: ``Kd_j (M^-1)_jj / rate`` along the arm's path is held to at most the larger of
#: ``STABLE_DAMPING`` and ``MAX_RISE`` times its value at the start (``2 zeta w / rate``): a
#: loop at the bandwidth asked for where it starts, never ringing where the inertia falls far
#: below that. On the Panda at 1 kHz and 5 Hz (start 0.063), multi-sines whose joint 2
#: crosses zero (joints 1 and 3 aligned) reached 1.9 on the diagonal and 2.1-2.5 in the
#: spectral radius of ``M^-1 Kd / rate`` with gains for the start alone, and the drive rang to
#: 14,000 N m; held to 0.25, the radius stays under 0.5. Fast loops chosen on purpose keep
#: theirs: the double pendulum's sweeps at 20 Hz and 500 Hz start at 0.50 and reach 1.31
#: (2.6 times), tracked stably.
STABLE_DAMPING = 0.25
MAX_RISE = 3.0


def quantise(position, counts: int) -> np.ndarray:
    """An encoder's reading of ``position`` [rad]: whole steps of ``2 pi / counts``."""
    step = 2.0 * math.pi / counts
    return np.round(np.asarray(position, dtype=float) / step) * step


def per_joint(value, n: int, name: str) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
    if not (np.isfinite(arr).all() and (arr >= 0).all()):
        raise ConfigError(f"{name} must be finite and >= 0 (one value or one per joint)")
    return arr


def least_inertia(model: RigidBodyModel, rows: np.ndarray) -> np.ndarray:
    """The least inertia each joint meets over the configurations ``rows`` (k, n), the other
    joints free: ``1 / max_k (M(q_k)^-1)_jj`` [kg m^2] (n,)."""
    return 1.0 / np.diagonal(np.linalg.inv(model.mass_matrix(rows)), axis1=1, axis2=2).max(axis=0)


def default_gains(
    model: RigidBodyModel,
    q0,
    bandwidth: float = 5.0,
    damping: float = 1.0,
    *,
    path=None,
    rate: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """PD gains ``Kp = m_j w^2``, ``Kd = 2 zeta m_j w``, ``w = 2 pi bandwidth``, at ``q0``.

    ``m_j = 1 / (M^-1)_jj`` is the inertia joint ``j`` meets with the other joints free, not
    ``M_jj``: on an arm whose joints 1 and 3 are nearly aligned (the Panda's), gains from
    ``M_jj`` give ``M^-1 Kd`` eigenvalues of thousands per second, and a 1 kHz drive loop
    with them is unstable. With ``path`` (configurations the arm will pass, one per row) and
    ``rate`` [Hz], a joint's two gains are scaled down by one factor where ``Kd_j (M^-1)_jj /
    rate`` along the path would exceed its bound (:data:`STABLE_DAMPING`, :data:`MAX_RISE`);
    elsewhere they stay (lowering every joint's gains for its least inertia loosened a small
    arm's tracking until its joint stuck).
    """
    if not (bandwidth > 0 and damping > 0):
        raise ConfigError(f"bandwidth and damping must be > 0; got {bandwidth}, {damping}")
    m = 1.0 / np.diag(np.linalg.inv(model.mass_matrix(np.asarray(q0, dtype=float))[0]))
    w = 2.0 * math.pi * bandwidth
    kp, kd = m * w**2, 2.0 * damping * m * w
    if path is not None and rate is not None:
        path = np.atleast_2d(np.asarray(path, dtype=float))
        rows = path[:: max(1, len(path) // 2000)]
        reach = 1.0 / least_inertia(model, rows)
        bound = max(STABLE_DAMPING, MAX_RISE * 2.0 * damping * w / rate)
        scale = np.minimum(1.0, bound * rate / (kd * reach))
        kp, kd = kp * scale, kd * scale
    return kp, kd


@dataclass
class _Drive:
    """The controller's state and settings (module notes)."""

    model: RigidBodyModel
    kind: str
    kp: np.ndarray
    kd: np.ndarray
    w: float
    alpha: float
    counts: int
    rate: float
    q_prev: np.ndarray
    v_filt: np.ndarray

    def read(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The encoder's position and the backward-difference velocity (and filter them)."""
        qm = quantise(q, self.counts)
        vm = (qm - self.q_prev) * self.rate
        self.q_prev = qm
        self.v_filt = self.v_filt + self.alpha * (vm - self.v_filt)
        return qm, vm

    def command(self, qm: np.ndarray, ref: tuple[np.ndarray, ...], ff: np.ndarray) -> np.ndarray:
        q_r, dq_r, ddq_r = ref
        e, de = q_r - qm, dq_r - self.v_filt
        if self.kind == "pd":
            return ff + self.kp * e + self.kd * de
        if self.kind == "torque":
            a = ddq_r + self.w**2 * e + 2.0 * self.w * de
            return self.model.inverse_dynamics(qm, self.v_filt, a)[0]
        return np.zeros_like(qm)


def make_drive(
    model, controller, gains, q0, v0, rate, counts, bandwidth, velocity_filter, path=None
) -> _Drive:
    """The drive at the start state ``(q0, v0)``; ``path``: the reference's positions."""
    if controller not in CONTROLLERS:
        raise ConfigError(f"controller must be one of {CONTROLLERS}; got {controller!r}")
    if not (isinstance(counts, int | np.integer) and counts >= 2):
        raise ConfigError(f"encoder_counts must be an integer >= 2; got {counts!r}")
    if gains is None:
        kp, kd = default_gains(model, q0, bandwidth, path=path, rate=rate)
    else:
        kp, kd = (per_joint(g, model.n, "gains") for g in gains)
    if not velocity_filter > 0:
        raise ConfigError(f"velocity_filter must be > 0 Hz; got {velocity_filter!r}")
    alpha = 1.0 - math.exp(-2.0 * math.pi * velocity_filter / rate)
    q_prev = quantise(q0 - v0 / rate, int(counts))
    return _Drive(
        model, controller, kp, kd, 2 * math.pi * bandwidth, alpha, int(counts), rate, q_prev, v0
    )
