"""Issue 17: interactive friction figures in the HTML report (Plotly, inlined, offline), the
static PNGs kept for the Markdown. The browser check is tests/report/test_report_browser.py."""

from __future__ import annotations

import json
import re
import warnings

import numpy as np
import pytest

from fricid.errors import FricidWarning
from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.report import Document, Figure, model_report, render_html, render_markdown
from fricid.report.interactive import stribeck_range
from fricid.samples import FrictionSamples

pytest.importorskip("plotly", reason="plotly is a dependency of fricid (pip install -e .)")

INTERACTIVE = ("friction_vs_velocity", "stribeck_region", "residuals")


@pytest.fixture(scope="module")
def doc():
    v = np.geomspace(0.004, 2.0, 14)
    v = np.concatenate([v, -v])
    f = np.sign(v) * (0.1 + 0.2 * np.exp(-np.abs(v) / 0.04) + 0.03 * np.abs(v))
    f = f * np.where(v > 0, 1.0, 0.85)
    samples = FrictionSamples(
        velocity=v, load=0.0, temperature=25.0, friction=f, direction=np.sign(v).astype(int)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        fitted = fit(samples, "stribeck_asym", "varpro")
        trust = assess_trust(fitted, samples, validate=False)
        return model_report(fitted, samples, trust=trust)


def _specs(html: str) -> dict[str, dict]:
    found = re.findall(r"Plotly\.newPlot\('plotly-([a-z_]+)',", html)
    specs = re.findall(r"var s=(\{.*?\});Plotly\.newPlot", html)
    return {name: json.loads(s.replace("<\\/", "</")) for name, s in zip(found, specs, strict=True)}


def test_html_has_the_interactive_figures_with_plotly_inlined(doc):
    html = render_html(doc)
    head, body = html.split("</head>", 1)
    assert head.count("<script") == 1 and '<script type="text/javascript">' in head  # inline
    assert "<script src" not in body and "cdn.plot.ly" not in body  # nothing fetched
    assert re.search(r"plotly\.js v\d", head)  # the library itself, inline, once
    assert html.count("plotly.js v") == 1
    specs = _specs(html)
    assert set(specs) == set(INTERACTIVE)
    # per direction: a measured and a model trace for each
    names = [t["name"] for t in specs["friction_vs_velocity"]["data"]]
    assert {"measured, positive direction", "model, negative direction"} <= set(names)
    stribeck = specs["stribeck_region"]["layout"]
    assert stribeck["xaxis"]["type"] == "log"
    assert [a["text"] for a in stribeck["annotations"]] == ["w_s_pos", "w_s_neg"]
    lo, hi = (10**x for x in stribeck["xaxis"]["range"])
    assert lo < 0.004 and hi < 2.0  # opens on the low-speed end
    assert len(specs["residuals"]["layout"]["shapes"]) == 2  # the ±2 RMSE lines
    for name in INTERACTIVE:  # the PNG stays, for a browser without JavaScript
        block = html.split(f'id="plotly-{name}"', 1)[1].split("</figure>", 1)[0]
        assert "<noscript><img" in block and "data:image/png;base64," in block


def test_markdown_links_the_static_pngs(doc):
    md = render_markdown(doc)
    for name in INTERACTIVE:
        assert f"({name}.png)" in md
    assert "Plotly" not in md


def test_a_document_without_interactive_figures_does_not_carry_plotly(doc):
    png = doc.figures()[0].png
    plain = Document("plain")
    plain.section("A").add(Figure("f", "F", png))
    assert "plotly.js" not in render_html(plain)


def test_stribeck_range():
    v = np.array([-2.0, -0.01, 0.01, 2.0])
    assert stribeck_range(v, {"w_s": 0.02}) == pytest.approx((0.008, 0.4))
    assert stribeck_range(v, {"w_s": 0.5}) is None  # 20 w_s beyond the data: all of it
    assert stribeck_range(v, {}) is None
