"""Joint trajectories a robot can play: periodic Fourier series (Swevers et al. 1997), the
same played from rest and back to rest by quintic blends, and constant-velocity sweeps of one
joint (BAS-RBFNN paper section 2).

Every trajectory has ``joints``, ``duration`` [s] and ``evaluate(t) -> (q, dq, ddq)`` with
arrays of shape ``(len(t), n)`` in SI units (rad, rad/s, rad/s^2; m for a prismatic joint),
and ``sample(rate)`` giving the times ``k / rate`` over ``[0, duration]`` and the states.

The Fourier series of joint ``i`` (Swevers, Ganseman, Tukel, De Schutter, Van Brussel, "Optimal
robot excitation and identification", IEEE T-RA 13(5), 1997, eq. 25)::

    q_i(t)   = q0_i + sum_k a_ik / (w_f k) sin(w_f k t) - b_ik / (w_f k) cos(w_f k t)
    dq_i(t)  = sum_k a_ik cos(w_f k t) + b_ik sin(w_f k t)
    ddq_i(t) = sum_k -a_ik w_f k sin(w_f k t) + b_ik w_f k cos(w_f k t)

for ``k = 1..H``: periodic with period ``2 pi / w_f`` in position, velocity and acceleration,
so a robot may repeat it without a jump. It does not start at rest unless ``sum_k a_ik = 0``
and ``sum_k k b_ik = 0``; :class:`RampedTrajectory` blends it in from rest and out to rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError

__all__ = [
    "FourierTrajectory",
    "RampedTrajectory",
    "SweepTrajectory",
    "fourier_basis",
    "quintic",
]


def fourier_basis(t: np.ndarray, w_f: float, harmonics: int) -> tuple[np.ndarray, ...]:
    """The matrices mapping ``[a_1..a_H, b_1..b_H]`` of one joint to ``q - q0``, ``dq``,
    ``ddq`` at the times ``t``: three arrays of shape ``(len(t), 2 H)`` (module notes)."""
    t = np.asarray(t, dtype=float).reshape(-1, 1)
    k = np.arange(1, harmonics + 1, dtype=float)
    wk = w_f * k
    s, c = np.sin(wk * t), np.cos(wk * t)
    pos = np.hstack([s / wk, -c / wk])
    vel = np.hstack([c, s])
    acc = np.hstack([-s * wk, c * wk])
    return pos, vel, acc


@dataclass(frozen=True)
class FourierTrajectory:
    """A periodic Fourier-series trajectory of every joint (module notes).

    Attributes
    ----------
    joints : tuple of str
    w_f : float
        The base frequency [rad/s]; the period is ``2 pi / w_f``.
    q0 : ndarray, shape (n,)
        The offsets [rad or m].
    a, b : ndarray, shape (n, H)
        The coefficients [rad/s or m/s] (module notes).
    """

    joints: tuple[str, ...]
    w_f: float
    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.joints)
        q0 = np.asarray(self.q0, dtype=float).reshape(-1)
        a = np.atleast_2d(np.asarray(self.a, dtype=float))
        b = np.atleast_2d(np.asarray(self.b, dtype=float))
        if q0.shape != (n,) or a.shape[0] != n or a.shape != b.shape or a.shape[1] < 1:
            raise ConfigError(
                f"a Fourier trajectory of {n} joints needs q0 of shape ({n},) and a, b of "
                f"shape ({n}, H); got {q0.shape}, {a.shape}, {b.shape}"
            )
        if not (np.isfinite(self.w_f) and self.w_f > 0):
            raise ConfigError(f"the base frequency must be > 0; got {self.w_f}")
        if not (np.isfinite(q0).all() and np.isfinite(a).all() and np.isfinite(b).all()):
            raise ConfigError("the Fourier coefficients must be finite")
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "q0", q0)
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    @property
    def harmonics(self) -> int:
        """``H``, the number of harmonics."""
        return int(self.a.shape[1])

    @property
    def period(self) -> float:
        """``2 pi / w_f`` [s]."""
        return 2.0 * np.pi / self.w_f

    @property
    def duration(self) -> float:
        """One period [s]."""
        return self.period

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, dq, ddq)`` at the times ``t`` [s], each of shape ``(len(t), n)``."""
        pos, vel, acc = fourier_basis(np.atleast_1d(t), self.w_f, self.harmonics)
        coef = np.hstack([self.a, self.b]).T  # (2H, n)
        return self.q0 + pos @ coef, vel @ coef, acc @ coef

    def sample(self, rate: float) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        """Times ``k / rate`` over ``[0, duration]`` and the states there."""
        return _sample(self, rate)

    def repeated(
        self, periods: int = 1, *, ramp: float = 1.0, limits: dict | None = None
    ) -> RampedTrajectory:
        """``periods`` periods, blended in from rest and out to rest over ``ramp`` s each
        (within ``limits``' ``lower``, ``upper`` and ``velocity`` when given)."""
        return RampedTrajectory(self, periods, ramp, limits)


def _sample(traj, rate: float) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    if not (np.isfinite(rate) and rate > 0):
        raise ConfigError(f"the rate must be > 0 Hz; got {rate}")
    count = int(np.floor(traj.duration * rate + 1e-9)) + 1
    t = np.arange(count) / rate
    return t, traj.evaluate(t)


def quintic(
    duration: float, start: np.ndarray, end: tuple[np.ndarray, np.ndarray, np.ndarray]
) -> np.ndarray:
    """The coefficients ``c`` (6, n) of ``p(s) = sum_i c_i s^i`` on ``[0, duration]`` from rest
    at ``start`` to the state ``end = (q, dq, ddq)``."""
    T = float(duration)
    q, v, a = (np.asarray(x, dtype=float) for x in end)
    c = np.zeros((6, q.size))
    c[0] = start
    # p(T) = q, p'(T) = v, p''(T) = a with c1 = c2 = 0
    M = np.array(
        [[T**3, T**4, T**5], [3 * T**2, 4 * T**3, 5 * T**4], [6 * T, 12 * T**2, 20 * T**3]]
    )
    rhs = np.vstack([q - start, v, a])
    c[3:] = np.linalg.solve(M, rhs)
    return c


def _poly(c: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    s = s.reshape(-1, 1)
    powers = s ** np.arange(6)
    i = np.arange(6)
    d1 = np.hstack([np.zeros_like(s), (i[1:] * powers[:, :-1])])
    d2 = np.hstack([np.zeros((s.shape[0], 2)), (i[2:] * (i[2:] - 1) * powers[:, :-2])])
    return powers @ c, d1 @ c, d2 @ c


def _rest_point(
    duration: float,
    state: tuple[np.ndarray, ...],
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
    velocity: np.ndarray | None = None,
    names: tuple[str, ...] = (),
) -> np.ndarray:
    """The rest position from which a quintic reaches ``state`` with the least squared
    acceleration (the quintic is linear in its start; the integral is a quadratic in it); with
    limits, the best of the rest positions whose quintic stays within ``[lower, upper]`` and
    ``|dq| <= velocity`` (a fine grid of candidates per joint)."""
    s = np.linspace(0.0, duration, 201)
    zero = np.zeros_like(state[0])
    base = _poly(quintic(duration, zero, state), s)  # from rest at 0
    unit = _poly(quintic(duration, np.ones_like(zero), (zero, zero, zero)), s)  # 1 -> 0
    best = -np.sum(base[2] * unit[2], axis=0) / np.sum(unit[2] * unit[2], axis=0)
    if lower is None or upper is None:
        return best
    vel = np.full_like(zero, np.inf) if velocity is None else np.asarray(velocity, dtype=float)
    out = np.empty_like(best)
    for j in range(best.size):
        cand = np.concatenate([[best[j]], np.linspace(lower[j], upper[j], 401)])
        p = base[0][:, j, None] + unit[0][:, j, None] * cand
        v = base[1][:, j, None] + unit[1][:, j, None] * cand
        a = base[2][:, j, None] + unit[2][:, j, None] * cand
        ok = (p.min(axis=0) >= lower[j]) & (p.max(axis=0) <= upper[j])
        ok &= np.abs(v).max(axis=0) <= vel[j]
        if not ok.any():
            raise ConfigError(
                f"a {duration:g} s ramp cannot bring {names[j] if names else j + 1} between rest "
                "and the "
                "excitation within its position and velocity limits: lengthen the ramp, or "
                "design the excitation at rest at its start"
            )
        cost = np.where(ok, np.sum(a * a, axis=0), np.inf)
        out[j] = cand[int(np.argmin(cost))]
    return out


@dataclass(frozen=True)
class RampedTrajectory:
    """A periodic trajectory played ``periods`` times, from rest and back to rest.

    The ramp in is the quintic from rest at ``start`` to the state at ``t = 0`` of the
    periodic part, with the rest position chosen for the least squared acceleration; the ramp
    out the mirror image from the state at the end (module notes). With ``limits`` (``lower``,
    ``upper``, ``velocity``), the rest positions are the best whose ramps keep within them.
    Time 0 is the start of the ramp in; the periodic part runs over
    ``[ramp, ramp + periods * period]``.
    """

    base: FourierTrajectory
    periods: int = 1
    ramp: float = 1.0
    limits: dict | None = field(default=None, repr=False)
    start: np.ndarray = field(init=False, repr=False)
    stop: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if int(self.periods) < 1 or not (np.isfinite(self.ramp) and self.ramp > 0):
            raise ConfigError(f"need periods >= 1 and ramp > 0 s; got {self.periods}, {self.ramp}")
        object.__setattr__(self, "periods", int(self.periods))
        s0 = self.base.evaluate(0.0)
        s1 = self.base.evaluate(self.base.period * self.periods)
        lim = self.limits or {}
        bounds = (lim.get("lower"), lim.get("upper"), lim.get("velocity"))
        start = _rest_point(self.ramp, tuple(x[0] for x in s0), *bounds, self.joints)
        mirrored = (s1[0][0], -s1[1][0], s1[2][0])  # time runs backwards out of the end
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "stop", _rest_point(self.ramp, mirrored, *bounds, self.joints))

    @property
    def joints(self) -> tuple[str, ...]:
        return self.base.joints

    @property
    def duration(self) -> float:
        return 2.0 * self.ramp + self.periods * self.base.period

    @property
    def excitation(self) -> tuple[float, float]:
        """The interval [s] of the periodic part."""
        return self.ramp, self.ramp + self.periods * self.base.period

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        q, dq, ddq = self.base.evaluate(t - self.ramp)
        t0, t1 = self.excitation
        first, last = t < t0, t > t1
        if first.any():
            s0 = tuple(x[0] for x in self.base.evaluate(0.0))
            c = quintic(self.ramp, self.start, s0)
            q[first], dq[first], ddq[first] = _poly(c, np.clip(t[first], 0.0, t0))
        if last.any():
            s1 = self.base.evaluate(self.periods * self.base.period)
            c = quintic(self.ramp, self.stop, (s1[0][0], -s1[1][0], s1[2][0]))
            p, v, a = _poly(c, np.clip(self.duration - t[last], 0.0, self.ramp))
            q[last], dq[last], ddq[last] = p, -v, a
        return q, dq, ddq

    def sample(self, rate: float) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        return _sample(self, rate)


@dataclass(frozen=True)
class SweepTrajectory:
    """Constant-velocity sweeps of one joint, the others held still (BAS-RBFNN paper
    section 2): piecewise segments in which the velocity goes from ``v0`` to ``v1`` by a
    half-cosine, ``v(s) = v0 + (v1 - v0) (1 - cos(pi s / T)) / 2`` (a constant speed where
    ``v0 = v1``), so the acceleration is continuous and zero at both ends of a segment.

    Attributes
    ----------
    joints : tuple of str
    joint : int
        The index of the swept joint.
    hold : ndarray, shape (n,)
        The configuration of the other joints (and the swept joint's start).
    segments : ndarray, shape (m, 4)
        ``(duration, q at the start, v0, v1)`` of each segment, in order.
    """

    joints: tuple[str, ...]
    joint: int
    hold: np.ndarray
    segments: np.ndarray

    @property
    def duration(self) -> float:
        return float(np.sum(self.segments[:, 0]))

    @property
    def starts(self) -> np.ndarray:
        """Each segment's start time [s]."""
        return np.concatenate([[0.0], np.cumsum(self.segments[:-1, 0])])

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        starts = self.starts
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1)
        T, p0, v0, v1 = self.segments[k].T
        s = t - starts[k]
        dv, x = v1 - v0, np.pi * s / T
        q = np.tile(self.hold, (t.size, 1))
        dq, ddq = np.zeros_like(q), np.zeros_like(q)
        q[:, self.joint] = p0 + v0 * s + 0.5 * dv * (s - np.sin(x) * T / np.pi)
        dq[:, self.joint] = v0 + 0.5 * dv * (1.0 - np.cos(x))
        ddq[:, self.joint] = 0.5 * dv * np.pi / T * np.sin(x)
        return q, dq, ddq

    def sample(self, rate: float) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        return _sample(self, rate)
