"""The URDF reader's parsing of links and joints (:func:`fricid.io.urdf.read_urdf`).

Every number read is a plain decimal within a physical range, and bad input is one
:class:`~fricid.errors.DataError` naming the file, the element and the attribute. Beyond what
eq. 7 (BAS-RBFNN paper) needs (masses, centres of mass, origins, axes), a link's inertia tensor
and a joint's ``<limit>`` and ``<mimic>`` are read for the whole arm's rigid-body dynamics
(:mod:`fricid.robot`): an inertia tensor is checked to be physical (symmetric positive
semi-definite, its principal moments obeying the triangle inequality).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import DataError

#: m/s^2, the gravity used unless another is given.
STANDARD_GRAVITY = 9.80665

#: Largest magnitude [m] of a position coordinate (origins, centres of mass) and of an axis
#: component: a kilometre is beyond any robot.
MAX_LENGTH = 1e3

#: Largest magnitude [rad] of an ``rpy`` angle.
MAX_ANGLE = 1e3

#: The masses [kg] a link may have besides 0 (a massless link).
MASS_RANGE = (1e-9, 1e6)

#: Smallest norm of a moving joint's axis (the axis is normalised).
MIN_AXIS_NORM = 1e-6

#: Largest magnitude [kg m^2] of an inertia tensor's element.
MAX_INERTIA = 1e6

#: Largest ``<limit effort>`` [N m or N] and ``<limit velocity>`` [rad/s or m/s] read.
MAX_EFFORT = 1e6
MAX_SPEED = 1e4

#: Relative tolerance of the inertia checks (positive semi-definite, triangle inequality):
#: URDF writers round to 4-6 significant digits.
INERTIA_RTOL = 1e-3

#: A plain decimal number: ASCII digits, optional sign, point and exponent.
_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")

_ROTATING = ("revolute", "continuous")

_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass(frozen=True)
class _Link:
    mass: float
    com: np.ndarray  # centre of mass in the link frame [m]
    # about the centre of mass, in the link frame [kg m^2]
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    note: str | None = None  # why the inertia tensor is not physical, if it is not


@dataclass(frozen=True)
class Limit:
    """A joint's ``<limit>``: positions [rad or m] (infinite when absent or continuous),
    speed [rad/s or m/s] and effort [N m or N] (infinite when absent)."""

    lower: float = -math.inf
    upper: float = math.inf
    velocity: float = math.inf
    effort: float = math.inf


@dataclass(frozen=True)
class _Joint:
    name: str
    kind: str
    parent: str
    child: str
    xyz: np.ndarray
    rot: np.ndarray  # rotation of the origin (3 x 3)
    axis: np.ndarray  # unit vector in the joint frame
    limit: Limit = Limit()
    mimic: str | None = None  # the joint this one copies (<mimic joint=...>)


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw: ``Rz(y) Ry(p) Rx(r)``."""
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


class _Reader:
    """Attribute parsing with errors naming the file, the element and the attribute."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, what: str) -> DataError:
        return DataError(f"{where}: {what}", file=self.source)

    def numbers(
        self, el, attr: str, where: str, count: int, default: str, bound: float
    ) -> np.ndarray:
        """``count`` plain decimal numbers (module notes) of magnitude at most ``bound``."""
        text = el.get(attr, default) if el is not None else default
        parts = text.split()
        shown = f"{attr}='{text[:40]}'"
        if len(parts) != count or not all(_NUMBER.fullmatch(p) for p in parts):
            raise self.fail(where, f"{shown} is not {count} plain decimal numbers")
        values = np.array([float(p) for p in parts], dtype=float)
        if not np.isfinite(values).all():
            raise self.fail(where, f"{shown} overflows a double")
        if (np.abs(values) > bound).any():
            raise self.fail(where, f"{shown} has a magnitude over {bound:g}")
        return values

    def name(self, el, where: str) -> str:
        value = el.get("name")
        if not value:
            raise self.fail(where, "has no name")
        return value

    def link(self, el) -> tuple[str, _Link]:
        name = self.name(el, "a <link>")
        where = f"<link name='{name[:60]}'>"
        inertial = el.find("inertial")
        if inertial is None:
            return name, _Link(0.0, np.zeros(3))
        mass_el = inertial.find("mass")
        if mass_el is None:
            raise self.fail(where, "<inertial> has no <mass>")
        at = f"{where} <inertial><mass>"
        mass = float(self.numbers(mass_el, "value", at, 1, "", math.inf)[0])
        low, high = MASS_RANGE
        if mass != 0 and not low <= mass <= high:
            raise self.fail(
                at, f"value={mass!r} kg is not 0 (massless) nor within [{low:g}, {high:g}] kg"
            )
        origin = inertial.find("origin")
        com = self.numbers(origin, "xyz", f"{where} <inertial><origin>", 3, "0 0 0", MAX_LENGTH)
        rpy = self.numbers(origin, "rpy", f"{where} <inertial><origin>", 3, "0 0 0", MAX_ANGLE)
        inertia, note = self.inertia(inertial.find("inertia"), f"{where} <inertial><inertia>")
        rot = _rpy(*rpy)
        return name, _Link(abs(mass), com, rot @ inertia @ rot.T, note)

    def inertia(self, el, where: str) -> tuple[np.ndarray, str | None]:
        """The tensor of ``<inertia>`` (zero when absent), and why it is not physical (None
        when it is). Many published URDFs carry rounded or placeholder tensors that are not,
        so this is a note for the rigid-body model to report, not an error."""
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        v = {k: self.numbers(el, k, where, 1, "0", MAX_INERTIA)[0] for k in keys}
        tensor = np.array(
            [
                [v["ixx"], v["ixy"], v["ixz"]],
                [v["ixy"], v["iyy"], v["iyz"]],
                [v["ixz"], v["iyz"], v["izz"]],
            ]
        )
        moments = np.linalg.eigvalsh(tensor)
        tol = INERTIA_RTOL * max(float(np.abs(moments).max()), 1e-300)
        shown = np.array2string(moments, precision=3)
        note = None
        if moments[0] < -tol:
            note = f"{where}: not positive semi-definite (principal moments {shown} kg m^2)"
        elif 2 * moments.max() > moments.sum() + 2 * tol:
            note = (
                f"{where}: principal moments {shown} kg m^2 break the triangle inequality "
                "(no rigid body has them)"
            )
        return tensor, note

    def joint(self, el) -> _Joint:
        name = self.name(el, "a <joint>")
        where = f"<joint name='{name[:60]}'>"
        kind = el.get("type", "")
        if kind not in _TYPES:
            raise self.fail(where, f"type='{kind[:40]}' is not one of {', '.join(_TYPES)}")
        ends = []
        for tag in ("parent", "child"):
            end = el.find(tag)
            if end is None or not end.get("link"):
                raise self.fail(where, f"has no <{tag} link='...'>")
            ends.append(end.get("link"))
        if ends[0] == ends[1]:
            raise self.fail(where, f"its parent and child are the same link '{ends[0][:60]}'")
        origin = el.find("origin")
        xyz = self.numbers(origin, "xyz", f"{where} <origin>", 3, "0 0 0", MAX_LENGTH)
        rpy = self.numbers(origin, "rpy", f"{where} <origin>", 3, "0 0 0", MAX_ANGLE)
        axis = self.numbers(el.find("axis"), "xyz", f"{where} <axis>", 3, "1 0 0", MAX_LENGTH)
        norm = float(np.linalg.norm(axis))
        if kind in ("revolute", "continuous", "prismatic") and not norm >= MIN_AXIS_NORM:
            raise self.fail(f"{where} <axis>", f"xyz has norm {norm:.3g}, under {MIN_AXIS_NORM:g}")
        mimic = el.find("mimic")
        mimic_of = None if mimic is None else (mimic.get("joint") or "")
        if mimic_of == "":
            raise self.fail(f"{where} <mimic>", "names no joint")
        return _Joint(
            name,
            kind,
            ends[0],
            ends[1],
            xyz,
            _rpy(*rpy),
            axis / (norm or 1.0),
            self.limit(el.find("limit"), kind, f"{where} <limit>"),
            mimic_of,
        )

    def limit(self, el, kind: str, where: str) -> Limit:
        """A joint's ``<limit>`` (a continuous joint has no position limits)."""
        if el is None:
            return Limit()
        big = "1e300"
        lower, upper = (
            float(self.numbers(el, k, where, 1, d, math.inf)[0])
            for k, d in (("lower", "-" + big), ("upper", big))
        )
        velocity = float(self.numbers(el, "velocity", where, 1, big, math.inf)[0])
        effort = float(self.numbers(el, "effort", where, 1, big, math.inf)[0])
        if kind == "continuous" or (lower == 0 and upper == 0):
            lower, upper = -math.inf, math.inf  # URDF: 0 0 on a revolute means no limits
        if not lower <= upper:
            raise self.fail(where, f"lower={lower!r} is above upper={upper!r}")
        for key, value, high in (("velocity", velocity, MAX_SPEED), ("effort", effort, MAX_EFFORT)):
            if value < 0:
                raise self.fail(where, f"{key}={value!r} is negative")
            if value == 0 or value > high:
                value = math.inf  # 0 or absurd: no limit given
            if key == "velocity":
                velocity = value
            else:
                effort = value
        lower = -math.inf if lower <= -1e300 else lower
        upper = math.inf if upper >= 1e300 else upper
        return Limit(lower, upper, velocity, effort)
