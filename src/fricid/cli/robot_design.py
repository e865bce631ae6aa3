"""``fricid robot design``: a Fourier excitation of every joint of a robot, optimised within
its limits, written as a design file, a CSV table and a ROS 2 JointTrajectory YAML, with the
parameters' predicted standard errors printed before anyone moves the robot."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape

from ..errors import ConfigError
from ._app import console, handle_errors, robot_app
from ._options import out_option, robot_urdf
from ._paths import check_paths
from ._progress import QuietOption, tracker

__all__ = ["design_command", "parse_noise", "parse_workspace"]


def parse_workspace(text: str | None) -> dict[str, tuple[float, float]]:
    """``'j1=-1:1,j2=0:0.5'`` -> ``{"j1": (-1.0, 1.0), "j2": (0.0, 0.5)}``."""
    out: dict[str, tuple[float, float]] = {}
    for item in (text or "").split(","):
        if not item.strip():
            continue
        name, sep, rng = item.partition("=")
        lo, colon, hi = rng.partition(":")
        try:
            pair = (float(lo), float(hi))
        except ValueError:
            pair = None
        if not sep or not colon or not name.strip() or pair is None:
            raise ConfigError(f"--workspace takes JOINT=LO:HI[,JOINT=LO:HI...]; got '{item}'")
        out[name.strip()] = pair
    return out


def _model(urdf: Path | None, robot: str | None, joints: str | None):
    from ..robot import RigidBodyModel

    path, default = robot_urdf(urdf, robot)
    if urdf is not None:
        check_paths(inputs={"--urdf": urdf})
    names = [j.strip() for j in joints.split(",") if j.strip()] if joints else default
    return RigidBodyModel.from_urdf(path, names), str(path)


def _design_lines(design) -> list[str]:
    m = design.margins
    lines = [
        f"condition number {design.cond:.4g} (best random start {design.cond_start:.4g}), "
        f"log det W'W/rows {design.logdet:.4g} (start {design.logdet_start:.4g}); "
        f"{design.evaluations} evaluations, {design.seconds:.1f} s, "
        f"{'converged' if design.converged else 'not converged: ' + design.message}",
        f"peak / limit (the limits less the margin of {100 * design.limits['margin']:.0f} %):",
        f"  {'joint':<20} {'position':>9} {'velocity':>9} {'accel.':>9} {'effort':>9}",
    ]
    for i, j in enumerate(design.joints):
        row = [float(m[k][i]) for k in ("position", "velocity", "acceleration", "effort")]
        flag = "  <- at a limit" if max(v for v in row if v == v) > 0.98 else ""
        shown = (f"{100 * v:8.1f}%" if v == v else " no limit" for v in row)
        lines.append(f"  {j:<20} " + " ".join(shown) + flag)
    return lines


def _peaks_text(peaks: dict) -> str:
    """``position 93.2 %, velocity 99.7 %, ...``: each quantity's worst peak over its limit
    (a quantity without any limit left out)."""
    worst = {k: float(np.nanmax(v)) for k, v in peaks.items() if np.isfinite(v).any()}
    return ", ".join(f"{k} {100 * v:.1f} %" for k, v in worst.items())


def parse_noise(text: str, n: int) -> np.ndarray:
    """``"0.05"`` or ``"0.05,0.1,..."`` (one per joint) -> the noise std per joint [N m]."""
    try:
        values = np.array([float(x) for x in text.split(",")])
    except ValueError:
        values = np.array([])
    if values.size not in (1, n) or not (np.isfinite(values).all() and (values > 0).all()):
        raise ConfigError(
            f"--torque-noise takes one positive number or {n} (one per joint); got '{text}'"
        )
    return np.broadcast_to(values, (n,)).copy()


def _error_lines(design, model, sigma: np.ndarray, rate: float, duration: float) -> list[str]:
    se = design.standard_errors(model, sigma, rate=rate, duration=duration)
    shown = f"{sigma[0]:g} N m per joint" if np.all(sigma == sigma[0]) else (
        "[" + ", ".join(f"{s:g}" for s in sigma) + "] N m"
    )  # fmt: skip
    lines = [
        f"predicted standard errors with torque noise {shown}, {duration:g} s at {rate:g} Hz:",
    ]
    width = min(60, max(len(n) for n in design.names))
    for name, s in zip(design.names, se, strict=True):
        shown = name if len(name) <= width else name[: width - 3] + "..."
        lines.append(f"  {shown:<{width}} {s:10.3g}")
    return lines


@robot_app.command("design", short_help="Design an excitation trajectory within the limits.")
@handle_errors
def design_command(
    out: Annotated[Path, out_option("The design file to write (JSON, re-read by fricid).")],
    urdf: Annotated[Path | None, typer.Option(help="The robot's URDF.")] = None,
    robot: Annotated[
        str | None, typer.Option(help="An example robot: panda, ur5, double_pendulum.")
    ] = None,
    joints: Annotated[
        str | None, typer.Option(help="Comma-separated joints to move (default: all).")
    ] = None,
    harmonics: Annotated[int, typer.Option(min=1, help="Harmonics per joint.")] = 5,
    period: Annotated[float, typer.Option(min=0.1, help="The period [s].")] = 10.0,
    criterion: Annotated[str, typer.Option(help="cond or d-optimal.")] = "cond",
    friction: Annotated[
        str, typer.Option(help="Friction columns: coulomb_viscous_asym, coulomb_viscous, none.")
    ] = "coulomb_viscous_asym",
    workspace: Annotated[
        str | None,
        typer.Option(help="Per-joint ranges within the URDF's, 'j1=-1:1,j2=0:0.5' [rad or m]."),
    ] = None,
    acceleration: Annotated[
        float | None,
        typer.Option(help="Acceleration limit [rad/s^2] (default velocity limit x w_f x H)."),
    ] = None,
    margin: Annotated[float, typer.Option(help="Fraction of each limit kept free.")] = 0.05,
    at_rest: Annotated[
        bool, typer.Option("--at-rest", help="Every joint at rest at the start of a period.")
    ] = False,
    torque_noise: Annotated[
        str,
        typer.Option(
            help="Torque noise std [N m] for the standard errors: one number, or one per joint "
            "(comma-separated)."
        ),
    ] = "0.05",
    duration: Annotated[
        float, typer.Option(min=0.0, help="Seconds of excitation played (periods rounded up).")
    ] = 60.0,
    rate: Annotated[float, typer.Option(min=1.0, help="Log and CSV rate [Hz].")] = 1000.0,
    yaml_rate: Annotated[float, typer.Option(min=1.0, help="Points per second in YAML.")] = 100.0,
    ramp: Annotated[float, typer.Option(min=0.1, help="Blend from and to rest [s].")] = 1.0,
    starts: Annotated[int, typer.Option(min=1, help="Random starts drawn.")] = 8,
    max_evaluations: Annotated[
        int, typer.Option(min=1, help="Criterion evaluations (Panda: 10000 in about 30 s).")
    ] = 10000,
    seed: Annotated[int, typer.Option(min=0, help="Seed of the random starts.")] = 0,
    csv: Annotated[Path | None, typer.Option(help="Also write the trajectory as CSV.")] = None,
    ros_yaml: Annotated[
        Path | None, typer.Option(help="Also write a ROS 2 JointTrajectory YAML.")
    ] = None,
    quiet: QuietOption = False,
) -> None:
    """Design a periodic Fourier excitation of every joint (Swevers et al. 1997) that
    minimises the condition number of the stacked base regressor and friction columns (or
    maximises log det, --criterion d-optimal) within the URDF's position, velocity and effort
    limits, an acceleration limit and your --workspace. Prints the condition number against
    the best random start, each joint's peaks against its limits, and the predicted standard
    error of every base parameter and friction coefficient for --torque-noise over --duration.
    The CSV and YAML play the excitation for --duration (whole periods), blended from rest and
    back to rest over --ramp s each; bring the robot to rest at the first point first."""
    from ..robot.excitation import design_excitation
    from ..robot.excitation_files import (
        save_design,
        write_joint_trajectory_yaml,
        write_trajectory_csv,
    )

    check_paths(out_files={"--out": out, "--csv": csv, "--ros-yaml": ros_yaml})
    model, source = _model(urdf, robot, joints)
    with tracker("designing the excitation", max_evaluations, unit="evaluations", quiet=quiet) as t:
        design = design_excitation(
            model,
            harmonics=harmonics,
            period=period,
            criterion=criterion,
            friction=friction,
            workspace=parse_workspace(workspace),
            acceleration_limit=acceleration,
            margin=margin,
            at_rest=at_rest,
            starts=starts,
            seed=seed,
            max_evaluations=max_evaluations,
            progress=lambda done, total: t.update(done, total=total),
        )
    periods = max(1, math.ceil(duration / design.trajectory.period - 1e-9))
    lines = [f"{model.n} joints of {source}: {', '.join(model.joints)}", *_design_lines(design)]
    sigma = parse_noise(torque_noise, model.n)
    lines += _error_lines(design, model, sigma, rate, periods * design.trajectory.period)
    from ..robot.limits import assumed_limits, ramped_within_limits

    asked = ramp
    played, ramp, whole, first = ramped_within_limits(
        model, design.trajectory, periods, ramp, design.limits, rate
    )
    lines.append(
        f"played: {periods} periods with {ramp:g} s ramps, {played.duration:.2f} s; worst peak / "
        "limit " + _peaks_text(whole)
    )
    if ramp != asked:
        lines.append(
            f"ramps lengthened from {asked:g} s: with them the peaks were {_peaks_text(first)}"
        )
    assumed = assumed_limits(model)
    if assumed:
        lines.append("no limit in the URDF, so assumed: " + "; ".join(assumed))
    extra = {"source": source, "torque_noise": sigma.tolist(), "periods": periods, "ramp": ramp}
    extra["locked"] = {str(k): float(v) for k, v in model.locked.items()}
    written = [save_design(design, out, extra)]
    if csv is not None:
        written.append(write_trajectory_csv(played, csv, rate=rate, kinds=model.kinds))
    if ros_yaml is not None:
        written.append(write_joint_trajectory_yaml(played, ros_yaml, rate=yaml_rate))
    lines.append("wrote " + ", ".join(str(p) for p in written))
    console.print(escape("\n".join(lines)), highlight=False, soft_wrap=True)
