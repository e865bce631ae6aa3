"""Issue 17: the HTML report checked in a real headless browser.

Selenium (the ``dev`` extra) drives Debian's ``chromium`` with ``chromium-driver`` (``.ci/run``
installs both before ``make test-all``): the page loads without console errors, every figure is
visible (each interactive Plotly figure drawn, each PNG decoded), the table of contents
links reach their sections, and a screenshot is saved as a test artefact: ``report.png``
in the test's tmp folder and, when ``FRICID_ARTIFACTS`` is set, copied into that folder as
``report-browser.png``. Without selenium, a browser or its driver the test is skipped and
says which is missing.
"""

from __future__ import annotations

import os
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
