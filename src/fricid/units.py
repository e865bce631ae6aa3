"""Units: SI inside (rad, rad/s, N m, A, degC, s); conversions happen once, at the edge.

Every reader and CLI flag converts through :func:`to_si`, which knows each quantity's
accepted unit spellings and refuses anything else with the list of what it accepts.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .errors import ConfigError

__all__ = ["DEG", "SI_UNITS", "UNITS", "from_si", "to_si"]

#: The SI unit fricid uses inside for each quantity.
SI_UNITS: dict[str, str] = {
    "time": "s",
    "position": "rad",
    "velocity": "rad/s",
    "torque": "N m",
    "current": "A",
    "temperature": "degC",
    "torque_constant": "N m/A",
    "acceleration": "rad/s^2",
}

#: One degree in radians (the one copy in fricid).
DEG = math.pi / 180.0
_RPM = 2.0 * math.pi / 60.0

#: The accepted unit spellings: quantity -> unit -> ``(scale, offset)``, where
#: ``si = value * scale + offset``.
UNITS: dict[str, dict[str, tuple[float, float]]] = {
    "time": {"s": (1.0, 0.0), "ms": (1e-3, 0.0), "us": (1e-6, 0.0), "min": (60.0, 0.0)},
    "position": {"rad": (1.0, 0.0), "deg": (DEG, 0.0), "rev": (2.0 * math.pi, 0.0)},
    "velocity": {
        "rad/s": (1.0, 0.0),
        "deg/s": (DEG, 0.0),
        "rpm": (_RPM, 0.0),
        "rev/s": (2.0 * math.pi, 0.0),
    },
    "torque": {"N m": (1.0, 0.0), "Nm": (1.0, 0.0), "mN m": (1e-3, 0.0), "mNm": (1e-3, 0.0)},
    "current": {"A": (1.0, 0.0), "mA": (1e-3, 0.0)},
    "temperature": {"degC": (1.0, 0.0), "C": (1.0, 0.0), "K": (1.0, -273.15)},
    "torque_constant": {"N m/A": (1.0, 0.0), "Nm/A": (1.0, 0.0), "mNm/A": (1e-3, 0.0)},
    "acceleration": {"rad/s^2": (1.0, 0.0), "rad/s2": (1.0, 0.0), "deg/s^2": (DEG, 0.0)},
}


def _factor(quantity: str, unit: str) -> tuple[float, float]:
    """The ``(scale, offset)`` of ``unit`` for ``quantity``: ``si = value * scale + offset``.

    Raises
    ------
    ConfigError
        An unknown quantity, or a unit spelling ``quantity`` does not accept (the message
        lists the accepted spellings).
    """
    try:
        table = UNITS[quantity]
    except KeyError:
        raise ConfigError(
            f"unknown quantity '{quantity}'; known quantities: {', '.join(UNITS)}"
        ) from None
    try:
        return table[unit.strip()]
    except KeyError:
        raise ConfigError(
            f"unknown {quantity} unit '{unit}'; use one of: {', '.join(table)}"
        ) from None


def to_si(values: ArrayLike, unit: str, quantity: str) -> ArrayLike:
    """Convert values given in ``unit`` to the SI unit of ``quantity``.

    Parameters
    ----------
    values : array_like
        The values, in ``unit``.
    unit : str
        Their unit, one of the spellings in ``UNITS[quantity]`` (surrounding spaces ignored),
        e.g. ``"deg/s"`` or ``"rpm"`` for a velocity.
    quantity : str
        What the values measure, a key of :data:`UNITS` (``"velocity"``, ``"torque"``, ...).

    Returns
    -------
    array_like
        The values in :data:`SI_UNITS` ``[quantity]``: a float array, or ``values`` itself,
        unconverted and uncopied, when ``unit`` is already SI.

    Raises
    ------
    ConfigError
        An unknown quantity, or a unit that ``quantity`` does not accept (the message lists
        the accepted spellings).

    See Also
    --------
    from_si : the inverse conversion.

    Examples
    --------
    >>> round(float(to_si(60.0, "rpm", "velocity")), 6)
    6.283185
    >>> round(float(to_si(300.0, "K", "temperature")), 2)
    26.85
    """
    scale, offset = _factor(quantity, unit)
    if scale == 1.0 and offset == 0.0:
        return values
    return np.asarray(values, dtype=float) * scale + offset


def from_si(values: ArrayLike, unit: str, quantity: str) -> ArrayLike:
    """Convert SI values of ``quantity`` to ``unit`` (the inverse of :func:`to_si`).

    Parameters
    ----------
    values : array_like
        The values, in :data:`SI_UNITS` ``[quantity]``.
    unit : str
        The unit wanted, one of the spellings in ``UNITS[quantity]``.
    quantity : str
        What the values measure, a key of :data:`UNITS`.

    Returns
    -------
    array_like
        The values in ``unit``: a float array, or ``values`` itself when ``unit`` is SI.

    Raises
    ------
    ConfigError
        An unknown quantity or unit, as in :func:`to_si`.

    Examples
    --------
    >>> round(float(from_si(DEG, "deg", "position")), 12)
    1.0
    """
    scale, offset = _factor(quantity, unit)
    if scale == 1.0 and offset == 0.0:
        return values
    return (np.asarray(values, dtype=float) - offset) / scale
