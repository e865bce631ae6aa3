"""``fricid simulate``: a raw log from the virtual joint."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ._app import app, err_console, handle_errors
from ._progress import QuietOption, progress_bar


def design_hints(scenario) -> dict:
    """What a later ``fricid extract`` needs to know about a simulated design (kept in the
    log's metadata, so the defaults of ``extract`` match the experiment)."""
    opts = scenario.extract_options()
    hints = {"gravity": opts["gravity"]}
    if opts.get("positions") is not None:
        hints["positions_rad"] = [float(p) for p in opts["positions"]]
        hints["bin_halfwidth_rad"] = float(opts["bin_halfwidth"])
    return hints


@app.command("simulate")
@handle_errors
def simulate_command(
    out: Annotated[
        Path,
        typer.Option(
            "--out", "-o", help="Raw log to write: .parquet (recommended for size) or .csv."
        ),
    ] = Path("log.parquet"),
    preset: Annotated[
        str,
        typer.Option(
            help="paper1: the BAS-RBFNN experiment (gravity, "
            "load and temperature effects); paper2: the RWSAVSBAS "
            "one (horizontal joint, Stribeck)."
        ),
    ] = "paper1",
    size: Annotated[
        str,
        typer.Option(
            help="full (the paper's design; paper1 is ~70 million "
            "samples), reduced (seconds), quick (tests)."
        ),
    ] = "reduced",
    seed: Annotated[int, typer.Option(help="Random seed (same seed, same log).")] = 0,
    coverage: Annotated[
        str,
        typer.Option(
            help="both (each direction over the whole range) or split (forward runs logged on "
            "the lower half of the range, backward runs on the upper half: eq. 11 cannot pair "
            "them, extract identifies gravity jointly)."
        ),
    ] = "both",
    quiet: QuietOption = False,
) -> None:
    """Simulate a bidirectional constant-velocity campaign on the virtual joint and write its
    raw log: time [s], position [rad], velocity [rad/s], motor current [A] (torque = K I),
    temperature [degC], with the torque constant K in the file's metadata. Progress goes to
    stderr (a bar on a terminal, a line per tenth with the time left otherwise; --quiet: none)."""
    from ..io import write_rawlog
    from ..sim import preset as get_preset
    from ..sim import simulate

    scenario = get_preset(preset, size)
    scenario = replace(scenario, design=replace(scenario.design, coverage=coverage))
    hints = design_hints(scenario)
    n_t, n_v, _ = scenario.design.shape

    def chunks():
        with progress_bar(
            f"simulating {scenario.name} ({size})",
            total=n_t * n_v,
            unit="velocity-temperature runs",
            quiet=quiet,
        ) as advance:
            for log in simulate(scenario, seed=seed):
                advance()
                yield replace(log, meta={**log.meta, "design": hints})

    write_rawlog(chunks(), out)
    err_console.print(f"wrote {escape(str(out))} ({scenario.name}, {size}, seed {seed})")
