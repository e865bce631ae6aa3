"""Small constant-velocity sweep logs with gravity, for the extraction tests (not a test module).

The joint follows eq. 8 of the BAS-RBFNN paper, ``tau_m = tau_f - tau_g``, with eq. 7's
``tau_g = p_x cos(q) - p_y sin(q)`` and friction ``sign(v) (1 + 2 |v|)`` [N m]; each speed is
one traverse forward and one back over ``span``, with a rest between traverses.
"""

from __future__ import annotations

import numpy as np

from fricid.samples import RawLog


def friction(v) -> np.ndarray:
    """N m, the true friction at velocity ``v`` [rad/s]."""
    v = np.asarray(v, dtype=float)
    return np.sign(v) * (1.0 + 2.0 * np.abs(v))


def sweep_log(
    speeds,
    *,
    p=(3.0, 1.0),
    span=(-1.2, 1.2),
    rate: float = 100.0,
    noise: float = 0.05,
    seed: int = 0,
    coupled: float = 0.0,
    offsets=None,
    rest: float = 0.5,
    extra=(),
    source: str = "sweep.csv",
) -> RawLog:
    """A log of traverses at ``speeds`` [rad/s] (each forward then back).

    ``coupled`` [N m] adds ``coupled sin(2 q + 0.3)``, a position dependence eq. 7 cannot
    follow; ``offsets`` (one per speed, N m) shifts that speed's friction in both directions
    (a disturbed run); ``extra`` is a list of ``(velocity, seconds)`` moves appended at the end
    (a standstill creep, say).
    """
    rng = np.random.default_rng(seed)
    offsets = np.zeros(len(speeds)) if offsets is None else np.asarray(offsets, dtype=float)
    parts: list[tuple[np.ndarray, ...]] = []
    t0 = 0.0

    def add(t, q, v, bias=0.0):
        nonlocal t0
        g = p[0] * np.cos(q) - p[1] * np.sin(q) + coupled * np.sin(2.0 * q + 0.3)
        tau = friction(v) + np.sign(v) * bias - g + noise * rng.standard_normal(t.size)
        parts.append((t0 + t, q, v, tau))
        t0 = t0 + t[-1] + 1.0 / rate

    def dwell(q):
        m = int(rest * rate)
        add(np.arange(m) / rate, np.full(m, q), np.zeros(m))

    for v, bias in zip(speeds, offsets, strict=True):
        n = round((span[1] - span[0]) / v * rate)
        t = np.arange(n) / rate
        add(t, span[0] + v * t, np.full(n, v), bias)
        dwell(span[1])
        add(t, span[1] - v * t, np.full(n, -v), bias)
        dwell(span[0])
    for v, seconds in extra:
        n = int(seconds * rate)
        t = np.arange(n) / rate
        add(t, span[0] + v * t, np.full(n, v))
        dwell(span[0] + v * t[-1])
    time, position, velocity, torque = (np.concatenate(c) for c in zip(*parts, strict=True))
    return RawLog(
        time=time,
        position=position,
        velocity=velocity,
        temperature=25.0,
        torque=torque,
        source=source,
    )
