"""Ready-made scenarios: the two seed papers' experiments on the virtual joint.

``preset(name, size)`` returns a :class:`~fricid.sim.joint.Scenario`. Sizes: ``"full"`` is the
paper's design, ``"reduced"`` a few-seconds demo, ``"quick"`` a sub-second unit-test campaign;
all sizes share the joint and its noise, only the design shrinks.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import ConfigError
from ..models import Stribeck
from ..units import DEG
from .design import Design
from .faults import FAULT_KINDS, Faults
from .joint import Joint, Noise, Scenario
from .laws import LoadTemperatureLaw, ModelLaw

__all__ = ["PRESETS", "SIZES", "preset"]


#: Sizes of every preset, largest first.
SIZES: tuple[str, ...] = ("full", "reduced", "quick")


def _deg(values) -> np.ndarray:
    return np.asarray(values, dtype=float) * DEG


# -- paper1: the BAS-RBFNN paper ----------------------------------------------------------------

#: Gravity coefficients of the BAS-RBFNN paper (section 2.2, Fig. 1), read as motor-side N m.
PAPER1_GRAVITY = (0.2011, 0.06175)

_PAPER1_DESIGNS = {
    # 21 positions x 15 velocities x 21 temperatures x 10 repetitions: about 79 million samples
    "full": dict(
        velocities=_deg([0.1, 0.3, 0.5, 1, 2, 4, 6, 9, 13, 18, 24, 31, 38, 44, 50]),
        temperatures=np.arange(5.0, 46.0, 2.0),
        positions=_deg(np.arange(-60.0, -19.0, 2.0)),
        repetitions=10,
    ),
    # 11 positions x 6 velocities x 5 temperatures x 3 repetitions: about 1.3 million samples
    "reduced": dict(
        velocities=_deg([0.5, 1, 2, 6, 18, 50]),
        temperatures=np.array([5.0, 15.0, 25.0, 35.0, 45.0]),
        positions=_deg(np.arange(-60.0, -19.0, 4.0)),
        repetitions=3,
    ),
    # 5 positions x 3 velocities x 2 temperatures x 2 repetitions: about 0.1 million samples
    "quick": dict(
        velocities=_deg([1, 6, 30]),
        temperatures=np.array([15.0, 35.0]),
        positions=_deg(np.arange(-60.0, -19.0, 10.0)),
        repetitions=2,
    ),
}


def _paper1(size: str) -> Scenario:
    design = Design(
        bin_halfwidth=1.0 * DEG,
        sample_rate=250.0,
        acceleration=200.0 * DEG,
        settle_time=0.2,
        dwell_time=0.2,
        **_PAPER1_DESIGNS[size],
    )
    joint = Joint(
        law=LoadTemperatureLaw(),
        p_x=PAPER1_GRAVITY[0],
        p_y=PAPER1_GRAVITY[1],
        inertia=0.01,
        torque_constant=0.5,
    )
    return Scenario("paper1", size, design, joint, Noise(), gravity="fit", description=_PAPER1_DOC)


_PAPER1_DOC = """\
BAS-RBFNN paper, section 2: a joint with gravity (eq. 7, p_x = 0.2011, p_y = 0.06175 N m),
bidirectional constant-velocity sweeps over positions -60..-20 deg (bins +-1 deg), 15
velocities 0.1-50 deg/s, temperatures 5-45 degC, 10 repetitions, 250 Hz (full size).
Motion: trapezoid at 200 deg/s^2, traverse extended by the ramp plus 0.2 s of travel, 0.2 s
dwells. Joint: J = 0.01 kg m^2, K = 0.5 N m/A. True law: LoadTemperatureLaw (Coulomb
0.04 + 0.6 |L| N m, Stribeck excess 0.08 + 0.3 |L| N m at v_s = 2 deg/s with exponent 1.5,
viscous 0.2 N m s/rad at 25 degC with exp(-(T - 25)/80), Coulomb times exp(-(T - 25)/200)).
Noise: current 10 mA rms (5 mN m), 1 mA ADC step, 0.2 % spikes of 0.5-2 A, velocity
0.5 % + 2e-5 rad/s, 20-bit encoder, temperature 0.05 degC, per-traverse friction offset
2 mN m rms. Averaged combined samples then carry about 0.45-0.65 mN m of noise
(fricid.sim.expected_noise_std)."""


# -- paper2: the RWSAVSBAS paper ----------------------------------------------------------------

#: Stribeck parameters of the RWSAVSBAS paper, Table 2 (tau_c, tau_s, w_s, tau_v; delta = 1),
#: read as N m and rad/s (the paper gives no units).
PAPER2_STRIBECK = (0.084, 0.641, 0.066, 0.0026, 1.0)

#: 17 velocity set-points [rad/s], dense around w_s = 0.066 rad/s where the Stribeck curve
#: bends (7 points from 0.005 to 0.09 fix tau_s and w_s) and spread up to 4 rad/s so the
#: viscous slope (0.0104 N m over the range) is resolved against the noise.
PAPER2_VELOCITIES = np.array(
    [
        0.005,
        0.01,
        0.02,
        0.03,
        0.045,
        0.066,
        0.09,
        0.12,
        0.16,
        0.22,
        0.3,
        0.5,
        0.8,
        1.3,
        2.0,
        3.0,
        4.0,
    ]
)

#: Per-traverse friction offset [N m] of paper2. Calibrated so that the combined samples (eq. 11
#: of the BAS-RBFNN paper; 0.5 (tau1 - tau2) in the RWSAVSBAS paper) carry sigma_c = 3.16 mN m
#: of noise (sigma_c^2 = s^2 / (2 R) with R = 10 repetitions): the expected optimal SSE of a
#: 4-parameter Stribeck fit (delta fixed to 1) to the 17 samples is then
#: (17 - 4) sigma_c^2 = 1.3e-4, the paper's reported fitness (Table 1).
PAPER2_PASS_OFFSET = 0.01414

_PAPER2_DESIGNS = {
    "full": dict(velocities=PAPER2_VELOCITIES, bin_halfwidth=0.5, repetitions=10),
    "reduced": dict(velocities=PAPER2_VELOCITIES, bin_halfwidth=0.1, repetitions=10),
    "quick": dict(
        velocities=np.array([0.01, 0.03, 0.066, 0.2, 0.6, 2.0]), bin_halfwidth=0.05, repetitions=3
    ),
}


def _paper2(size: str) -> Scenario:
    design = Design(
        temperatures=np.array([25.0]),
        positions=np.array([0.0]),
        sample_rate=250.0,
        acceleration=40.0,
        settle_time=0.2,
        dwell_time=0.2,
        **_PAPER2_DESIGNS[size],
    )
    joint = Joint(
        law=ModelLaw(Stribeck(), np.array(PAPER2_STRIBECK)),
        p_x=0.0,
        p_y=0.0,
        inertia=0.01,
        torque_constant=0.5,
    )
    noise = Noise(pass_offset_std=PAPER2_PASS_OFFSET)
    return Scenario("paper2", size, design, joint, noise, gravity="none", description=_PAPER2_DOC)


_PAPER2_DOC = """\
RWSAVSBAS paper, section 2.1: a horizontal joint (gravity 0), so the measured torque is the
friction. True law: fricid's Stribeck model with the paper's Table 2 values tau_c 0.084 N m,
tau_s 0.641 N m, w_s 0.066 rad/s, tau_v 0.0026 N m s/rad, delta 1. 17 velocities 0.005-4 rad/s,
one temperature (25 degC), traverse +-0.5 rad (full; +-0.1 reduced, +-0.05 quick), 10
repetitions (3 quick), 250 Hz, trapezoid at 40 rad/s^2, traverse extended by the ramp plus
0.2 s of travel. Noise as paper1 but a per-traverse friction offset of 14.1 mN m rms,
calibrated so the optimal SSE of a Stribeck fit to the 17 combined samples is about 1.3e-4
(the paper's fitness): sigma_c = 3.16 mN m per sample. With that noise the Fisher standard
errors are about 2 % (tau_c), 0.4 % (tau_s), 1.3 % (w_s) and 35 % (tau_v: its 10 mN m at
4 rad/s is three noise sigmas): all four are identifiable, tau_v only coarsely."""


#: Preset builders by name.
PRESETS = {"paper1": _paper1, "paper2": _paper2}


def _max_current(scenario: Scenario) -> float:
    """The largest steady motor current [A] of a design (both directions, every bin and
    temperature): the scale of the saturation fault."""
    d, joint = scenario.design, scenario.joint
    t, v, p = np.meshgrid(d.temperatures, d.velocities, d.positions, indexing="ij")
    tau = [joint.motor_torque(p, s * v, 0.0, t) for s in (-1.0, 1.0)]
    return float(max(np.abs(x).max() for x in tau)) / joint.torque_constant


def preset(name: str, size: str = "full") -> Scenario:
    """The scenario ``name`` at ``size`` ("full", "reduced", "quick").

    Parameters
    ----------
    name : str
        ``paper1``: the BAS-RBFNN paper's experiment (joint with gravity; velocity-, load- and
        temperature-dependent friction). ``paper2``: the RWSAVSBAS paper's (horizontal joint;
        the Stribeck law of its Table 2). A suffix adds faults of a real campaign at typical
        magnitudes (:meth:`fricid.sim.Faults.typical`): ``"paper1+faults"`` all of them,
        ``"paper2+rest+spikes"`` the ones named (:data:`fricid.sim.FAULT_KINDS`).
    size : str
        One of :data:`SIZES`.

    Returns
    -------
    Scenario
        See its ``description`` for every number.
    """
    key, *kinds = (part.strip() for part in str(name).strip().lower().split("+"))
    if key not in PRESETS:
        raise ConfigError(f"unknown preset '{name}'; choose one of: {', '.join(PRESETS)}")
    if size not in SIZES:
        raise ConfigError(f"unknown preset size '{size}'; choose one of: {', '.join(SIZES)}")
    scenario = PRESETS[key](size)
    if not kinds:
        return scenario
    if "faults" in kinds:
        kinds = [k for k in kinds if k != "faults"] + list(FAULT_KINDS)
    faults = Faults.typical(
        kinds,
        max_speed=float(scenario.design.velocities.max()),
        max_current=_max_current(scenario),
    )
    described = f"{scenario.description}\nFaults injected: {faults}."
    return replace(scenario, faults=faults, description=described)
