"""``fricid extract``: raw log to friction samples (BAS-RBFNN paper, section 2)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape

from ..errors import ConfigError
from ._app import app, console, err_console, handle_errors, plural
from ._options import TemperatureOption, TorqueConstantOption, out_option, parse_grid
from ._paths import check_paths
from ._progress import QuietOption, progress_bar
from ._torque_constant import (
    UrdfJointOption,
    UrdfOption,
    UrdfPositionOption,
    identify_from_urdf,
    print_torque_constant,
)


def parse_positions(text: str | None, unit: str) -> np.ndarray | None:
    """``"-60:-20:2"`` (start:stop:step, stop included) or ``"-60,-40,-20"`` -> rad."""
    from ..units import to_si

    if text is None:
        return None
    values = np.asarray(parse_grid(text, "--positions"), dtype=float)
    return np.asarray(to_si(values, unit, "position"), dtype=float)


def parse_column_map(
    items: list[str] | None, flag: str = "--map", what: str = "COLUMN"
) -> tuple[dict[str, str], dict[str, str]]:
    """``["time=t:ms", "velocity=dq"]`` -> ``({"time": "t", "velocity": "dq"}, {"time": "ms"})``.

    ``flag`` (``--map``, ``--channels``, ``--var``) and ``what`` (what stands right of ``=``)
    name the flag in messages.
    """
    from ..io.options import parse_pairs

    if not items:
        raise ConfigError(_NEEDS[flag])
    try:
        pairs = parse_pairs(items, form=f"QUANTITY={what}[:UNIT]")
    except ConfigError as exc:
        raise ConfigError(f"{flag} takes QUANTITY={what}[:UNIT]; {exc}") from None
    columns: dict[str, str] = {}
    units: dict[str, str] = {}
    for quantity, rest in pairs.items():
        column, _, unit = rest.rpartition(":") if ":" in rest else (rest, "", "")
        columns[quantity] = column.strip()
        if unit.strip():
            units[quantity] = unit.strip()
    return columns, units


#: What a format needs of its mapping flag, when the flag is missing.
_NEEDS = {
    "--map": "--format generic needs --map QUANTITY=COLUMN[:UNIT] for time, velocity and torque "
    "or current (e.g. --map time=t:s --map velocity=dq:deg/s --map torque=tau:Nm)",
    "--channels": "--format channels needs --channels QUANTITY=PATTERN:UNIT for velocity (or "
    "position) and torque (or current), e.g. --channels 'torque={name}_tau{joint}_{speed}.t:Nm'",
    "--var": "--format mat needs --var QUANTITY=NAME:UNIT: time, velocity and torque (a log) or "
    "velocity and friction (a table of means), e.g. --var velocity=qd:rad/s",
}

#: Flag -> (parameter, the reader option it sets). A flag given with a format whose reader
#: lacks that option (:data:`fricid.io.READER_OPTIONS`) is refused, never silently dropped.
READER_FLAGS: dict[str, tuple[str, str]] = {
    "--map": ("column_map", "columns"),
    "--joint": ("joint", "joint"),
    "--topic": ("topic", "topic"),
    "--temperature-topic": ("temperature_topic", "temperature_topic"),
    "--effort": ("effort", "effort"),
    "--torque-constant": ("torque_constant", "torque_constant"),
    "--velocity-unit": ("velocity_unit", "velocity_unit"),
    "--flip-sign": ("flip_sign", "flip_sign"),
    "--nominal-torque": ("nominal_torque", "nominal_torque"),
    "--temperature": ("temperature", "temperature"),
    "--skip-bad-rows": ("skip_bad_rows", "skip_bad_rows"),
    "--channels": ("channel_patterns", "channels"),
    "--var": ("variables", "variables"),
    "--join": ("join", "join"),
    "--join-tolerance": ("join_tolerance", "tolerance"),
    "--time-unit": ("time_unit", "time_unit"),
}

#: Flags of the extraction (:func:`fricid.extract.extract`): refused for a reader that gives
#: samples directly (:func:`fricid.io.registry.gives_samples`).
EXTRACT_FLAGS: dict[str, str] = {
    "--positions": "positions",
    "--position-unit": "position_unit",
    "--bin-halfwidth": "bin_halfwidth",
    "--median-window": "median_window",
    "--gravity": "gravity",
}


def _given(ctx: typer.Context, param: str) -> bool:
    """Whether ``param`` was set on the command line (not left at its default)."""
    source = ctx.get_parameter_source(param)  # an enum of click's (typer may vendor click)
    return source is not None and source.name not in ("DEFAULT", "DEFAULT_MAP")


def check_flags(ctx: typer.Context, fmt: str, log: Path, variables: list[str] | None) -> None:
    """Refuse a flag that ``fmt`` does not use, saying why (table-driven from the registry).

    Raises
    ------
    ConfigError
        An unknown format; a reader flag whose option the reader lacks (naming the formats
        that take it); an extraction flag with a reader that gives samples directly.
    """
    from ..io.registry import CHUNKED_READERS, READER_OPTIONS, READERS, gives_samples

    if fmt not in READERS:
        raise ConfigError(f"--format must be one of {', '.join(READERS)}; got '{fmt}'")
    for flag, (param, option) in READER_FLAGS.items():
        if _given(ctx, param) and option not in READER_OPTIONS[fmt]:
            takers = [r for r in READERS if option in READER_OPTIONS[r]]
            raise ConfigError(
                f"{flag} does not apply to --format {fmt}: it is an option of --format "
                f"{' and '.join(takers)}"
            )
    if _given(ctx, "chunk_rows") and fmt not in CHUNKED_READERS:
        raise ConfigError(
            f"--chunk-rows does not apply to --format {fmt}: only --format "
            f"{' and '.join(CHUNKED_READERS)} read a log in chunks"
        )
    probe = {"variables": parse_column_map(variables, "--var", "NAME")[0]} if variables else {}
    if gives_samples(fmt, log, probe):
        what = (
            "steady-state EPOS recordings give one operating point per file"
            if fmt == "epos"
            else "a MATLAB table of means (--var friction=...) is read straight into samples"
        )
        for flag, param in EXTRACT_FLAGS.items():
            if _given(ctx, param):
                raise ConfigError(
                    f"{flag} does not apply to --format {fmt} here: {what}, so there is "
                    "nothing to extract"
                )


def chunks_expected(log: Path, fmt: str, chunk_rows: int) -> int | None:
    """How many chunks of ``chunk_rows`` a log is read in, when its file says how many rows it
    has (a Parquet table: its footer), for the progress estimate; None otherwise."""
    if fmt != "table" or log.suffix.lower() != ".parquet" or chunk_rows < 1:
        return None
    try:
        import pyarrow.parquet as pq

        rows = int(pq.ParquetFile(log).metadata.num_rows)
    except Exception:  # the reader reports a bad file properly
        return None
    return max(1, -(-rows // int(chunk_rows)))


def _format_help() -> str:
    from ..io.registry import READER_EXAMPLES

    return "\b\nFormats (--format), one example each:\n" + "\n".join(
        f"  {name}: {example}" for name, example in READER_EXAMPLES.items()
    )


@app.command("extract", epilog=_format_help())
@handle_errors
def extract_command(
    ctx: typer.Context,
    log: Annotated[
        Path,
        typer.Argument(
            help="Raw log (.parquet or .csv from `fricid simulate` or a converted recording), "
            "a folder of steady-state EPOS recordings (--format epos), a folder of per-channel "
            "files (--format channels) or a MATLAB file (--format mat).",
        ),
    ],
    out: Annotated[
        Path,
        out_option(
            "Samples to write (.csv or .parquet): from a log, direction 0 (forwards and "
            "backwards averaged into one magnitude, the BAS-RBFNN paper's eq. 11) or the one "
            "direction measured; the operating points as recorded (+1 and -1 rows) from EPOS "
            "recordings at one steady velocity each or a MATLAB table of means."
        ),
    ] = Path("samples.csv"),
    by_direction: Annotated[
        Path | None, typer.Option(help="Also write the per-direction samples (+1 and -1) here.")
    ] = None,
    fmt: Annotated[
        str,
        typer.Option(
            "--format",
            help="table (fricid's CSV/Parquet raw log), generic (any CSV/Parquet table, with "
            "--map), rosbag (a ROS 2 bag folder or .mcap/.db3 file with "
            "sensor_msgs/msg/JointState; needs --joint), epos (a Maxon EPOS recorder CSV or a "
            "folder of them; a file at one steady velocity gives one point), channels (a folder "
            "of headerless 'time value' files, one per channel and run, with --channels) or mat "
            "(a MATLAB v5/v7.3 file, with --var). Examples below.",
        ),
    ] = "table",
    column_map: Annotated[
        list[str] | None,
        typer.Option(
            "--map",
            metavar="QUANTITY=COLUMN[:UNIT]",
            help="generic: QUANTITY=COLUMN[:UNIT], repeatable, e.g. --map time=t:ms --map "
            "velocity=dq:deg/s --map current=i:A --map position=q:deg --map "
            "temperature=T:degC. time, velocity and torque or current are required; a unit "
            "may instead stand in the column name, as 'dq [deg/s]' (then --map velocity=dq "
            "finds it).",
        ),
    ] = None,
    channel_patterns: Annotated[
        list[str] | None,
        typer.Option(
            "--channels",
            metavar="QUANTITY=PATTERN:UNIT",
            help="channels: QUANTITY=PATTERN:UNIT, repeatable, one per quantity (velocity or "
            "position, torque or current, optionally temperature). In PATTERN, {field} matches "
            "part of a file name and * any text: --channels "
            "'torque={name}_tau{joint}_{speed}.t:Nm'. A run is one value of the fields.",
        ),
    ] = None,
    variables: Annotated[
        list[str] | None,
        typer.Option(
            "--var",
            metavar="QUANTITY=NAME:UNIT",
            help="mat: QUANTITY=NAME:UNIT, repeatable; a struct field as a.b, variables "
            "joined end to end as a,b. A log: time, velocity, torque or current (position, "
            "temperature optional). A table of means: velocity and friction (load, "
            "temperature optional).",
        ),
    ] = None,
    join: Annotated[
        str,
        typer.Option(
            help="channels: join channels on the velocity (else position) time stamps: exact, "
            "nearest (the nearest sample within --join-tolerance) or linear (interpolated)."
        ),
    ] = "nearest",
    join_tolerance: Annotated[
        float | None,
        typer.Option(
            help="channels: largest time difference [s] of --join nearest (default "
            "half the median sample period)."
        ),
    ] = None,
    time_unit: Annotated[
        str, typer.Option(help="channels: unit of the time column of every file.")
    ] = "s",
    joint: Annotated[
        str | None,
        typer.Option(
            help="rosbag: the joint's name in JointState.name; channels: the value of the "
            "{joint} field; mat: the 1-based column of variables with one column per joint."
        ),
    ] = None,
    topic: Annotated[str, typer.Option(help="rosbag: the JointState topic.")] = "/joint_states",
    temperature_topic: Annotated[
        str | None,
        typer.Option(
            help="rosbag: a sensor_msgs/msg/Temperature topic [degC]; else --temperature, or none."
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
            "friction). Default: from the log's design, else fit with positions, joint with a "
            "position channel (none, with a note, when eq. 7 is not determined), none without."
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
    skip_bad_rows: Annotated[
        bool,
        typer.Option(
            help="EPOS: drop a data row with a malformed cell (a typed note) instead of "
            "stopping; the rows dropped are counted and listed (file, line, column)."
        ),
    ] = False,
    temperature: TemperatureOption = None,
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
    urdf: UrdfOption = None,
    urdf_joint: UrdfJointOption = None,
    urdf_position: UrdfPositionOption = None,
    quiet: QuietOption = False,
) -> None:
    """Extract friction samples from a raw log: segment the constant-velocity traverses, median
    filter the current, torque = K I (eq. 13), average the repetitions per position bin,
    separate friction and gravity (eq. 9-11), fit p_x, p_y (eq. 7) and take the gravity torque
    as the load (eq. 12; equations of the BAS-RBFNN paper). Writes samples with velocity
    [rad/s], load [N m], temperature [degC], friction [N m], direction, count, std [N m]. A
    flag that the format does not use is an error."""
    from ..io import write_samples
    from ..io.registry import gives_samples
    from ..units import to_si
    from ..workflow import load_joint

    check_paths(
        inputs={"LOG": log},
        folders=fmt in ("epos", "rosbag", "channels"),
        out_files={"--out": out, "--by-direction": by_direction},
    )
    check_flags(ctx, fmt, log, variables)
    pos = parse_positions(positions, position_unit)
    half = None if bin_halfwidth is None else float(to_si(bin_halfwidth, position_unit, "position"))
    extract_options = {
        "positions": pos,
        "bin_halfwidth": half,
        "median_window": median_window,
        "gravity": gravity,
    }
    given = {option for _, (param, option) in READER_FLAGS.items() if _given(ctx, param)}
    if fmt == "table":  # the temperature of a log without its column
        reader_options: dict = {"temperature": temperature} if "temperature" in given else {}
    elif fmt == "generic":
        columns, units = parse_column_map(column_map)
        reader_options = {"columns": columns, "units": units, "torque_constant": torque_constant}
        if "temperature" in given:  # a log without one records none: none made up
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
        if "temperature" in given:
            reader_options["temperature"] = temperature
    elif fmt == "epos":
        reader_options = {
            "flip_sign": flip_sign,
            "nominal_torque": nominal_torque * 1e-3,
            "torque_constant": torque_constant,
            "skip_bad_rows": skip_bad_rows,
        }
        if "temperature" in given:  # the recorder logs none: none made up
            reader_options["temperature"] = temperature
    elif fmt == "channels":
        patterns, units = parse_column_map(channel_patterns, "--channels", "PATTERN")
        reader_options = {
            "channels": patterns,
            "units": units,
            "joint": joint,
            "join": join,
            "tolerance": join_tolerance,
            "time_unit": time_unit,
            "torque_constant": torque_constant,
        }
        if "temperature" in given:
            reader_options["temperature"] = temperature
    else:  # mat (check_flags refused any other format)
        names, units = parse_column_map(variables, "--var", "NAME")
        reader_options = {
            "variables": names,
            "units": units,
            "joint": joint,
            "torque_constant": torque_constant,
        }
        if "temperature" in given:
            reader_options["temperature"] = temperature
    if gives_samples(fmt, log, reader_options):
        extract_options = {}
    if urdf is not None or urdf_joint is not None or urdf_position:
        check_paths(inputs={"--urdf": urdf})
        k_fit = identify_from_urdf(
            log,
            fmt,
            reader_options,
            extract_options,
            chunk_rows,
            urdf=urdf,
            joint=urdf_joint,
            positions=urdf_position,
        )
        if torque_constant is None and "torque_constant" in reader_options:
            reader_options["torque_constant"] = k_fit.K
            err_console.print(f"samples converted with the identified K = {k_fit.K:.6g} N m/A")
        else:
            err_console.print("samples converted with the given (or the log's own) K, not this one")

    with progress_bar(
        f"extracting {log.name}",
        total=chunks_expected(log, fmt, chunk_rows),
        unit="chunks read",
        quiet=quiet,
    ) as advance:
        data = load_joint(
            log,
            fmt,
            reader_options=reader_options,
            extract_options=extract_options,
            chunk_rows=chunk_rows,
            on_chunk=advance,
        )
    if identify_torque_constant:
        print_torque_constant(log, fmt, reader_options, chunk_rows)
    write_samples(data.samples, out)
    if by_direction is not None:
        write_samples(data.by_direction, by_direction)
    if data.extraction is not None:
        console.print(data.extraction.summary(), markup=False, highlight=False)
        if data.extraction.quality is not None:
            for line in data.extraction.quality.accounting():
                err_console.print(line, markup=False, highlight=False)
        if pos is None and data.extraction.options.get("positions") is not None:
            err_console.print("used the position bins recorded with the log")
    else:
        skipped = data.samples.meta.get("skipped_rows") or {}
        n_bad = sum(len(rows) for rows in skipped.values())
        err_console.print(
            f"{plural(len(data.samples), 'steady operating point')} ("
            + " and ".join(
                {-1: "backwards", 1: "forwards"}.get(int(d), "at rest")
                for d in data.samples.directions()
            )
            + (f", {data.samples.velocity[0]:+.4g} rad/s)" if len(data.samples) == 1 else ")")
            + (f"; {n_bad} bad rows skipped in {len(skipped)} files" if n_bad else ""),
            markup=False,
            highlight=False,
        )
    if fmt == "channels":
        how = {
            "exact": "on identical time stamps",
            "nearest": "by the nearest sample within "
            + (f"{join_tolerance:g} s" if join_tolerance else "half the median sample period"),
            "linear": "by linear interpolation",
        }.get(join, join)
        err_console.print(f"channels joined {how}, onto the velocity (else position) time stamps")
    err_console.print(
        f"wrote {escape(str(out))} ({plural(len(data.samples), 'sample')})"
        + (f" and {escape(str(by_direction))}" if by_direction else "")
    )
