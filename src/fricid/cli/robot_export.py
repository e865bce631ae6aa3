"""``fricid robot export``: every joint's model at once, as one ros2_control-style YAML or one
C header and source with a function per joint and a dispatcher (:mod:`fricid.export.robot`).

A command of its own rather than ``fricid export`` with several files: that command's
argument is one model and its options describe one joint (``--joint``, ``--prefix``); a robot
needs a mapping joint -> model file and a robot name, and its outputs are the robot's."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from ._app import err_console, handle_errors, robot_app
from ._options import AllowUntrusted, SmoothZone, out_option

#: ``--to`` values and what each writes.
ROBOT_TARGETS = {
    "ros2_control": "one YAML, a block per joint (Coulomb-viscous per direction, projected)",
    "c": "<robot>_friction.h and .c: a function per joint and <robot>_friction(joint, v, load, T)",
    "urdf": "a whole-arm fit as the robot's URDF (--urdf or --robot): inertials that reproduce "
    "the identified base parameters (the rest the URDF's) and each joint's <dynamics> (its "
    "friction's Coulomb-viscous projection)",
    "mjcf": "a whole-arm fit as MJCF for MuJoCo (--urdf or --robot): inertials that reproduce "
    "the identified base parameters (the rest the URDF's), each joint's frictionloss and "
    "damping",
}


def _joint_models(files: dict[str, Path]) -> tuple[dict, dict[str, str], dict[str, str], list]:
    """joint -> (its FittedModel, its source's name, the SHA-256 of that file's bytes), and
    the joints refused (one message each); a whole-arm fit file (``fricid robot fit``'s
    output) gives every joint of the arm, in the URDF's order
    (:meth:`fricid.fitted.arm.ArmFit.joint_model`)."""
    from ..errors import ConfigError
    from ..export import file_sha256
    from ..fitted import FittedModel
    from ..fitted.arm import ARM_KIND, ArmFit
    from ..io._jsonfile import read_json

    fitted, sources, sha256, refused = {}, {}, {}, []
    for joint, path in files.items():
        doc = read_json(path, what="model file")
        if isinstance(doc, dict) and doc.get("kind") == ARM_KIND:
            arm = ArmFit.from_dict(doc, source=str(path))
            named, why = _every_joint(arm.joints, arm.joint_model)
            refused.extend(why)
        else:
            named = {joint: FittedModel.load(path)}
        for name, model in named.items():
            if name in fitted:
                raise ConfigError(f"joint '{name}' is given twice ({sources[name]} and {path})")
            fitted[name], sha256[name] = model, file_sha256(path)
            sources[name] = path.name if len(named) == 1 else f"{path.name} ({name})"
    return fitted, sources, sha256, refused


def _every_joint(joints, check) -> tuple[dict, list[str]]:
    """``check(joint)`` for every joint, and every joint's refusal (not the first alone)."""
    from ..errors import ConfigError

    out, refused = {}, []
    for joint in joints:
        try:
            out[joint] = check(joint)
        except ConfigError as exc:
            refused.append(str(exc))
    return out, refused


def _refuse(refused: list[str]) -> None:
    """One error for every joint refused, a line each."""
    from ..errors import ConfigError

    if len(refused) == 1:
        raise ConfigError(refused[0])
    if refused:
        raise ConfigError(f"{len(refused)} joints refused:\n  " + "\n  ".join(refused))


def _whole_arm(files: dict[str, Path], urdf: Path | None, robot: str | None, out):
    """The rigid-body model of the one whole-arm fit in ``files``, built from ``urdf`` (or the
    example ``robot``), and its identified standard inertial parameters."""
    from ..errors import ConfigError
    from ..fitted.arm import ARM_KIND, ArmFit
    from ..io._jsonfile import read_json
    from ..robot import RigidBodyModel
    from ._options import robot_urdf

    paths = set(files.values())
    doc = read_json(next(iter(paths)), what="model file") if len(paths) == 1 else None
    if not (isinstance(doc, dict) and doc.get("kind") == ARM_KIND):
        raise ConfigError("--to urdf and mjcf take one whole-arm fit (fricid robot fit's file)")
    path = robot_urdf(urdf, robot, "--to urdf and mjcf need the robot's URDF: ")[0]
    if out is None:
        raise ConfigError("--to urdf and mjcf write a file: give --out")
    arm = ArmFit.from_dict(doc, source=str(next(iter(paths))))
    values = arm.standard.get("values")
    if values is None:
        raise ConfigError("the arm fit has no standard inertial parameters to write")
    model = RigidBodyModel.from_urdf(path, list(arm.joints))
    return model, np.asarray(values, dtype=float)


def _model_files(items: list[str]) -> dict[str, Path]:
    """``JOINT=FILE``, a model file (joint = its stem) or a folder (its ``*.json`` files, by
    name) -> joint -> file, in the order given."""
    from ..errors import ConfigError

    out: dict[str, Path] = {}

    def add(joint: str, path: Path) -> None:
        if path.resolve() in {p.resolve() for p in out.values()}:
            raise ConfigError(f"{path} is given twice")
        if joint in out:
            raise ConfigError(f"joint '{joint}' is given twice ({out[joint]} and {path})")
        if not path.is_file():
            raise ConfigError(f"model file {path} for joint '{joint}' does not exist")
        out[joint] = path

    for item in items:
        joint, sep, rest = item.partition("=")
        if sep and joint.strip() and not Path(item).exists():
            add(joint.strip(), Path(rest.strip()))
            continue
        path = Path(item)
        if path.is_dir():
            files = sorted(path.glob("*.json"))
            if not files:
                raise ConfigError(f"folder {path} holds no model file (*.json)")
            for file in files:
                add(file.stem, file)
        else:
            add(path.stem, path)
    return out


@robot_app.command("export")
@handle_errors
def robot_export_command(
    models: Annotated[
        list[str],
        typer.Argument(
            metavar="MODEL",
            help="The joints' model files: JOINT=FILE, or FILE (the joint is its name without "
            ".json), or a folder of them (every *.json, joints in file-name order), or a "
            "whole-arm fit (fricid robot fit's output: every joint, in the URDF's order).",
        ),
    ],
    to: Annotated[
        str,
        typer.Option(
            "--to",
            help="; ".join(f"{k}: {v}" for k, v in ROBOT_TARGETS.items())
            + " (yaml: the same as ros2_control).",
        ),
    ],
    out: Annotated[
        Path | None,
        out_option(
            "c: the folder to write <robot>_friction.h and .c into (default: the current "
            "folder). ros2_control: the file to write (default: stdout). urdf, mjcf: the file "
            "to write."
        ),
    ] = None,
    robot_name: Annotated[
        str,
        typer.Option(
            "--robot-name", help="c: the C name of the robot (files, dispatcher, functions)."
        ),
    ] = "fricid",
    smooth: Annotated[
        str, typer.Option(help="c: smoothing near zero velocity: none, tanh or linear.")
    ] = "none",
    zone: SmoothZone = 0.0,
    clamp: Annotated[
        bool,
        typer.Option(
            "--clamp/--no-clamp", help="c: hold each joint's inputs in its operating range."
        ),
    ] = False,
    node: Annotated[
        str, typer.Option(help="ros2_control: the ROS 2 node the parameters are under.")
    ] = "friction_compensation",
    max_loss: Annotated[
        float,
        typer.Option(help="ros2_control: largest projection error per joint (0.5 = 50 %)."),
    ] = 0.5,
    allow_undetermined: Annotated[
        bool,
        typer.Option(
            "--allow-undetermined",
            help="Export models whose records say some parameters are not determined.",
        ),
    ] = False,
    allow_untrusted: AllowUntrusted = False,
    urdf: Annotated[
        Path | None, typer.Option(help="urdf, mjcf: the robot's URDF the arm was fitted with.")
    ] = None,
    robot: Annotated[
        str | None, typer.Option(help="urdf, mjcf: an example robot's URDF instead.")
    ] = None,
) -> None:
    """Export every joint of a robot at once: one ros2_control-style YAML with a block per
    joint, or one C header and source with a function per joint and a dispatcher
    `double <robot>_friction(int joint, double velocity, double load, double temperature)`
    (0 for an unknown joint). Each joint's part is its single-joint export (`fricid export`);
    nothing is written unless every joint exports."""
    from rich.markup import escape

    from ..errors import ConfigError
    from ..export import (
        Smoothing,
        refuse_undetermined,
        refuse_untrusted,
        undetermined_held,
        write_text,
    )
    from ..export.robot import export_robot_c, robot_ros2_yaml_text
    from ._paths import check_paths

    target = to.strip().lower()
    target = "ros2_control" if target == "yaml" else target  # the single-joint export's name
    if target not in ROBOT_TARGETS:
        raise ConfigError(f"unknown target '{to}'; choose one of: {', '.join(ROBOT_TARGETS)}")
    for flag, value in (("--urdf", urdf), ("--robot", robot)):
        if value is not None and target not in ("urdf", "mjcf"):
            err_console.print(f"note: {flag} applies to urdf and mjcf only; ignored for {target}")
    where = {"out_dirs" if target == "c" else "out_files": {"--out": out}}
    check_paths(inputs={"--urdf": urdf} if urdf is not None else {}, **where)
    files = _model_files(models)
    fitted, sources, sha256, refused = _joint_models(files)

    # ros2_control and URDF hold each joint's Coulomb-viscous projection (as the single-joint
    # yaml and urdf: never a LuGre model's sigma_0 or sigma_1); C and MJCF the parameters
    held_as = {"ros2_control": "yaml", "urdf": "urdf"}.get(target, "c")

    def refuse(joint: str) -> None:
        try:
            held = undetermined_held(fitted[joint], held_as)
            refuse_undetermined(fitted[joint], allow_undetermined, held)
        except ConfigError as exc:
            raise type(exc)(f"joint {joint}: {exc}") from None
        refuse_untrusted(fitted[joint], allow_untrusted, joint)

    _refuse(refused + _every_joint(fitted, refuse)[1])
    if target in ("urdf", "mjcf"):
        model, standard = _whole_arm(files, urdf, robot, out)
        if target == "urdf":
            from ..export.robot_urdf import write_robot_urdf

            written = write_robot_urdf(out, model, standard, fitted, max_loss=max_loss)
        else:
            from ..export._common import plain
            from ..export._trust import trust_line
            from ..export.robot_mjcf import write_robot_mjcf
            from ..export.robot_urdf import INERTIALS

            levels = {j: {n: p.value for n, p in m.parameters.items()} for j, m in fitted.items()}
            lines = [INERTIALS] + [f"joint {plain(j)}: {trust_line(m)}" for j, m in fitted.items()]
            arm = model.with_parameters(standard)
            written, notes = write_robot_mjcf(arm, out, levels, comments=lines)
            for note in notes:
                err_console.print(f"note: {escape(note)}", highlight=False)
        err_console.print(f"wrote {escape(str(written))}", highlight=False)
        return
    if target == "c":
        paths = export_robot_c(
            fitted,
            out or Path.cwd(),
            Smoothing(smooth, zone),
            robot=robot_name,
            sources=sources,
            sha256=sha256,
            clamp=clamp,
        )
        for path in paths:
            err_console.print(f"wrote {escape(str(path))}", highlight=False)
        return
    text = robot_ros2_yaml_text(
        fitted, node=node, max_loss=max_loss, sources=sources, sha256=sha256
    )
    if out is None:
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        write_text(text, out)
        err_console.print(f"wrote {escape(str(out))}", highlight=False)
