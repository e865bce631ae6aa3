"""``report.md`` escapes what it shows as ``report.html`` does: a string from a model file or
a file name is text, never HTML or Markdown structure.

The Markdown is rendered with a CommonMark reader (``markdown-it-py``, raw HTML allowed as
CommonMark allows it, GFM tables on): no element may come from a file's text (no ``<img
onerror>``, no link, no emphasis), every table row keeps its header's cells, and the hostile
text is shown as it is.
"""

from __future__ import annotations

import json
import re
import warnings
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from markdown_it import MarkdownIt
from typer.testing import CliRunner

from fricid.cli import app
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.io import write_samples
from fricid.report import Document, Figure, Note, Table
from fricid.report.render import render_html, render_markdown

HOSTILE = "<img src=x onerror=alert(1)>|`x`"
#: More of what a Markdown reader reads: a link, emphasis, a heading, a list, an entity,
#: a code fence, a raw HTML block, a line break.
MARKUP = [
    HOSTILE,
    "[click](javascript:alert(1)) ![i](x.png) <https://e.x>",
    "_em_ *em* ~~del~~ # head &amp; &lt;b&gt;",
    "- item\n1. one\n> quote\n```\ncode\n```",
    "<script>alert(1)</script>",
    "| a | b |\n|---|---|",
    "\\<img src=y onerror=alert(2)>",
]
ALLOWED = {"h1", "h2", "h3", "p", "table", "thead", "tbody", "tr", "th", "td"}
ALLOWED |= {"ul", "li", "strong", "code", "blockquote", "a", "img"}


class _Tags(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def rendered(md: str) -> tuple[str, list[tuple[str, dict[str, str | None]]]]:
    html = MarkdownIt("commonmark").enable("table").render(md)
    parser = _Tags()
    parser.feed(html)
    return html, parser.tags


def assert_inert(md: str, figures: set[str], csvs: set[str]) -> str:
    """Every element of the rendered Markdown is one fricid writes: images and links only to
    its own files, no event handler, no element a file's text could make."""
    html, tags = rendered(md)
    for tag, attrs in tags:
        assert tag in ALLOWED, (tag, attrs)
        assert not any(name.startswith("on") for name in attrs), (tag, attrs)
        if tag == "img":
            assert attrs.get("src") in {f"{n}.png" for n in figures}, attrs
        if tag == "a":
            assert attrs.get("href") in {f"{n}.csv" for n in csvs}, attrs
    assert not re.search(r"(?<!\\)<[A-Za-z/!?]", _outside_code(md)), "raw HTML in report.md"
    for block in re.findall(r"(?:^\|.*\|$\n?)+", md, flags=re.M):  # pipe tables
        widths = {len(re.findall(r"(?<!\\)\|", line)) for line in block.splitlines()}
        assert len(widths) == 1, block
    return html


def _outside_code(md: str) -> str:
    """The Markdown without its code spans (whose text a reader shows as it is)."""
    return re.sub(r"(`+)(?!`).*?(?<!`)\1(?!`)", "", md)


def test_every_text_of_a_document_is_escaped():
    png = b"\x89PNG" + bytes(10)
    doc = Document(HOSTILE, "\n\n".join(MARKUP), meta={HOSTILE: HOSTILE, "b": MARKUP[1]})
    sec = doc.section(HOSTILE, "\n".join(f"- {m}" for m in MARKUP))
    frame = pd.DataFrame({HOSTILE: MARKUP, "y": [HOSTILE] * len(MARKUP)})
    sec.add(Table("tab", HOSTILE, frame, caption="\n\n".join(MARKUP)))
    sec.add(Figure("fig", HOSTILE, png, caption=HOSTILE))
    sec.add(Note(HOSTILE, kind="warning"))
    sec.add(Note("\n\n".join(MARKUP)))
    md = render_markdown(doc)
    html = assert_inert(md, {"fig"}, {"tab"})
    assert html.count("&lt;img src=x onerror=alert(1)&gt;") >= 8
    assert "<script>" not in html and "&lt;script&gt;" in html
    # tables show every character of a cell, backticks and pipes included
    assert re.search(r"<td[^>]*>&lt;img src=x onerror=alert\(1\)&gt;\|`x`</td>", html)


@pytest.mark.parametrize("text", ["1. x", "- x", "+ x", "> x", "# x", "= x", "    x", "12) x"])
def test_no_text_starts_a_block(text):
    doc = Document("t", text)
    sec = doc.section("s", f"- {text}")
    sec.add(Note(text))
    _html, tags = rendered(render_markdown(doc))
    assert {t for t, _ in tags} <= {"h1", "h2", "p", "ul", "li"}, tags
    # the same lists as the HTML (the report's own "- " lists), none made by the text
    assert sum(t == "li" for t, _ in tags) == render_html(doc).count("<li>")


def _hostile_model(tmp_path: Path) -> Path:
    """A fitted model file whose every string field that loads holds :data:`HOSTILE`."""
    rng = np.random.default_rng(0)
    v = np.concatenate([np.geomspace(0.01, 2, 12), -np.geomspace(0.01, 2, 12)])
    from fricid.samples import FrictionSamples

    samples = FrictionSamples(
        velocity=v,
        load=0.0,
        temperature=25.0,
        friction=0.1 * np.sign(v) + 0.05 * v + 0.001 * rng.standard_normal(24),
        source="fuzz",
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = fit(samples, "stribeck", max_evals=300).to_dict()
    paths: list[tuple] = []

    def walk(value, path=()):
        if isinstance(value, str):
            paths.append(path)
        elif isinstance(value, dict):
            for k, v in value.items():
                walk(v, (*path, k))
        elif isinstance(value, list):
            for i, v in enumerate(value):
                walk(v, (*path, i))

    walk(doc)
    probe = tmp_path / "probe.json"
    kept = []
    for path in paths:
        if path == ("model",):
            continue
        trial = json.loads(json.dumps(doc))
        _set(trial, path, HOSTILE)
        probe.write_text(json.dumps(trial))
        try:
            FittedModel.load(probe)
        except Exception:  # the loader refuses this field's hostile value: left as it was
            continue
        kept.append(path)
    for path in kept:
        _set(doc, path, HOSTILE)
    for record in doc["parameters"].values():
        record["note"] = HOSTILE
    assert len(kept) >= 5, kept
    model = tmp_path / "m.json"
    model.write_text(json.dumps(doc))
    FittedModel.load(model)
    write_samples(samples, tmp_path / f"{HOSTILE.replace('/', '')}.csv")
    return model


def _set(doc, path, value):
    for key in path[:-1]:
        doc = doc[key]
    doc[path[-1]] = value


@pytest.mark.slow
def test_a_hostile_model_files_strings_are_text_in_report_md(tmp_path):
    model = _hostile_model(tmp_path)
    samples = tmp_path / f"{HOSTILE}.csv"
    out = tmp_path / "rep"
    result = CliRunner().invoke(app, ["report", str(model), str(samples), "--out", str(out)])
    assert result.exit_code == 0, result.output
    md = (out / "report.md").read_text(encoding="utf-8")
    manifest = json.loads((out / "manifest.json").read_text())
    figures = {Path(f).stem for f in manifest["files"] if f.endswith(".png")}
    csvs = {Path(f).stem for f in manifest["files"] if f.endswith(".csv")}
    html = assert_inert(md, figures, csvs)
    assert "onerror" in md and html.count("&lt;img src=x onerror=alert(1)&gt;|") >= 5
