"""``fricid export``: a model file to C code, URDF, MJCF or ros2_control-style YAML."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from ._app import app, err_console, handle_errors
from ._paths import check_paths


def _targets_help() -> str:
    from ..export import TARGETS

    return "Target: " + "; ".join(f"{name}: {line}" for name, line in TARGETS.items()) + "."


@app.command("export")
@handle_errors
def export_command(
    model: Annotated[
        Path,
        typer.Argument(help="Model file (JSON, from `fricid fit`)."),
    ],
    to: Annotated[str, typer.Option("--to", help=_targets_help())],
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            help=(
                "For c: the directory to write <prefix>_friction.h and .c into (default: the "
                "current directory). For urdf, mjcf, yaml: the file to write (default: stdout)."
            ),
        ),
    ] = None,
    smooth: Annotated[
        str,
        typer.Option(
            help=(
                "C only. Smoothing near zero velocity: none (the model as identified), tanh "
                "(sign(v) -> tanh(v/zone), analytic models), linear (straight line between the "
                "model's values at -zone and +zone, every model)."
            )
        ),
    ] = "none",
    zone: Annotated[float, typer.Option(help="Half-width of the smoothing zone [rad/s].")] = 0.0,
    prefix: Annotated[
        str,
        typer.Option(
            help=("C only: the function is <prefix>_friction (change it to link several joints).")
        ),
    ] = "fricid",
    joint: Annotated[str, typer.Option(help="Joint name in URDF, MJCF and YAML.")] = "joint",
    max_loss: Annotated[
        float,
        typer.Option(
            help=(
                "URDF, MJCF, YAML: largest accepted projection error, RMS error / RMS friction "
                "over the operating range (0.5 = 50 %). Beyond it the export is refused and "
                "says what would be lost."
            )
        ),
    ] = 0.5,
) -> None:
    """Export a model for a controller or a simulator.

    C gets the full model (every family, per-direction and RBF included) as one function,
    `double fricid_friction(double velocity, double load, double temperature)` in SI units,
    libm only, no allocation. URDF, MJCF and YAML hold Coulomb plus viscous friction, so they
    get the least-squares projection over the model's operating range, with its error and
    what is lost stated in a comment. Files are written atomically; on error nothing is.
    """
    from ..errors import ConfigError
    from ..export import TARGETS, Smoothing, description_text, export_c, write_text
    from ..fitted import FittedModel

    target = to.strip().lower()
    check_paths(
        inputs={"MODEL": model}, **{"out_dirs" if target == "c" else "out_files": {"--out": out}}
    )
    if target not in TARGETS:
        raise ConfigError(f"unknown export target '{to}'; choose one of: {', '.join(TARGETS)}")
    fitted = FittedModel.load(model)
    if target == "c":
        paths = export_c(
            fitted, out or Path.cwd(), Smoothing(smooth, zone), prefix=prefix, source=model.name
        )
        for path in paths:
            err_console.print(f"wrote {path}")
        return
    if smooth != "none":
        err_console.print(f"note: --smooth applies to the C export only; ignored for {target}")
    text = description_text(target, fitted, joint=joint, max_loss=max_loss, source=model.name)
    if out is None:
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        write_text(text, out)
        err_console.print(f"wrote {out}")
