"""A robot's URDF read for one thing: the gravity load of a joint (BAS-RBFNN paper eq. 7).

:func:`read_urdf` parses a URDF with :mod:`xml.etree.ElementTree` and nothing else: the file is
size-capped (:data:`MAX_BYTES`), a document type or entity declaration is refused (no entity
expansion), and xacro macros are refused (run ``xacro`` first; nothing in the file is ever
executed or fetched). Only links' ``<inertial>`` (``<mass value>``, ``<origin xyz>``) and
joints' ``type``, ``<parent>``, ``<child>``, ``<origin xyz rpy>`` and ``<axis xyz>`` are read;
meshes, limits and inertia tensors are ignored. Bad input is one :class:`DataError` naming the
file and the element.

What is read is checked before it is used:

- the file: a regular file (no device, FIFO or directory), read with a cap of
  :data:`MAX_BYTES`; its encoding is taken from its byte-order mark or, without one, its XML
  declaration (UTF-8, UTF-16, UTF-32, US-ASCII or ISO-8859-1; any other is refused), and the
  DOCTYPE and entity refusal applies to the decoded text, so no encoding hides a declaration;
- the numbers: every numeric attribute matches a plain decimal number (digits, an optional
  point and exponent: no ``nan``, ``inf``, ``0x10``, ``0_1`` or non-ASCII digits) and lies in
  a physical range: positions (origins, centres of mass) and axis components within
  :data:`MAX_LENGTH` m, angles within :data:`MAX_ANGLE` rad, masses 0 or within
  :data:`MASS_RANGE` kg (0 is a massless link, as a link without ``<inertial>`` is: URDF
  writers put ``<mass value="0"/>`` on frames that carry no body), and a moving joint's axis
  of norm at least :data:`MIN_AXIS_NORM` (then normalised);
- the graph: every joint names defined links, its parent differs from its child, no link has
  two parent joints, the joints form no cycle, and exactly one link (the root) has no parent.

:func:`gravity_coefficients` gives eq. 7's ``p_x, p_y`` [N m] of a revolute (or continuous)
joint from the masses and centres of mass of every link downstream of it, with the chain's
other joints at given positions (default zero) and gravity ``-z`` in the root link's frame.

Conventions
-----------
- ``theta`` of eq. 7 is the URDF joint position: zero where the URDF puts it, positive by the
  right-hand rule about the joint's ``<axis>``. A log's position column must use the same zero
  and sign for eq. 7 to match.
- ``tau_g`` is the torque gravity exerts on the downstream links about the joint axis, positive
  along ``+theta`` (so at rest without friction the motor holds ``-tau_g``, eq. 8).
- The ``x`` of eq. 7 is the horizontal direction ``a x z`` (``a`` the joint axis in the root
  frame, ``z`` up): a centre of mass at distance ``r`` from the axis and angle ``phi`` from
  that direction (about ``a``) at ``theta = 0`` gives ``p_x = m g r cos(phi)``, ``p_y = m g r
  sin(phi)``. For example, with the axis along ``+y``, ``x`` is ``+x`` and a centre of mass
  below the axis (``z < 0``) has ``p_y > 0``.
- Eq. 7 holds exactly for any axis not vertical (a tilted axis scales both coefficients by the
  sine of its angle to the vertical); a vertical axis carries no gravity load and is refused.
- URDF rotations: ``rpy`` is roll about x, then pitch about y, then yaw about z, all about
  the fixed axes (``R = Rz(yaw) Ry(pitch) Rx(roll)``); prismatic joints translate along their
  axis by their position [m]; fixed, floating and planar joints are rigid at their origin.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataError
from ._urdf_text import MAX_BYTES, check_graph, parse_xml

__all__ = [
    "MASS_RANGE",
    "MAX_ANGLE",
    "MAX_BYTES",
    "MAX_EFFORT",
    "MAX_INERTIA",
    "MAX_LENGTH",
    "MAX_SPEED",
    "MIN_AXIS_NORM",
    "STANDARD_GRAVITY",
    "GravityLoad",
    "Limit",
    "Robot",
    "gravity_coefficients",
    "read_urdf",
    "urdf_gravity",
]

from ._urdf_reader import (
    _ROTATING,
    MASS_RANGE,
    MAX_ANGLE,
    MAX_EFFORT,
    MAX_INERTIA,
    MAX_LENGTH,
    MAX_SPEED,
    MIN_AXIS_NORM,
    STANDARD_GRAVITY,
    Limit,
    _Joint,
    _Link,
    _Reader,
)


@dataclass(frozen=True, eq=False)
class Robot:
    """The kinematic tree of a URDF, as far as gravity needs it (:func:`read_urdf`).

    Attributes
    ----------
    name : str
        The robot's name.
    root : str
        The root link (gravity is ``-z`` in its frame).
    links : dict
        Link name -> mass and centre of mass (links without ``<inertial>`` have mass 0).
    joints : dict
        Joint name -> type, parent, child, origin and axis, in file order.
    source : str or None
        The file read.
    """

    name: str
    root: str
    links: dict = field(repr=False)
    joints: dict = field(repr=False)
    source: str | None = None

    def downstream(self, joint: str) -> list[str]:
        """The links moved by ``joint``: its child and every link below it."""
        children: dict[str, list[str]] = {}
        for j in self.joints.values():
            children.setdefault(j.parent, []).append(j.child)
        out, todo, seen = [], [self.joints[joint].child], set()
        while todo:
            link = todo.pop()
            if link in seen:  # a tree has none; read_urdf refuses cycles
                continue
            seen.add(link)
            out.append(link)
            todo.extend(children.get(link, ()))
        return out


@dataclass(frozen=True)
class GravityLoad:
    """Eq. 7's coefficients of one joint computed from a URDF (:func:`gravity_coefficients`).

    Attributes
    ----------
    p_x, p_y : float
        N m, the coefficients of ``tau_g = p_x cos(theta) - p_y sin(theta)`` (eq. 7).
    joint : str
        The joint.
    mass : float
        kg, the mass of the links downstream of the joint.
    links : tuple of str
        Those links.
    positions : dict
        The other joints' positions used (rad or m; joints not named were at zero).
    gravity : float
        m/s^2.
    source : str or None
        The URDF file.
    """

    p_x: float
    p_y: float
    joint: str
    mass: float
    links: tuple[str, ...]
    positions: dict = field(default_factory=dict)
    gravity: float = STANDARD_GRAVITY
    source: str | None = None

    def torque(self, theta) -> np.ndarray:
        """The gravity torque [N m] at joint position ``theta`` [rad] (eq. 7)."""
        theta = np.asarray(theta, dtype=float)
        return self.p_x * np.cos(theta) - self.p_y * np.sin(theta)

    def summary(self) -> str:
        """One line for the CLI."""
        return (
            f"gravity load of joint '{self.joint}' from the URDF (eq. 7): p_x = {self.p_x:.6g}, "
            f"p_y = {self.p_y:.6g} N m ({self.mass:.6g} kg in {len(self.links)} links)"
        )


def _about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit vector ``axis`` (Rodrigues)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def read_urdf(path: str | os.PathLike[str]) -> Robot:
    """Read a URDF's kinematic tree with its links' masses and centres of mass.

    Parameters
    ----------
    path : path-like
        The ``.urdf`` file (plain URDF: expand a ``.xacro`` with ``xacro`` first).

    Returns
    -------
    Robot

    Raises
    ------
    DataError
        One line naming the file (and the element and attribute): not a regular file, over
        :data:`MAX_BYTES`, an encoding not read (module notes), not XML, with a DOCTYPE or
        entity declaration, xacro macros, a root that is not ``<robot>``, a number that is not
        a plain decimal or lies outside its physical range, a joint naming an unknown link or
        the same link as parent and child, a link with two parents, a cycle of joints, or not
        exactly one root.
    """
    path = Path(path)
    src = str(path)
    root = parse_xml(path)
    macro = next((el.tag for el in root.iter() if el.tag.startswith("{")), None)
    if macro is not None:  # xacro:macro, xacro:include ... (namespaced elements)
        raise DataError(
            f"<{macro.rpartition('}')[2][:40]}> is a namespaced (xacro) element; xacro macros "
            "are not expanded here: run xacro first",
            file=src,
        )
    if root.tag != "robot":
        raise DataError(f"the root element is <{root.tag[:40]}>, not <robot>", file=src)
    reader = _Reader(src)
    links: dict[str, _Link] = {}
    for el in root.findall("link"):
        name, link = reader.link(el)
        if name in links:
            raise reader.fail(f"<link name='{name[:60]}'>", "is defined twice")
        links[name] = link
    joints: dict[str, _Joint] = {}
    parent_of: dict[str, str] = {}
    for el in root.findall("joint"):
        j = reader.joint(el)
        where = f"<joint name='{j.name[:60]}'>"
        if j.name in joints:
            raise reader.fail(where, "is defined twice")
        for link in (j.parent, j.child):
            if link not in links:
                raise reader.fail(where, f"names link '{link[:60]}', which is not defined")
        if j.child in parent_of:
            raise reader.fail(
                where, f"link '{j.child[:60]}' already has parent joint '{parent_of[j.child][:60]}'"
            )
        parent_of[j.child] = j.name
        joints[j.name] = j
    return Robot(root.get("name", ""), check_graph(links, joints, src), links, joints, src)


def _link_frames(robot: Robot, q: Mapping[str, float]):
    """Every link's pose (rotation, origin) in the root frame, and every joint's frame
    (rotation, origin) in it, with the joints at positions ``q`` (default zero)."""
    frames = {robot.root: (np.eye(3), np.zeros(3))}
    joint_frames = {}
    children: dict[str, list[_Joint]] = {}
    for j in robot.joints.values():
        children.setdefault(j.parent, []).append(j)
    todo = [robot.root]
    while todo:
        link = todo.pop()
        rot, pos = frames[link]
        for j in children.get(link, ()):
            jrot, jpos = rot @ j.rot, pos + rot @ j.xyz
            joint_frames[j.name] = (jrot, jpos)
            value = float(q.get(j.name, 0.0))
            if j.kind in _ROTATING:
                frames[j.child] = (jrot @ _about(j.axis, value), jpos)
            elif j.kind == "prismatic":
                frames[j.child] = (jrot, jpos + jrot @ (j.axis * value))
            else:
                frames[j.child] = (jrot, jpos)
            todo.append(j.child)
    return frames, joint_frames


def gravity_coefficients(
    robot: Robot,
    joint: str,
    positions: Mapping[str, float] | None = None,
    *,
    gravity: float = STANDARD_GRAVITY,
) -> GravityLoad:
    """Eq. 7's ``p_x, p_y`` [N m] of ``joint`` from the links downstream of it.

    Parameters
    ----------
    robot : Robot
        From :func:`read_urdf`.
    joint : str
        A revolute or continuous joint whose axis is not vertical.
    positions : mapping, optional
        The other joints' positions (rad for revolute, m for prismatic); joints not named are
        at zero. The joint's own position, if given, is ignored (eq. 7 is its function).
    gravity : float
        m/s^2, along ``-z`` of the root link.

    Returns
    -------
    GravityLoad

    Raises
    ------
    ConfigError
        An unknown joint (the joints are listed), a joint that does not rotate, a position for
        an unknown or rigid joint, a non-finite position or gravity.
    DataError
        The axis is vertical, or no mass downstream: gravity exerts no torque about it.

    Notes
    -----
    ``tau_g(theta) = a . sum_i (c_i(theta) - o) x (m_i g)`` (``a`` the axis, ``o`` a point on
    it, ``c_i`` the centres of mass, ``g = (0, 0, -gravity)``); rotating the downstream links
    rigidly about ``a`` makes it a sinusoid with no offset, so ``p_x = tau_g(0)`` and ``p_y =
    -tau_g(pi/2)`` exactly (module docstring for the conventions).
    """
    if joint not in robot.joints:
        names = [n for n, j in robot.joints.items() if j.kind in _ROTATING]
        raise ConfigError(
            f"the URDF has no joint '{joint}'; its rotating joints: {', '.join(names) or 'none'}"
        )
    target = robot.joints[joint]
    if target.kind not in _ROTATING:
        raise ConfigError(f"joint '{joint}' is {target.kind}; eq. 7 needs a revolute joint")
    q = dict(positions or {})
    for name, value in q.items():
        if name not in robot.joints or robot.joints[name].kind not in (*_ROTATING, "prismatic"):
            raise ConfigError(f"a position is given for '{name}', which is not a moving joint")
        if not math.isfinite(float(value)):
            raise ConfigError(f"the position of joint '{name}' must be finite; got {value!r}")
    if not (math.isfinite(gravity) and gravity > 0):
        raise ConfigError(f"gravity must be a positive number [m/s^2]; got {gravity!r}")
    q.pop(joint, None)
    links = robot.downstream(joint)
    mass = sum(robot.links[name].mass for name in links)
    g = np.array([0.0, 0.0, -gravity])
    tau = []
    for theta in (0.0, math.pi / 2):
        frames, joint_frames = _link_frames(robot, {**q, joint: theta})
        jrot, origin = joint_frames[joint]
        axis = jrot @ target.axis
        total = np.zeros(3)
        for name in links:
            rot, pos = frames[name]
            link = robot.links[name]
            total += np.cross(pos + rot @ link.com - origin, link.mass * g)
        tau.append(float(axis @ total))
    src = robot.source
    if abs(axis[2]) > 1 - 1e-9:
        raise DataError(
            f"<joint name='{joint[:60]}'>: its axis is vertical, gravity exerts no "
            "torque about it (a horizontal joint: use --gravity none)",
            file=src,
        )
    if not mass > 0:
        raise DataError(f"<joint name='{joint[:60]}'>: no link downstream has a mass", file=src)
    return GravityLoad(tau[0], -tau[1], joint, float(mass), tuple(links), q, float(gravity), src)


def urdf_gravity(
    path: str | os.PathLike[str],
    joint: str,
    positions: Mapping[str, float] | None = None,
    *,
    gravity: float = STANDARD_GRAVITY,
) -> GravityLoad:
    """:func:`read_urdf` then :func:`gravity_coefficients` (the parameters as there)."""
    return gravity_coefficients(read_urdf(path), joint, positions, gravity=gravity)
