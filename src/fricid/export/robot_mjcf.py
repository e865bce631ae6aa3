"""A whole arm as an MJCF model: its rigid-body dynamics and each joint's friction, for MuJoCo.

:func:`robot_mjcf_text` writes the kinematic tree of a :class:`~fricid.robot.RigidBodyModel`
as nested ``<body>`` elements, one per identified joint, each at the joint's placement in its
parent's frame, with the joint (``hinge`` or ``slide``, its axis, its range where the URDF
gives one), the body's inertial parameters (the model's, locked and fixed links merged:
``<inertial pos mass fullinertia>`` about the centre of mass), and a ``<motor>`` actuator of
gear 1 per joint (named ``<joint>_motor``) that applies a torque. No geometry is written: the
model is for dynamics, not for looking at or for contacts (``contype``/``conaffinity`` 0).
Angles are in radians (``<compiler angle="radian"/>``) and gravity is the model's.

Friction goes to MuJoCo's joint ``frictionloss`` [N m] (dry friction, a soft constraint: see
:data:`fricid.export.mjcf.FRICTIONLOSS_LINES`) and ``damping`` [N m s/rad] (viscous), with
``solreffriction`` at two timesteps on every joint (:data:`SOLREF_LINES`): with MuJoCo's default
time constant of 0.02 s a light joint's friction stays far below its ``frictionloss`` while it
slides, the constraint's force being the joint's inertia times the velocity over the time
constant until it reaches the level. Measured with mujoco 4.0.0 (``mj_forward`` on the
exported Panda at the middle of its ranges, one joint moving): joint 7 (frictionloss 0.559
N m) held 0.004, 0.042 and 0.174 N m at 0.1, 0.3 and 1 rad/s with the default, and 0.157,
0.555 and 0.559 N m at 0.03, 0.1 and 0.3 rad/s with the 2 ms written at the file's 1 ms
timestep (0.559 from 0.03 rad/s at 0.125 ms); joint 1 (0.682 N m) its level from 0.1 rad/s
with the default, from 0.01 with the 2 ms. Every joint also gets the static export's stiffer
``solimpfriction`` (:data:`fricid.export.mjcf.STIFF_SOLIMP`): under a slow torque ramp to 1.5
times a frictionloss of 0.6 N m (gravity off, the arm at rest mid-range, the break-away test of
:mod:`fricid.export.mujoco_step`), the Panda's joints 1, 4 and 7 set sliding at 0.13, 0.55 and
1.01 of it with MuJoCo's default (0.9 0.95), at 1.008, 1.044 and 1.029 with the stiffer one.
``tests/export/test_robot_mjcf.py`` checks both.
MuJoCo cannot hold the rest of fricid's laws: a Stribeck rise (``tau_s`` above ``tau_c``) and
different levels per direction are lost (the mean of the two directions is written); each
loss is one of the returned notes and a line of the file's comment. Data never becomes code
(:mod:`fricid.export._common`): numbers through :func:`fmt_float`, joint names checked
against a strict pattern, text in comments through :func:`plain`; the XML is built by
:mod:`xml.etree.ElementTree`, and the file is written atomically.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..fitted import FittedModel
from ..robot import RigidBodyModel
from ..robot._pin import pinocchio
from ..sim.robot_friction import ArmFriction
from ._common import ExportError, fmt_float, plain
from .descriptions import _check_joint, _xml, write_text
from .mjcf import STIFF_SOLIMP
from .projection import project

#: The exported comment's lines on ``solreffriction`` and ``solimpfriction`` (module notes).
SOLREF_LINES = (
    "solreffriction = 2 timesteps on every joint (the stiffest MuJoCo allows by default): "
    "with the default 0.02 s a light joint's friction stays far below frictionloss while it "
    "slides; keep it at 2 timesteps if you change the timestep",
    f'solimpfriction = "{STIFF_SOLIMP}" on every joint: MuJoCo applies frictionloss as a soft '
    "constraint under which a joint creeps; with the default (0.9 0.95) a heavy joint set "
    "sliding by a slow torque ramp well below frictionloss, with this one at it: keep it",
)

__all__ = ["joint_friction", "robot_mjcf_text", "write_robot_mjcf"]

#: Mass [kg] and principal inertia [kg m^2] given to a moving body that has none (MuJoCo
#: refuses massless moving bodies); a note says so.
MIN_MASS, MIN_INERTIA = 1e-6, 1e-9


def _levels(params: Mapping[str, float], key: str) -> list[float]:
    vals = [params[k] for k in (key, f"{key}_pos", f"{key}_neg") if k in params]
    return [float(v) for v in vals]


def _differ(levels: list[float]) -> bool:
    """The two directions' levels differ beyond rounding (a projection's last digits)."""
    return bool(levels) and max(levels) - min(levels) > 1e-9 * max(map(abs, levels))


def joint_friction(joint: str, params: Mapping[str, float]) -> tuple[float, float, list[str]]:
    """``(frictionloss, damping, notes)`` of one joint's friction parameters.

    ``params`` in fricid's names: ``tau_c``, ``tau_v`` (and ``tau_s``, ``w_s``, ``delta``),
    or their ``_pos``/``_neg`` pairs (``stribeck_asym``), the Coulomb-viscous families'
    ``f_c``, ``beta`` (and pairs), or a LuGre law's (``sigma_2`` the viscous coefficient). The
    two directions are averaged.
    """
    coulomb = _levels(params, "tau_c") or _levels(params, "f_c")  # coulomb_viscous: f_c, beta
    viscous = _levels(params, "tau_v") or _levels(params, "beta")
    notes = []
    if "sigma_0" in params:  # LuGre: sigma_2 is its viscous coefficient
        viscous = viscous or _levels(params, "sigma_2")
        notes.append(
            f"joint {plain(joint)}: LuGre friction; its bristle dynamics (pre-sliding, "
            "hysteresis) are lost here (MuJoCo 4's dcmotor lugre could hold them)"
        )
    if not coulomb and not viscous:
        raise ExportError(
            f"joint {plain(joint)}: no tau_c/f_c or tau_v/beta among {sorted(params)}"
        )
    if _differ(coulomb) or _differ(viscous):
        notes.append(
            f"joint {plain(joint)}: Coulomb {', '.join(f'{c:.4g}' for c in coulomb)} N m and "
            f"viscous {', '.join(f'{v:.4g}' for v in viscous)} N m s/rad differ by direction; "
            "MuJoCo has one level, the mean is written"
        )
    static = _levels(params, "tau_s")
    for suffix in ("", "_pos", "_neg"):
        s, c = params.get(f"tau_s{suffix}"), params.get(f"tau_c{suffix}")
        if s is not None and c is not None and float(s) != float(c):
            levels = ", ".join(f"{x:.4g}" for x in static)
            notes.append(
                f"joint {plain(joint)}: Stribeck friction (static {levels} N m above Coulomb at "
                "low speed) is lost: MuJoCo's frictionloss is one level"
            )
            break
    fl = float(np.mean(coulomb)) if coulomb else 0.0
    damping = float(np.mean(viscous)) if viscous else 0.0
    return fl, damping, notes


def _frictions(model: RigidBodyModel, friction: Any) -> dict[str, dict[str, float]]:
    if friction is None:
        return {}
    if isinstance(friction, ArmFriction):
        if friction.n != model.n:
            raise ExportError(f"the friction law has {friction.n} joints, the model {model.n}")
        return {j: friction.parameters(i) for i, j in enumerate(model.joints)}
    if isinstance(friction, Mapping):
        unknown = [j for j in friction if j not in model.joints]
        if unknown:
            raise ExportError(f"friction for joints not in the model: {plain(unknown)}")
        return {j: _as_parameters(j, p) for j, p in friction.items()}
    raise ExportError("friction must be an ArmFriction or a mapping joint -> parameters")


def _as_parameters(joint: str, friction: Any) -> dict[str, float]:
    """A joint's parameters; a :class:`~fricid.fitted.FittedModel` by the Coulomb-viscous
    projection over its operating range, per direction (:func:`fricid.export.project`), as
    every other export that holds Coulomb plus viscous friction."""
    if not isinstance(friction, FittedModel):
        return dict(friction)
    proj = project(friction, True)
    out = {}
    for side, key in (("pos", "positive"), ("neg", "negative")):
        out[f"tau_c_{side}"] = float(proj.coulomb[key])
        out[f"tau_v_{side}"] = float(proj.viscous[key])
    return out


def _quat(rotation: np.ndarray) -> np.ndarray:
    pin = pinocchio()
    q = pin.Quaternion(rotation)
    return np.array([q.w, q.x, q.y, q.z])


def _inertial(inertia: Any, joint: str, notes: list[str]) -> dict[str, str]:
    mass = float(inertia.mass)
    com = np.asarray(inertia.lever, dtype=float)
    rot = np.asarray(inertia.inertia, dtype=float)
    if mass <= 0:
        notes.append(
            f"joint {plain(joint)}: its body has no mass; MuJoCo needs one: {MIN_MASS:g} kg "
            f"and {MIN_INERTIA:g} kg m^2 written"
        )
        mass, rot = MIN_MASS, np.eye(3) * MIN_INERTIA
    principal = np.linalg.eigvalsh(0.5 * (rot + rot.T))
    tol = 1e-12 * max(principal.max(), 1e-12)
    if principal.min() < -tol or principal[0] + principal[1] < principal[2] - tol:
        raise ExportError(
            f"joint {plain(joint)}: its body's inertia about the centre of mass (principal "
            f"{', '.join(f'{x:.4g}' for x in principal)} kg m^2) is not physical (positive, "
            "A + B >= C): MuJoCo refuses it"
        )
    full = (rot[0, 0], rot[1, 1], rot[2, 2], rot[0, 1], rot[0, 2], rot[1, 2])
    return {
        "pos": " ".join(fmt_float(x, "com") for x in com),
        "mass": fmt_float(mass, "mass"),
        "fullinertia": " ".join(fmt_float(x, "inertia") for x in full),
    }


def _joint_attributes(
    model: RigidBodyModel,
    i: int,
    axis: np.ndarray,
    friction: Mapping[str, float] | None,
    timestep: float,
) -> tuple[dict[str, str], list[str]]:
    name = model.joints[i]
    attrs = {
        "name": name,
        "type": "slide" if model.kinds[i] == "prismatic" else "hinge",
        "axis": " ".join(fmt_float(x, "axis") for x in axis),
    }
    lo, hi = float(model.lower[i]), float(model.upper[i])
    if np.isfinite(lo) and np.isfinite(hi) and lo < hi:
        attrs["range"] = f"{fmt_float(lo, 'lower')} {fmt_float(hi, 'upper')}"
        attrs["limited"] = "true"
    notes: list[str] = []
    if friction is not None:
        fl, damping, notes = joint_friction(name, friction)
        attrs["frictionloss"] = fmt_float(fl, "frictionloss")
        attrs["damping"] = fmt_float(damping, "damping")
        attrs["solreffriction"] = f"{fmt_float(2 * timestep, 'timestep')} 1"
        attrs["solimpfriction"] = STIFF_SOLIMP
    return attrs, notes


def robot_mjcf_text(
    model: RigidBodyModel,
    friction: ArmFriction | Mapping[str, Mapping[str, float]] | None = None,
    *,
    name: str = "fricid_robot",
    timestep: float = 1e-3,
    comments: Sequence[str] = (),
) -> tuple[str, list[str]]:
    """The MJCF text of ``model`` with ``friction``, and the notes on what MuJoCo cannot hold.

    Parameters
    ----------
    model : RigidBodyModel
        The arm; its inertial parameters are written (``model.with_parameters`` for others).
    friction : ArmFriction or mapping, optional
        Each joint's friction: the simulator's law, or ``joint -> parameters`` in fricid's
        names (:func:`joint_friction`); none: no friction written.
    name : str
        The ``<mujoco model>`` name (checked like a joint name).
    timestep : float
        MuJoCo's ``option/timestep`` [s].
    comments : sequence of str
        More lines for the first comment (each joint's trust verdict,
        :func:`fricid.export._trust.trust_line`; where the inertials come from): fixed words,
        numbers and :func:`~fricid.export._common.plain` text only (checked as the other
        lines are).

    Returns
    -------
    (str, list of str)
        The document and the notes (also in its first comment).

    Raises
    ------
    ExportError
        A joint name that is not a plain name, friction that does not fit the model, a
        non-finite number.
    """
    pm = model._model
    frictions = _frictions(model, friction)
    for joint in model.joints:
        _check_joint(joint)
    notes: list[str] = []
    root = ET.Element("mujoco", {"model": _check_joint(name)})
    ET.SubElement(root, "compiler", {"angle": "radian", "autolimits": "true"})
    gravity = " ".join(fmt_float(x, "gravity") for x in model.gravity)
    ET.SubElement(root, "option", {"timestep": fmt_float(timestep, "timestep"), "gravity": gravity})
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", {"contype": "0", "conaffinity": "0"})
    world = ET.SubElement(root, "worldbody")
    bodies = {0: world}
    actuators = ET.SubElement(root, "actuator")
    for i in range(1, pm.njoints):
        joint = model.joints[i - 1]
        placement = pm.jointPlacements[i]
        body = ET.SubElement(
            bodies[pm.parents[i]],
            "body",
            {
                "name": f"{joint}_body",
                "pos": " ".join(fmt_float(x, "position") for x in placement.translation),
                "quat": " ".join(fmt_float(x, "rotation") for x in _quat(placement.rotation)),
            },
        )
        bodies[i] = body
        ET.SubElement(body, "inertial", _inertial(pm.inertias[i], joint, notes))
        axis = np.asarray(pm.joints[i].extract().axis, dtype=float)
        attrs, joint_notes = _joint_attributes(model, i - 1, axis, frictions.get(joint), timestep)
        notes.extend(joint_notes)
        ET.SubElement(body, "joint", attrs)
        ET.SubElement(actuators, "motor", {"name": f"{joint}_motor", "joint": joint, "gear": "1"})
    lines = [
        f"fricid export of a robot's rigid-body dynamics: {model.n} joints, source "
        f"{plain(os.path.basename(model.source or 'unknown'))}",
        "inertial parameters about each body's centre of mass in its joint frame; no geometry",
        "friction: frictionloss = Coulomb [N m], damping = viscous [N m s/rad]"
        if frictions
        else "no friction written",
        *(SOLREF_LINES if frictions else ()),
        *comments,
        *notes,
    ]
    ET.indent(root)
    return _xml(lines, root), notes


def write_robot_mjcf(
    model: RigidBodyModel,
    path: str | os.PathLike[str],
    friction: ArmFriction | Mapping[str, Mapping[str, float]] | None = None,
    **options: Any,
) -> tuple[Path, list[str]]:
    """Write :func:`robot_mjcf_text` to ``path`` atomically; the path and the notes."""
    text, notes = robot_mjcf_text(model, friction, **options)
    return write_text(text, path), notes
