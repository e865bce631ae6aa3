"""Issue 17: the HTML report checked in a real headless browser.

Selenium (the ``dev`` extra) drives Debian's ``chromium`` with ``chromium-driver`` (``.ci/run``
installs both before ``make test-all``): the page loads without console errors, every figure is
visible (each interactive Plotly figure drawn, each PNG decoded), the table of contents
links reach their sections, and a screenshot is saved as a test artefact: ``report.png``
in the test's tmp folder and, when ``FRICID_ARTIFACTS`` is set, copied into that folder as
``report-browser.png``. What a person sees is checked on the drawn page: no legend overlaps
an axis title or a plotting area (bounding boxes), every axis is titled with its unit, the
friction chart has one panel per load and temperature band (shared axes, a colour per
direction, not per band) and the residuals one per input, the speed on a log axis. Without
selenium, a browser or its driver the test is skipped and says which is missing.
"""

from __future__ import annotations

import os
import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from fricid.errors import FricidWarning
from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.report import model_report, write_document
from fricid.samples import FrictionSamples

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
DRIVERS = ("chromedriver", "chromium-driver")


def _which(names) -> str | None:
    return next((p for p in map(shutil.which, names) if p), None)


@pytest.fixture(scope="module")
def browser():
    webdriver = pytest.importorskip(
        "selenium.webdriver", reason="selenium is not installed (pip install -e '.[dev]')"
    )
    binary, driver = _which(BROWSERS), _which(DRIVERS)
    if binary is None or driver is None:
        pytest.skip(
            "no headless browser: install Debian's chromium and chromium-driver "
            f"(found browser {binary}, driver {driver}); .ci/run installs them"
        )
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = binary
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"):
        opts.add_argument(arg)
    opts.add_argument("--window-size=1280,1600")
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    drv = webdriver.Chrome(options=opts, service=Service(driver))
    drv.set_page_load_timeout(60)
    yield drv
    drv.quit()


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    """A per-direction Stribeck model's report (both directions, a wide speed range)."""
    rng = np.random.default_rng(0)
    v = np.geomspace(0.003, 3.0, 18)
    v = np.concatenate([v, -v])
    mag = 0.1 + 0.25 * np.exp(-np.abs(v) / 0.05) + 0.02 * np.abs(v)
    f = np.sign(v) * mag * np.where(v > 0, 1.0, 0.8) + 0.002 * rng.standard_normal(v.size)
    samples = FrictionSamples(
        velocity=v, load=0.0, temperature=25.0, friction=f, direction=np.sign(v).astype(int)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        fitted = fit(samples, "stribeck_asym", "varpro")
        doc = model_report(fitted, samples, trust=assess_trust(fitted, samples, validate=False))
    return write_document(doc, tmp_path_factory.mktemp("browser") / "report")


@pytest.fixture(scope="module")
def banded_report(tmp_path_factory) -> Path:
    """A report of samples at 3 loads and 3 temperatures (9 bands), both directions."""
    rng = np.random.default_rng(1)
    v0 = np.geomspace(0.005, 2.0, 8)
    v, load, temp = (
        a.ravel() for a in np.meshgrid(np.concatenate([v0, -v0]), [0.0, 0.5, 1.0], [20, 35, 50])
    )
    mag = 0.1 + 0.05 * load + 0.15 * np.exp(-np.abs(v) / 0.05) + 0.02 * np.abs(v)
    mag *= 1.0 - 0.004 * (temp - 20)
    f = np.sign(v) * mag + 0.002 * rng.standard_normal(v.size)
    samples = FrictionSamples(
        velocity=v, load=load, temperature=temp, friction=f, direction=np.sign(v).astype(int)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        fitted = fit(samples, "stribeck", "varpro")
        doc = model_report(fitted, samples, trust=assess_trust(fitted, samples, validate=False))
    return write_document(doc, tmp_path_factory.mktemp("banded") / "report")


#: What the page shows of every Plotly figure: its axes' titles (layout and drawn boxes), the
#: legend's box, the plotting areas, the panel titles and the colours of the traces.
_LAYOUT_JS = """
var out = {};
document.querySelectorAll('.plotly-figure').forEach(function (gd) {
  var L = gd._fullLayout, box = function (e) {
    var r = e.getBoundingClientRect();
    return [r.left, r.top, r.right, r.bottom];
  };
  var axes = Object.keys(L).filter(function (k) { return /^[xy]axis[0-9]*$/.test(k); });
  var texts = Array.from(gd.querySelectorAll('.infolayer text')).filter(function (t) {
    return /^[xy][0-9]*title$/.test(t.getAttribute('class'));
  });
  var legend = gd.querySelector('g.legend');
  out[gd.id] = {
    axes: axes.map(function (k) {
      return [k, L[k].title.text || '', L[k].type, L[k].matches || null];
    }),
    titles: texts.map(function (t) { return [t.getAttribute('class'), t.textContent, box(t)]; }),
    legend: legend ? box(legend.querySelector('.bg') || legend) : null,
    plots: Array.from(gd.querySelectorAll('.nsewdrag')).map(box),
    panels: L._subplots.cartesian.length,
    annotations: (L.annotations || []).map(function (a) { return a.text; }),
    colors: Array.from(new Set(gd.data.map(function (t) {
      return (t.marker && t.marker.color) || (t.line && t.line.color);
    })))
  };
});
return out;
"""


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _draw(browser, report) -> dict:
    browser.get(report.as_uri())
    browser.set_script_timeout(30)
    drawn = browser.execute_async_script(
        "var done = arguments[0], t0 = Date.now();"
        "(function poll(){ var d = document.querySelectorAll('.plotly-figure');"
        " var ok = Array.from(d).every(e => e.querySelector('svg.main-svg'));"
        " if (ok || Date.now() - t0 > 20000) done(ok); else setTimeout(poll, 100);"
        "})();"
    )
    assert drawn
    return browser.execute_script(_LAYOUT_JS)


@pytest.mark.slow  # 19-25 s each measured under load (the page holds plotly.js, 4 MB)
@pytest.mark.parametrize("which", ["report", "banded_report"])
def test_what_a_person_sees_legends_units_and_panels(browser, which, request, tmp_path):
    figures = _draw(browser, request.getfixturevalue(which))
    if which == "banded_report":  # the small multiples, as a CI artefact to look at
        browser.execute_script(
            "document.getElementById('plotly-friction_vs_velocity').scrollIntoView()"
        )
        shot = tmp_path / "report-banded.png"
        assert browser.save_screenshot(str(shot))
        artefacts = os.environ.get("FRICID_ARTIFACTS")
        if artefacts:
            Path(artefacts).mkdir(parents=True, exist_ok=True)
            shutil.copy(shot, Path(artefacts) / "report-banded.png")
    assert {"plotly-friction_vs_velocity", "plotly-residuals"} <= set(figures)
    for name, fig in figures.items():
        for key, title, _type, _matches in fig["axes"]:  # every axis titled, with its unit
            assert re.search(r"\[[^\]]+\]", title), (name, key, title)
        assert len(fig["titles"]) == len(fig["axes"]), (name, fig["titles"])
        for cls, text, rect in fig["titles"]:  # drawn, and clear of the legend
            assert text and rect[2] > rect[0] and rect[3] > rect[1], (name, cls)
            assert fig["legend"] is None or not _overlap(fig["legend"], rect), (name, text)
        for rect in fig["plots"]:  # the legend covers no data either
            assert fig["legend"] is None or not _overlap(fig["legend"], rect), name
    friction = figures["plotly-friction_vs_velocity"]
    residuals = figures["plotly-residuals"]
    assert len(friction["colors"]) == 2  # a colour per direction, whatever the bands
    if which == "banded_report":  # 3 loads x 3 temperatures: one panel each, shared axes
        assert friction["panels"] == 9 and len(friction["plots"]) == 9
        assert len(set(friction["annotations"])) == 9
        assert all("load" in a and "°C" in a for a in friction["annotations"])
        shared = [m for _k, _t, _ty, m in friction["axes"]]
        assert shared.count(None) == 2 and set(shared) == {None, "x", "y"}
        titles = [t for _k, t, _ty, _m in residuals["axes"] if _k.startswith("x")]
        assert residuals["panels"] == 3 and len(titles) == 3
        assert titles[0].startswith("speed |velocity| [rad/s], log scale")
        assert titles[1:] == ["load [N m]", "temperature [°C]"]
    else:  # one band: one panel
        assert friction["panels"] == 1 and residuals["panels"] == 1
    speed = next(a for a in residuals["axes"] if a[0] == "xaxis")
    assert speed[2] == "log"  # the speeds span three decades: the PNG's log axis


@pytest.mark.slow  # 4.9 s with its page's set-up, quiet machine (default run kept short)
def test_report_in_a_real_browser(browser, report, tmp_path):
    browser.get(report.as_uri())
    # every interactive figure drawn by plotly.js (inlined: the page is offline)
    browser.set_script_timeout(30)
    drawn = browser.execute_async_script(
        "var done = arguments[0], t0 = Date.now();"
        "(function poll(){ var d = document.querySelectorAll('.plotly-figure');"
        " var ok = Array.from(d).every(e => e.querySelector('svg.main-svg'));"
        " if (ok || Date.now() - t0 > 20000) done([d.length, ok]); else setTimeout(poll, 100);"
        "})();"
    )
    assert drawn[0] >= 3 and drawn[1], drawn
    errors = [e for e in browser.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]
    assert not errors, errors
    figures = browser.find_elements("css selector", "figure")
    assert len(figures) == len(list(report.parent.glob("*.png"))) >= 4  # every figure written
    for fig in figures:
        title = fig.find_element("tag name", "h3").text
        plots = fig.find_elements("css selector", ".plotly-figure")
        shown = plots[0] if plots else fig.find_element("tag name", "img")
        assert shown.is_displayed(), title
        assert shown.size["width"] > 300 and shown.size["height"] > 200, (title, shown.size)
        if not plots:  # a PNG: decoded by the browser
            assert browser.execute_script("return arguments[0].naturalWidth", shown) > 0, title
    links = browser.find_elements("css selector", "nav a")
    assert len(links) >= 3
    targets = [a.get_attribute("href").split("#", 1)[1] for a in links]
    for target in targets:
        browser.find_element("css selector", f'nav a[href="#{target}"]').click()
        assert browser.execute_script("return location.hash") == f"#{target}"
        top = browser.execute_script(
            "return document.getElementById(arguments[0]).getBoundingClientRect().top", target
        )
        at_end = browser.execute_script(
            "return window.innerHeight + window.scrollY >= document.body.scrollHeight - 2"
        )
        assert abs(top) < 5 or at_end, (target, top)
    browser.execute_script("window.scrollTo(0, 0)")
    shot = tmp_path / "report.png"
    assert browser.save_screenshot(str(shot)) and shot.stat().st_size > 10_000
    artefacts = os.environ.get("FRICID_ARTIFACTS")
    if artefacts:
        Path(artefacts).mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, Path(artefacts) / "report-browser.png")
