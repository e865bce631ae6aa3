"""``fricid extract``'s torque-constant flags: K of the BAS-RBFNN paper's eq. 13
(``tau = K I``) from a torque sensor (``--identify-torque-constant``) or from the gravity load
a URDF gives (``--urdf``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import ConfigError
from ._app import console

__all__ = [
    "UrdfJointOption",
    "UrdfOption",
    "UrdfPositionOption",
    "identify_from_urdf",
    "print_torque_constant",
]

#: ``--urdf PATH``.
UrdfOption = Annotated[
    Path | None,
    typer.Option(
        "--urdf",
        help="Identify K of tau = K I (eq. 13) from a current-only log and the gravity load of "
        "--urdf-joint computed from this URDF (masses and centres of mass of the links below "
        "the joint, eq. 7): e.g. --urdf robot.urdf --urdf-joint elbow. The log's position "
        "must be the URDF joint's (same zero and sign). Prints K with its 95 % interval "
        "(the gear efficiency is not identified from gravity alone), then writes the samples "
        "in N m with that K (or with --torque-constant, or the log's own K, where given). "
        "Needs gravity fit or joint (both directions over several positions).",
    ),
]

#: ``--urdf-joint NAME``.
UrdfJointOption = Annotated[
    str | None,
    typer.Option(
        "--urdf-joint",
        help="The URDF joint the log records (revolute or continuous, axis not vertical).",
    ),
]

#: ``--urdf-position NAME=VALUE`` (repeatable).
UrdfPositionOption = Annotated[
    list[str] | None,
    typer.Option(
        "--urdf-position",
        metavar="NAME=VALUE",
        help="The position of another URDF joint during the log, NAME=VALUE in rad (m for a "
        "prismatic joint), e.g. --urdf-position shoulder=0.5; repeatable; joints not given "
        "are at zero.",
    ),
]


def print_torque_constant(log: Path, fmt: str, reader_options: dict, chunk_rows: int) -> None:
    """``--identify-torque-constant``: K (and the efficiency) from current and torque."""
    from ..extract.torque_constant import fit_torque_constant
    from ..io import open_log

    opened = open_log(log, fmt, reader_options, chunk_rows=chunk_rows, steady=False)
    if not hasattr(opened, "__next__"):
        raise ConfigError(
            "--identify-torque-constant needs a log of samples over time with both a current "
            "and a torque column, not a folder of steady-state recordings"
        )
    console.print(fit_torque_constant(opened).summary(), markup=False, highlight=False)


def identify_from_urdf(
    log: Path,
    fmt: str,
    reader_options: dict,
    extract_options: dict,
    chunk_rows: int,
    *,
    urdf: Path | None,
    joint: str | None,
    positions: list[str] | None,
):
    """``--urdf``: eq. 7 fitted on the current [A] against the URDF's [N m] gives K.

    Reads the log once with ``K = 1`` (the current as torque), prints the URDF's gravity load
    and K with its interval, and returns the :class:`~fricid.extract.TorqueConstantFit`.

    Raises
    ------
    ConfigError
        ``--urdf`` without ``--urdf-joint`` (or the reverse), a format that gives samples
        directly, ``--gravity none``, a bad joint or position.
    DataError
        A bad URDF, a log without current, a gravity fit that fails.
    """
    from ..extract.torque_constant import current_as_torque, torque_constant_from_gravity
    from ..io.options import parse_assignments
    from ..io.registry import READER_OPTIONS, gives_samples
    from ..io.urdf import urdf_gravity
    from ..workflow import load_joint

    if urdf is None or joint is None:
        raise ConfigError("--urdf and --urdf-joint go together (and --urdf-position needs both)")
    if gives_samples(fmt, log, reader_options):
        raise ConfigError(
            "--urdf needs a log of samples over time (current and position), not steady "
            "operating points"
        )
    if extract_options.get("gravity") == "none":
        raise ConfigError("--urdf identifies K from the gravity load: --gravity none has none")
    try:
        pos = parse_assignments(positions)
    except ConfigError as exc:
        raise ConfigError(f"--urdf-position: {exc}") from None
    load = urdf_gravity(urdf, joint, pos)
    console.print(load.summary(), markup=False, highlight=False)
    ropts = dict(reader_options)
    if "torque_constant" in READER_OPTIONS[fmt]:
        ropts["torque_constant"] = 1.0  # readers of current need some K; it is dropped
    amps = load_joint(
        log,
        fmt,
        reader_options=ropts,
        extract_options=extract_options,
        chunk_rows=chunk_rows,
        chunk_map=current_as_torque,
    )
    g = amps.extraction.gravity if amps.extraction is not None else None
    if g is None:
        raise ConfigError(
            "--urdf needs gravity identified from the log: give --positions (gravity fit) or "
            "--gravity joint"
        )
    fit = torque_constant_from_gravity(
        (g.p_x, g.p_y), (g.p_x_se, g.p_y_se), (load.p_x, load.p_y), source=str(log)
    )
    console.print(
        f"gravity (eq. 7) on the current: p_x = {g.p_x:.6g} +- {g.p_x_se:.2g}, "
        f"p_y = {g.p_y:.6g} +- {g.p_y_se:.2g} A",
        markup=False,
        highlight=False,
    )
    console.print(fit.summary(), markup=False, highlight=False)
    return fit
