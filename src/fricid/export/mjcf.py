"""MuJoCo specifics of the MJCF export: how ``frictionloss`` behaves, and LuGre friction in
MuJoCo's ``dcmotor`` actuator.

Static models
    MuJoCo holds static friction as the joint's ``frictionloss`` [N m] (dry friction) and
    ``damping`` [N m s/rad] (viscous), so a static model gets the Coulomb-viscous projection
    of :mod:`fricid.export.projection` (:func:`fricid.export.mjcf_text`). MuJoCo's
    documentation (Computation, "Friction loss") models ``frictionloss`` as a constraint, an
    upper limit on the friction force, solved like the others with the softness of the
    joint's ``solreffriction``/``solimpfriction`` (default ``solref`` 0.02 s): a torque below
    ``frictionloss`` does not hold the joint exactly still but lets it creep, and the
    constraint reacts over about the ``solref`` time constant. :data:`FRICTIONLOSS_LINES` say
    so in the exported comment; ``benchmarks/bench_mujoco.py`` measures what it costs against
    a stick-slip (Karnopp) joint, with the default and a stiffer ``solreffriction``. Its run
    with mujoco 4.0.0 (Coulomb 0.3 N m, viscous 0.1 N m s/rad, J 0.01 kg m^2, 2 s of a
    0.6 N m sine torque, 1 ms steps): RMS position error 0.45 % of the span with the default
    ``solref``, 0.05 % with ``solreffriction="0.002 1"`` (the Python joint's own at 1 ms:
    0.09 %); at 0.1 ms steps 0.52 % and 0.007 %.
LuGre (dynamic) models
    MuJoCo 4.0 added the ``dcmotor`` actuator (XML reference, actuator/dcmotor) with optional
    LuGre friction: ``lugre="stiffness damping coulomb static stribeck"`` = sigma_0 [N m/rad],
    sigma_1 [N m s/rad], tau_c [N m], tau_s [N m], w_s [rad/s], with sigma_2 in the standard
    ``damping`` attribute; ``input="none"`` makes it a passive device, and ``motorconst="0 0"``
    disables its electrical branch (``resistance`` must still be positive). Its Stribeck curve
    has no exponent: fricid's check (``tests/export/test_mujoco.py``, mujoco 4.0.0) finds the
    bristle
    state at constant velocity settling to ``g(v) / sigma_0`` with
    ``g(v) = tau_c + (tau_s - tau_c) exp(-(v / w_s)^2)``, the exponent delta = 2
    (:data:`MUJOCO_STRIBECK_EXPONENT`). A model with another delta gets the ``w_s`` whose
    delta = 2 curve is closest to its steady-state friction over the operating range (least
    squares), and the export states that error. Older MuJoCo has no ``dcmotor``: the comment
    also gives the static projection (``frictionloss``/``damping``) with its error.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel
from ..models import lugre
from ._common import ExportError, fmt_float, plain, summary_lines
from .projection import _nnls, operating_grid, rests_on

__all__ = [
    "FRICTIONLOSS_LINES",
    "MUJOCO_STRIBECK_EXPONENT",
    "STIFF_SOLIMP",
    "LuGreMapping",
    "frictionloss_lines",
    "is_lugre",
    "lugre_mapping",
    "mjcf_lugre_elements",
]

#: The exponent of MuJoCo's LuGre Stribeck curve (module docstring; mujoco 4.0.0).
MUJOCO_STRIBECK_EXPONENT = 2.0

#: The ``solimpfriction`` a static MJCF export writes on its joint: the friction constraint's
#: impedance 0.99-0.999 instead of MuJoCo's default 0.9-0.95, under which the joint creeps
#: below ``frictionloss`` and breaks away far under it (the lead screw's model,
#: ``benchmarks/results/mujoco_static.txt``: at 0.44 of it with the default, 1.04 with this,
#: where a joint that sticks exactly reads 1.05 by the check's own ramp).
STIFF_SOLIMP = "0.99 0.999 0.001"

#: How MuJoCo applies the exported static friction, for the comment of a static MJCF export.
FRICTIONLOSS_LINES = (
    "MuJoCo applies frictionloss as a soft constraint (solreffriction, solimpfriction): under "
    "any torque the joint creeps; with MuJoCo's default solimpfriction (0.9 0.95) a slow "
    "torque ramp sets it sliding well below frictionloss, with this joint's "
    f'solimpfriction="{STIFF_SOLIMP}" it creeps far less and slides at frictionloss: keep it',
    "MuJoCo >= 4.0 also has LuGre friction (dcmotor actuator, lugre attribute): a dynamic "
    "model (fricid's lugre) exports to it; this static model has no bristle dynamics",
)


def frictionloss_lines(fitted: FittedModel) -> tuple[str, ...]:
    """:data:`FRICTIONLOSS_LINES` for ``fitted``; a Dahl or per-direction LuGre model's second
    line says that its bristle dynamics are what the steady-state projection leaves out (it
    is not static)."""
    if isinstance(fitted.model, str) and fitted.model.strip().lower() == "dahl":
        return (
            FRICTIONLOSS_LINES[0],
            "this is the steady state of a Dahl model (dynamic): its bristle stiffness sigma_0 "
            "(pre-sliding, the lag after each reversal) is not exported, frictionloss has none; "
            "MuJoCo >= 4.0's LuGre (dcmotor actuator) carries it for a lugre model",
        )
    if isinstance(fitted.model, str) and fitted.model.strip().lower() == "lugre_asym":
        return (
            FRICTIONLOSS_LINES[0],
            "this is the steady state of a LuGre model with its levels per direction "
            "(dynamic): its bristles (sigma_0, sigma_1: pre-sliding, the lag after each "
            "reversal) are not exported, frictionloss has none; MuJoCo >= 4.0's LuGre "
            "(dcmotor actuator) has one level for both directions and carries them for a "
            "lugre model",
        )
    return FRICTIONLOSS_LINES


def is_lugre(fitted: FittedModel) -> bool:
    """Whether ``fitted`` is a LuGre model (by name; its parameters are checked on export)."""
    return isinstance(fitted.model, str) and fitted.model.strip().lower() == "lugre"


@dataclass(frozen=True)
class LuGreMapping:
    """A LuGre model in MuJoCo's terms, and what the mapping and a static projection lose.

    Attributes
    ----------
    theta : the model's 7 parameters (:data:`fricid.models.lugre.PARAM_NAMES`).
    w_s : rad/s, the Stribeck velocity for MuJoCo's exponent (``theta``'s own when delta = 2).
    rms_error, max_error, max_at : N m, N m, rad/s: steady-state friction of the mapped model
        against the model's over the velocity grid (0 when delta = 2).
    rms_friction : N m, RMS steady-state friction over the grid.
    static : ``(frictionloss, damping)``, the Coulomb-viscous projection of the steady state.
    static_rms_error, static_max_error : N m, that projection's error over the grid (the
        bristle dynamics are lost on top of it).
    static_rests_on : lines on the undetermined parameters that projection rests on
        (:func:`fricid.export.projection.rests_on`).
    speed : the ``|v|`` range of the grid [rad/s].
    """

    theta: tuple[float, ...]
    w_s: float
    rms_error: float
    max_error: float
    max_at: float
    rms_friction: float
    static: tuple[float, float]
    static_rms_error: float
    static_max_error: float
    speed: tuple[float, float]
    static_rests_on: tuple[str, ...] = ()

    @property
    def relative_error(self) -> float:
        return self.rms_error / self.rms_friction if self.rms_friction > 0 else 0.0

    def summary(self) -> list[str]:
        """Lines for the exported comment."""
        s0, s1, s2, tau_c, tau_s, w_s, delta = self.theta
        lo, hi = self.speed
        lines = [
            f"LuGre model: sigma_0 {s0:.6g} N m/rad, sigma_1 {s1:.6g} N m s/rad, sigma_2 "
            f"{s2:.6g} N m s/rad, tau_c {tau_c:.6g} N m, tau_s {tau_s:.6g} N m, w_s {w_s:.6g} "
            f"rad/s, delta {delta:.6g}",
            "MuJoCo >= 4.0 dcmotor actuator without a control input (input none, motorconst "
            "0 0: no electrical branch; resistance 1 is required and unused): lugre = sigma_0 "
            "sigma_1 tau_c tau_s w_s; sigma_2 is the joint's damping",
            _passivity_line(self.theta),
        ]
        if delta == MUJOCO_STRIBECK_EXPONENT:
            lines.append("MuJoCo's Stribeck exponent is 2, as this model's: the mapping is exact")
        else:
            lines.append(
                f"MuJoCo's Stribeck exponent is 2, this model's {delta:.6g}: w_s refit to "
                f"{self.w_s:.6g} rad/s (least squares over |velocity| {lo:.4g} to {hi:.4g} "
                f"rad/s); steady-state error RMS {self.rms_error:.4g} N m "
                f"({100 * self.relative_error:.3g} % of the RMS friction "
                f"{self.rms_friction:.4g} N m), max {self.max_error:.4g} N m at "
                f"{self.max_at:.4g} rad/s"
            )
        fl, damping = self.static
        lines.append(
            f'without dcmotor (MuJoCo < 4.0): <joint frictionloss="{fmt_float(fl)}" '
            f'damping="{fmt_float(damping)}"/>, the least-squares Coulomb-viscous projection '
            f"of the steady state: error RMS {self.static_rms_error:.4g} N m, max "
            f"{self.static_max_error:.4g} N m, and the bristle dynamics (pre-sliding, "
            "break-away, hysteresis) are lost"
        )
        return lines + list(self.static_rests_on)


def _passivity_line(theta: np.ndarray) -> str:
    """Whether the LuGre model is passive (Barabanov and Ortega 2000: ``sigma_1 <= 4 sigma_2
    tau_c / (tau_s - tau_c)``): a model that is not can feed energy into the simulation."""
    margin = float(lugre.passivity_margin(theta))
    if margin == math.inf:
        return "the LuGre model is passive for any sigma_1 (tau_s <= tau_c)"
    if margin >= 0:
        return f"the LuGre model is passive (margin {margin:.3g} N m s/rad)"
    return (
        f"the LuGre model is NOT passive (margin {margin:.3g} N m s/rad: sigma_1 above 4 "
        "sigma_2 tau_c / (tau_s - tau_c)): its friction can feed energy into the simulation"
    )


def _params(fitted: FittedModel) -> np.ndarray:
    try:
        theta = np.array([float(fitted.params[k]) for k in lugre.PARAM_NAMES])
    except (KeyError, TypeError, ValueError) as exc:
        raise ExportError(
            f"a LuGre model needs the parameters {', '.join(lugre.PARAM_NAMES)}: {exc}"
        ) from None
    margin = lugre.passivity_margin(theta)
    if not np.all(np.isfinite(theta)) or margin == -np.inf:
        raise ExportError(
            "LuGre parameters must be finite, sigma_0, tau_c, w_s > 0 and sigma_1, sigma_2 >= 0"
        )
    return theta


def lugre_mapping(fitted: FittedModel, velocity_range=None) -> LuGreMapping:
    """Map a fitted LuGre model to MuJoCo's (module docstring).

    ``velocity_range`` overrides the model's operating range (as for
    :func:`fricid.export.project`); load and temperature do not enter LuGre friction.
    """
    theta = _params(fitted)
    X, info = operating_grid(fitted, velocity_range, 0.0, 25.0)
    v = X[:, 0]
    F = lugre.steady_state(theta, v)

    def mapped(w_s: float) -> np.ndarray:
        th = theta.copy()
        th[5], th[6] = w_s, MUJOCO_STRIBECK_EXPONENT
        return lugre.steady_state(th, v)

    w_s = float(theta[5])
    if theta[6] != MUJOCO_STRIBECK_EXPONENT:
        from scipy.optimize import minimize_scalar  # here: `fricid --help` starts without it

        res = minimize_scalar(
            lambda lw: float(np.mean((mapped(math.exp(lw)) - F) ** 2)),
            bounds=(math.log(w_s) - 6.0, math.log(w_s) + 6.0),
            method="bounded",
            options={"xatol": 1e-8},
        )
        w_s = float(math.exp(res.x))
    resid = mapped(w_s) - F
    k = int(np.argmax(np.abs(resid)))
    A = np.column_stack([np.sign(v), v])
    static = _nnls(A, F)
    static_resid = A @ static - F
    return LuGreMapping(
        theta=tuple(theta.tolist()),
        w_s=w_s,
        rms_error=float(np.sqrt(np.mean(resid**2))),
        max_error=float(abs(resid[k])),
        max_at=float(v[k]),
        rms_friction=float(np.sqrt(np.mean(F**2))),
        static=(float(static[0]), float(static[1])),
        static_rms_error=float(np.sqrt(np.mean(static_resid**2))),
        static_max_error=float(np.abs(static_resid).max()),
        speed=info["speed"],
        static_rests_on=tuple(rests_on(fitted, X, False)),
    )


def _summary(
    fitted: FittedModel, source: str | None, sha256: str | None, rms_error: float
) -> list[str]:
    """:func:`summary_lines`, its trust line saying when the mapping onto MuJoCo's LuGre
    (``rms_error`` [N m] from the model's steady state) misses the model beyond its scatter."""
    try:
        return summary_lines(
            fitted,
            source,
            sha256,
            projection_rms=rms_error,
            projection="mapping onto MuJoCo's LuGre",
        )
    except ConfigError:  # 'lugre' not in this build's model registry: the fixed lines only
        lines = ["fricid export of a LuGre model ('lugre')"]
        if sha256 is not None:
            lines.append(f"model file sha256 {plain(sha256)}")
        if source:
            lines.append(f"file name {plain(source)}")
        return lines


def mjcf_lugre_elements(
    fitted: FittedModel,
    name: str,
    *,
    max_loss: float,
    source: str | None = None,
    sha256: str | None = None,
    velocity_range=None,
) -> tuple[list[str], list[ET.Element]]:
    """The comment lines and the elements (``<joint>``, ``<actuator>``) of a LuGre export.

    ``name`` is the checked joint name. Refused (:class:`ExportError`) when the refit of
    ``w_s`` misses the model's steady state by more than ``max_loss`` (RMS, relative).
    """
    mapping = lugre_mapping(fitted, velocity_range)
    if not mapping.relative_error <= max_loss:
        raise ExportError(
            f"MuJoCo's LuGre (Stribeck exponent 2) cannot represent this model's exponent "
            f"{mapping.theta[6]:.4g} within the tolerance: the closest w_s misses its steady "
            f"state by {100 * mapping.relative_error:.3g} % RMS (tolerance {100 * max_loss:.3g} "
            "%); raise the tolerance (--max-loss) to write it anyway"
        )
    s0, s1, s2, tau_c, tau_s = mapping.theta[:5]
    lines = [
        *_summary(fitted, source, sha256, mapping.rms_error),
        *mapping.summary(),
        f"copy damping onto your <joint> {plain(name)} and the dcmotor into <actuator>",
    ]
    joint = ET.Element("joint", {"name": name, "damping": fmt_float(s2, "sigma_2")})
    actuator = ET.Element("actuator")
    lugre_attr = " ".join(
        fmt_float(x, key)
        for x, key in zip(
            (s0, s1, tau_c, tau_s, mapping.w_s),
            ("sigma_0", "sigma_1", "tau_c", "tau_s", "w_s"),
            strict=True,
        )
    )
    ET.SubElement(
        actuator,
        "dcmotor",
        {
            "name": f"{name}_lugre",
            "joint": name,
            "input": "none",
            "motorconst": "0 0",
            "resistance": "1",
            "lugre": lugre_attr,
        },
    )
    return lines, [joint, actuator]
