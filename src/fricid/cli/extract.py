"""``fricid extract``: raw log to friction samples (BAS-RBFNN paper, section 2)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape

from ..errors import ConfigError
from ._app import app, console, err_console, handle_errors
from ._options import TemperatureOption, TorqueConstantOption, out_option, parse_grid
from ._progress import progress_bar


def parse_positions(text: str | None, unit: str) -> np.ndarray | None:
    """``"-60:-20:2"`` (start:stop:step, stop included) or ``"-60,-40,-20"`` -> rad."""
    from ..units import to_si

    if text is None:
        return None
    values = np.asarray(parse_grid(text, "--positions"), dtype=float)
    return np.asarray(to_si(values, unit, "position"), dtype=float)


def parse_column_map(items: list[str] | None) -> tuple[dict[str, str], dict[str, str]]:
    """``["time=t:ms", "velocity=dq"]`` -> ``({"time": "t", "velocity": "dq"}, {"time": "ms"})``."""
    from ..io.options import parse_pairs

    if not items:
        raise ConfigError(
            "--format generic needs --map QUANTITY=COLUMN[:UNIT] for time, velocity and torque "
            "or current (e.g. --map time=t:s --map velocity=dq:deg/s --map torque=tau:Nm)"
        )
    try:
        pairs = parse_pairs(items, form="QUANTITY=COLUMN[:UNIT]")
    except ConfigError as exc:
        raise ConfigError(f"--map takes QUANTITY=COLUMN[:UNIT]; {exc}") from None
    columns: dict[str, str] = {}
    units: dict[str, str] = {}
    for quantity, rest in pairs.items():
        column, _, unit = rest.rpartition(":") if ":" in rest else (rest, "", "")
        columns[quantity] = column.strip()
        if unit.strip():
            units[quantity] = unit.strip()
    return columns, units


def _print_torque_constant(log: Path, fmt: str, reader_options: dict, chunk_rows: int) -> None:
    """``--identify-torque-constant``: K (and the efficiency) from current and torque."""
    from ..extract.torque_constant import fit_torque_constant
    from ..io import open_log

    opened = open_log(log, fmt, reader_options, chunk_rows=chunk_rows)
    if not hasattr(opened, "__next__"):
        raise ConfigError(
            "--identify-torque-constant needs a log of samples over time with both a current "
            "and a torque column, not a folder of steady-state recordings"
        )
    console.print(fit_torque_constant(opened).summary(), markup=False, highlight=False)


@app.command("extract")
@handle_errors
def extract_command(
    log: Annotated[
        Path,
        typer.Argument(
            help="Raw log (.parquet or .csv from `fricid "
            "simulate` or a converted recording), or a folder of "
            "steady-state EPOS recordings with --format epos.",
            exists=True,
        ),
    ],
    out: Annotated[
        Path, out_option("Samples to write (.csv or .parquet): direction 0, combined by eq. 11.")
    ] = Path("samples.csv"),
    by_direction: Annotated[
        Path | None, typer.Option(help="Also write the per-direction samples (+1 and -1) here.")
    ] = None,
    fmt: Annotated[
        str,
        typer.Option(
            "--format",
            help="table (fricid's CSV/Parquet raw log), "
            "rosbag (a ROS 2 bag folder or .mcap/.db3 file with "
            "sensor_msgs/msg/JointState; needs --joint) or epos (a "
            "folder of Maxon EPOS recorder CSVs, one steady velocity "
            "per file) or generic (any CSV/Parquet table, with --map).",
        ),
    ] = "table",
    column_map: Annotated[
        list[str] | None,
        typer.Option(
            "--map",
            help="generic: QUANTITY=COLUMN[:UNIT], repeatable, e.g. --map time=t:ms --map "
            "velocity=dq:deg/s --map current=i:A --map position=q:deg --map "
            "temperature=T:degC. time, velocity and torque or current are required; a unit "
            "may instead stand in the column name, as 'dq [deg/s]'.",
        ),
    ] = None,
    joint: Annotated[
        str | None, typer.Option(help="rosbag: the joint's name in JointState.name.")
    ] = None,
    topic: Annotated[str, typer.Option(help="rosbag: the JointState topic.")] = "/joint_states",
    temperature_topic: Annotated[
        str | None,
        typer.Option(
            help="rosbag: a sensor_msgs/msg/Temperature topic [degC]; else --temperature is used."
        ),
    ] = None,
    effort: Annotated[
        str,
        typer.Option(
            help="rosbag: what JointState.effort holds: torque "
            "[N m] or current [A] (then give --torque-constant)."
        ),
    ] = "torque",
    torque_constant: TorqueConstantOption = None,
    velocity_unit: Annotated[
        str, typer.Option(help="rosbag: unit of JointState.velocity.")
    ] = "rad/s",
    positions: Annotated[
        str | None,
        typer.Option(
            help=(
                "Position bins START:STOP:STEP or a comma list, in --position-unit. Default: the "
                "design recorded by `fricid simulate`, else one bin per steady traverse."
            )
        ),
    ] = None,
    position_unit: Annotated[
        str, typer.Option(help="Unit of --positions and --bin-halfwidth: rad or deg.")
    ] = "deg",
    bin_halfwidth: Annotated[
        float | None, typer.Option(help="Half width of a position bin (default: half the spacing).")
    ] = None,
    median_window: Annotated[
        int, typer.Option(help="Running-median window [samples] on the current, odd; 1 disables.")
    ] = 5,
    gravity: Annotated[
        str | None,
        typer.Option(
            help="fit (joint with gravity: eq. 7, 11, 12; where the two directions do not "
            "cover the same positions it falls back to joint, with a note), joint (eq. 7 and "
            "one friction per set-point and direction by least squares over all steady "
            "samples, no pairing: e.g. --gravity joint) or none (horizontal joint: torque is "
            "friction). Default: from the log's design, else fit with positions, none without."
        ),
    ] = None,
    flip_sign: Annotated[
        bool,
        typer.Option(
            help="EPOS: negate velocity and torque (motor "
            "convention, as the lead-screw recordings need)."
        ),
    ] = False,
    nominal_torque: Annotated[
        float,
        typer.Option(help="EPOS: the motor's nominal torque [mN m], reference of the % channel."),
    ] = 9.84,
    temperature: TemperatureOption = 25.0,
    chunk_rows: Annotated[
        int, typer.Option(help="Rows read at a time (bounded memory).")
    ] = 1_000_000,
    identify_torque_constant: Annotated[
        bool,
        typer.Option(
            "--identify-torque-constant",
            help="Also identify K of tau = K I (eq. 13) from a log with both motor current and "
            "a joint torque sensor (e.g. --map current=i:A --map torque=tau_j:Nm), with its "
            "95 % interval and, when both power flows were logged, the gear efficiency; "
            "printed before the samples are written (reads the log a second time).",
        ),
    ] = False,
) -> None:
    """Extract friction samples from a raw log: segment the constant-velocity traverses, median
    filter the current, torque = K I (eq. 13), average the repetitions per position bin,
    separate friction and gravity (eq. 9-11), fit p_x, p_y (eq. 7) and take the gravity torque
    as the load (eq. 12). Writes samples with velocity [rad/s], load [N m], temperature [degC],
    friction [N m], direction, count, std [N m]."""
    from ..io import write_samples
    from ..units import to_si
    from ..workflow import load_joint

    pos = parse_positions(positions, position_unit)
    half = None if bin_halfwidth is None else float(to_si(bin_halfwidth, position_unit, "position"))
    extract_options = {
        "positions": pos,
        "bin_halfwidth": half,
        "median_window": median_window,
        "gravity": gravity,
    }
    if fmt == "table":
        reader_options = {}
    elif fmt == "generic":
        columns, units = parse_column_map(column_map)
        reader_options = {"columns": columns, "units": units, "torque_constant": torque_constant}
        if "temperature" not in columns:
            reader_options["temperature"] = temperature
    elif fmt == "rosbag":
        reader_options = {
            "topic": topic,
            "effort": effort,
            "torque_constant": torque_constant,
            "velocity_unit": velocity_unit,
        }
        if joint is not None:
            reader_options["joint"] = joint
        if temperature_topic:
            reader_options["temperature_topic"] = temperature_topic
        else:
            reader_options["temperature"] = temperature
    elif fmt == "epos":
        reader_options = {
            "flip_sign": flip_sign,
            "temperature": temperature,
            "nominal_torque": nominal_torque * 1e-3,
        }
        if log.is_dir():
            extract_options = {}
    else:
        raise ConfigError(f"--format must be table, generic, rosbag or epos; got '{fmt}'")

    with progress_bar("extracting", total=None) as advance:
        data = load_joint(
            log,
            fmt,
            reader_options=reader_options,
            extract_options=extract_options,
            chunk_rows=chunk_rows,
            on_chunk=advance,
        )
    if identify_torque_constant:
        _print_torque_constant(log, fmt, reader_options, chunk_rows)
    write_samples(data.samples, out)
    if by_direction is not None:
        write_samples(data.by_direction, by_direction)
    if data.extraction is not None:
        console.print(data.extraction.summary(), markup=False, highlight=False)
        if pos is None and data.extraction.options.get("positions") is not None:
            err_console.print("used the position bins recorded with the log")
    else:
        err_console.print(
            f"{len(data.samples)} steady operating points (directions {data.samples.directions()})"
        )
    err_console.print(
        f"wrote {escape(str(out))} ({len(data.samples)} samples)"
        + (f" and {escape(str(by_direction))}" if by_direction else "")
    )
