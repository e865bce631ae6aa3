"""``fricid robot fit``: a whole arm's base inertial parameters and every joint's friction from
one log of any trajectory (:func:`fricid.identify.dynamic.arm.fit_arm`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from ..errors import ConfigError
from ._app import console, handle_errors, robot_app
from ._options import out_option
from ._paths import check_paths
from .robot_simulate import _ROBOTS, _model


def _split(text: str | None) -> list[str] | None:
    if not text:
        return None
    return [p.strip() for p in text.split(",") if p.strip()]


def _friction(text: str):
    """``stribeck_asym`` or ``joint1=coulomb_viscous,joint2=stribeck_asym``."""
    if "=" not in text:
        return text
    out = {}
    for part in _split(text) or []:
        name, sep, family = part.partition("=")
        if not sep or not name.strip() or not family.strip():
            raise ConfigError(f"--friction: expected JOINT=FAMILY, got {part!r}")
        out[name.strip()] = family.strip()
    return out


def _pm(rec: dict) -> str:
    if rec.get("not_determined") or rec.get("value") is None:
        return "not determined"
    low, high = rec["ci95"]
    if low is None:
        return f"{rec['value']:.4g}"
    half, mid = (high - low) / 2, (high + low) / 2
    if abs(mid - rec["value"]) <= 0.05 * half:  # symmetric about the value
        text = f"{rec['value']:.4g} +- {half:.2g}"
    else:  # one-sided (a search box's face, zero, a profile region): its two ends
        text = f"{rec['value']:.4g} [{low:.3g}, {high:.3g}]"
    return text + (" (not bounded)" if rec.get("note", "").startswith("not bounded") else "")


def _table(fit) -> None:
    from rich.table import Table

    table = Table(title="Friction per joint (95 % intervals)")
    table.add_column("joint")
    table.add_column("family")
    table.add_column("parameters")
    table.add_column("held-out / noise", justify="right")
    table.add_column("verdict")
    for joint in fit.joints:
        entry = fit.friction[joint]
        params = "; ".join(f"{n} {_pm(r)}" for n, r in entry["parameters"].items())
        check = fit.validation[joint]
        ratio = check.get("ratio")
        ratio_text = f"{ratio:.2f}" if ratio is not None and np.isfinite(ratio) else "-"
        verdict = check["level"] + (f": {'; '.join(check['reasons'])}" if check["reasons"] else "")
        table.add_row(joint, entry["family"], params, ratio_text, verdict)
    console.print(table)
    se = np.array([np.nan if s is None else s for s in fit.base["stderr"]], dtype=float)
    values = np.asarray(fit.base["values"], dtype=float)
    determined = np.isfinite(se)
    well = determined & (np.abs(values) > 2 * np.nan_to_num(se, nan=np.inf))
    console.print(
        f"Base inertial parameters: {values.size}, {int(determined.sum())} determined, "
        f"{int(well.sum())} well determined (|value| > 2 standard errors); standard parameters "
        f"{fit.standard.get('used', 'not made consistent')}"
        + (
            " (the least-squares estimate "
            + ("was already" if fit.standard["consistent_ls"] else "was not")
            + " physically consistent)"
            if "consistent_ls" in fit.standard
            else ""
        )
    )
    prov = fit.provenance
    console.print(
        f"Estimator {prov['estimator']}; low-pass {prov['cutoff']:.3g} Hz, decimation "
        f"{prov['decimation']}, {prov['samples']} equations; {prov['seconds']:.1f} s"
    )
    if str(prov.get("closed_loop", "")).startswith("detected"):
        console.print(f"Closed loop {prov['closed_loop']}.")


@robot_app.command("fit")
@handle_errors
def robot_fit_command(
    log: Annotated[Path, typer.Argument(help="The robot log (CSV, Parquet, ROS 2 bag, folder).")],
    out: Annotated[Path, out_option("The fit file to write (JSON).")],
    urdf: Annotated[Path | None, typer.Option(help="The robot's URDF.")] = None,
    robot: Annotated[
        str | None,
        typer.Option(help=f"An example robot instead of --urdf: {_ROBOTS}."),
    ] = None,
    joints: Annotated[
        str | None,
        typer.Option(help="Joints to identify, comma-separated (default: the URDF's movable)."),
    ] = None,
    friction: Annotated[
        str,
        typer.Option(
            help="Friction family for every joint (stribeck_asym, coulomb_viscous_asym, "
            "coulomb_viscous, stribeck; coulomb_viscous_load(_asym): Coulomb friction growing "
            "with the joint's load, eq. 3 of the BAS-RBFNN paper, the load being the log's "
            "load channel or else the arm's gravity torque; lugre: dynamic friction, its "
            "bristles identified from every row given the arm's rigid body, each parameter "
            "reported not determined where the log does not inform it) or JOINT=FAMILY,... "
            "per joint."
        ),
    ] = "stribeck_asym",
    validate: Annotated[
        Path | None,
        typer.Option(help="A second log for held-out validation (default: the last quarter)."),
    ] = None,
    encoder_counts: Annotated[
        int | None, typer.Option(help="Encoder counts per revolution (default: from the log).")
    ] = None,
    cutoff: Annotated[
        float | None, typer.Option(help="Low-pass cut-off [Hz] (default: chosen from the log).")
    ] = None,
    consistent: Annotated[
        bool, typer.Option(help="Make the inertial parameters physically consistent.")
    ] = True,
    closed_loop: Annotated[
        bool | None,
        typer.Option(
            "--closed-loop/--open-loop",
            help=(
                "--closed-loop: the log was recorded under position control (a PD loop): leave "
                "out the rows within one period of the cut-off of every reversal, where the "
                "joint sticks while the loop builds torque and the filtered friction columns do "
                "not hold (measured on a PD-tracked arm: Coulomb levels 4 standard errors low "
                "without it), up to 1.5 periods for a joint whose residuals show its sticks "
                "farther out (each joint's window is in the fit file). --open-loop: keep those "
                "rows, which carry the Stribeck rise of an open-loop log. Default: decided from "
                "the data, closed loop when a joint's residuals near its reversals show sticks "
                "(the fit file's provenance says which, and the printout; a law without a "
                "Stribeck rise leaves such a misfit in open loop too, and the printout says so)."
            ),
        ),
    ] = None,
) -> None:
    """Identify a whole arm from any trajectory: base inertial parameters and every joint's
    friction together, with intervals and a held-out verdict per joint."""
    from ..identify.dynamic.arm import WINDOW_PERIODS, fit_arm
    from ..io import read_robot_log

    if urdf is None and robot is None:
        raise ConfigError("give --urdf (your robot's URDF) or --robot (an example robot)")
    inputs = {"LOG": log, "--urdf": urdf, "--validate": validate}
    inputs = {k: v for k, v in inputs.items() if v is not None}
    check_paths(inputs=inputs, folders=["LOG", "--validate"], out_files={"--out": out})
    model = _model(robot, urdf, joints)
    data = read_robot_log(log, joints=list(model.joints))
    second = read_robot_log(validate, joints=list(model.joints)) if validate else None
    fit = fit_arm(
        data,
        model,
        friction=_friction(friction),
        consistent=consistent,
        encoder_counts=encoder_counts,
        cutoff=cutoff,
        validate=second,
        urdf=Path(model.source).name if model.source else None,
        reversal_window=None if closed_loop is None else WINDOW_PERIODS * closed_loop,
    )
    fit.save(out)
    _table(fit)
    console.print(f"Wrote {out}")
