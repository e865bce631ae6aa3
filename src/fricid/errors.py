"""The exception hierarchy of fricid.

Every error that bad input or bad options can cause is a :class:`FricidError`. The CLI turns
one into a single line on stderr and exit status 2 (DESIGN.md, "Errors").
"""

from __future__ import annotations

from os import PathLike

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
]


class FricidError(Exception):
    """Base class of every error fricid raises on purpose."""


class ConfigError(FricidError, ValueError):
    """An option, parameter or setting is invalid (not the data)."""


class DataError(FricidError, ValueError):
    """Input data is invalid. Names the file, the row and the column where they are known.

    ``row`` is the 1-based line number in the file where the file has lines (a CSV), else the
    0-based index of the record.
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
    """Base class of the caveats fricid attaches to an answer that stands (DESIGN.md, "Errors")."""


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
