"""``fricid compensate``: the tracking gain of a model used as friction feed-forward."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from ._app import app, console, err_console, handle_errors
from ._options import ModelFile, SmoothKind, SmoothZone


def truth_names() -> tuple[str, ...]:
    """``--truth`` choices: ``model``, then every simulation preset."""
    from ..sim import PRESETS

    return ("model", *PRESETS)


def resolve_truth(name: str):
    """The plant's friction for ``--truth``: None for the model itself, else the virtual
    joint of that simulation preset (:func:`fricid.sim.preset`, its law and inertia)."""
    from ..control import Truth
    from ..errors import ConfigError
    from ..sim import preset

    key = str(name).strip().lower()
    if key not in truth_names():
        raise ConfigError(f"unknown truth '{name}'; choose one of: {', '.join(truth_names())}")
    if key == "model":
        return None
    joint = preset(key, "quick").joint
    return Truth(joint.law, key, joint.inertia)


@app.command("compensate")
@handle_errors
def compensate_command(
    model: ModelFile,
    truth: Annotated[
        str,
        typer.Option(
            help=(
                "True friction of the simulated joint: model (the model itself, i.e. the gain "
                "if it were exact), paper1 or paper2 (the virtual joint's law of that "
                "simulation preset, and its inertia)."
            )
        ),
    ] = "model",
    frequency: Annotated[float, typer.Option(help="Reference sinusoid frequency [Hz].")] = 0.2,
    peak_velocity: Annotated[
        float | None,
        typer.Option(
            help=("Peak reference velocity [rad/s]. Default: half the largest identified speed.")
        ),
    ] = None,
    periods: Annotated[float, typer.Option(help="Reference periods simulated.")] = 2.0,
    inertia: Annotated[float, typer.Option(help="Joint inertia [kg m^2] (truth=model).")] = 0.01,
    bandwidth: Annotated[
        float,
        typer.Option(
            help=("PD bandwidth [Hz]: K_p = J (2 pi f)^2, K_d = 2 J (2 pi f) (critically damped).")
        ),
    ] = 10.0,
    kp: Annotated[
        float | None, typer.Option(help="Proportional gain [N m/rad] (overrides).")
    ] = None,
    kd: Annotated[
        float | None, typer.Option(help="Derivative gain [N m s/rad] (overrides).")
    ] = None,
    load: Annotated[
        float | None,
        typer.Option(
            help=("Joint load [N m] (friction input). Default: middle of the identified range.")
        ),
    ] = None,
    temperature: Annotated[
        float | None,
        typer.Option(help=("Temperature [degC]. Default: middle of the identified range.")),
    ] = None,
    dt: Annotated[float, typer.Option(help="Integration step [s].")] = 2e-4,
    smooth: SmoothKind = "none",
    zone: SmoothZone = 0.0,
    plot: Annotated[
        Path | None,
        typer.Option(
            help=("PNG to write. Default: <model>.compensation.png in the current directory.")
        ),
    ] = None,
    no_plot: Annotated[bool, typer.Option("--no-plot", help="Write no figure.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print the result as JSON.")] = False,
) -> None:
    """Simulate the joint tracking a slow sinusoid (crossing zero velocity) under PD control,
    without and with the model as torque feed-forward, and report the tracking error (RMS
    and max) of both, with a plot.

    The plant sticks at zero velocity until the applied torque exceeds the break-away
    friction (fixed-step Karnopp scheme); the feed-forward is the model at the reference
    velocity. See `fricid.control.tracking` for every detail.
    """
    from ..control import compensation_study, default_config, plot_compensation
    from ..models.smoothing import Smoothing
    from ..fitted import FittedModel

    fitted = FittedModel.load(model)
    config = default_config(
        fitted,
        frequency=frequency,
        peak_velocity=peak_velocity,
        periods=periods,
        inertia=inertia,
        bandwidth=bandwidth,
        kp=kp,
        kd=kd,
        load=load,
        temperature=temperature,
        dt=dt,
    )
    result = compensation_study(
        fitted, config, truth=resolve_truth(truth), smoothing=Smoothing(smooth, zone)
    )
    if not no_plot:
        plot_path = plot or Path(f"{model.stem}.compensation.png")
        plot_compensation(result, plot_path)
        err_console.print(f"wrote {plot_path}")
    if as_json:
        console.print_json(json.dumps(result.to_dict()))
        return
    cfg = result.config
    k_p, k_d = cfg.gains
    table = Table(
        title=(
            f"Tracking {cfg.amplitude:.3g} rad sin(2 pi {cfg.frequency:g} Hz t), model "
            f"'{fitted.model}', true friction '{result.truth}'"
        )
    )
    table.add_column("controller")
    table.add_column(escape("RMS error [mrad]"), justify="right")
    table.add_column(escape("max error [mrad]"), justify="right")
    table.add_row(
        "PD only", f"{1e3 * result.rms['without']:.4g}", f"{1e3 * result.max['without']:.4g}"
    )
    table.add_row(
        "PD + friction feed-forward",
        f"{1e3 * result.rms['with']:.4g}",
        f"{1e3 * result.max['with']:.4g}",
    )
    console.print(table)
    console.print(
        f"RMS error {result.improvement:.3g}x smaller with feed-forward "
        f"(K_p {k_p:.4g} N m/rad, K_d {k_d:.4g} N m s/rad, J {cfg.inertia:g} kg m^2, "
        f"load {cfg.load:.4g} N m, temperature {cfg.temperature:.4g} degC, dt {cfg.dt:g} s)",
        highlight=False,
    )
    for note in result.notes:
        console.print(f"note: {note}", highlight=False)
