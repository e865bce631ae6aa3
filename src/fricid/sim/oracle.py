"""The test oracle: what an extraction of a simulated campaign should find (the equations cited
are the BAS-RBFNN paper's).

Rows follow the extractor's order: temperature, then velocity set-point, then position bin
(ascending), then, per direction, -1 before +1. Truth is taken at the nominal operating point
(set-point velocity, set temperature, bin centre); averaging over a bin changes it by far less
than the noise (the load is smooth in position, its curvature over +-1 deg is 1e-4 relative).
"""

from __future__ import annotations

import math

import numpy as np

from ..samples import FrictionSamples
from .joint import Scenario

__all__ = [
    "MEDIAN_EFFICIENCY",
    "expected_noise_std",
    "operating_grid",
    "true_gravity",
    "true_samples",
]

#: Variance factor of the mean of a running median against the plain mean of Gaussian samples:
#: pi/2 for long windows (about 1.25 for a 5-sample window, 1.33 for 9), used as a mild
#: upper bound.
MEDIAN_EFFICIENCY = math.pi / 2.0


def operating_grid(scenario: Scenario) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(temperature, velocity, position) of every operating point, in the extractor's order."""
    d = scenario.design
    t, v, p = np.meshgrid(d.temperatures, d.velocities, d.positions, indexing="ij")
    order = np.lexsort((p.ravel(), v.ravel(), t.ravel()))
    return t.ravel()[order], v.ravel()[order], p.ravel()[order]


def true_gravity(scenario: Scenario) -> tuple[float, float]:
    """The true (p_x, p_y) [N m] of eq. 7 (zeros for a horizontal joint)."""
    return float(scenario.joint.p_x), float(scenario.joint.p_y)


def true_samples(scenario: Scenario, *, by_direction: bool = False) -> FrictionSamples:
    """The true friction at every operating point of the design.

    With ``by_direction=False``: one row per point, direction 0, velocity and friction of the
    positive direction as eq. 11 defines them, ``(F(v) - F(-v)) / 2`` (equal to F(v) for a
    symmetric law). With ``by_direction=True``: two rows per point (-1 then +1), velocity and
    friction signed. Load is the true gravity torque at the bin centre (eq. 12), 0 for a
    horizontal joint.
    """
    temp, vel, pos = operating_grid(scenario)
    joint = scenario.joint
    load = joint.gravity(pos)
    if scenario.gravity == "none":
        load = np.zeros_like(load)
    if not by_direction:
        friction = 0.5 * (joint.law(vel, load, temp) - joint.law(-vel, load, temp))
        return FrictionSamples(
            velocity=vel,
            load=load,
            temperature=temp,
            friction=friction,
            direction=np.zeros_like(vel),
            source=f"truth:{scenario.name}/{scenario.size}",
        )
    sign = np.tile([-1.0, 1.0], vel.size)
    vel2, load2, temp2 = (np.repeat(a, 2) for a in (vel, load, temp))
    vel2 = sign * vel2
    return FrictionSamples(
        velocity=vel2,
        load=load2,
        temperature=temp2,
        friction=joint.law(vel2, load2, temp2),
        direction=sign,
        source=f"truth:{scenario.name}/{scenario.size}",
    )


def expected_noise_std(
    scenario: Scenario, *, by_direction: bool = False, median_window: int = 5
) -> np.ndarray:
    """Approximate standard deviation [N m] of each averaged sample's friction, row-aligned
    with :func:`true_samples`.

    Per direction and pass, a bin of half-width h at speed v holds ``n = 2 h f_s / v`` samples;
    over R passes the mean carries ``s_p^2 / R + c s^2 / (R n)``, with s_p the per-traverse
    offset, s the per-sample torque noise (Gaussian plus quantisation) and c the median filter's
    variance factor (:data:`MEDIAN_EFFICIENCY`, 1 without filter). The combined sample (eq. 11)
    halves that variance. Spikes are assumed removed; the gravity fit's own error (many points,
    far smaller) is ignored. For a horizontal joint extracted over the whole steady traverse the
    bins are wider than ``2 h``, so this is an upper bound there. Empirically, the noise floor
    is also the RMS of extracted minus true friction.
    """
    _, vel, _ = operating_grid(scenario)
    d, noise = scenario.design, scenario.noise
    n = 2.0 * d.bin_halfwidth * d.sample_rate / vel
    c = MEDIAN_EFFICIENCY if median_window > 1 else 1.0
    s = noise.sample_torque_std(scenario.joint.torque_constant)
    var = (noise.pass_offset_std**2 + c * s * s / n) / d.repetitions
    if by_direction:
        return np.repeat(np.sqrt(var), 2)
    return np.sqrt(var / 2.0)
