"""Files of an excitation: the trajectory as a CSV table and as a ROS 2
``trajectory_msgs/JointTrajectory`` YAML a robot can play, and the design as JSON that
:func:`load_design` reads back. Every file is written atomically (:mod:`fricid.io.atomic`).

The CSV has the columns of a robot log's wide table (:func:`fricid.io.write_robot_log`):
``time [s]`` then ``<joint>.position [rad]``, ``<joint>.velocity [rad/s]``,
``<joint>.acceleration [rad/s^2]`` (m, m/s, m/s^2 for a prismatic joint). It is a command, not
a log: it has no torque, so it is not a :class:`~fricid.samples.RobotLog` until the robot's
log of playing it adds one.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..io._csv import csv_preamble, preamble_fields, write_csv
from ..io.atomic import atomic_write
from .trajectories import FourierTrajectory

__all__ = [
    "DESIGN_FORMAT",
    "TRAJECTORY_FORMAT",
    "load_design",
    "save_design",
    "write_joint_trajectory_yaml",
    "write_trajectory_csv",
]

#: The format tag of a design file.
DESIGN_FORMAT = "fricid-excitation/1"

#: The format tag of a trajectory table.
TRAJECTORY_FORMAT = "fricid-trajectory/1"

#: Quantity -> (state index, unit of a revolute joint, unit of a prismatic joint).
_QUANTITIES = {
    "position": (0, "rad", "m"),
    "velocity": (1, "rad/s", "m/s"),
    "acceleration": (2, "rad/s^2", "m/s^2"),
}


def _number(x: float) -> str:
    """A finite number as text (refuses NaN and infinities: data never becomes code)."""
    x = float(x)
    if not math.isfinite(x):
        raise ConfigError(f"refusing to write a non-finite number ({x})")
    return repr(x)


def _name(joint: str) -> str:
    if not joint or any(ch in joint for ch in ',;\t"[]\r\n#') or not joint.isprintable():
        raise ConfigError(f"joint name {joint!r} cannot be written in a table header")
    return joint


def write_trajectory_csv(
    traj: Any,
    path: str | os.PathLike[str],
    *,
    rate: float = 1000.0,
    kinds: Any = None,
    source: str | None = None,
) -> Path:
    """``traj`` sampled at ``rate`` [Hz] as a CSV table (module notes).

    Parameters
    ----------
    traj : a trajectory (``joints``, ``duration``, ``evaluate``)
    path : path-like
    rate : float
    kinds : sequence of str, optional
        Each joint's type (``prismatic`` gets m, m/s, m/s^2); default revolute.
    source : str, optional
        Written in the comment lines (e.g. the design file).
    """
    import pyarrow as pa

    t, states = traj.sample(rate)
    kinds = kinds or ("revolute",) * len(traj.joints)
    units = {"time": "s"}
    columns = {"time": t}
    for quantity, (index, rad, metre) in _QUANTITIES.items():
        for j, (joint, kind) in enumerate(zip(traj.joints, kinds, strict=True)):
            label = f"{_name(joint)}.{quantity}"
            units[label] = metre if kind == "prismatic" else rad
            columns[label] = states[index][:, j]
    if not all(np.isfinite(v).all() for v in columns.values()):
        raise ConfigError("refusing to write a trajectory with non-finite values")
    fields = preamble_fields(TRAJECTORY_FORMAT, source, None, None, {"rate": float(rate)})
    path = Path(path)
    write_csv(path, csv_preamble(fields, units), [pa.table(columns)])
    return path


def _vector(values: np.ndarray) -> str:
    return "[" + ", ".join(_number(v) for v in values) + "]"


def write_joint_trajectory_yaml(
    traj: Any, path: str | os.PathLike[str], *, rate: float = 100.0
) -> Path:
    """``traj`` sampled at ``rate`` [Hz] as a ROS 2 ``trajectory_msgs/JointTrajectory`` in
    YAML (``ros2 topic pub`` and ``ros2 action send_goal`` take it): ``joint_names`` and one
    point per sample after ``t = 0`` with positions, velocities, accelerations and
    ``time_from_start {sec, nanosec}``. The robot must first be brought to rest at the state
    at ``t = 0`` (written in a comment): the trajectory starts there."""
    t, (q, dq, ddq) = traj.sample(rate)
    names = ", ".join(json.dumps(str(j)) for j in traj.joints)  # JSON strings are YAML
    lines = [
        "# trajectory_msgs/JointTrajectory written by fricid; start at rest at",
        f"# positions {_vector(q[0])}",
        "header:",
        "  stamp: {sec: 0, nanosec: 0}",
        '  frame_id: ""',
        f"joint_names: [{names}]",
        "points:",
    ]
    for k in range(1, t.size):
        ns = round(t[k] * 1e9)
        lines += [
            f"  - positions: {_vector(q[k])}",
            f"    velocities: {_vector(dq[k])}",
            f"    accelerations: {_vector(ddq[k])}",
            "    effort: []",
            f"    time_from_start: {{sec: {ns // 1_000_000_000}, nanosec: {ns % 1_000_000_000}}}",
        ]
    path = Path(path)
    with atomic_write(path) as fh:
        fh.write("\n".join(lines) + "\n")
    return path


# -- the design as JSON ----------------------------------------------------------------------


def _listed(values: Any) -> Any:
    """Numbers for JSON: an infinite limit (none in the URDF) as null."""
    arr = np.asarray(values, dtype=float)
    out = np.where(np.isfinite(arr), arr, np.nan).tolist()
    if arr.ndim == 0:
        return None if math.isnan(out) else out
    return [None if math.isnan(x) else x for x in out]


def _unlisted(values: Any) -> np.ndarray:
    """:func:`_listed` read back: null as infinity."""
    if isinstance(values, list):
        return np.array([np.inf if x is None else float(x) for x in values])
    return np.asarray(np.inf if values is None else float(values))


def design_record(design: Any, extra: dict | None = None) -> dict:
    """The JSON document of an :class:`~fricid.robot.excitation.ExcitationDesign`."""
    tr = design.trajectory
    doc = {
        "format": DESIGN_FORMAT,
        "joints": list(tr.joints),
        "w_f": tr.w_f,
        "period": tr.period,
        "q0": tr.q0.tolist(),
        "a": tr.a.tolist(),
        "b": tr.b.tolist(),
        "criterion": design.criterion,
        "friction": design.friction,
        "names": list(design.names),
        "cond": design.cond,
        "cond_start": design.cond_start,
        "logdet": design.logdet,
        "logdet_start": design.logdet_start,
        "limits": {k: _listed(v) for k, v in design.limits.items()},
        "margins": {k: _listed(v) for k, v in design.margins.items()},
        "samples": design.samples,
        "evaluations": design.evaluations,
        "seconds": design.seconds,
        "converged": design.converged,
        "message": design.message,
        "seed": design.seed,
    }
    doc.update(extra or {})
    return doc


def save_design(design: Any, path: str | os.PathLike[str], extra: dict | None = None) -> Path:
    """Write the design (coefficients, settings, figures) as JSON, atomically."""
    text = json.dumps(design_record(design, extra), indent=2, allow_nan=False)
    path = Path(path)
    with atomic_write(path) as fh:
        fh.write(text + "\n")
    return path


def _field(doc: dict, key: str, path: Path) -> Any:
    if key not in doc:
        raise DataError(f"the design has no '{key}'", file=path, column=key)
    return doc[key]


def load_design(path: str | os.PathLike[str]) -> Any:
    """Read a design file written by :func:`save_design`; an
    :class:`~fricid.robot.excitation.ExcitationDesign` (its limits and margins as arrays)."""
    from .excitation import CRITERIA, FRICTION_COLUMNS, ExcitationDesign

    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataError(f"cannot read the design: {exc}", file=path) from exc
    if not isinstance(doc, dict) or doc.get("format") != DESIGN_FORMAT:
        raise DataError(f"not a design file (format {DESIGN_FORMAT} expected)", file=path)
    try:
        traj = FourierTrajectory(
            tuple(str(j) for j in _field(doc, "joints", path)),
            float(_field(doc, "w_f", path)),
            np.asarray(_field(doc, "q0", path), dtype=float),
            np.asarray(_field(doc, "a", path), dtype=float),
            np.asarray(_field(doc, "b", path), dtype=float),
        )
    except (TypeError, ValueError, ConfigError) as exc:
        raise DataError(f"bad coefficients: {exc}", file=path) from exc
    for key, allowed in (("criterion", CRITERIA), ("friction", tuple(FRICTION_COLUMNS))):
        if _field(doc, key, path) not in allowed:
            raise DataError(f"{key} must be one of {allowed}", file=path, column=key)
    try:
        arrays = {
            key: {str(k): _unlisted(v) for k, v in dict(doc.get(key) or {}).items()}
            for key in ("limits", "margins")
        }
    except (TypeError, ValueError) as exc:
        raise DataError(f"bad limits or margins: {exc}", file=path) from exc
    return ExcitationDesign(
        traj,
        str(_field(doc, "criterion", path)),
        str(_field(doc, "friction", path)),
        tuple(doc.get("names", ())),
        cond=float(doc.get("cond", math.nan)),
        cond_start=float(doc.get("cond_start", math.nan)),
        logdet=float(doc.get("logdet", math.nan)),
        logdet_start=float(doc.get("logdet_start", math.nan)),
        limits=arrays["limits"],
        margins=arrays["margins"],
        samples=int(doc.get("samples", 0)),
        evaluations=int(doc.get("evaluations", 0)),
        seconds=float(doc.get("seconds", 0.0)),
        converged=bool(doc.get("converged", False)),
        message=str(doc.get("message", "")),
        seed=int(doc.get("seed", 0)),
    )
