"""The joints of a multi-joint file mapped to the names asked for, and the column names of a
wide table read as ``(quantity, joint)``.

Mapping rules (:func:`match_joints`), for each joint of the file: its exact name among those
asked for, else the one asked-for name equal to it ignoring case, else, for a joint known by
a number (``q1``), the asked-for name at that 1-based index (0-based when the file's numbers
are exactly 0 to k-1). The file must have as many joints as were asked for: a joint left
over or missing is one :class:`~fricid.errors.DataError` listing both sides, never a guess;
the one exception is a file with more joints than asked for whose every asked-for joint it
names (exactly, else ignoring case): those joints are taken, by name.

Column names (:func:`parse_name`), case-insensitive in the quantity: ``<joint>.<quantity>``,
``<quantity>_<joint>``, ``<joint>_<quantity>`` and ``<quantity><number>`` (``q1``, ``dq1``,
``tau1``), checked in that order, where the quantity is one of :data:`ALIASES`; ``time`` or
``t`` is the time; a bare quantity (``position``) belongs to no joint (a one-joint table, or
a temperature shared by all joints).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError

__all__ = [
    "ALIASES",
    "check_names",
    "constants_for",
    "match_joints",
    "parse_name",
    "velocity_from_position",
]

#: The spellings of each per-joint quantity in a column name (lower case).
ALIASES: dict[str, tuple[str, ...]] = {
    "position": ("position", "pos", "q"),
    "velocity": ("velocity", "vel", "dq", "qd"),
    "acceleration": ("acceleration", "acc", "ddq", "qdd"),
    "torque": ("torque", "effort", "eff", "tau"),
    "current": ("current", "cur", "i"),
    "temperature": ("temperature", "temp"),
    "load": ("load",),
}

_QUANTITY = {alias: q for q, aliases in ALIASES.items() for alias in aliases}
_LONGEST_FIRST = sorted(_QUANTITY, key=len, reverse=True)
_NUMBERED = re.compile(r"([a-z]+)([0-9]+)")
_NUMBER = re.compile(r"[0-9]+")


def parse_name(name: str) -> tuple[str, str | None] | None:
    """What a column holds, from its name (without the bracketed unit).

    Parameters
    ----------
    name : str
        The column's name, e.g. ``"q1"``, ``"elbow.position"``, ``"tau_3"``.

    Returns
    -------
    tuple of (str, str or None), or None
        ``(quantity, joint)``: a key of :data:`ALIASES` or ``"time"``, and the joint as
        written (None for a column of no joint); None for a column that is none of these.

    Examples
    --------
    >>> parse_name("q1"), parse_name("elbow_joint.velocity"), parse_name("tau_3")
    (('position', '1'), ('velocity', 'elbow_joint'), ('torque', '3'))
    >>> parse_name("position_shoulder"), parse_name("shoulder_effort"), parse_name("notes")
    (('position', 'shoulder'), ('torque', 'shoulder'), None)
    """
    name = name.strip()
    low = name.lower()
    if low in ("time", "t"):
        return ("time", None)
    if low in _QUANTITY:
        return (_QUANTITY[low], None)
    left, dot, right = name.rpartition(".")
    if dot and left and right.lower() in _QUANTITY:
        return (_QUANTITY[right.lower()], left)
    for alias in _LONGEST_FIRST:
        if low.startswith(alias + "_") and len(low) > len(alias) + 1:
            return (_QUANTITY[alias], name[len(alias) + 1 :])
    for alias in _LONGEST_FIRST:
        if low.endswith("_" + alias) and len(low) > len(alias) + 1:
            return (_QUANTITY[alias], name[: -len(alias) - 1])
    m = _NUMBERED.fullmatch(low)
    if m is not None and m.group(1) in _QUANTITY:
        return (_QUANTITY[m.group(1)], m.group(2))
    return None


def check_names(joints: Sequence[str]) -> list[str]:
    """The names asked for (``joints=``): unique, non-empty strings, else a ConfigError."""
    if isinstance(joints, str):
        raise ConfigError(f"joints= must be a list of joint names, not the string {joints!r}")
    names = list(joints)
    if not names or not all(isinstance(n, str) and n.strip() for n in names):
        raise ConfigError(f"joints= must be a non-empty list of joint names, got {names!r}")
    if len(set(names)) != len(names):
        twice = sorted({n for n in names if names.count(n) > 1})
        raise ConfigError(f"joints= names {', '.join(twice)} more than once")
    return names


def _count(n: int) -> str:
    return f"{n} joint" if n == 1 else f"{n} joints"


def _by_name(wanted: str, found: list[str]) -> str | None:
    """The joint of the file named ``wanted``, exactly or else alone ignoring case."""
    if wanted in found:
        return wanted
    same = [f for f in found if f.lower() == wanted.lower()]
    return same[0] if len(same) == 1 else None


def _target(found: str, wanted: list[str], zero_based: bool) -> str | None:
    """The asked-for name a joint of the file maps to (the module's rules), or None."""
    if found in wanted:
        return found
    same = [w for w in wanted if w.lower() == found.lower()]
    if len(same) == 1:
        return same[0]
    if _NUMBER.fullmatch(found):
        i = int(found) - (0 if zero_based else 1)
        if 0 <= i < len(wanted):
            return wanted[i]
    return None


def match_joints(
    found: Sequence[str],
    wanted: Sequence[str] | None,
    *,
    file: str | os.PathLike[str] | None,
) -> tuple[list[str], list[str]]:
    """Map the joints of a file to the names asked for.

    Parameters
    ----------
    found : sequence of str
        The joints as the file names them, in file order.
    wanted : sequence of str or None
        The names to map to (e.g. a URDF's moving joints, in order); None keeps the file's.
    file : str or os.PathLike or None
        The file (for messages).

    Returns
    -------
    order : list of str
        The file's joints in the order of ``wanted``.
    names : list of str
        Their names: ``wanted`` (or ``found`` when None).

    Raises
    ------
    ConfigError
        ``wanted`` empty, with an empty or repeated name.
    DataError
        Another number of joints than asked for, a joint of the file that maps to no name
        asked for, or two that map to one; the message lists what the file has and what was
        asked for.

    Examples
    --------
    >>> match_joints(["1", "2"], ["shoulder", "elbow"], file=None)
    (['1', '2'], ['shoulder', 'elbow'])
    >>> match_joints(["Elbow", "shoulder"], ["shoulder", "elbow"], file=None)
    (['shoulder', 'Elbow'], ['shoulder', 'elbow'])
    """
    found = list(found)
    if wanted is None:
        return found, found
    wanted = check_names(wanted)
    has = ", ".join(repr(f) for f in found) or "none"
    asked = ", ".join(repr(w) for w in wanted)
    if len(found) > len(wanted):
        by_name = [_by_name(w, found) for w in wanted]
        if all(by_name):
            return by_name, wanted  # type: ignore[return-value]
    if len(found) != len(wanted):
        numbered = all(_NUMBER.fullmatch(f) for f in found)
        why = "numbered columns cannot say which is which" if numbered else "not all by name"
        raise DataError(
            f"the file has {_count(len(found))} ({has}) but {len(wanted)} "
            f"{'was' if len(wanted) == 1 else 'were'} asked for ({asked}), {why}: name the "
            "file's columns after the joints (e.g. '<joint>.position [rad]'), or in Python "
            "give joints= with one name per joint of the file",
            file=file,
        )
    numbers = [int(f) for f in found if _NUMBER.fullmatch(f)]
    zero_based = sorted(numbers) == list(range(len(found)))
    target = {f: _target(f, wanted, zero_based) for f in found}
    problems = [f"{f!r} matches no name asked for" for f, t in target.items() if t is None]
    for w in wanted:
        by = [f for f, t in target.items() if t == w]
        if len(by) > 1:
            problems.append(f"{' and '.join(repr(f) for f in by)} both map to {w!r}")
        elif not by:
            problems.append(f"no joint of the file maps to {w!r}")
    if problems:
        raise DataError(
            f"cannot map the file's joints ({has}) to the joints asked for ({asked}): "
            + "; ".join(problems)
            + " (a name matches exactly, then ignoring case, then a number as a 1-based index)",
            file=file,
        )
    inverse = {t: f for f, t in target.items()}
    return [inverse[w] for w in wanted], wanted


def constants_for(names: Sequence[str], torque_constants: Any) -> Any:
    """``torque_constants=`` as one K [N m/A] per joint of ``names``: a mapping by joint name
    (every joint named), or a sequence already in the order of ``names``; None stays None."""
    if not isinstance(torque_constants, Mapping):
        return torque_constants
    missing = [n for n in names if n not in torque_constants]
    unknown = [k for k in torque_constants if k not in names]
    if missing or unknown:
        raise ConfigError(
            f"torque_constants= must give one K [N m/A] for each joint ({', '.join(names)})"
            + (f"; missing: {', '.join(missing)}" if missing else "")
            + (f"; not a joint of the log: {', '.join(map(str, unknown))}" if unknown else "")
        )
    return [torque_constants[n] for n in names]


def velocity_from_position(position: np.ndarray, time: np.ndarray, file: Any) -> np.ndarray:
    """Velocities as the central difference of positions (:func:`numpy.gradient`: second
    order inside, one-sided at the ends), for a file that logs none."""
    if len(time) < 2:
        raise DataError(
            "the file has no velocities, and one row is too few to compute them from the positions",
            file=file,
            column="velocity",
        )
    with np.errstate(over="ignore", invalid="ignore"):  # RobotLog reports absurd values
        return np.gradient(position, time, axis=0)
