"""The registry of joint-log readers and their options, and one entry that opens a log by name.

``fricid extract --format``, the fleet manifest's ``reader`` column and
:func:`fricid.workflow.load_joint` all name a reader from :data:`READERS` and pass it options
from :data:`READER_OPTIONS` (SI units); :func:`open_log` checks both and calls the reader.

>>> from fricid.io import open_log
>>> opened = open_log("run.csv", "generic", {"columns": {"time": "t", "velocity": "dq",
...                   "torque": "tau"}})                                 # doctest: +SKIP
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..samples import FrictionSamples, RawLog

__all__ = [
    "CHUNKED_READERS",
    "EPOS_FOLDER_ONLY",
    "READERS",
    "READER_EXAMPLES",
    "READER_OPTIONS",
    "check_keys",
    "check_reader",
    "gives_samples",
    "open_log",
]

#: Readers of a joint's log: ``table`` (fricid's raw-log CSV/Parquet, as ``fricid simulate``
#: writes), ``generic`` (any CSV/Parquet through a column mapping and units,
#: :func:`fricid.io.read_table_log`), ``rosbag`` (a ROS 2 bag or MCAP file with
#: ``sensor_msgs/msg/JointState``, :func:`fricid.io.iter_rosbag`) and ``epos`` (a Maxon EPOS
#: recorder CSV, or a folder of steady-state recordings, one operating point per file; a single
#: steady recording gives its point as its folder does).
#: ``channels`` (a folder of headerless ``time value`` files, one per channel and run, by
#: file-name patterns, :func:`fricid.io.channels.read_channels`) and ``mat`` (a MATLAB v5 or
#: v7.3 file, variables by name, :func:`fricid.io.matlab.read_mat`).
READERS: tuple[str, ...] = ("table", "generic", "rosbag", "epos", "channels", "mat")

#: Options each reader accepts (SI units), passed to its :mod:`fricid.io` function.
READER_OPTIONS: dict[str, tuple[str, ...]] = {
    "table": ("temperature",),
    "generic": ("columns", "units", "torque_constant", "temperature"),
    "rosbag": (
        "joint",
        "topic",
        "temperature_topic",
        "temperature",
        "effort",
        "effort_unit",
        "torque_constant",
        "position_unit",
        "velocity_unit",
        "time_source",
    ),
    "epos": (
        "nominal_torque",
        "flip_sign",
        "temperature",
        "torque_constant",
        "counts_per_turn",
        "pattern",
        "load",
        "skip_bad_rows",
    ),
    "channels": (
        "channels",
        "units",
        "joint",
        "join",
        "tolerance",
        "time_unit",
        "temperature",
        "torque_constant",
    ),
    "mat": ("variables", "units", "joint", "temperature", "torque_constant"),
}

#: Readers that read a log a chunk of rows at a time (``chunk_rows`` of :func:`open_log`).
CHUNKED_READERS: tuple[str, ...] = ("table", "rosbag")

#: One-line examples of ``fricid extract`` per reader (its ``--help`` lists them).
READER_EXAMPLES: dict[str, str] = {
    "table": "fricid extract log.parquet -o samples.csv",
    "generic": "fricid extract run.csv --format generic --map time=t:ms --map velocity=dq:deg/s "
    "--map torque=tau:Nm",
    "rosbag": "fricid extract bag/ --format rosbag --joint elbow --effort current "
    "--torque-constant 0.1",
    "epos": "fricid extract recordings/ --format epos --flip-sign (one steady point per file)",
    "channels": "fricid extract runs/ --format channels "
    "--channels 'torque={name}_tau{joint}_{speed}.t:Nm' "
    "--channels 'velocity={name}_vel{joint}_{speed}.t:rad/s' --joint 1",
    "mat": "fricid extract means.mat --format mat --var velocity=fwd.v,bwd.v:rad/s "
    "--var friction=fwd.tau,bwd.tau:Nm --joint 2 (or --var time=t:s ... for a log)",
}


def gives_samples(reader: str, path: str | os.PathLike[str], options: Mapping[str, Any]) -> bool:
    """Whether ``reader`` gives friction samples directly (no extraction to apply).

    True for a folder of steady-state EPOS recordings (one operating point per file), one
    EPOS recording that holds one steady operating point (:func:`fricid.io.epos.steady_recording`:
    the same sample as its folder gives for it) and a MATLAB table of means (a ``friction``
    variable); every other log is extracted by :func:`fricid.extract.extract`, so extraction
    options apply to it.
    """
    if reader == "epos":
        from .epos import steady_recording

        return Path(path).is_dir() or steady_recording(path)
    if reader == "mat":
        return "friction" in dict(options.get("variables") or {})
    return False


#: Options of reader ``epos`` that apply to a folder of steady-state recordings only.
EPOS_FOLDER_ONLY: tuple[str, ...] = ("pattern", "load")


def check_keys(given: Mapping[str, Any], allowed: Sequence[str], what: str) -> None:
    """Refuse a key of ``given`` that is not in ``allowed``.

    Parameters
    ----------
    given : Mapping
        The options given.
    allowed : sequence of str
        The options accepted.
    what : str
        What an option is, for the message (e.g. ``"option of reader 'table'"``).

    Raises
    ------
    ConfigError
        Naming the first unknown key and listing the allowed ones.
    """
    unknown = [k for k in given if k not in allowed]
    if unknown:
        choices = ", ".join(allowed) if allowed else "none"
        raise ConfigError(f"unknown {what} '{unknown[0]}'; allowed: {choices}")


def check_reader(reader: str, options: Mapping[str, Any]) -> None:
    """Refuse an unknown reader, or an option that ``reader`` does not take.

    Raises
    ------
    ConfigError
        Listing the readers, or the reader's options; ``generic`` without ``columns``.
    """
    if reader not in READERS:
        raise ConfigError(f"unknown reader '{reader}'; choose one of: {', '.join(READERS)}")
    check_keys(options, READER_OPTIONS[reader], f"option of reader '{reader}'")
    if reader == "generic" and "columns" not in options:
        raise ConfigError(
            "reader 'generic' needs the option 'columns', each quantity's column in the file "
            "(fricid extract: --map time=t:ms --map velocity=dq:deg/s ...; fit --trajectory: "
            '--reader-option \'columns={"time": "t", "velocity": "dq", ...}\' with '
            "--reader-option 'units={...}')"
        )


def open_log(
    path: str | os.PathLike[str],
    reader: str = "table",
    options: Mapping[str, Any] | None = None,
    *,
    chunk_rows: int = 1_000_000,
    steady: bool = True,
) -> FrictionSamples | Iterator[RawLog]:
    """Open a joint's log with a reader of :data:`READERS`.

    Parameters
    ----------
    path : path-like
        The log: a fricid raw log (``table``), any CSV/Parquet table (``generic``), a ROS 2
        bag or MCAP file (``rosbag``), an EPOS recorder CSV or a folder of steady-state EPOS
        recordings (``epos``), a folder of per-channel files (``channels``), a MATLAB file
        (``mat``).
    reader : str
        One of :data:`READERS`.
    options : Mapping, optional
        The reader's options (:data:`READER_OPTIONS`, SI units).
    chunk_rows : int
        Rows read at a time from a ``table`` log or a bag (bounded memory).
    steady : bool
        Whether one EPOS recording that holds one steady operating point gives that point's
        samples (:func:`gives_samples`); False reads it as a time series (a trajectory's
        identification).

    Returns
    -------
    FrictionSamples or iterator of RawLog
        Samples for a folder of steady-state EPOS recordings (one operating point per file),
        one steady recording (with ``steady``) and a MATLAB table of means
        (:func:`gives_samples`), else the log as a stream of
        chunks (one chunk for ``generic``, an EPOS file and a MATLAB log; one per run for
        ``channels``, each run's time starting again).

    Raises
    ------
    ConfigError
        An unknown reader or option; a folder-only EPOS option given for one file; a bag
        read without the joint's name (the message lists the bag's joints).
    DataError
        Unreadable data, naming file, row and column where known.
    """
    # each reader imported where it is used: a raw log needs neither pandas nor the others
    path = Path(path)
    opts = dict(options or {})
    check_reader(reader, opts)
    if reader == "epos":
        from .epos import epos_steady_samples, read_epos, steady_recording

        if path.is_dir():
            return epos_steady_samples(path, **opts)
        extra = [k for k in EPOS_FOLDER_ONLY if k in opts]
        if extra:
            raise ConfigError(f"reader option '{extra[0]}' applies to a folder of EPOS recordings")
        if steady and steady_recording(path):  # the sample its folder gives for it
            return epos_steady_samples(path, **opts)
        return iter([read_epos(path, **opts)])
    if reader == "generic":
        from .generic import read_table_log

        return iter([read_table_log(path, **opts)])
    if reader == "channels":
        from .channels import read_channels

        return iter(read_channels(path, **opts))
    if reader == "mat":
        from .matlab import read_mat

        got = read_mat(path, **opts)
        return got if isinstance(got, FrictionSamples) else iter([got])
    if reader == "rosbag":
        from .rosbag import iter_rosbag, rosbag_joints

        if "joint" not in opts:
            topic = opts.get("topic", "/joint_states")
            raise ConfigError(
                f"reading a bag needs the joint's name; {path} has joints: "
                f"{', '.join(rosbag_joints(path, topic=topic))}"
            )
        return iter_rosbag(path, chunk_rows=chunk_rows, **opts)
    from .tables import iter_rawlog

    return iter_rawlog(path, chunk_rows=chunk_rows, **opts)
