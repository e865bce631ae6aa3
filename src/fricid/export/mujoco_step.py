"""The MuJoCo integrator and timestep an MJCF export needs, measured by simulation in MuJoCo.

An exported fragment (:func:`fricid.export.mjcf_text`) is exact as a model, but MuJoCo
integrates it with its own step: stiff bristles (LuGre's ``sigma_0``) integrated at a
millisecond break away at a fraction of their static friction, and a trajectory drifts off.
:func:`check_timestep` measures, for the fragment built into the one-joint model of
:mod:`fricid.export.mujoco_check` (inertia ``J``), two things per integrator of
:data:`INTEGRATORS` and timestep of :data:`TIMESTEPS`:

(a) break-away: a slow torque ramp ``u = 1.5 F_s t / T`` over :data:`RAMP_SECONDS`, from
    rest, with ``F_s`` the fragment's largest static friction (a ``dcmotor``'s ``lugre``
    ``max(tau_c, tau_s)``, else the joint's ``frictionloss``); the break-away torque is the
    applied torque when ``|v|`` first exceeds :data:`BREAKAWAY_VELOCITY` (a fraction) of the
    reference's velocity at the end of the ramp;
(b) a held-out trajectory: the multi-sine torque :func:`multisine` (peak ``1.2 F_s``, three
    frequencies, :data:`MULTISINE_SECONDS`), which sticks and slips at every velocity
    reversal; its error is the RMS of the position against the reference's (interpolated to
    the step's times), over the reference's position span.

The reference is the same fragment under RK4 at the finest timestep of the ladder (its own
agreement with fricid's joint, :func:`fricid.control.plant.drive` under the true model, is
checked in ``tests/export/test_mujoco.py``). A step passes when the break-away is within
:data:`BREAKAWAY_TOLERANCE` of the reference's and the trajectory within
:data:`TRAJECTORY_TOLERANCE` of the span; the recommendation for an integrator is the largest
timestep that passes with the next finer step of the ladder passing too (the errors are not
monotone in the step: RK4 can break away right at 2 ms and wrong at 1 ms; the ladder is run
coarse to fine and stops there), and the
recommendation of the export the largest of those (ties in :data:`INTEGRATORS`' order,
MuJoCo's default first). Signals are applied one sample per step (zero-order hold), the
steps run inside MuJoCo (``mujoco.rollout``), and nothing is cached: 0.75-3.3 s measured on
two shared cores under a load of about 10 (the LuGre fragments' fine steps dominate; a static
fragment passes at the coarse steps and stops there).

Measured (mujoco 4.0.0, ``benchmarks/bench_mujoco_step.py``; break-away error % / trajectory
error % of the span). The README's example (``fricid simulate --trajectory multisine
--duration 10``, ``fricid fit --trajectory``: sigma_0 1.19e4 N m/rad, sigma_1 0.001, not
determined; J 0.01 kg m^2): implicitfast, Euler and implicit break away 82-96 % low at every
step from 5 ms to 0.2 ms (trajectory 2-79 %) and pass from 0.1 ms (0.42 / 0.57); RK4 passes
from 0.2 ms (0.34 / 0.86), breaks away right at 2 ms (0.48 %) but diverges on the trajectory
there, and 89 % low at 1 ms: recommended RK4 at 0.2 ms (implicitfast 0.1 ms); four times
those steps miss (RK4 0.8 ms: 89.5 / 4.7; implicitfast 0.4 ms: 92 / 7.8). The virtual joint's
truth (sigma_0 1e4, sigma_1 1): every integrator passes from 0.2 ms (implicitfast 0.42 /
0.65). Static and Dahl fragments (``frictionloss``): 5 ms passes against the reference; with
MuJoCo's default ``solimpfriction`` its soft ``frictionloss`` crept so that the reference
itself broke away at 22-44 % of the friction; the export's stiffer one
(:data:`fricid.export.mjcf.STIFF_SOLIMP`) holds it at 1.044 where a joint that sticks exactly
reads 1.05 by this ramp (``benchmarks/results/mujoco_static.txt``). A reference still off by
more than :data:`BREAKAWAY_TOLERANCE` is said in the comment.

Without MuJoCo, :func:`default_timestep` gives the documented conservative default:
``implicitfast`` at the largest ladder step below ``0.05 sqrt(J / sigma_0)`` for a LuGre
fragment (a twentieth of the bristles' natural time constant), :data:`STATIC_DEFAULT` for a
static one, not measured.
"""

from __future__ import annotations

import math
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from .mujoco_check import one_joint_xml, require_mujoco

__all__ = [
    "BREAKAWAY_TOLERANCE",
    "INTEGRATORS",
    "TIMESTEPS",
    "TRAJECTORY_TOLERANCE",
    "StepAdvice",
    "StepCell",
    "check_timestep",
    "default_timestep",
    "model_inertia",
    "multisine",
    "static_friction",
    "timestep_advice",
]

#: MuJoCo's integrators, in the order ties are broken (MuJoCo's recommended default first).
INTEGRATORS = ("implicitfast", "RK4", "Euler", "implicit")

#: The ladder of timesteps [s], largest first; the last is the reference's (RK4).
TIMESTEPS = (5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5)

#: Largest relative error of the break-away torque against the reference's.
BREAKAWAY_TOLERANCE = 0.05

#: Largest RMS position error of the held-out trajectory, as a fraction of its span.
TRAJECTORY_TOLERANCE = 0.01

#: Duration of the break-away ramp [s] (to 1.5 times the static friction).
RAMP_SECONDS = 0.5

#: Duration of the held-out multi-sine [s].
MULTISINE_SECONDS = 1.0

#: Break-away: ``|v|`` above this fraction of the reference's velocity at the ramp's end.
BREAKAWAY_VELOCITY = 0.01

#: The joint inertia [kg m^2] simulated when neither the model file nor the caller gives one.
DEFAULT_INERTIA = 0.01

#: The timestep without MuJoCo for a fragment without bristles (frictionloss, damping) [s].
STATIC_DEFAULT = 1e-4


@dataclass(frozen=True)
class StepCell:
    """One integrator at one timestep: the break-away torque [N m] and both errors
    (relative to the reference's break-away and to its position span; ``inf`` when the
    run diverged or never broke away)."""

    integrator: str
    timestep: float
    breakaway: float
    breakaway_error: float
    trajectory_error: float

    @property
    def passed(self) -> bool:
        return (
            self.breakaway_error <= BREAKAWAY_TOLERANCE
            and self.trajectory_error <= TRAJECTORY_TOLERANCE
        )

    def describe(self) -> str:
        """``RK4 at 0.0002 s: break-away 0.8131 N m (-0.08 %), trajectory 0.36 % of the span``."""
        return (
            f"{self.integrator} at {self.timestep:g} s: break-away {self.breakaway:.4g} N m "
            f"(error {_pct(self.breakaway_error)}), held-out trajectory "
            f"{_pct(self.trajectory_error)} of its span"
        )


def _pct(value: float) -> str:
    return f"{100 * value:.3g} %" if math.isfinite(value) else "inf (diverged or no break-away)"


@dataclass(frozen=True)
class StepAdvice:
    """What :func:`check_timestep` measured (or, ``measured`` False, the default).

    Attributes
    ----------
    integrator, timestep : the recommendation (``timestep`` None: no step of the ladder
        passes with any integrator).
    measured : whether MuJoCo measured it; ``why`` says otherwise why not.
    inertia : kg m^2, the joint's inertia the fragment was simulated with.
    reference_breakaway, span : N m and rad, the reference's break-away and position span.
    cells : every integrator at every timestep.
    seconds : the time the check took.
    """

    integrator: str
    timestep: float | None
    measured: bool
    inertia: float
    reference_breakaway: float = math.nan
    span: float = math.nan
    cells: tuple[StepCell, ...] = ()
    seconds: float = 0.0
    why: str = ""
    inertia_from: str = "given"
    static_level: float = math.nan
    bristles: bool = False

    def best(self, integrator: str) -> StepCell | None:
        """The recommended cell of ``integrator``: the largest timestep that passes with the
        next finer one of the ladder passing too (the finest alone), or None."""
        row = sorted(
            (c for c in self.cells if c.integrator == integrator), key=lambda c: -c.timestep
        )
        for i, c in enumerate(row):
            finer = row[i + 1].passed if i + 1 < len(row) else c.timestep == TIMESTEPS[-1]
            if c.passed and finer:
                return c
        return None

    def lines(self) -> list[str]:
        """Lines for the exported comment and the CLI."""
        tol = (
            f"break-away within {100 * BREAKAWAY_TOLERANCE:g} % and a held-out trajectory "
            f"within {100 * TRAJECTORY_TOLERANCE:g} % of its span"
        )
        if not self.measured:
            return [
                f"integrator: MuJoCo not measured ({self.why}); conservative default "
                f'<option integrator="{self.integrator}" timestep="{self.timestep!r}"/> '
                f"(joint inertia {self.inertia:.4g} kg m^2, {self.inertia_from}), not "
                f"checked against {tol}"
            ]
        head = (
            f"integrator and timestep measured in MuJoCo ({self.seconds:.2g} s; joint inertia "
            f"{self.inertia:.4g} kg m^2 ({self.inertia_from}), no gravity; reference RK4 at "
            f"{TIMESTEPS[-1]:g} s, "
            f"break-away {self.reference_breakaway:.4g} N m, span {self.span:.4g} rad): the "
            f"largest timestep of {', '.join(f'{t:g}' for t in TIMESTEPS)} s keeping {tol} "
            "(both against the reference)"
        )
        lines = [head]
        off = self.reference_breakaway / self.static_level - 1.0
        if math.isfinite(off) and abs(off) > BREAKAWAY_TOLERANCE:
            level = (
                "the exported LuGre's break-away torque max(tau_c, tau_s)"
                if self.bristles
                else "the exported frictionloss (the model's Coulomb level, as MuJoCo takes it)"
            )
            lines.append(
                f"MuJoCo itself (the reference) breaks away at {self.reference_breakaway:.4g} "
                f"N m, {100 * off:+.3g} % off {level} "
                f"{self.static_level:.4g} N m, at any timestep"
                + (
                    ": frictionloss is a soft constraint that creeps below it; a stiffer "
                    "solimpfriction holds it closer"
                    if self.static_level > 0 and not self.bristles
                    else ""
                )
            )
        if self.timestep is None:
            lines.append(
                f"no timestep down to {TIMESTEPS[-1]:g} s meets this with any integrator; "
                "use a smaller one and check it"
            )
            return lines
        chosen = self.best(self.integrator)
        lines.append(
            f'recommended: <option integrator="{self.integrator}" timestep='
            f'"{self.timestep!r}"/>: {chosen.describe() if chosen else ""}'
        )
        others = []
        for integ in INTEGRATORS:
            if integ == self.integrator:
                continue
            cell = self.best(integ)
            others.append(f"{integ} {cell.timestep:g} s" if cell else f"{integ} none")
        lines.append("largest passing timestep of the others: " + ", ".join(others))
        return lines


def _lugre_attr(root: ET.Element) -> list[float] | None:
    for act in root.findall("actuator"):
        for el in act:
            if el.tag == "dcmotor" and el.get("lugre"):
                return [float(x) for x in el.get("lugre").split()]
    return None


def _parsed(fragment: str) -> ET.Element:
    try:
        return ET.fromstring(f"<fragment>{fragment}</fragment>")
    except ET.ParseError as exc:
        raise ConfigError(f"the MJCF fragment does not parse: {exc}") from None


def static_friction(fragment: str) -> float:
    """The fragment's largest static friction [N m]: a ``dcmotor``'s LuGre ``max(tau_c,
    tau_s)``, else the joint's ``frictionloss`` (0 without)."""
    root = _parsed(fragment)
    lug = _lugre_attr(root)
    if lug is not None:
        return max(lug[2], lug[3])
    joint = root.find("joint")
    return float(joint.get("frictionloss", 0.0)) if joint is not None else 0.0


def multisine(t: np.ndarray, level: float) -> np.ndarray:
    """The held-out torque [N m]: peak about ``1.2 level``, at 1, 2.7 and 5.3 Hz."""
    s = (
        np.sin(2 * np.pi * t)
        + 0.4 * np.sin(2 * np.pi * 2.7 * t + 1.0)
        + 0.25 * np.sin(2 * np.pi * 5.3 * t + 2.0)
    )
    return 1.2 * level * s / 1.3


def default_timestep(fragment: str, inertia: float, why: str) -> StepAdvice:
    """The conservative default without MuJoCo (module docstring), not measured."""
    lug = _lugre_attr(_parsed(fragment))
    limit = STATIC_DEFAULT if lug is None else 0.05 * math.sqrt(inertia / lug[0])
    below = [t for t in TIMESTEPS if t <= limit]
    step = below[0] if below else limit
    return StepAdvice("implicitfast", step, False, inertia, why=why)


def _runner(fragment: str, inertia: float):
    """``run(integrator, dt, torque(t), seconds) -> (t, q, v)`` through ``mujoco.rollout``."""
    mujoco = require_mujoco()
    from mujoco import rollout

    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS

    def run(integrator: str, dt: float, torque, seconds: float):
        model = mujoco.MjModel.from_xml_string(
            one_joint_xml(fragment, inertia, dt, integrator=integrator)
        )
        data = mujoco.MjData(model)
        state0 = np.empty(mujoco.mj_stateSize(model, spec))
        mujoco.mj_getState(model, data, state0, spec)
        t = np.arange(round(seconds / dt)) * dt
        states, _ = rollout.rollout(model, data, state0, torque(t).reshape(1, -1, 1))
        # row i: the state after step i; sample i holds the state before torque[i] acts
        q = np.concatenate([[0.0], states[0, :-1, 1]])
        v = np.concatenate([[0.0], states[0, :-1, 2]])
        return t, q, v

    return run


def _breakaway(u: np.ndarray, v: np.ndarray, threshold: float) -> float:
    k = np.flatnonzero(~(np.abs(v) <= threshold))  # NaN counts as broken away
    return float(u[k[0]]) if k.size and np.isfinite(v[k[0]]) else math.nan


def check_timestep(fragment: str, inertia: float, *, every_step: bool = False) -> StepAdvice:
    """Measure every integrator at every timestep of the ladder in MuJoCo (module docstring).

    Parameters
    ----------
    fragment : the text :func:`fricid.export.mjcf_text` wrote.
    inertia : kg m^2, the joint's inertia about its axis.
    every_step : run every timestep of the ladder (for a table) instead of stopping at two
        passing steps in a row; the recommendation is the same.

    Returns
    -------
    StepAdvice
        The recommendation and every cell. Raises :class:`ConfigError` without MuJoCo
        (:func:`default_timestep` is the fallback) or when the reference itself diverges.
    """
    mujoco = require_mujoco()
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)  # diverging steps are measured, not shown
    try:
        return _check(fragment, inertia, every_step)
    finally:
        mujoco.set_mju_user_warning(previous)


def _check(fragment: str, inertia: float, every_step: bool) -> StepAdvice:
    start = time.perf_counter()
    run = _runner(fragment, inertia)
    static_level = static_friction(fragment)
    level = static_level if static_level > 0 else 1.0  # no dry friction: the ramp's scale

    def ramp(t):
        return 1.5 * level * t / RAMP_SECONDS

    def held_out(t):
        return multisine(t, level)

    dt_ref = TIMESTEPS[-1]
    t_r, _, v_r = run("RK4", dt_ref, ramp, RAMP_SECONDS)
    t_m, q_m, _ = run("RK4", dt_ref, held_out, MULTISINE_SECONDS)
    threshold = BREAKAWAY_VELOCITY * abs(v_r[-1])
    ref_b = _breakaway(ramp(t_r), v_r, threshold)
    span = float(np.ptp(q_m))
    if not (np.all(np.isfinite(q_m)) and math.isfinite(ref_b) and span > 0):
        raise ConfigError(
            f"the MuJoCo reference (RK4 at {dt_ref:g} s) diverged or never broke away"
        )

    def cell(integrator: str, dt: float) -> StepCell:
        if integrator == "RK4" and dt == dt_ref:  # the reference itself
            return StepCell(integrator, dt, ref_b, 0.0, 0.0)
        t, _, v = run(integrator, dt, ramp, RAMP_SECONDS)
        b = _breakaway(ramp(t), v, threshold)
        t, q, _ = run(integrator, dt, held_out, MULTISINE_SECONDS)
        err = math.inf
        if np.all(np.isfinite(q)):
            err = float(np.sqrt(np.mean((q - np.interp(t, t_m, q_m)) ** 2)) / span)
        b_err = abs(b / ref_b - 1.0) if math.isfinite(b) else math.inf
        return StepCell(integrator, dt, b, b_err, err)

    cells = []
    for integrator in INTEGRATORS:  # coarse to fine, until two steps in a row pass
        row: list[StepCell] = []
        for dt in TIMESTEPS:
            row.append(cell(integrator, dt))
            if not every_step and len(row) >= 2 and row[-1].passed and row[-2].passed:
                break
        cells.extend(row)
    advice = StepAdvice("implicitfast", None, True, inertia, ref_b, span, tuple(cells))
    best = [(advice.best(i), i) for i in INTEGRATORS]
    passing = [(c.timestep, -INTEGRATORS.index(i), i) for c, i in best if c is not None]
    integrator, timestep = "implicitfast", None
    if passing:
        timestep, _, integrator = max(passing)
    return StepAdvice(
        integrator,
        timestep,
        True,
        inertia,
        ref_b,
        span,
        tuple(cells),
        seconds=time.perf_counter() - start,
        static_level=static_level,
        bristles=_lugre_attr(_parsed(fragment)) is not None,
    )


def model_inertia(fitted, inertia: float | None = None) -> tuple[float, str]:
    """The joint inertia to simulate [kg m^2] and where it comes from: ``inertia`` when
    given, else the one a trajectory fit identified (``provenance["trajectory"]["joint"]``),
    else :data:`DEFAULT_INERTIA`."""
    if inertia is not None:
        if not (math.isfinite(inertia) and inertia > 0):
            raise ConfigError(f"the joint inertia must be > 0, got {inertia!r}")
        return float(inertia), "given"
    row = (fitted.provenance or {}).get("trajectory", {}).get("joint", {}).get("inertia", {})
    value = row.get("value") if isinstance(row, dict) else None
    if isinstance(value, int | float) and math.isfinite(value) and value > 0:
        return float(value), "identified with the model"
    return DEFAULT_INERTIA, "a default: the joint's own was not given"


def timestep_advice(fragment: str, inertia: float, inertia_from: str = "given") -> StepAdvice:
    """:func:`check_timestep` when MuJoCo is installed, else :func:`default_timestep`."""
    from dataclasses import replace

    try:
        import mujoco  # noqa: F401
    except ImportError:
        advice = default_timestep(fragment, inertia, "MuJoCo is not installed")
    else:
        advice = check_timestep(fragment, inertia)
    return replace(advice, inertia_from=inertia_from)
