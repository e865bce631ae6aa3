"""A fixed-base robot's rigid-body dynamics from its URDF, computed by Pinocchio.

:meth:`RigidBodyModel.from_urdf` reads the URDF with :func:`fricid.io.urdf.read_urdf` (size
cap, no DTD or entities, no xacro, every number a plain decimal in a physical range) and builds
the Pinocchio model from the checked tree itself, joint by joint: Pinocchio never parses the
file. The identified joints are revolute, continuous (one angle) or prismatic; every other
moving joint is locked at a given position (default zero) and, with the fixed joints, merged
into the body of the joint it hangs from, as a URDF's rigid links are.

The model gives, per sample, the inverse dynamics ``tau = M(q) ddq + C(q, dq) dq + g(q)``,
the mass matrix, the gravity torque and the linear regressor of the standard inertial
parameters, ``tau = Y(q, dq, ddq) pi`` (Atkeson, An and Hollerbach 1986). ``pi`` holds ten
numbers per identified joint's body, in Pinocchio's order: ``m, m c_x, m c_y, m c_z, I_xx,
I_xy, I_yy, I_xz, I_yz, I_zz`` [kg, kg m, kg m^2], the inertia about the joint frame's origin
in that frame. The friction of each joint is not part of it: fricid's friction families add it
(BAS-RBFNN paper eq. 1-4, RWSAVSBAS paper eq. 7), and the single-joint gravity of BAS-RBFNN
paper eq. 7, ``p_x cos q + p_y sin q``, is the special case of one revolute joint with a
horizontal axis.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..io.urdf import STANDARD_GRAVITY, Robot, read_urdf
from ._pin import pinocchio

__all__ = ["PARAMETER_SYMBOLS", "PARAMETER_UNITS", "RigidBodyModel"]

#: The ten standard inertial parameters of a body, in Pinocchio's order.
PARAMETER_SYMBOLS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")

#: Their units.
PARAMETER_UNITS = ("kg", "kg m", "kg m", "kg m", *("kg m^2",) * 6)

_IDENTIFIED = ("revolute", "continuous", "prismatic")


def _motion(pin: Any, kind: str, axis: np.ndarray, value: float) -> Any:
    """The placement a locked joint adds at position ``value``."""
    if kind in ("revolute", "continuous"):
        return pin.SE3(pin.AngleAxis(value, axis).matrix(), np.zeros(3))
    if kind == "prismatic":
        return pin.SE3(np.eye(3), axis * value)
    return pin.SE3.Identity()


def _children(robot: Robot) -> dict[str, list[Any]]:
    out: dict[str, list[Any]] = {}
    for j in robot.joints.values():
        out.setdefault(j.parent, []).append(j)
    return out


@dataclass(frozen=True, eq=False)
class RigidBodyModel:
    """A fixed-base robot's rigid-body dynamics (module notes); build with :meth:`from_urdf`.

    Attributes
    ----------
    joints : tuple of str
        The identified joints, in the model's order (parents before children).
    kinds : tuple of str
        Each joint's type (``revolute``, ``continuous`` or ``prismatic``).
    lower, upper, velocity_limit, effort_limit : ndarray, shape (n,)
        The URDF's limits (infinite where it gives none).
    locked : dict
        The moving joints not identified, with the positions they are locked at.
    bodies : dict
        Joint -> the URDF links rigidly moved by it alone (its body).
    notes : tuple of str
        What the URDF says that is not physical (a link's inertia tensor), kept as given.
    source : str or None
        The URDF file.
    """

    joints: tuple[str, ...]
    kinds: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    velocity_limit: np.ndarray
    effort_limit: np.ndarray
    locked: dict = field(default_factory=dict)
    bodies: dict = field(default_factory=dict, repr=False)
    notes: tuple[str, ...] = ()
    source: str | None = None
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -STANDARD_GRAVITY]))
    _model: Any = field(default=None, repr=False)
    _data: Any = field(default=None, repr=False)

    # -- construction ------------------------------------------------------------------------

    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        joints: Sequence[str] | None = None,
        *,
        locked: Mapping[str, float] | None = None,
        gravity: float = STANDARD_GRAVITY,
    ) -> RigidBodyModel:
        """Read a URDF (:func:`fricid.io.urdf.read_urdf`) and build its dynamics.

        Parameters
        ----------
        path : path-like
            The URDF.
        joints : sequence of str, optional
            The joints to identify; default every revolute, continuous and prismatic joint
            that does not mimic another.
        locked : mapping, optional
            Positions [rad or m] of moving joints left out of ``joints`` (default zero).
        gravity : float
            m/s^2, along ``-z`` of the URDF's root link.
        """
        return cls.from_robot(read_urdf(path), joints, locked=locked, gravity=gravity)

    @classmethod
    def from_robot(
        cls,
        robot: Robot,
        joints: Sequence[str] | None = None,
        *,
        locked: Mapping[str, float] | None = None,
        gravity: float = STANDARD_GRAVITY,
    ) -> RigidBodyModel:
        """Build from an already read :class:`~fricid.io.urdf.Robot` (:meth:`from_urdf`)."""
        pin = pinocchio()
        moving = [n for n, j in robot.joints.items() if j.kind in _IDENTIFIED]
        if joints is None:
            chosen = {n for n in moving if robot.joints[n].mimic is None}
        else:
            chosen = set(joints)
            if len(chosen) != len(joints):
                raise ConfigError(f"a joint is named twice in {list(joints)}")
            unknown = [n for n in joints if n not in moving]
            if unknown:
                raise ConfigError(
                    f"the URDF has no revolute, continuous or prismatic joint "
                    f"{', '.join(map(repr, unknown))}; it has: {', '.join(moving) or 'none'}"
                )
        floating = [n for n, j in robot.joints.items() if j.kind in ("floating", "planar")]
        if floating:
            raise DataError(
                f"joint '{floating[0][:60]}' is {robot.joints[floating[0]].kind}: only "
                "fixed-base robots are modelled",
                file=robot.source,
            )
        locks = {n: 0.0 for n in moving if n not in chosen}
        for name, value in (locked or {}).items():
            if name not in locks:
                raise ConfigError(f"'{name}' is locked, but it is not a moving joint left out")
            if not math.isfinite(float(value)):
                raise ConfigError(f"the locked position of '{name}' must be finite; got {value!r}")
            locks[name] = float(value)
        if not (math.isfinite(gravity) and gravity >= 0):
            raise ConfigError(f"gravity must be a number >= 0 [m/s^2]; got {gravity!r}")
        if not chosen:
            raise DataError("the URDF has no joint to identify", file=robot.source)

        model = pin.Model()
        model.name = robot.name or "robot"
        g = np.array([0.0, 0.0, -float(gravity)])
        model.gravity = pin.Motion(np.concatenate([g, np.zeros(3)]))
        at = {robot.root: (0, pin.SE3.Identity())}  # link -> (joint index, placement in it)
        bodies: dict[str, list[str]] = {}
        names: list[str] = []
        kinds: list[str] = []
        limits: list[tuple[float, float, float, float]] = []
        children = _children(robot)
        todo = [robot.root]
        while todo:
            link = todo.pop(0)
            parent_id, parent_placement = at[link]
            for j in children.get(link, ()):
                placement = parent_placement * pin.SE3(j.rot, j.xyz)
                if j.name in chosen:
                    lim = j.limit
                    if j.kind == "prismatic":
                        jm = pin.JointModelPrismaticUnaligned(j.axis)
                    else:
                        jm = pin.JointModelRevoluteUnaligned(j.axis)
                    lo, hi = (lim.lower, lim.upper) if j.kind != "continuous" else (-1e30, 1e30)
                    jid = model.addJoint(
                        parent_id,
                        jm,
                        placement,
                        j.name,
                        np.array([min(lim.effort, 1e30)]),
                        np.array([min(lim.velocity, 1e30)]),
                        np.array([max(lo, -1e30)]),
                        np.array([min(hi, 1e30)]),
                    )
                    at[j.child] = (jid, pin.SE3.Identity())
                    names.append(j.name)
                    kinds.append(j.kind)
                    limits.append((lim.lower, lim.upper, lim.velocity, lim.effort))
                else:
                    motion = _motion(pin, j.kind, j.axis, locks.get(j.name, 0.0))
                    at[j.child] = (parent_id, placement * motion)
                jid, link_placement = at[j.child]
                body = robot.links[j.child]
                if jid > 0:
                    bodies.setdefault(model.names[jid], []).append(j.child)
                if body.mass > 0 and jid > 0:
                    inertia = pin.Inertia(body.mass, body.com, body.inertia)
                    model.appendBodyToJoint(jid, inertia, link_placement)
                todo.append(j.child)
        lim_arr = np.array(limits, dtype=float).reshape(-1, 4)
        notes = tuple(
            robot.links[link].note
            for name in names
            for link in bodies.get(name, ())
            if robot.links[link].note
        )
        return cls(
            joints=tuple(names),
            kinds=tuple(kinds),
            lower=lim_arr[:, 0],
            upper=lim_arr[:, 1],
            velocity_limit=lim_arr[:, 2],
            effort_limit=lim_arr[:, 3],
            locked=locks,
            bodies={k: tuple(v) for k, v in bodies.items()},
            notes=notes,
            source=robot.source,
            gravity=g,
            _model=model,
            _data=model.createData(),
        )

    # -- parameters --------------------------------------------------------------------------

    @property
    def n(self) -> int:
        """The number of identified joints."""
        return len(self.joints)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """``joint:symbol`` for each standard inertial parameter (:data:`PARAMETER_SYMBOLS`)."""
        return tuple(f"{j}:{s}" for j in self.joints for s in PARAMETER_SYMBOLS)

    def parameters(self) -> np.ndarray:
        """The URDF's standard inertial parameters ``pi``, shape (10 n,) (module notes)."""
        m = self._model
        return np.concatenate([m.inertias[i].toDynamicParameters() for i in range(1, m.njoints)])

    def with_parameters(self, pi: np.ndarray) -> RigidBodyModel:
        """A copy whose bodies have the standard inertial parameters ``pi`` (10 n,)."""
        pin = pinocchio()
        pi = np.asarray(pi, dtype=float)
        if pi.shape != (10 * self.n,) or not np.isfinite(pi).all():
            raise ConfigError(f"pi must be {10 * self.n} finite numbers; got shape {pi.shape}")
        model = pin.Model(self._model)
        for i in range(self.n):
            model.inertias[i + 1] = pin.Inertia.FromDynamicParameters(pi[10 * i : 10 * i + 10])
        return RigidBodyModel(
            self.joints,
            self.kinds,
            self.lower,
            self.upper,
            self.velocity_limit,
            self.effort_limit,
            dict(self.locked),
            dict(self.bodies),
            self.notes,
            self.source,
            self.gravity.copy(),
            model,
            model.createData(),
        )

    # -- dynamics, one row per sample ----------------------------------------------------------

    def _rows(self, *arrays: Any) -> tuple[np.ndarray, ...]:
        out = []
        for a in arrays:
            a = np.atleast_2d(np.asarray(a, dtype=float))
            if a.shape[-1] != self.n:
                raise ConfigError(f"expected {self.n} joint columns {self.joints}; got {a.shape}")
            out.append(a)
        rows = {a.shape[0] for a in out}
        if len(rows) > 1:
            raise ConfigError(f"the arrays have different numbers of rows: {sorted(rows)}")
        return tuple(out)

    def inverse_dynamics(self, q, dq, ddq) -> np.ndarray:
        """``M(q) ddq + C(q, dq) dq + g(q)`` [N m or N], shape (N, n) (RNEA)."""
        pin = pinocchio()
        q, dq, ddq = self._rows(q, dq, ddq)
        m, d = self._model, self._data
        return np.array([pin.rnea(m, d, *row) for row in zip(q, dq, ddq, strict=True)])

    def gravity_torque(self, q) -> np.ndarray:
        """``g(q)`` [N m or N], the torque holding the arm still against gravity, (N, n)."""
        pin = pinocchio()
        (q,) = self._rows(q)
        m, d = self._model, self._data
        return np.array([pin.computeGeneralizedGravity(m, d, row) for row in q])

    def mass_matrix(self, q) -> np.ndarray:
        """``M(q)``, shape (N, n, n) (CRBA, symmetrised)."""
        pin = pinocchio()
        (q,) = self._rows(q)
        out = np.empty((q.shape[0], self.n, self.n))
        for k, row in enumerate(q):
            mm = pin.crba(self._model, self._data, row)
            out[k] = np.triu(mm) + np.triu(mm, 1).T
        return out

    def forward_dynamics(self, q, dq, tau) -> np.ndarray:
        """``ddq = M(q)^-1 (tau - C(q, dq) dq - g(q))``, shape (N, n) (ABA)."""
        pin = pinocchio()
        q, dq, tau = self._rows(q, dq, tau)
        m, d = self._model, self._data
        return np.array([pin.aba(m, d, *row) for row in zip(q, dq, tau, strict=True)])

    def regressor(self, q, dq, ddq) -> np.ndarray:
        """``Y`` with ``inverse_dynamics = Y pi``, shape (N, n, 10 n) (module notes)."""
        pin = pinocchio()
        q, dq, ddq = self._rows(q, dq, ddq)
        m, d = self._model, self._data
        return np.array(
            [pin.computeJointTorqueRegressor(m, d, *row) for row in zip(q, dq, ddq, strict=True)]
        )

    def gravity_regressor(self, q) -> np.ndarray:
        """``Y(q, 0, 0)``: the regressor of the gravity torque alone, shape (N, n, 10 n)."""
        (q,) = self._rows(q)
        zero = np.zeros_like(q)
        return self.regressor(q, zero, zero)
