"""Reports: figures, tables and their HTML and Markdown rendering.

>>> from fricid.report import model_report, write_document
>>> doc = model_report(fitted, samples)            # doctest: +SKIP
>>> write_document(doc, "report/")                  # doctest: +SKIP

:mod:`.document` (the format-free content), :mod:`.render` (HTML, Markdown), :mod:`.writer`
(the folder, written all or nothing), :mod:`.style`, :mod:`.plots` and :mod:`.paper_plots`
(matplotlib figures created directly, Agg canvas, no pyplot), :mod:`.model` (the report of one
identified model), :mod:`.trust` (its "Can I trust this?" verdict, also the fleet's verdict
columns), :mod:`.rbf` (the RBF network's part), :mod:`.studies` (the papers' studies
from :mod:`fricid.experiments`, as text, files and documents) and :mod:`.reproduce`
(``fricid reproduce``).
"""

from __future__ import annotations

from .document import Document, Figure, Note, Section, Table
from .model import model_report
from .render import render_html, render_markdown
from .trust import Trust, assess_trust
from .writer import write_document

__all__ = [
    "Document",
    "Figure",
    "Note",
    "Section",
    "Table",
    "Trust",
    "assess_trust",
    "model_report",
    "render_html",
    "render_markdown",
    "write_document",
]
