"""What sub-commands share: option definitions, and flag values parsed by :mod:`fricid.io.options`.

Option definitions are ``Annotated`` types, used as a parameter's annotation::

    def export_command(model: ModelFile, smooth: SmoothKind = "none", zone: SmoothZone = 0.0,
                       out: Annotated[Path | None, out_option("File to write.")] = None): ...

The parsers of ``NAME=VALUE`` and ``NAME=LOW:HIGH`` live in :mod:`fricid.io.options` (the
fleet manifest uses them too); here they only turn its :class:`~fricid.errors.ConfigError`
into a :class:`typer.BadParameter` naming the flag (exit status 2).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from ..errors import ConfigError
from ..io import options as _parse

__all__ = [
    "AllowUntrusted",
    "BoundOption",
    "DirectionOption",
    "FixOption",
    "LogFormatOption",
    "MaxEvalsOption",
    "ModelFile",
    "SeedOption",
    "SmoothKind",
    "SmoothZone",
    "TemperatureOption",
    "TorqueConstantOption",
    "out_option",
    "parse_assignments",
    "parse_grid",
    "parse_ranges",
]

T = TypeVar("T")

#: ``--format`` of ``fit --trajectory``: the log's reader.
LogFormatOption = Annotated[
    str,
    typer.Option(
        "--format",
        help="--trajectory: the log's format (table: CSV or Parquet with unit headers; "
        "fricid extract --help lists every format).",
    ),
]

#: A model file argument (JSON written by ``fricid fit``), which must exist.
ModelFile = Annotated[
    Path,
    typer.Argument(help="Model file (JSON, from `fricid fit`)."),
]

#: ``--fix NAME=VALUE`` (repeatable), parsed by :func:`parse_assignments`.
FixOption = Annotated[
    list[str] | None,
    typer.Option(
        "--fix",
        metavar="NAME=VALUE",
        help="Hold a parameter at a value, NAME=VALUE (SI units), e.g. --fix delta=1. Repeatable.",
    ),
]

#: ``--bound NAME=LOW:HIGH`` (repeatable), parsed by :func:`parse_ranges`.
BoundOption = Annotated[
    list[str] | None,
    typer.Option(
        "--bound",
        metavar="NAME=LOW:HIGH",
        help=(
            "Search range of a parameter, NAME=LOW:HIGH (SI units). Repeatable. Default ranges "
            "scale with the samples (friction samples only: a trajectory fit searches its own)."
        ),
    ),
]

#: ``--seed``: the random seed of a stochastic computation.
SeedOption = Annotated[int, typer.Option("--seed", help="Random seed (same seed, same result).")]

#: ``--max-evals``: an optimiser's budget.
MaxEvalsOption = Annotated[
    int | None, typer.Option("--max-evals", help="Budget in model evaluations.")
]

#: ``--direction``: which samples a fit uses (:data:`fricid.workflow.DIRECTIONS`).
DirectionOption = Annotated[
    str,
    typer.Option(
        "--direction",
        help="Which samples to use: all, combined (direction 0: forwards and backwards "
        "averaged into one magnitude), both (+1 and -1: each direction's own), pos, neg.",
    ),
]

#: ``--smooth``: smoothing of sign(v) near zero velocity (as the C export does).
SmoothKind = Annotated[
    str,
    typer.Option(
        "--smooth",
        help=(
            "Smoothing near zero velocity: none (the model as identified), tanh (sign(v) -> "
            "tanh(v/zone), analytic models), linear (straight lines from 0 at rest to the "
            "model's values at -zone and +zone, every model)."
        ),
    ),
]

#: ``--zone``: half-width of the smoothing zone [rad/s].
SmoothZone = Annotated[
    float, typer.Option("--zone", help="Half-width of the smoothing zone [rad/s].")
]

#: ``--allow-untrusted``: export a model whose recorded trust verdict is "no".
AllowUntrusted = Annotated[
    bool,
    typer.Option(
        "--allow-untrusted",
        help=(
            "Export a model whose recorded trust verdict is 'no' (refused otherwise); the "
            "file's comment says so."
        ),
    ),
]

#: ``--torque-constant``: K of tau = K I when the effort is a motor current.
TorqueConstantOption = Annotated[
    float | None,
    typer.Option(
        "--torque-constant", help="K [N m/A] of tau = K I (eq. 13), when effort is current."
    ),
]

#: ``--temperature``: a constant temperature [degC] for a log that records none.
TemperatureOption = Annotated[
    float | None,
    typer.Option(
        "--temperature",
        help="The joint's temperature [degC], recorded with the samples, for a log that logs "
        "none. Without it such a log records no temperature (none is made up); fricid's own "
        "table log without a temperature column needs it.",
    ),
]


class OutPath(type(Path())):  # type: ignore[misc]  # the platform's concrete path class
    """A path given to ``--out``, remembering whether it ended with a separator
    (``folder_meant``): the path itself drops it, and ``export --to mjcf --out d/`` wrote a
    file named ``d``."""

    folder_meant = False


def out_path(raw: str | Path) -> Path:
    """``--out``'s value as an :class:`OutPath` (checked by ``_paths.check_paths``); a
    command's default (a path already) as it is."""
    if isinstance(raw, Path):
        return raw
    path = OutPath(raw)
    path.folder_meant = raw.endswith(("/", os.sep))
    return path


def out_option(help: str, **kwargs: Any) -> Any:
    """The ``--out``/``-o`` option with its command's own help text."""
    return typer.Option("--out", "-o", help=help, parser=out_path, **kwargs)


def robot_urdf(
    urdf: Path | None, robot: str | None, context: str = ""
) -> tuple[Path, list[str] | None]:
    """The URDF of ``--urdf FILE`` or of the example robot ``--robot NAME`` (exactly one), and
    the example's default joints (None for ``--urdf``); ``context`` leads the error."""
    if (urdf is None) == (robot is None):
        raise ConfigError(
            f"{context}give --urdf or --robot, one of them (--urdf FILE: the robot's URDF; "
            "--robot NAME: an example robot)"
        )
    if urdf is not None:
        return urdf, None
    from ..robot import example_urdf

    return example_urdf(robot)


def _flag(parse: Callable[[Any], T], value: Any, flag: str) -> T:
    try:
        return parse(value)
    except ConfigError as exc:
        raise typer.BadParameter(str(exc), param_hint=flag) from None


def parse_assignments(items: Iterable[str] | None, flag: str) -> dict[str, float]:
    """``["delta=1", "xi=2"]`` -> ``{"delta": 1.0, "xi": 2.0}`` (:mod:`fricid.io.options`).

    Raises
    ------
    typer.BadParameter
        Naming ``flag``: an item that is not NAME=VALUE with a finite number, or a name
        given twice.
    """
    return _flag(_parse.parse_assignments, list(items or []), flag)


def parse_ranges(items: Iterable[str] | None, flag: str) -> dict[str, tuple[float, float]]:
    """``["w_s=0.001:1"]`` -> ``{"w_s": (0.001, 1.0)}`` (:mod:`fricid.io.options`).

    Raises
    ------
    typer.BadParameter
        Naming ``flag``: an item that is not NAME=LOW:HIGH with finite LOW < HIGH, or a name
        given twice.
    """
    return _flag(_parse.parse_ranges, list(items or []), flag)


def parse_grid(text: str, flag: str) -> list[float]:
    """``"-60:-20:2"`` (START:STOP:STEP, stop included) or ``"-60,-40,-20"`` -> points.

    Raises
    ------
    ConfigError
        ``"<flag> takes START:STOP:STEP (step > 0) or a list: ..."``, with the reason.
    """
    try:
        return _parse.parse_grid(text)
    except ConfigError as exc:
        raise ConfigError(f"{flag} takes START:STOP:STEP (step > 0) or a list: {exc}") from None
