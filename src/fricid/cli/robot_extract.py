"""``fricid robot extract``: every joint's friction samples from constant-velocity sweeps of a
whole arm, gravity computed from the whole configuration (:func:`fricid.extract.extract_arm`)."""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from ._app import console, err_console, handle_errors, robot_app
from ._options import out_option
from ._paths import check_paths

#: The gravity parameters' file in the output folder.
GRAVITY_FILE = "gravity.json"


def _file_stem(joint: str) -> str:
    """A joint's name as a file name: letters, digits, ``_ . -`` kept, anything else ``_``."""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", joint).strip(".") or "joint"
    return stem[:100]


def _stems(joints) -> dict[str, str]:
    """Joint -> file stem, unique (a clash gets the joint's index appended)."""
    out: dict[str, str] = {}
    for i, joint in enumerate(joints):
        stem = _file_stem(joint)
        out[joint] = stem if stem not in out.values() else f"{stem}_{i + 1}"
    return out


def _with_temperature(log, temperature: float | None):
    """``log`` with ``temperature`` [degC] where it logged none (--temperature is for the
    recordings without a temperature column: with several files, some may have one)."""
    if log.temperature is not None or temperature is None:
        return log
    return replace(log, temperature=temperature)


def _split(items: list[str] | None) -> list[str] | None:
    """``["a,b", "c"]`` -> ``["a", "b", "c"]``."""
    if not items:
        return None
    return [name.strip() for item in items for name in item.split(",") if name.strip()]


def _joint_table(result, joint: str) -> list[str]:
    """One joint's set-points as its samples file holds them: velocity, friction with its
    standard error (the arm fit's, the gravity parameters' uncertainty included), gravity
    load, passes and samples."""
    g = result.gravity
    lines = [
        f"{joint}: {len(g.joint_levels(joint))} set-points, residual "
        f"{g.residual_rms.get(joint, float('nan')):.3g} N m",
        f"  {'T [degC]':>8} {'v [rad/s]':>10} {'friction [N m]':>15} {'+- se':>9} "
        f"{'load [N m]':>11} {'passes':>6} {'samples':>8}",
    ]
    for row in result.setpoints(joint):
        se = f"{row['friction_se']:>9.2g}" if math.isfinite(row["friction_se"]) else f"{'-':>9}"
        lines.append(
            f"  {row['temperature']:>8.4g} {row['velocity']:>+10.4g} {row['friction']:>+15.5g} "
            f"{se} {row['load']:>+11.4g} {row['passes'] or '-':>6} {row['count']:>8}"
        )
    return lines + _not_averaged(result[joint].quality)


#: What each kind of run left out of the set-points was (the quality table's kinds).
_LEFT_OUT = {
    "rest": "standstill",
    "unsteady": "no steady plateau: return moves, stick-slip, aborted moves",
}


def _not_averaged(quality) -> list[str]:
    """The runs the extraction did not average into a set-point, by kind, with their speeds,
    and the set-points flagged for scatter: a requested speed missing from the table above
    shows here (the whole record is the samples file's quality table)."""
    if quality is None:
        return []
    lines = []
    for kind, what in _LEFT_OUT.items():
        rows = quality.kind == kind
        if rows.any():
            speeds = sorted({round(float(v), 3) for v in quality.velocity[rows]})
            shown = ", ".join(f"{v:+.3g}" if v else "0" for v in speeds[:12])
            more = f" and {len(speeds) - 12} more" if len(speeds) > 12 else ""
            lines.append(
                f"  not averaged: {int(rows.sum())} {kind} run(s) ({what}) at {shown}{more} rad/s"
            )
    flagged = quality.setpoints & quality.flagged
    if flagged.any():
        speeds = ", ".join(f"{float(v):+.3g}" for v in quality.velocity[flagged])
        lines.append(f"  flagged (scatter far above their neighbours): {speeds} rad/s")
    return lines


def _tables(result) -> list[str]:
    """The printed tables: each joint's set-points, a row per joint, the base gravity
    parameters."""
    lines = [line for joint in result for line in (*_joint_table(result, joint), "")]
    head = (
        f"{'joint':<24} {'set-points':>10} {'samples':>8} {'|friction| [N m]':>20} "
        f"{'|gravity| max':>13} {'residual':>9}"
    )
    lines.append(head)
    for r in result.table():
        span = f"{r['friction min [N m]']:.4g} - {r['friction max [N m]']:.4g}"
        lines.append(
            f"{r['joint'][:24]:<24} {r['set-points']:>10} {r['samples']:>8} {span:>20} "
            f"{r['gravity max [N m]']:>13.4g} {r['residual [N m]']:>9.3g}"
        )
    g = result.gravity
    what = "identified from the sweeps" if g.identified else "the URDF's (not identified)"
    lines.append(f"base gravity parameters ({what}; value +- standard error, URDF):")
    for name, b, se, u in zip(g.names, g.beta, g.beta_se, g.beta_urdf, strict=True):
        told = (
            f"+- {se:.2g}"
            if math.isfinite(se)
            else "(not determined by the sweeps)"
            if g.identified
            else "(kept)"
        )
        lines.append(f"  {b:+.6g} {told}  (URDF {u:+.6g})  {name}")
    return lines


@robot_app.command("extract")
@handle_errors
def robot_extract_command(
    logs: Annotated[
        list[Path],
        typer.Argument(
            help="The robot's sweeps: a wide CSV/Parquet table (q1, dq1, tau1, ... or "
            "<joint>.position, ...), a ROS 2 bag with a JointState topic, or a folder of "
            "per-channel files. Several recordings of "
            "one robot (one joint swept per file, say) are read as one log, each after the "
            "previous: same joints and rate, and the gravity "
            "they share identified from all.",
            metavar="LOG",
        ),
    ],
    urdf: Annotated[Path | None, typer.Option("--urdf", help="The robot's URDF.")] = None,
    robot_name: Annotated[
        str | None,
        typer.Option(
            "--robot",
            help="An example robot instead of --urdf: panda, ur5 or double_pendulum (the "
            "example-robot-data URDFs).",
        ),
    ] = None,
    out: Annotated[
        Path,
        out_option(
            "Folder to write: <joint>.csv per swept joint (its per-direction friction samples, "
            f"load = gravity torque) and {GRAVITY_FILE} (the base gravity parameters with "
            "standard errors and covariance, every set-point's friction); files of those names "
            "are replaced."
        ),
    ] = Path("robot_samples"),
    joints: Annotated[
        list[str] | None,
        typer.Option(
            "--joints",
            metavar="NAMES",
            help="Joints to extract (comma-separated or repeated); default every joint of the "
            "log that has a constant-velocity sweep.",
        ),
    ] = None,
    urdf_masses: Annotated[
        bool,
        typer.Option(
            "--urdf-masses",
            help="Keep the URDF's masses (gravity parameters not identified from the sweeps).",
        ),
    ] = False,
    temperature: Annotated[
        float | None,
        typer.Option(help="The temperature [degC] to record for each log that has none."),
    ] = None,
    torque_constant: Annotated[
        list[str] | None,
        typer.Option(
            "--torque-constant",
            metavar="JOINT=K",
            help="JOINT=K [N m/A] (repeatable): tau = K I (eq. 13) for a log of currents.",
        ),
    ] = None,
    reader: Annotated[
        str, typer.Option(help="Layout of LOG: auto, table, rosbag or channels.")
    ] = "auto",
    topic: Annotated[str, typer.Option(help="ROS 2 bags: the JointState topic.")] = "/joint_states",
) -> None:
    """Extract every joint's friction from constant-velocity sweeps of a whole arm.

    Each joint's gravity torque is computed from the whole configuration at every sample (the
    URDF's rigid-body model; on an arm the gravity of one joint depends on the others'
    positions, which the BAS-RBFNN paper's eq. 7 of one joint cannot represent), with the
    base gravity parameters identified from the sweeps themselves (the URDF's masses are
    approximate) jointly with every joint's friction per set-point, with cluster-robust
    intervals. Each joint's samples are then fitted by `fricid fit` like a single joint's. The
    joints of the log that the URDF has are modelled; the URDF's other moving joints are held
    at 0.
    """
    from ..extract import extract_arm
    from ..extract.arm import CONFOUNDED
    from ..io import read_robot_log
    from ..io.atomic import atomic_write
    from ..io.tables import write_samples
    from ..io.urdf import read_urdf
    from ..robot import RigidBodyModel
    from ..samples import join_robot_logs
    from ._options import parse_assignments, robot_urdf

    urdf = robot_urdf(urdf, robot_name)[0]
    names = ["LOG"] if len(logs) == 1 else [f"LOG {k + 1}" for k in range(len(logs))]
    check_paths(
        inputs={**dict(zip(names, logs, strict=True)), "--urdf": urdf},
        folders=names,
        out_dirs={"--out": out},
    )
    robot = read_urdf(urdf)
    constants = parse_assignments(torque_constant, "--torque-constant") or None
    moving = [
        n for n, j in robot.joints.items() if j.kind in ("revolute", "continuous", "prismatic")
    ]
    options = {"reader": reader, "topic": topic, "torque_constants": constants}
    read = [read_robot_log(p, **options) for p in logs]
    if all(j.isdigit() and j not in moving for log in read for j in log.joints):
        # numbered columns (q1, dq1, tau1, ...): the URDF's moving joints in order, as
        # `robot fit` reads them (every moving joint logged, or the reader says what is not)
        read = [read_robot_log(p, joints=moving, **options) for p in logs]
        err_console.print(
            "note: the log's joints 1-"
            f"{len(moving)} read as the URDF's moving joints in order: {', '.join(moving)}",
            markup=False,
            highlight=False,
        )
    data = join_robot_logs([_with_temperature(log, temperature) for log in read])
    modelled = [n for n in moving if n in data.joints]
    if not modelled:
        from ..errors import DataError

        raise DataError(
            f"no joint of the log ({', '.join(data.joints)}) is a moving joint of the URDF "
            f"({', '.join(moving) or 'none'}); rename the log's columns to the URDF's names",
            file=data.source,
        )
    model = RigidBodyModel.from_robot(robot, modelled)
    result = extract_arm(data, model, joints=_split(joints), identify=not urdf_masses)
    stems = _stems(result)
    doc = {"urdf": urdf.name, "log": " + ".join(log.name for log in logs)}
    doc.update(result.gravity.as_meta())
    doc["files"] = {joint: f"{stems[joint]}.csv" for joint in result}
    text = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    # everything is computed before the first file is written; each file is written atomically
    out.mkdir(parents=True, exist_ok=True)
    for joint, res in result.items():
        write_samples(res.by_direction, out / f"{stems[joint]}.csv")
    with atomic_write(out / GRAVITY_FILE) as fh:
        fh.write(text)
    for line in _tables(result):
        console.print(line, markup=False, highlight=False)
    for note in result.gravity.notes:
        if note.startswith(CONFOUNDED):  # warned already
            continue
        err_console.print(f"note: {note}", markup=False, highlight=False)
    err_console.print(
        f"wrote {len(result)} samples file(s) and {GRAVITY_FILE} into {out}",
        markup=False,
        highlight=False,
    )
