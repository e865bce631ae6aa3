"""The exception hierarchy of fricid.

Every error that bad input or bad options can cause is a :class:`FricidError`. The CLI turns
one into a single line on stderr and exit status 2 (DESIGN.md, "Errors").
"""

from __future__ import annotations

import sys
from os import PathLike
from pathlib import Path

__all__ = [
    "ConfigError",
    "ConvergenceWarning",
    "DataError",
    "DataQualityWarning",
    "ExtrapolationWarning",
    "FricidError",
    "FricidWarning",
    "IdentifiabilityWarning",
    "IgnoredArgumentWarning",
    "user_stacklevel",
]

#: The package's folder: frames of files under it are fricid's own.
_PACKAGE = str(Path(__file__).resolve().parent)


def user_stacklevel() -> int:
    """The ``stacklevel`` that makes a warning point at the user's call.

    Called as ``warnings.warn(message, category, stacklevel=user_stacklevel())``: counts the
    frames from the function that warns up to the first one outside the fricid package (the
    user's script, a notebook cell, a test), however deep inside fricid the warning arose, so
    Python's ``file:line: Category: message`` names the user's line.

    Returns
    -------
    int
        1 when the whole stack is fricid's (the command line), the warning's own line.
    """
    frame = sys._getframe(1)
    level = 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    return level if frame is not None else 1


class FricidError(Exception):
    """Base class of every error fricid raises on purpose.

    Catch this to handle any bad input or bad option; anything else escaping fricid is a
    bug. The command line turns it into one line on stderr and exit status 2.
    """


class ConfigError(FricidError, ValueError):
    """An option, parameter or setting is invalid (not the data).

    The message names the option, the values it accepts and the value received.
    """


class DataError(FricidError, ValueError):
    """Input data is invalid; the message names the file, the row and the column.

    Parameters
    ----------
    message : str
        What is wrong, without the location (that is added from the other arguments).
    file : str or os.PathLike, optional
        The file the data came from.
    row : int, optional
        The 1-based line number in the file where the file has lines (a CSV), else the
        0-based index of the record (a Parquet row, a bag's message).
    column : str, optional
        The column or field.

    Attributes
    ----------
    message : str
        ``message`` as given.
    file : str or None
        ``file`` as a string.
    row : int or None
        ``row`` as given.
    column : str or None
        ``column`` as given.

    Examples
    --------
    >>> str(DataError("not a number: 'x'", file="log.csv", row=7, column="velocity"))
    "log.csv, row 7, column 'velocity': not a number: 'x'"
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | PathLike[str] | None = None,
        row: int | None = None,
        column: str | None = None,
    ) -> None:
        self.message = message
        self.file = None if file is None else str(file)
        self.row = row
        self.column = column
        super().__init__(self._render())

    def _render(self) -> str:
        """The message prefixed with the known parts of the location."""
        where = []
        if self.file is not None:
            where.append(self.file)
        if self.row is not None:
            where.append(f"row {self.row}")
        if self.column is not None:
            where.append(f"column '{self.column}'")
        text = f"{', '.join(where)}: {self.message}" if where else self.message
        return " ".join(text.splitlines())  # one line, whatever text the file put in it


class FricidWarning(UserWarning):
    """Base class of the caveats fricid attaches to an answer that stands (DESIGN.md, "Errors").

    Raised with ``stacklevel`` pointing at the caller's line; filter the whole family with
    ``warnings.simplefilter("ignore", FricidWarning)``. The command line prints each as one
    line on stderr and saves it with the result.
    """


class ConvergenceWarning(FricidWarning):
    """An optimiser stopped before converging (budget spent, stopped, stalled)."""


class ExtrapolationWarning(FricidWarning):
    """A prediction lies outside the operating range the model was identified on."""


class IdentifiabilityWarning(FricidWarning):
    """The data cannot determine a parameter (at a bound, singular, strongly correlated)."""


class DataQualityWarning(FricidWarning):
    """The data were usable but something in them needs a look (outliers, scatter, transients)."""


class IgnoredArgumentWarning(FricidWarning):
    """An argument or option was given that the chosen method does not use."""
