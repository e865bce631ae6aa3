"""``fricid simulate``: a raw log from the virtual joint."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ._app import app, err_console, handle_errors
from ._progress import QuietOption, progress_bar

#: Raw samples of the full ``paper1`` campaign, in millions, for ``--help`` (importing the
#: simulator to count them would slow every command's start; tests/cli checks the count
#: against ``preset("paper1", "full").design.n_samples()``).
PAPER1_FULL_MILLIONS = 79


def design_hints(scenario) -> dict:
    """What a later ``fricid extract`` needs to know about a simulated design (kept in the
    log's metadata, so the defaults of ``extract`` match the experiment)."""
    opts = scenario.extract_options()
    hints = {"gravity": opts["gravity"]}
    if opts.get("positions") is not None:
        hints["positions_rad"] = [float(p) for p in opts["positions"]]
        hints["bin_halfwidth_rad"] = float(opts["bin_halfwidth"])
    return hints


#: ``--duration``'s default [s].
DEFAULT_DURATION = 20.0


def _check_kind(trajectory, preset: str, size: str, coverage: str, duration: float) -> None:
    """Refuse options of the other kind of log (they would be ignored without a word: a
    ``--preset paper2`` trajectory log was byte for byte the default's)."""
    from ..errors import ConfigError

    if trajectory is not None:
        given = [
            f"--{name} {value}"
            for name, value, default in (
                ("preset", preset, "paper1"),
                ("size", size, "reduced"),
                ("coverage", coverage, "both"),
            )
            if value != default
        ]
        if given:
            raise ConfigError(
                f"{', '.join(given)}: not for --trajectory, which simulates one experiment on the "
                "documented joint; drop them, or drop --trajectory for a campaign"
            )
    elif duration != DEFAULT_DURATION:
        raise ConfigError(
            "--duration is the length of a --trajectory experiment; a campaign's length comes "
            "from --preset and --size"
        )


def _trajectory_log(kind: str, duration: float, seed: int):
    """The log of one trajectory experiment on the documented joint (see simulate's help)."""
    import inspect

    import numpy as np

    from ..errors import ConfigError
    from ..sim import Joint
    from ..sim import trajectory as tr

    if kind not in tr.KINDS:
        raise ConfigError(f"--trajectory must be one of {', '.join(tr.KINDS)}; got {kind!r}")
    if not (np.isfinite(duration) and 1.0 <= duration <= 3600.0):
        raise ConfigError(f"--duration must be between 1 and 3600 s; got {duration!r}")
    make = getattr(tr, kind)
    options = {"duration": duration}
    if "seed" in inspect.signature(make).parameters:
        options["seed"] = seed
    joint = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=0.01)
    return tr.simulate_trajectory(make(**options), tr.LuGreTruth(), joint, seed=seed)


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
            help=f"full (the paper's design; paper1 is about {PAPER1_FULL_MILLIONS} million "
            "samples), reduced (seconds), quick (tests)."
        ),
    ] = "reduced",
    seed: Annotated[int, typer.Option(help="Random seed (same seed, same log).")] = 0,
    coverage: Annotated[
        str,
        typer.Option(
            help="both (each direction over the whole range) or split (forward runs logged on "
            "the lower half of the range, backward runs on the upper half: the BAS-RBFNN paper's "
            "eq. 11 cannot pair them, extract identifies gravity jointly)."
        ),
    ] = "both",
    trajectory: Annotated[
        str | None,
        typer.Option(
            help="Instead of the campaign, one trajectory experiment on a joint with LuGre "
            "friction (the truth's parameters in the log's metadata): "
            "sine, chirp, multisine, slow_multisine, stick_slip or presliding. For "
            "`fricid fit LOG --trajectory`; --preset, --size and --coverage do not apply.",
        ),
    ] = None,
    duration: Annotated[
        float, typer.Option(help="--trajectory: the experiment's length [s], sampled at 1 kHz.")
    ] = DEFAULT_DURATION,
    quiet: QuietOption = False,
) -> None:
    """Simulate a bidirectional constant-velocity campaign on the virtual joint and write its
    raw log: time [s], position [rad], velocity [rad/s], motor current [A] (torque = K I),
    temperature [degC], with the torque constant K in the file's metadata. Progress goes to
    stderr (a bar on a terminal, a line per tenth with the time left otherwise; --quiet: none).
    With --trajectory, one experiment of any motion instead (J 0.01 kg m^2, gravity p_x 0.3,
    p_y 0.1 N m, LuGre friction: its parameters in the log's metadata)."""
    from ..io import write_rawlog

    _check_kind(trajectory, preset, size, coverage, duration)
    if trajectory is not None:
        write_rawlog(_trajectory_log(trajectory, duration, seed), out)
        err_console.print(
            f"wrote {escape(str(out))} (trajectory {escape(trajectory)}, {duration:g} s, "
            f"seed {seed}, LuGre truth)"
        )
        return
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
