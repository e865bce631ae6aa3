"""Render a :class:`~fricid.report.document.Document` as self-contained HTML or as Markdown.

The HTML embeds every figure as a base64 PNG and every table as an HTML table, with a small
inline style sheet: one file that opens anywhere, offline. Figures that carry a Plotly version
(:mod:`fricid.report.interactive`) are interactive there, plotly.js inlined once (not from a
CDN), the PNG kept as the fallback without JavaScript. The Markdown links the PNG and CSV
files written beside it. Text in sections and notes is plain text with a tiny markup: blank
lines separate paragraphs, lines starting with ``- `` form a list, ```code``` and ``**bold**``.
"""

from __future__ import annotations

import base64
import html
import math
import re
from importlib import resources
from numbers import Number

from .document import Document, Figure, Note, Section, Table

__all__ = ["format_value", "plotly_js", "render_html", "render_markdown", "slug"]

_CSS = """
body{font-family:-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;max-width:1100px;
margin:2em auto;padding:0 1.2em;color:#1d2330;line-height:1.5;background:#fff}
h1{font-size:1.7em;margin-bottom:.2em}h2{margin-top:2.2em;border-bottom:2px solid #e3e7ee;
padding-bottom:.2em}h3{margin-top:1.6em;font-size:1.1em}
.summary{font-size:1.05em;color:#333}
table{border-collapse:collapse;margin:.6em 0 .4em;font-size:.92em}
th,td{border:1px solid #d5dae3;padding:.28em .65em;text-align:right}
th{background:#f1f4f9;font-weight:600}td:first-child,th:first-child{text-align:left}
tr:nth-child(even) td{background:#fafbfd}
.meta td{text-align:left}.meta td:first-child{color:#555;white-space:nowrap}
figure{margin:1.2em 0}figure img{max-width:100%;border:1px solid #e3e7ee}
figcaption,.caption{color:#444;font-size:.92em;margin-top:.3em}
.note-warning{border-left:4px solid #d9822b;background:#fff6ec;padding:.5em .9em}
code{background:#f1f4f9;padding:0 .25em;border-radius:3px}
nav ul{columns:2;font-size:.92em}.files{color:#666;font-size:.85em}
.plotly-figure{width:100%;min-height:480px;border:1px solid #e3e7ee}
details.folded summary{cursor:pointer}details.folded summary h3{display:inline;margin-right:.6em}
details.folded .rows{color:#666;font-size:.9em}
"""


def slug(text: str) -> str:
    """An HTML anchor for a heading."""
    s = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")
    return s or "section"


def format_value(value, digits: int = 4) -> str:
    """A table cell as text: floats to ``digits`` significant digits, NaN and None as a dash."""
    if value is None:
        return "–"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, Number):
        f = float(value)  # type: ignore[arg-type]
        if math.isnan(f):
            return "–"
        if float(f).is_integer() and abs(f) < 1e6 and not isinstance(value, float):
            return str(int(f))
        return f"{f:.{digits}g}"
    return str(value)


def _inline_html(text: str) -> str:
    out = html.escape(text, quote=False)
    out = re.sub(r"`([^`]+)`", r"<code>\1</code>", out)
    return re.sub(r"\*\*([^*]+)\*\*", r"<strong>\1</strong>", out)


def _blocks(text: str) -> list[tuple[str, list[str]]]:
    """Split text into ("p", [lines]) and ("ul", [items]) blocks."""
    blocks: list[tuple[str, list[str]]] = []
    for para in re.split(r"\n\s*\n", text.strip()):
        lines = [ln.rstrip() for ln in para.splitlines() if ln.strip()]
        if not lines:
            continue
        if all(ln.lstrip().startswith("- ") for ln in lines):
            blocks.append(("ul", [ln.lstrip()[2:] for ln in lines]))
        else:
            blocks.append(("p", lines))
    return blocks


def _text_html(text: str, cls: str = "") -> str:
    attr = f' class="{cls}"' if cls else ""
    parts = []
    for kind, lines in _blocks(text):
        if kind == "ul":
            items = "".join(f"<li>{_inline_html(i)}</li>" for i in lines)
            parts.append(f"<ul{attr}>{items}</ul>")
        else:
            parts.append(f"<p{attr}>{_inline_html(' '.join(lines))}</p>")
    return "\n".join(parts)


def _cells(table: Table) -> tuple[list[str], list[list[str]]]:
    frame = table.frame.reset_index() if table.index else table.frame
    header = [str(c) for c in frame.columns]
    rows = [[format_value(v, table.digits) for v in row] for row in frame.itertuples(index=False)]
    return header, rows


def _table_html(table: Table) -> str:
    header, rows = _cells(table)
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in rows
    )
    caption = _text_html(table.caption, "caption") if table.caption else ""
    heading = f'<h3 id="{slug(table.title)}">{_inline_html(table.title)}</h3>'
    content = (
        f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>\n{caption}\n"
        f'<div class="files">{table.name}.csv</div>'
    )
    if table.is_folded:  # long: one line until opened, the verdict and figures stay in view
        rows = len(table.frame)
        return (
            f'<details class="folded"><summary>{heading}'
            f'<span class="rows">{rows} rows: click to show</span></summary>\n{content}</details>'
        )
    return f"{heading}\n{content}"


def plotly_js() -> str | None:
    """plotly.js from the installed ``plotly`` package (inlined: no CDN, works offline), or
    None without it (the figures are then shown as PNG)."""
    try:
        return (resources.files("plotly") / "package_data" / "plotly.min.js").read_text("utf-8")
    except (ModuleNotFoundError, FileNotFoundError, OSError):  # pragma: no cover
        return None


def _figure_html(fig: Figure, interactive: bool = False) -> str:
    data = base64.b64encode(fig.png).decode("ascii")
    caption = _text_html(fig.caption) if fig.caption else ""
    img = f'<img alt="{html.escape(fig.title)}" src="data:image/png;base64,{data}">'
    if interactive and fig.plotly:
        spec = fig.plotly.replace("</", "<\\/")  # never closes the script element
        div_id = f"plotly-{fig.name}"
        img = (
            f'<div class="plotly-figure" id="{div_id}"></div>'
            f"<script>(function(){{var s={spec};Plotly.newPlot({div_id!r},s.data,s.layout,"
            "{responsive:true,displaylogo:false});})();</script>"
            f"<noscript>{img}</noscript>"
        )
    return (
        f'<figure id="{slug(fig.title)}"><h3>{_inline_html(fig.title)}</h3>{img}'
        f"<figcaption>{caption}</figcaption>"
        f'<div class="files">{fig.name}.png</div></figure>'
    )


def _item_html(item, interactive: bool = False) -> str:
    if isinstance(item, Table):
        return _table_html(item)
    if isinstance(item, Figure):
        return _figure_html(item, interactive)
    if isinstance(item, Note):
        cls = "note-warning" if item.kind == "warning" else ""
        return f'<div class="{cls}">{_text_html(item.text)}</div>'
    raise TypeError(f"unknown report item {type(item).__name__}")


def _meta_html(meta: dict) -> str:
    if not meta:
        return ""
    rows = "".join(
        f"<tr><td>{html.escape(str(k))}</td><td>{html.escape(format_value(v, 6))}</td></tr>"
        for k, v in meta.items()
    )
    return f'<table class="meta"><tbody>{rows}</tbody></table>'


def _section_html(sec: Section, interactive: bool = False) -> str:
    body = [f'<h2 id="{slug(sec.title)}">{_inline_html(sec.title)}</h2>']
    if sec.text:
        body.append(_text_html(sec.text))
    body.extend(_item_html(i, interactive) for i in sec.items)
    return "<section>\n" + "\n".join(body) + "\n</section>"


def render_html(doc: Document) -> str:
    """The document as one self-contained HTML page: figures embedded as base64 PNG, those
    with a Plotly version interactive (plotly.js inlined once, in the head; the PNG kept for
    a browser without JavaScript)."""
    js = plotly_js() if any(f.plotly for f in doc.figures()) else None
    toc = "".join(
        f'<li><a href="#{slug(s.title)}">{_inline_html(s.title)}</a></li>' for s in doc.sections
    )
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(doc.title)}</title><style>{_CSS}</style>",
        f'<script type="text/javascript">{js}</script>' if js else "",
        "</head><body>",
        f"<h1>{_inline_html(doc.title)}</h1>",
        _text_html(doc.summary, "summary") if doc.summary else "",
        _meta_html(doc.meta),
        f"<nav><ul>{toc}</ul></nav>" if len(doc.sections) > 2 else "",
        *(_section_html(s, js is not None) for s in doc.sections),
        "</body></html>",
    ]
    return "\n".join(p for p in parts if p) + "\n"


# -- Markdown ---------------------------------------------------------------------------------
#
# Every text reaches the Markdown as it reaches the HTML: a table cell or a meta value as
# plain text, a title, caption, note or section text as the tiny markup of the module
# docstring (its `code` and **bold** kept, everything else literal). Plain text is escaped
# so that no Markdown or HTML reader gives it a meaning: the characters HTML and Markdown
# read (< > & ` * _ [ ] | \\ ! ~ #) get a backslash, a line cannot start a block (a list, a
# heading, a quote, a code block), line breaks become spaces. A code span's fence is longer
# than any run of backticks in it, and its text is never read as HTML by a Markdown reader.

#: Characters escaped with a backslash wherever they are (CommonMark allows one before any
#: ASCII punctuation): HTML (``<``, ``>``, ``&``), emphasis, code, links, tables, images,
#: strike-through, headings. ``_`` is escaped only where it could open or close emphasis.
_MD_ALWAYS = frozenset("\\`*[]<>&|!~#")
#: What could open a block at the start of a line (a list, a quote, a setext underline, an
#: ordered list's number): its punctuation gets a backslash there.
_MD_BLOCK_START = re.compile(r"[-+=>:]|\d{1,9}[.)]")


def _md_escape(text: str, *, line_start: bool = True) -> str:
    """``text`` as literal Markdown on one line: nothing in it is markup or HTML.

    With ``line_start`` it may begin a line, so a first character that would open a block
    there (``-``, ``+``, ``=``, ``>``, ``:``, ``1.``) is escaped too.
    """
    text = re.sub(r"\s+", " ", str(text))  # line breaks (and U+2028, ...) to spaces
    out = []
    for i, ch in enumerate(text):
        if ch in _MD_ALWAYS:
            out.append("\\" + ch)
        elif ch == "_":
            before = text[i - 1] if i else " "
            after = text[i + 1] if i + 1 < len(text) else " "
            out.append("_" if before.isalnum() and after.isalnum() else "\\_")
        else:
            out.append(ch)
    escaped = "".join(out)
    start = _MD_BLOCK_START.match(escaped) if line_start else None
    if start is None:
        return escaped
    at = start.end() - 1  # the punctuation: the sign, or the number's '.' or ')'
    return escaped[:at] + "\\" + escaped[at:]


def _md_cell(text: str) -> str:
    """A table cell: literal (:func:`_md_escape`), inside its row (never a line's start)."""
    return _md_escape(text, line_start=False)


def _md_code(text: str) -> str:
    """A Markdown code span of ``text`` (one line), fenced by more backticks than it holds."""
    runs = [len(r) for r in re.findall(r"`+", text)]
    fence = "`" * (max(runs, default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") or not text.strip() else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def _md_inline(text: str) -> str:
    """One line of the tiny markup as Markdown: `code` and **bold** as the HTML renders
    them (:func:`_inline_html`), every other character literal."""
    parts: list[str] = []
    for k, piece in enumerate(re.split(r"`([^`]+)`", " ".join(str(text).split()))):
        if k % 2:
            parts.append(_md_code(piece))
            continue
        for j, bit in enumerate(re.split(r"\*\*([^*]+)\*\*", piece)):
            literal = _md_escape(bit, line_start=not parts)
            parts.append(f"**{literal}**" if j % 2 else literal)
    return "".join(parts)


def _md_text(text: str) -> str:
    """Paragraphs and ``- `` lists of the tiny markup (:func:`_blocks`) as Markdown."""
    parts = []
    for kind, lines in _blocks(text):
        if kind == "ul":
            parts.append("\n".join(f"- {_md_inline(i)}" for i in lines))
        else:
            parts.append(_md_inline(" ".join(lines)))
    return "\n\n".join(parts)


def _table_md(table: Table) -> str:
    header, rows = _cells(table)
    lines = [
        f"### {_md_inline(table.title)}",
        "",
        "| " + " | ".join(_md_cell(h) for h in header) + " |",
        "|" + "|".join(":---" if i == 0 else "---:" for i in range(len(header))) + "|",
    ]
    lines += ["| " + " | ".join(_md_cell(c) for c in row) + " |" for row in rows]
    if table.caption:
        lines += ["", _md_text(table.caption)]
    lines += ["", f"Data: [{table.name}.csv]({table.name}.csv)"]
    return "\n".join(lines)


def _figure_md(fig: Figure) -> str:
    lines = [f"### {_md_inline(fig.title)}", "", f"![{_md_cell(fig.title)}]({fig.name}.png)"]
    if fig.caption:
        lines += ["", _md_text(fig.caption)]
    return "\n".join(lines)


def _item_md(item) -> str:
    if isinstance(item, Table):
        return _table_md(item)
    if isinstance(item, Figure):
        return _figure_md(item)
    if isinstance(item, Note):
        text = _md_text(item.text)
        if item.kind == "warning":
            return "\n".join("> " + ln if ln else ">" for ln in text.splitlines())
        return text
    raise TypeError(f"unknown report item {type(item).__name__}")


def render_markdown(doc: Document) -> str:
    """The document as Markdown; figures and CSVs are linked as files beside it.

    Every text is escaped as the HTML escapes it (:func:`_md_escape`): a string from a file
    (a model's name, notes, provenance, a file name) is shown as it is, never read as
    Markdown or HTML.
    """
    parts = [f"# {_md_inline(doc.title)}"]
    if doc.summary:
        parts.append(_md_text(doc.summary))
    if doc.meta:
        rows = [
            f"| {_md_cell(str(k))} | {_md_cell(format_value(v, 6))} |" for k, v in doc.meta.items()
        ]
        parts.append("\n".join(["| | |", "|:---|:---|", *rows]))
    for sec in doc.sections:
        parts.append(f"## {_md_inline(sec.title)}")
        if sec.text:
            parts.append(_md_text(sec.text))
        parts.extend(_item_md(i) for i in sec.items)
    return "\n\n".join(p for p in parts if p) + "\n"
