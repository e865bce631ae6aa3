"""Reports: figures, tables and their HTML and Markdown rendering.

>>> from fricid.identify.trust import assess_trust
>>> from fricid.report import model_report, write_document
>>> trust = assess_trust(fitted, samples)                   # doctest: +SKIP
>>> doc = model_report(fitted, samples, trust=trust)        # doctest: +SKIP
>>> write_document(doc, "report/")                          # doctest: +SKIP

:mod:`.document` (the format-free content), :mod:`.render` (HTML, Markdown), :mod:`.writer`
(the folder, written all or nothing), :mod:`.style`, :mod:`.plots` and :mod:`.paper_plots`
(matplotlib figures created directly, Agg canvas, no pyplot), :mod:`.model` (the report of one
identified model), :mod:`.arm` (the report of a whole arm's identification, a row per
joint), :mod:`.trust` (its "Can I trust this?" section, rendered from the record
:func:`fricid.identify.trust.assess_trust` computes; the report computes no validation or
verdict), :mod:`.rbf` (the RBF network's part), :mod:`.studies` (the papers' studies
from :mod:`fricid.experiments`, as text, files and documents) and :mod:`.reproduce`
(``fricid reproduce``).
"""

from __future__ import annotations

from .arm import arm_report
from .document import Document, Figure, Note, Section, Table
from .model import model_report
from .render import render_html, render_markdown
from .writer import write_document

__all__ = [
    "Document",
    "Figure",
    "Note",
    "Section",
    "Table",
    "arm_report",
    "model_report",
    "render_html",
    "render_markdown",
    "write_document",
]
