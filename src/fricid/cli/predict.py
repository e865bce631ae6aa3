"""``fricid predict``: friction of a model file at given points, or at a file of points."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import Annotated

import typer

from ._app import app, err_console, handle_errors
from ._options import out_option
from ._paths import check_paths

#: Significant digits of ``predict``'s numbers on a terminal (read by eye).
DISPLAY_DIGITS = 6


def _unit_help(quantity: str) -> str:
    from ..units import SI_UNITS, UNITS

    return f"Unit of the {quantity} ({', '.join(UNITS[quantity])}; default {SI_UNITS[quantity]})."


@app.command("predict")
@handle_errors
def predict_command(
    model: Annotated[
        Path,
        typer.Argument(help="Model file (JSON, from `fricid fit`)."),
    ],
    velocity: Annotated[
        list[float] | None,
        typer.Option(
            "--velocity",
            "-v",
            metavar="<float>",
            help="Velocity of a point (repeat for several points).",
        ),
    ] = None,
    load: Annotated[
        list[float] | None,
        typer.Option(
            metavar="<float>",
            help="Joint load [N m by default]: one value for all points, or one per --velocity. "
            "Needed when the model depends on load.",
        ),
    ] = None,
    temperature: Annotated[
        list[float] | None,
        typer.Option(
            metavar="<float>",
            help="Temperature [degC by default]: one value, or one per --velocity. Needed when "
            "the model depends on temperature.",
        ),
    ] = None,
    input_file: Annotated[
        Path | None,
        typer.Option(
            "--input",
            "-i",
            help="File of points (CSV or Parquet) with a 'velocity' column and optional 'load' and "
            "'temperature' columns; units in the column names ('velocity [deg/s]') or from the "
            "unit flags. Missing columns take --load / --temperature.",
        ),
    ] = None,
    velocity_unit: Annotated[str | None, typer.Option(help=_unit_help("velocity"))] = None,
    load_unit: Annotated[str | None, typer.Option(help=_unit_help("torque"))] = None,
    temperature_unit: Annotated[str | None, typer.Option(help=_unit_help("temperature"))] = None,
    friction_unit: Annotated[
        str, typer.Option(help="Unit of the friction written (N m, mNm, ...).")
    ] = "N m",
    smooth: Annotated[
        str,
        typer.Option(
            help=(
                "Smoothing near zero velocity, as the C export does: none, tanh (sign(v) -> "
                "tanh(v/zone)), linear (straight line across |v| < zone)."
            )
        ),
    ] = "none",
    zone: Annotated[
        float, typer.Option(help="Half-width of the smoothing zone, in the velocity unit.")
    ] = 0.0,
    out: Annotated[
        Path | None, out_option("CSV file to write (whole or not at all). Default: CSV on stdout.")
    ] = None,
    interval: Annotated[
        float | None,
        typer.Option(
            help="Also write the prediction interval at this level (e.g. 0.95): columns "
            "'low' and 'high', where a new measured sample falls with that probability; "
            "its width follows the fit's held-out errors near the point (levels 0.9 and "
            "0.95 calibrated, others follow them), plus, for samples from an arm's sweeps, "
            "the error of the identified gravity they all share; nan at rest (the friction "
            "is whatever holds the joint) and inside a gap between measured speeds (nothing "
            "measured backs one)."
        ),
    ] = None,
    digits: Annotated[
        int | None,
        typer.Option(
            min=1,
            max=17,
            help="Significant digits of the numbers written. Default: on a terminal 6; into a "
            "file or a pipe every number exact, in the fewest digits that read back to the "
            "same value (0.2, not 0.20000000000000001).",
        ),
    ] = None,
) -> None:
    """Friction of a model at operating points: CSV with velocity, load, temperature and
    friction columns, each labelled with its unit (no load or temperature column for a model
    that does not depend on it, unless one is given).

    Points outside the operating range the model was identified on (above the identified
    speeds, below the smallest one of their direction, in a gap between measured speeds, on a
    side a one-direction model was not identified on, outside the load or temperature range)
    are still predicted, with one warning line each on stderr naming the measured range.
    With --interval LEVEL, the prediction interval's ends are written too.

    Examples: `fricid predict m.json --velocity 0.1 --velocity 0.5 --load 0.2 --temperature 30`;
    `fricid predict m.json --input points.csv --velocity-unit deg/s --out friction.csv`.
    """
    import numpy as np

    from ..errors import ConfigError, ExtrapolationWarning
    from ..export import Smoothing, smooth_predict, write_text
    from ..export._common import printable_reasons, trust_of
    from ..export.points import default_filled, points_matrix, points_table, read_points
    from ..export.projection import friction_reads
    from ..fitted import FittedModel
    from ..fitted._interval import no_steady_interval
    from ..units import to_si

    if interval is not None and not 0.0 < interval < 1.0:  # the option's, not the file's
        raise ConfigError(f"--interval must lie in (0, 1), e.g. 0.95; got {interval!r}")
    check_paths(inputs={"MODEL": model, "--input": input_file}, out_files={"--out": out})
    fitted = FittedModel.load(model)
    flags = {"velocity": velocity_unit, "load": load_unit, "temperature": temperature_unit}
    quantity = {"velocity": "velocity", "load": "torque", "temperature": "temperature"}
    given = {"velocity": velocity, "load": load, "temperature": temperature}
    si = {
        k: None if not v else to_si(list(v), flags[k] or "", quantity[k]) if flags[k] else list(v)
        for k, v in given.items()
    }
    units = {k: u for k, u in flags.items() if u}
    cols: dict = {}  # the --input file's columns
    if input_file is not None:
        if velocity:
            raise ConfigError("give points either with --velocity or with --input, not both")
        cols, file_units = read_points(input_file, flags)
        units.update(file_units)
        for name in ("load", "temperature"):
            if name not in cols and si[name] is not None and len(si[name]) != 1:
                raise ConfigError(f"with --input, --{name} is one value for every point")
        X = points_matrix(
            fitted,
            cols["velocity"],
            cols.get("load", si["load"]),
            cols.get("temperature", si["temperature"]),
        )
    else:
        if not velocity:
            raise ConfigError("give the points: --velocity (repeatable), or --input FILE")
        X = points_matrix(fitted, si["velocity"], si["load"], si["temperature"])
    zone_si = float(to_si(zone, velocity_unit or "rad/s", "velocity"))
    _say_ignored(fitted, X, given, cols)
    loose = [n for n, p in fitted.parameters.items() if p.not_determined and not p.fixed]
    if fitted.kind != "rbf":  # those the friction at these points reads (not LuGre's sigma_1)
        loose = friction_reads(fitted, X, loose)
    if loose and fitted.kind != "rbf":  # as export refuses them: said, not hidden
        err_console.print(
            f"warning: the model's data do not determine {', '.join(loose)}: the friction "
            "predicted rests on values no measurement backs wherever they matter (the model "
            "file's notes say why)",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
    level, reasons = trust_of(fitted)
    if level == "no":  # as export refuses it: said, not hidden
        why = printable_reasons(reasons, limit=500)  # whole reasons: no name cut off
        err_console.print(
            f"warning: the model's trust verdict is 'no' ({why or 'no reason recorded'}): "
            "its own check rejects it, so neither the friction nor its interval is backed",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
    for bad in fitted.range_check(X):  # one line each on stderr (issue 11, defect 8)
        err_console.print(
            f"warning: {bad.message} ({bad.count} of {len(X)} points)",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)  # said above, once per quantity
        friction = smooth_predict(fitted, X, Smoothing(smooth, zone_si))
        extra = None
        unbacked = no_steady_interval(fitted) if interval is not None else ""
        if unbacked:  # the friction, with its interval columns empty and why
            extra = {"low": np.full(len(X), np.nan), "high": np.full(len(X), np.nan)}
            err_console.print(
                f"note: no prediction interval (low and high are nan): the model {unbacked}",
                markup=False,
                highlight=False,
                soft_wrap=True,
            )
        elif interval is not None:  # its half-width around the friction written
            try:
                half = fitted.predict_interval(X, interval, warn=False).half_width
            except ConfigError as err:  # a malformed record: named with its file
                raise ConfigError(f"{model}: {err}") from None
            extra = {"low": friction - half, "high": friction + half}
            rest = X[:, 0] == 0
            outside = fitted.outside_range(X) & ~rest
            why = {
                "at rest, where the friction is whatever holds the joint, up to break-away": rest,
                "outside the range the model was identified on, where nothing measured "
                "backs one (the warnings before this note say where)": outside,
                "in a gap between measured speeds, where nothing measured backs one (the "
                "warnings before this note say where)": np.isnan(half) & ~rest & ~outside,
            }
            for reason, where in why.items():
                if where.any():
                    err_console.print(
                        f"note: no prediction interval at {int(where.sum())} of {len(X)} "
                        f"points: {reason}",
                        markup=False,
                        highlight=False,
                        soft_wrap=True,
                    )
    units["friction"] = friction_unit
    if digits is None and out is None and sys.stdout.isatty():
        digits = DISPLAY_DIGITS
    # a load or temperature the model ignores and no one gave (0 N m, 25 degC) is made up
    given = {"load": load, "temperature": temperature}
    made_up = tuple(
        name
        for name in ("load", "temperature")
        if not (given[name] or name in cols) and default_filled(fitted, name)
    )
    text = points_table(X, friction, units, extra, digits, made_up)
    if out is None:
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        write_text(text, out)
        err_console.print(f"wrote {out} ({len(X)} points)")


def _say_ignored(fitted, X, given: dict, cols: dict) -> None:
    """A note for each load or temperature given (flag or column) that the model does not
    depend on: the friction is the same whatever it is, though the output echoes it."""
    used = fitted.inputs_used()
    for k, name in ((1, "load"), (2, "temperature")):
        if name in used or not (given.get(name) or name in cols):
            continue
        unit = "N m" if name == "load" else "degC"
        low, high = float(X[:, k].min()), float(X[:, k].max())
        shown = f"{low:g} {unit}" if low == high else f"{low:g} to {high:g} {unit}"
        err_console.print(
            f"note: model '{fitted.model}' does not depend on {name}: the friction is the same "
            f"at the {name} given ({shown}), which is written beside it as given",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
