"""An open-loop joint along a multi-sine, read through an encoder: the truth of
``bench_window.py`` and ``tests/identify/dynamic/test_trajectory_window.py``.

Its own code path, not the virtual joint's: the motion is prescribed (three sines of random
frequency), the torque follows by inverse dynamics, the position is rounded to the encoder's
counts and the velocity logged as backward differences of it.
"""

from __future__ import annotations

import numpy as np

from fricid.samples import RawLog

TRUTH = {"inertia": 0.02, "f_c": 0.4, "beta": 0.15, "p_x": -0.25, "p_y": 0.08}


def encoder_log(
    seed: int,
    counts: float,
    rate: float = 1000.0,
    seconds: float = 20.0,
    band: tuple[float, float] = (0.2, 0.9),
    amplitudes: tuple[float, float, float] = (0.5, 0.3, 0.2),
) -> RawLog:
    """A joint moved along three sines of random frequency in ``band`` [Hz] and the
    ``amplitudes`` [rad], its torque
    ``J qdd + f_c tanh(v / 2e-3) + beta v - (p_x cos q - p_y sin q)`` (fricid's gravity sign)
    plus 5 mN m of noise, the
    position read through an encoder of ``counts`` per revolution (rounded: a floor would move
    the zero by half a count, which rotates p_x, p_y by 0.8 mrad at 4096 counts)."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * rate)) / rate
    q = np.zeros_like(t)
    v = np.zeros_like(t)
    a = np.zeros_like(t)
    sines = zip(amplitudes, rng.uniform(*band, 3), rng.uniform(0, 6.3, 3), strict=True)
    for amp, f, ph in sines:
        w = 2 * np.pi * f
        q += amp * np.sin(w * t + ph)
        v += amp * w * np.cos(w * t + ph)
        a -= amp * w * w * np.sin(w * t + ph)
    T = TRUTH
    torque = (
        T["inertia"] * a
        + T["f_c"] * np.tanh(v / 2e-3)
        + T["beta"] * v
        - (T["p_x"] * np.cos(q) - T["p_y"] * np.sin(q))
        + rng.normal(0.0, 0.005, t.size)
    )
    step = 2 * np.pi / counts
    qm = np.round(q / step) * step
    vm = np.concatenate([[0.0], np.diff(qm) * rate])
    return RawLog(time=t, position=qm, velocity=vm, torque=torque, temperature=25.0)
