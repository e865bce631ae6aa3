"""Run an exported MJCF fragment in MuJoCo: a minimal one-joint model driven by a torque.

The check of :func:`fricid.export.mjcf_text` in a real simulator (issue 16): the fragment that
``fricid export --to mjcf`` writes (a ``<joint>``, and for a LuGre model an ``<actuator>``
with a ``dcmotor``) is built into a model of one hinge joint with inertia ``J`` about its
axis, no gravity, and a ``motor`` actuator (gear 1) that applies the torque; it is then
stepped under a torque signal, one sample per step. Compare the trajectory with a Python
joint under the true friction (:func:`fricid.control.plant.drive`): ``tests/export/test_mujoco.py``
and ``benchmarks/bench_mujoco.py`` do.

Needs the optional ``mujoco`` package (``pip install fricid[mujoco]``), imported only when a
model is run; the XML is built by :mod:`xml.etree.ElementTree` from the fragment's parsed
elements (only ``<joint>`` attributes that MuJoCo's joint knows are copied, and only
``dcmotor`` actuators).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from ..errors import ConfigError

__all__ = ["JOINT_ATTRIBUTES", "one_joint_xml", "require_mujoco", "run_torque"]

#: The ``<joint>`` attributes copied from a fragment (the rest are the test model's).
JOINT_ATTRIBUTES = ("name", "frictionloss", "damping", "solreffriction", "solimpfriction")


def require_mujoco():
    """The ``mujoco`` module, or a :class:`ConfigError` that says how to install it."""
    try:
        import mujoco
    except ImportError:
        raise ConfigError(
            "running an MJCF export needs MuJoCo: pip install 'fricid[mujoco]' (or mujoco)"
        ) from None
    return mujoco


def _fragment(text: str) -> tuple[ET.Element, list[ET.Element]]:
    try:
        root = ET.fromstring(f"<fragment>{text}</fragment>")
    except ET.ParseError as exc:
        raise ConfigError(f"the MJCF fragment does not parse: {exc}") from None
    joints = root.findall("joint")
    if len(joints) != 1:
        raise ConfigError(f"the MJCF fragment must hold one <joint>, found {len(joints)}")
    motors = [el for act in root.findall("actuator") for el in act if el.tag == "dcmotor"]
    return joints[0], motors


def one_joint_xml(
    fragment: str,
    inertia: float = 0.01,
    timestep: float = 1e-3,
    *,
    integrator: str = "implicitfast",
    joint_overrides: dict[str, str] | None = None,
) -> str:
    """The MJCF text of a one-joint model around an exported fragment (module docstring).

    Parameters
    ----------
    fragment : the text ``mjcf_text`` wrote (comment and elements).
    inertia : kg m^2, about the joint axis.
    timestep : s, MuJoCo's step (one torque sample per step).
    integrator : MuJoCo's ``option/integrator``.
    joint_overrides : attributes set on the joint after the fragment's (e.g.
        ``{"solreffriction": "0.002 1"}``).
    """
    if not (math.isfinite(inertia) and inertia > 0 and math.isfinite(timestep) and timestep > 0):
        raise ConfigError(f"inertia and timestep must be > 0, got {inertia!r}, {timestep!r}")
    source, motors = _fragment(fragment)
    attrs = {k: source.get(k) for k in JOINT_ATTRIBUTES if source.get(k) is not None}
    attrs.update(joint_overrides or {})
    attrs.setdefault("name", "joint")
    root = ET.Element("mujoco", {"model": "fricid_one_joint"})
    ET.SubElement(
        root,
        "option",
        {"timestep": repr(float(timestep)), "gravity": "0 0 0", "integrator": integrator},
    )
    body = ET.SubElement(ET.SubElement(root, "worldbody"), "body", {"name": "link"})
    j = repr(float(inertia))
    ET.SubElement(body, "inertial", {"pos": "0 0 0", "mass": "1", "diaginertia": f"{j} {j} {j}"})
    ET.SubElement(body, "joint", {"type": "hinge", "axis": "0 0 1", **attrs})
    actuator = ET.SubElement(root, "actuator")
    ET.SubElement(actuator, "motor", {"name": "fricid_drive", "joint": attrs["name"], "gear": "1"})
    for motor in motors:
        if motor.get("joint") != attrs["name"]:
            raise ConfigError(
                f"the fragment's dcmotor acts on joint {motor.get('joint')!r}, not on "
                f"{attrs['name']!r}"
            )
        actuator.append(motor)
    return ET.tostring(root, encoding="unicode")


def run_torque(xml: str, torque) -> dict[str, np.ndarray]:
    """Step the model of :func:`one_joint_xml` from rest under ``torque`` (n,) [N m].

    Sample ``i`` holds the state at ``t = i timestep``, before ``torque[i]`` acts (as
    :func:`fricid.control.plant.drive`).

    Returns
    -------
    dict
        ``time``, ``position`` [rad], ``velocity`` [rad/s], each (n,).
    """
    mujoco = require_mujoco()
    torque = np.asarray(torque, dtype=float).ravel()
    if not np.all(np.isfinite(torque)):
        raise ConfigError("run_torque: the torque must be finite")
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    drive = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "fricid_drive")
    q, v = np.empty(torque.size), np.empty(torque.size)
    for i, u in enumerate(torque):
        q[i], v[i] = data.qpos[0], data.qvel[0]
        data.ctrl[drive] = u
        mujoco.mj_step(model, data)
    return {"time": np.arange(torque.size) * model.opt.timestep, "position": q, "velocity": v}
