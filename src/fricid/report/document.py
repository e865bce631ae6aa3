"""The content of a report, independent of its format: sections of text, tables and figures.

A :class:`Document` is built by :func:`fricid.report.model_report` (one fitted model on one data
set) and by the paper reproductions (:mod:`fricid.report.reproduce`); it is rendered to
HTML and Markdown by :mod:`fricid.report.render` and written to a folder, every table also as
CSV and every figure as PNG, by :func:`fricid.report.write_document`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from ..errors import ConfigError

__all__ = ["Document", "Figure", "Item", "Note", "Section", "Table"]

_NAME = re.compile(r"^[a-z0-9][a-z0-9_\-]*$")


def _check_name(name: str) -> str:
    if not _NAME.match(name):
        raise ConfigError(
            f"report item name '{name}' must be lower-case letters, digits, '_' or '-' "
            "(it becomes a file name)"
        )
    return name


#: Tables longer than this many rows are folded in the HTML (the verdict and the figures stay
#: in view; a click opens the table).
FOLD_ROWS = 12


@dataclass
class Table:
    """A table: written as an HTML table, a Markdown pipe table and ``<name>.csv``.

    Attributes
    ----------
    name : file stem of the CSV (lower case, digits, ``_``, ``-``).
    title : heading, e.g. ``"Table 1. Fitness of the three analytic models"``.
    frame : the data; its index is written as the first column when ``index`` is true.
    caption : what the table shows; for a reproduced table, where the paper's numbers come from
        and why ours differ.
    index : write the frame's index.
    digits : significant digits of floats in HTML and Markdown (CSV keeps full precision).
    folded : shown folded in the HTML (a ``<details>`` element: the title and the number of
        rows, opened on a click); None (the default): when longer than :data:`FOLD_ROWS`.
    """

    name: str
    title: str
    frame: pd.DataFrame
    caption: str = ""
    index: bool = False
    digits: int = 4
    folded: bool | None = None

    def __post_init__(self) -> None:
        _check_name(self.name)

    @property
    def is_folded(self) -> bool:
        """Whether the HTML shows the table folded (``folded``, else its length)."""
        return len(self.frame) > FOLD_ROWS if self.folded is None else bool(self.folded)


@dataclass
class Figure:
    """A figure as PNG bytes: embedded in the HTML, linked from the Markdown, ``<name>.png``.

    ``caption`` says what the figure shows; for a reproduced figure, what the paper showed and
    where ours differ. ``plotly``, when given, is the same figure as Plotly JSON
    (:mod:`fricid.report.interactive`): the HTML shows it interactive (zoom, pan, hover) with
    the PNG as its no-JavaScript fallback; the Markdown links the PNG.
    """

    name: str
    title: str
    png: bytes
    caption: str = ""
    plotly: str | None = None

    def __post_init__(self) -> None:
        _check_name(self.name)
        if not self.png.startswith(b"\x89PNG"):
            raise ConfigError(f"figure '{self.name}' is not a PNG image")


@dataclass
class Note:
    """A paragraph of text; ``kind`` ``"warning"`` is set off (e.g. a study not yet available)."""

    text: str
    kind: str = "text"


Item = Table | Figure | Note


@dataclass
class Section:
    """A titled section: an introductory text, then tables, figures and notes in order."""

    title: str
    text: str = ""
    items: list[Item] = field(default_factory=list)

    def add(self, item: Item) -> Item:
        """Append ``item`` and return it."""
        self.items.append(item)
        return item


@dataclass
class Document:
    """A whole report: title, summary, sections and a few facts (``meta``) shown at the top."""

    title: str
    summary: str = ""
    sections: list[Section] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)

    def section(self, title: str, text: str = "") -> Section:
        """Append a new section and return it."""
        sec = Section(title, text)
        self.sections.append(sec)
        return sec

    def tables(self) -> list[Table]:
        """Every table, in order."""
        return [i for s in self.sections for i in s.items if isinstance(i, Table)]

    def figures(self) -> list[Figure]:
        """Every figure, in order."""
        return [i for s in self.sections for i in s.items if isinstance(i, Figure)]

    def check_unique(self) -> None:
        """Raise if two tables or two figures share a file name."""
        seen: set[str] = set()
        for item in self.tables() + self.figures():
            ext = "csv" if isinstance(item, Table) else "png"
            key = f"{item.name}.{ext}"
            if key in seen:
                raise ConfigError(f"two report items would both be written as {key}")
            seen.add(key)
