"""A robot's URDF with its identified dynamics: each identified joint's body gets the
identified inertial parameters and each joint's ``<dynamics>`` the identified friction.

The file written is the user's URDF, read again by the safe reader
(:func:`fricid.io._urdf_text.parse_xml`: size cap, no DOCTYPE or entity) and re-serialised by
:mod:`xml.etree.ElementTree`, with two kinds of change:

- **inertials**: the standard parameters nearest the source's that reproduce the identified
  base parameters (the data determine only those combinations; :data:`INERTIALS` says so in
  the file). A joint's body (:attr:`fricid.robot.RigidBodyModel.bodies`: its child link and
  the links fixed to it) is one rigid body, so the whole body's mass, centre of
  mass and inertia go into the child link's ``<inertial>`` and the other links of the body lose
  theirs (a comment in each says where the mass went); the torques of the arm are unchanged by
  that. Only physically consistent parameters are written (:mod:`fricid.robot.consistency`);
- **friction**: ``<dynamics damping= friction=/>`` from the least-squares Coulomb-viscous
  projection of each joint's friction model over its operating range
  (:mod:`fricid.export.projection`), refused beyond ``max_loss`` as the single-joint URDF
  export is (:func:`fricid.export.urdf_text`).

A comment at the top names the source URDF by its SHA-256 and says what was replaced.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..fitted import FittedModel
from ..io._urdf_text import parse_xml
from ..io.atomic import atomic_write
from ..robot.consistency import is_consistent
from ..robot.model import RigidBodyModel
from ._common import (
    ExportError,
    ensure_out_file,
    file_sha256,
    fmt_float,
    model_name,
    percent,
    plain,
    write_lines_checked,
)
from ._trust import trust_line
from .descriptions import DEFAULT_MAX_LOSS, _checked

__all__ = ["INERTIALS", "robot_urdf_text", "write_robot_urdf"]


def _inertial(pi: np.ndarray) -> ET.Element:
    """``<inertial>`` of one body's standard parameters (about the link frame's origin)."""
    m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = pi
    c = np.array([hx, hy, hz]) / m
    about_origin = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    about_com = about_origin - m * (c @ c * np.eye(3) - np.outer(c, c))  # parallel axes
    el = ET.Element("inertial")
    ET.SubElement(el, "origin", {"xyz": " ".join(fmt_float(x, "com") for x in c), "rpy": "0 0 0"})
    ET.SubElement(el, "mass", {"value": fmt_float(m, "mass")})
    keys = (
        ("ixx", 0, 0),
        ("ixy", 0, 1),
        ("ixz", 0, 2),
        ("iyy", 1, 1),
        ("iyz", 1, 2),
        ("izz", 2, 2),
    )
    ET.SubElement(el, "inertia", {k: fmt_float(about_com[i, j], k) for k, i, j in keys})
    return el


def _replace(parent: ET.Element, tag: str, new: ET.Element | None, note: str) -> None:
    for old in parent.findall(tag):
        parent.remove(old)
    write_lines_checked([note], ("--",))
    parent.insert(0, ET.Comment(f" {note} "))
    if new is not None:
        parent.insert(1, new)


#: What the written inertials are: the data determine only the base parameters (combinations
#: of the standard ones), the rest comes from the source URDF (the identification's
#: ``standard`` record: :mod:`fricid.identify.dynamic.arm._consistent`).
INERTIALS = (
    "inertials: the standard parameters nearest the source URDF's that reproduce the identified "
    "base parameters; what the data do not determine keeps the URDF's values"
)


def robot_urdf_text(
    model: RigidBodyModel,
    parameters: np.ndarray | None = None,
    frictions: Mapping[str, FittedModel] | None = None,
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
) -> str:
    """The model's source URDF with identified inertials and friction (module notes).

    Parameters
    ----------
    model : RigidBodyModel
        Built from the URDF to rewrite (its ``source``).
    parameters : ndarray, shape (10 n,), optional
        Standard inertial parameters of the identified joints' bodies (Pinocchio's order, as
        :meth:`~fricid.robot.RigidBodyModel.parameters`); None keeps the URDF's inertials.
    frictions : mapping, optional
        Joint name -> its fitted friction model.
    max_loss : float
        Largest RMS error of the Coulomb-viscous projection relative to the RMS friction.

    Raises
    ------
    ExportError
        Parameters of the wrong size, not physically consistent (the bodies named), a joint
        not in the model, or a friction model that the projection misses beyond ``max_loss``.
    """
    if model.source is None:
        raise ExportError("the robot model has no source URDF to rewrite")
    root = parse_xml(Path(model.source))
    links = {el.get("name"): el for el in root.findall("link")}
    joints = {el.get("name"): el for el in root.findall("joint")}
    lines = [
        f"fricid: identified dynamics written into {plain(Path(model.source).name)} "
        f"(SHA-256 {file_sha256(model.source)})"
    ]
    if parameters is not None:
        pi = np.asarray(parameters, dtype=float)
        if pi.shape != (10 * model.n,) or not np.isfinite(pi).all():
            raise ExportError(f"expected {10 * model.n} finite inertial parameters; got {pi.shape}")
        ok = is_consistent(pi)
        if not ok.all():
            bad = [j for j, good in zip(model.joints, ok, strict=True) if not good]
            raise ExportError(
                "the inertial parameters of the bodies of "
                f"{', '.join(plain(j) for j in bad)} are not physically consistent (no mass "
                "distribution has them): identify with physical consistency first"
            )
        for k, joint in enumerate(model.joints):
            body = model.bodies.get(joint, ())
            if not body:
                continue
            child, *others = body
            _replace(
                links[child],
                "inertial",
                _inertial(pi[10 * k : 10 * k + 10]),
                f"fricid: inertial of joint {plain(joint)}'s whole body "
                f"({', '.join(plain(b) for b in body)}), see the note at the top",
            )
            for other in others:
                _replace(
                    links[other],
                    "inertial",
                    None,
                    f"fricid: this link's mass is in link {plain(child)}'s inertial",
                )
        lines.append(f"{INERTIALS}: bodies of " + ", ".join(map(plain, model.joints)))
    for joint, fitted in (frictions or {}).items():
        if joint not in joints or joint not in model.joints:
            raise ExportError(f"no identified joint {plain(joint)} in the robot model")
        proj = _checked(fitted, f"URDF <dynamics> of joint {plain(joint)}", False, max_loss, {})
        element = ET.Element(
            "dynamics",
            {
                "damping": fmt_float(proj.viscous["both"], "damping"),
                "friction": fmt_float(proj.coulomb["both"], "friction"),
            },
        )
        _replace(
            joints[joint],
            "dynamics",
            element,
            f"fricid: Coulomb-viscous projection of model {plain(model_name(fitted))}, "
            f"{percent(proj.relative_error)} RMS from it over its operating range; "
            + trust_line(fitted, proj.rms_error, "Coulomb-viscous projection"),
        )
    if frictions:
        lines.append("friction: <dynamics> of " + ", ".join(map(plain, frictions)))
    write_lines_checked(lines, ("--",))
    root.insert(0, ET.Comment("\n" + "".join(f"     {line}\n" for line in lines)))
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write_robot_urdf(
    path: str | os.PathLike[str],
    model: RigidBodyModel,
    parameters: np.ndarray | None = None,
    frictions: Mapping[str, FittedModel] | None = None,
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
) -> Path:
    """Write :func:`robot_urdf_text` atomically to ``path`` (never the source URDF itself)."""
    out = ensure_out_file(path)
    if model.source is not None and out.resolve() == Path(model.source).resolve():
        raise ExportError(f"{out} is the source URDF: write the identified one beside it")
    text = robot_urdf_text(model, parameters, frictions, max_loss=max_loss)
    with atomic_write(out) as fh:
        fh.write(text)
    return out
