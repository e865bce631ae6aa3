"""``fricid export``: a model file to C code, URDF, MJCF or ros2_control-style YAML."""

from __future__ import annotations

import difflib
import sys
from pathlib import Path
from typing import Annotated

import typer

from ._app import app, err_console, handle_errors
from ._options import AllowUntrusted, ModelFile, SmoothZone, out_option
from ._paths import check_paths


def _targets_help() -> str:
    from ..export import TARGETS

    return "Target: " + "; ".join(f"{name}: {line}" for name, line in TARGETS.items()) + "."


def _is_arm_fit(path: Path) -> bool:
    """The file is a whole-arm fit (its ``kind``), which ``fricid robot export`` takes."""
    from ..fitted.arm import ARM_KIND
    from ..io._jsonfile import read_json

    doc = read_json(path, what="model file")
    return isinstance(doc, dict) and doc.get("kind") == ARM_KIND


@app.command("export")
@handle_errors
def export_command(
    model: ModelFile,
    to: Annotated[str, typer.Option("--to", help=_targets_help())],
    out: Annotated[
        Path | None,
        out_option(
            "For c: the directory to write <prefix>_friction.h and .c into (default: the "
            "current directory). For urdf, mjcf, yaml: the file to write (default: stdout)."
        ),
    ] = None,
    smooth: Annotated[
        str,
        typer.Option(
            help=(
                "C only. Smoothing near zero velocity: none (the model as identified), tanh "
                "(sign(v) -> tanh(v/zone), analytic models), linear (straight lines from 0 at "
                "rest to the model's values at -zone and +zone, every model)."
            )
        ),
    ] = "none",
    zone: SmoothZone = 0.0,
    prefix: Annotated[
        str,
        typer.Option(
            help=("C only: the function is <prefix>_friction (change it to link several joints).")
        ),
    ] = "fricid",
    clamp: Annotated[
        bool,
        typer.Option(
            "--clamp/--no-clamp",
            help=(
                "C only. Hold the inputs inside the model's operating range (recorded in the "
                "model file) before evaluating: load and temperature to [low, high]; velocity "
                "to [low, high] if the range spans zero, else its magnitude to at most the "
                "largest identified speed, sign kept. Off by default: outside the range the "
                "model extrapolates. The header comment states the range either way."
            ),
        ),
    ] = False,
    joint: Annotated[str, typer.Option(help="Joint name in URDF, MJCF and YAML.")] = "joint",
    node: Annotated[
        str, typer.Option(help="YAML only: the ROS 2 node name the parameters are under.")
    ] = "friction_compensation",
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
    inertia: Annotated[
        float | None,
        typer.Option(
            help=(
                "MJCF only: the joint's inertia [kg m^2] for measuring the integrator and "
                "timestep in MuJoCo (default: the one a trajectory fit identified, else 0.01)."
            ),
        ),
    ] = None,
    timestep_check: Annotated[
        bool,
        typer.Option(
            "--timestep-check/--no-timestep-check",
            help=(
                "MJCF only: measure in MuJoCo (when installed; about a second) the integrator "
                "and largest timestep that keep the break-away within 5 % and a held-out "
                "trajectory within 1 % of its span, and write them as <option> with the "
                "measured errors; without MuJoCo a conservative default, said so."
            ),
        ),
    ] = True,
    allow_undetermined: Annotated[
        bool,
        typer.Option(
            "--allow-undetermined",
            help=(
                "Export a model identified from a trajectory even though its records say the "
                "data do not determine some parameters (refused otherwise); the file's comment "
                "names them."
            ),
        ),
    ] = False,
    allow_untrusted: AllowUntrusted = False,
) -> None:
    """Export a model for a controller or a simulator.

    C gets the full model (every family, per-direction and RBF included) as one function,
    `double fricid_friction(double velocity, double load, double temperature)` in SI units,
    libm only, no allocation. URDF, MJCF and YAML hold Coulomb plus viscous friction, so they
    get the least-squares projection over the model's operating range, with its error and
    what is lost stated in a comment. Every file names the model by its file name (escaped)
    and the SHA-256 of its bytes; no other text of the model file is written except as
    escaped plain text, and every number is checked finite. A file is written whole or not at
    all: on error nothing is.
    """
    from rich.markup import escape

    from ..errors import ConfigError, DataError
    from ..export import (
        TARGETS,
        ExportError,
        Smoothing,
        description_text,
        export_c,
        file_sha256,
        refuse_undetermined,
        refuse_untrusted,
        undetermined_held,
        write_text,
    )
    from ..export._trust import trust_line
    from ..export.c import no_c_template
    from ..export.mjcf import is_lugre, lugre_mapping
    from ..fitted import FittedModel

    target = to.strip().lower()
    check_paths(
        inputs={"MODEL": model}, **{"out_dirs" if target == "c" else "out_files": {"--out": out}}
    )
    if target not in TARGETS:
        near = {"mujoco": "mjcf", "yml": "yaml", "ros": "yaml", "ros2": "yaml"}.get(target)
        near = near or next(iter(difflib.get_close_matches(target, list(TARGETS), n=1)), None)
        hint = f" (did you mean '{near}'?)" if near else ""
        raise ConfigError(
            f"unknown export target '{to}'{hint}; choose one of: {', '.join(TARGETS)}"
        )
    if _is_arm_fit(model):
        raise ConfigError(
            f"{model} is a whole-arm fit (fricid robot fit's output): export its joints with "
            f"fricid robot export {model} --to c (or ros2_control); the whole robot's URDF and "
            "MJCF are written from Python (the robots how-to)"
        )
    fitted = FittedModel.load(model)
    if target == "c" and (why := no_c_template(fitted)):  # before a flag that would not help
        raise ExportError(why)
    # only what the file's numbers depend on (a projection does not read LuGre's sigma_1)
    refuse_undetermined(fitted, allow_undetermined, undetermined_held(fitted, target))
    refuse_untrusted(fitted, allow_untrusted)
    sha256 = file_sha256(model)
    try:
        if target == "c":
            paths = export_c(
                fitted,
                out or Path.cwd(),
                Smoothing(smooth, zone),
                prefix=prefix,
                source=model.name,
                sha256=sha256,
                clamp=clamp,
            )
            from ..export.clamp import unclamped_speeds

            unheld = unclamped_speeds(fitted) if clamp else ""
            if unheld:
                err_console.print(
                    f"warning: {unheld}", markup=False, highlight=False, soft_wrap=True
                )
            _say_trust([trust_line(fitted)])
            for path in paths:
                err_console.print(f"wrote {escape(str(path))}", highlight=False)
            return
        for flag, given in (("--smooth", smooth != "none"), ("--clamp", clamp)):
            if given:
                err_console.print(
                    f"note: {flag} applies to the C export only; ignored for {target}"
                )
        options: dict = {"node": node} if target == "yaml" else {}
        advice = None
        if target == "mjcf" and timestep_check:
            from ..export.mujoco_step import model_inertia, timestep_advice

            bare = description_text(target, fitted, joint=joint, max_loss=max_loss)
            advice = timestep_advice(bare, *model_inertia(fitted, inertia))
            options["timestep"] = advice
        text = description_text(
            target,
            fitted,
            joint=joint,
            max_loss=max_loss,
            source=model.name,
            sha256=sha256,
            **options,
        )
    except DataError as exc:  # a bad value in the model: name the file the user gave
        if exc.file is not None:
            raise
        raise DataError(exc.message, file=model, row=exc.row, column=exc.column) from None
    if target == "mjcf" and is_lugre(fitted):  # what the mapping to MuJoCo costs, said here too
        for line in lugre_mapping(fitted).summary()[2:]:
            err_console.print(f"note: {line}", markup=False, highlight=False, soft_wrap=True)
    for line in advice.lines() if advice is not None else ():
        err_console.print(f"note: {line}", markup=False, highlight=False, soft_wrap=True)
    _say_trust(text.splitlines())
    if out is None:
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        write_text(text, out)
        err_console.print(f"wrote {escape(str(out))}", highlight=False)


def _say_trust(lines: list[str]) -> None:
    """The exported file's trust line on stderr unless it is a plain 'yes' (a script that
    exports sees a 'NO for this file's numbers' or a missing verdict, not only the file)."""
    said = next((ln for ln in lines if "trust verdict: " in ln), "")
    said = said[said.find("trust verdict: ") :]
    if said and not said.startswith("trust verdict: yes"):
        err_console.print(f"warning: {said}", markup=False, highlight=False, soft_wrap=True)
