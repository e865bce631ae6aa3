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


def test_small_multiples_per_band_and_residuals_against_every_input():
    """One panel per load and temperature band with shared axes and a colour per direction
    (not one colour per band, which repeated past the palette); the residuals against every
    input that varies, the speed on the log axis the PNG uses."""
    from fricid.report.interactive import friction_figure, residual_figure

    v0 = np.geomspace(0.005, 2.0, 6)
    v, load, temp = (
        a.ravel() for a in np.meshgrid(np.concatenate([v0, -v0]), [0.0, 0.5, 1.0], [20, 35, 50])
    )
    f = np.sign(v) * (0.1 + 0.05 * load + 0.02 * np.abs(v)) * (1 - 0.004 * (temp - 20))
    samples = FrictionSamples(
        velocity=v, load=load, temperature=temp, friction=f, direction=np.sign(v).astype(int)
    )
    spec = json.loads(friction_figure(samples, lambda X: np.sign(X[:, 0]) * 0.1))
    layout = spec["layout"]
    xaxes = sorted(k for k in layout if re.fullmatch(r"xaxis\d*", k))
    yaxes = sorted(k for k in layout if re.fullmatch(r"yaxis\d*", k))
    assert len(xaxes) == len(yaxes) == 9
    assert [layout[k].get("matches") for k in xaxes].count("x") == 8  # shared
    assert [layout[k].get("matches") for k in yaxes].count("y") == 8
    assert all(layout[k]["title"]["text"].endswith("[rad/s], log scale") for k in xaxes)
    labels = [a["text"] for a in layout["annotations"]]
    assert "load 0.5 N m, 35 °C" in labels and len(set(labels)) == 9
    colors = {t.get("marker", t.get("line", {})).get("color") for t in spec["data"]}
    assert len(colors) == 2
    assert sum(t["showlegend"] for t in spec["data"]) == 4  # each entry once
    assert layout["legend"]["x"] > 1  # beside the panels, clear of the axis titles
    res = json.loads(residual_figure(samples, f - np.sign(v) * 0.1))
    titles = [res["layout"][k]["title"]["text"] for k in ("xaxis", "xaxis2", "xaxis3")]
    assert titles == ["speed |velocity| [rad/s], log scale", "load [N m]", "temperature [°C]"]
    assert res["layout"]["xaxis"]["type"] == "log"
    assert res["layout"]["yaxis2"]["matches"] == "y"
    assert len(res["layout"]["shapes"]) == 6  # ±2 RMSE in each panel


def test_samples_without_load_or_temperature_are_drawn():
    """Load and temperature not measured (NaN): one panel, with the samples and the model
    (a band of NaN used to select nothing, leaving the chart empty)."""
    from fricid.report.interactive import friction_figure

    v = np.geomspace(0.01, 1.0, 8)
    v = np.concatenate([v, -v])
    samples = FrictionSamples(v, None, None, np.sign(v) * (0.1 + 0.02 * np.abs(v)))
    spec = json.loads(friction_figure(samples, lambda X: np.sign(X[:, 0]) * 0.1))
    assert [len(t["x"]) for t in spec["data"] if t["mode"] == "markers"] == [8, 8]
    assert "xaxis" in spec["layout"] and "xaxis2" not in spec["layout"]
