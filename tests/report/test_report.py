"""``fricid report``: one model on one data set, for every model family and real data."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError
from fricid.extract import extract
from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.io import epos_steady_samples, write_samples
from fricid.report import Document, Figure, Table, model_report, write_document
from fricid.report.render import render_html, render_markdown
from fricid.sim import preset, simulate

FAMILIES = ("coulomb_viscous", "stribeck", "msk", "vlt")


def png_stats(data: bytes) -> tuple[tuple[int, int], float]:
    """(width, height) and the pixel standard deviation of a PNG."""
    import matplotlib.image as mpimg

    img = mpimg.imread(io.BytesIO(data), format="png")
    return (img.shape[1], img.shape[0]), float(np.std(img[..., :3]))


def assert_report_folder(folder: Path, figures: set[str], tables: set[str]) -> None:
    html = (folder / "report.html").read_text(encoding="utf-8")
    md = (folder / "report.md").read_text(encoding="utf-8")
    assert html.count("data:image/png;base64,") >= len(figures)
    assert "<table>" in html
    for name in figures:
        data = (folder / f"{name}.png").read_bytes()
        (w, h), spread = png_stats(data)
        assert w >= 400 and h >= 300, name
        assert spread > 0.02, f"{name}.png looks blank"
        assert f"({name}.png)" in md
    for name in tables:
        assert (folder / f"{name}.csv").stat().st_size > 0
        assert f"({name}.csv)" in md
    manifest = json.loads((folder / "manifest.json").read_text())
    assert set(manifest["files"]) >= {f"{n}.png" for n in figures} | {f"{n}.csv" for n in tables}
    assert not [p for p in folder.parent.iterdir() if p.name.endswith(".tmp")]


@pytest.fixture(scope="module")
def paper1_samples():
    scenario = preset("paper1", "quick")
    result = extract(
        simulate(scenario, seed=3),
        positions=scenario.design.positions,
        bin_halfwidth=scenario.design.bin_halfwidth,
        gravity="fit",
    )
    return result.samples


@pytest.fixture(scope="module")
def leadscrew(leadscrew_dir):
    return epos_steady_samples(leadscrew_dir)


@pytest.mark.slow  # 5 s measured under load (default run kept short)
@pytest.mark.parametrize("family", FAMILIES)
def test_report_renders_for_each_family(family, paper1_samples, tmp_path):
    fitted = fit(paper1_samples, family, "lm", max_evals=3000)
    doc = model_report(
        fitted, paper1_samples, trust=assess_trust(fitted, paper1_samples), velocity_unit="deg/s"
    )
    out = tmp_path / "rep"
    path = write_document(doc, out)
    assert path == out / "report.html"
    figures = {"friction_vs_velocity", "parity", "residuals", "convergence"}
    assert_report_folder(out, figures, {"parameters", "metrics"})
    params = (out / "parameters.csv").read_text()
    for name in fitted.params:
        assert name in params
    assert "95% CI low" in params


@pytest.mark.slow  # 2 s measured under load (default run kept short)
def test_report_on_real_leadscrew_per_direction(leadscrew, tmp_path):
    fitted = fit(leadscrew, "stribeck_asym")
    doc = model_report(
        fitted, leadscrew, trust=assess_trust(fitted, leadscrew), velocity_unit="rpm"
    )
    write_document(doc, tmp_path / "rep")
    assert_report_folder(
        tmp_path / "rep",
        {"friction_vs_velocity", "residuals", "parity"},
        {"parameters", "metrics", "correlation"},
    )
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "tau_s_pos" in text and "tau_s_neg" in text
    assert "mN m" in text or "N m" in text


@pytest.mark.slow  # 1.7 s, quiet machine (default run kept short)
def test_cli_report(leadscrew, tmp_path):
    fitted = fit(leadscrew, "stribeck_asym")
    model = fitted.save(tmp_path / "m.json")
    samples = write_samples(leadscrew, tmp_path / "s.csv")
    res = CliRunner().invoke(
        app,
        [
            "report",
            str(model),
            str(samples),
            "--out",
            str(tmp_path / "r"),
            "--velocity-unit",
            "rpm",
        ],
    )
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r" / "report.html").is_file()
    assert "Trust: yes, because the fit converged" in res.output
    res = CliRunner().invoke(
        app,
        [
            "report",
            str(model),
            str(samples),
            "--out",
            str(tmp_path / "r"),
            "--velocity-unit",
            "furlong",
        ],
    )
    assert res.exit_code == 2
    assert "velocity-unit" in res.output


def _tiny_doc(png: bytes) -> Document:
    import pandas as pd

    doc = Document("t", "summary | with pipe", meta={"a": 1.5})
    sec = doc.section("S", "- one\n- two")
    sec.add(Table("tab", "A table", pd.DataFrame({"x": [1.0, np.nan], "y": ["a|b", "c"]})))
    sec.add(Figure("fig", "A figure", png, "caption `code`"))
    return doc


def test_write_is_all_or_nothing(tmp_path, monkeypatch):
    from fricid.report import writer

    png = b"\x89PNG" + bytes(100)
    out = tmp_path / "out"

    def boom(doc):
        raise RuntimeError("disk full")

    monkeypatch.setattr(writer, "render_html", boom)
    with pytest.raises(RuntimeError):
        write_document(_tiny_doc(png), out)
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []

    # an existing folder keeps foreign files, loses stale report files
    monkeypatch.undo()
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    write_document(_tiny_doc(png), out)
    doc = _tiny_doc(png)
    doc.sections[0].items.pop(0)  # drop the table: tab.csv is now stale
    write_document(doc, out)
    assert (out / "mine.txt").read_text() == "keep"
    assert not (out / "tab.csv").exists()
    assert (out / "fig.png").exists()


def test_render_escapes_and_rejects_bad_items():
    doc = _tiny_doc(b"\x89PNG" + bytes(10))
    html = render_html(doc)
    assert "<li>one</li>" in html and "<code>code</code>" in html
    md = render_markdown(doc)
    assert "a\\|b" in md and "| – |" in md.replace("–  ", "– ")
    with pytest.raises(ConfigError):
        Figure("Bad Name", "x", b"\x89PNG")
    with pytest.raises(ConfigError):
        Figure("ok", "x", b"GIF89a")


@pytest.mark.slow  # 1.4 s, quiet machine (default run kept short)
def test_report_for_the_rbf_network_with_bootstrap(paper1_samples, tmp_path):
    from fricid.fitted import FittedModel
    from fricid.identify.learned.rbf import fit_rbf

    fitted = fit_rbf(paper1_samples, n_centers=8, random_state=0)
    path = fitted.save(tmp_path / "rbf.json")
    fitted = FittedModel.load(path)
    doc = model_report(
        fitted, paper1_samples, trust=assess_trust(fitted, paper1_samples), bootstrap=50
    )
    write_document(doc, tmp_path / "rep")
    assert_report_folder(
        tmp_path / "rep",
        {"friction_vs_velocity", "residuals", "parity"},
        {"network", "parameters", "prediction_ci", "metrics"},
    )
    ci = __import__("pandas").read_csv(tmp_path / "rep" / "prediction_ci.csv")
    assert (ci["95% CI low [N m]"] <= ci["predicted [N m]"] + 1e-12).all()
    assert (ci["95% CI high [N m]"] >= ci["predicted [N m]"] - 1e-12).all()


# -- "Can I trust this?" (issue 11, "Where it shows") -------------------------------------------


def _trust_section(doc: Document):
    """The "Can I trust this?" section and the verdict line (the document's first row)."""
    sec = doc.sections[0]
    assert sec.title == "Can I trust this?"
    return sec, doc.meta["trust"]


def _says_once(doc: Document, line: str) -> None:
    """The verdict is stated once in the Markdown and once in the HTML (a note in the trust
    section repeated the first row word for word)."""
    verdict = line.split(",")[0]  # "Trust: yes" (the rest is escaped differently)
    assert render_markdown(doc).count(verdict) == 1
    assert render_html(doc).count(verdict) == 1


def test_report_validation_limit_is_a_size_not_a_time(leadscrew):
    """Whether the report runs lovo itself depends on the problem's size only, never on how
    busy the machine is (a measured time made the verdict flip under load)."""
    fitted = fit(leadscrew, "stribeck_asym")
    small = assess_trust(fitted, leadscrew, max_work=1)
    assert small.validation is None
    assert "over the limit of 1; use fricid fit --validate lovo" in small.validation_note
    assert assess_trust(fitted, leadscrew).validation is not None


def test_trust_yes_for_a_converged_fit_within_noise(leadscrew, tmp_path):
    fitted = fit(leadscrew, "stribeck_asym")
    assert fitted.converged and fitted.validation is None
    doc = model_report(fitted, leadscrew, trust=assess_trust(fitted, leadscrew))
    sec, line = _trust_section(doc)
    assert line.startswith("Trust: yes, because the fit converged")
    assert next(iter(doc.meta)) == "trust"
    _says_once(doc, line)
    # the trust check ran lovo itself, and says so; the quality table of the EPOS reader is shown
    assert "held-out RMSE (lovo, interior levels, lovo run here)" in sec.text, sec.text
    assert "lovo run here: 16 folds" in sec.text
    assert "32 set-points" in sec.text
    names = {getattr(i, "name", None) for i in sec.items}
    assert {"quality", "heldout"} <= names
    write_document(doc, tmp_path / "rep")
    md = (tmp_path / "rep" / "report.md").read_text()
    assert md.index("Can I trust this?") < md.index("## Parameters")
    assert md.count("Trust: yes") == 1
    params = __import__("pandas").read_csv(tmp_path / "rep" / "parameters.csv")
    assert params["95% interval"].str.match(r"^\[.+, .+\]$").all()
    assert (params["95% CI low"] <= params["value"]).all()
    assert (params["value"] <= params["95% CI high"]).all()


@pytest.mark.slow  # 1.2 s, quiet machine (the default run kept under 3 minutes)
def test_verdict_and_figures_come_first_and_long_tables_are_folded(leadscrew, tmp_path):
    """The verdict, then the figures; the 32-row data-quality table folded, the scatter it
    shows named apart from the verdict's and explained."""
    from fricid.report.render import render_html
    from fricid.report.trust import READINGS_STD

    fitted = fit(leadscrew, "stribeck_asym")
    trust = assess_trust(fitted, leadscrew)
    seen = []
    doc = model_report(fitted, leadscrew, trust=trust, progress=seen.append)
    assert seen[0] == "predictions, metrics" and "figures: residuals against each input" in seen
    titles = [s.title for s in doc.sections]
    assert titles[:3] == ["Can I trust this?", "Friction against velocity", "Residuals"]
    assert titles.index("Parameters") > titles.index("Residuals")
    quality = next(t for t in doc.tables() if t.name == "quality")
    assert len(quality.frame) > 12 and quality.is_folded
    assert READINGS_STD in quality.frame.columns and "scatter [N m]" not in quality.frame
    assert f"{trust.scatter:.3g} N m" in quality.caption and "square root" in quality.caption
    sec, _ = _trust_section(doc)
    assert "**Measurement scatter** (the one number every comparison here uses): " in sec.text
    html = render_html(doc)
    folded = html.split('<details class="folded">')
    assert (
        len(folded) >= 2 and 'id="data-quality-per-set-point"' in folded[1].split("</details>")[0]
    )
    params = next(t for t in doc.tables() if t.name == "parameters")
    assert not params.is_folded  # short tables stay open
    assert html.index('id="plotly-friction_vs_velocity"') < html.index('id="parameters"')


def test_trust_no_for_a_bas_fit_with_a_tiny_budget(leadscrew):
    from fricid.errors import ConvergenceWarning

    with pytest.warns(ConvergenceWarning):
        fitted = fit(leadscrew, "stribeck", "bas", max_evals=200)
    assert fitted.converged is False
    doc = model_report(fitted, leadscrew, trust=assess_trust(fitted, leadscrew))
    sec, line = _trust_section(doc)
    assert line.startswith("Trust: no, because the fit did NOT converge")
    _says_once(doc, line)
    assert "--method bas+lm" in line
    assert "NOT converged: method 'bas' ended after 200 of 200 evaluations" in sec.text
    params = next(s for s in doc.sections if s.title == "Parameters")
    table = next(i for i in params.items if getattr(i, "name", "") == "parameters")
    assert (table.frame["95% interval"] == "–").all()
    assert table.frame["status"].str.contains("did not converge").all()


def test_trust_names_open_sides_and_undetermined_parameters():
    from fricid.fitted import FittedModel, Parameter

    nan = float("nan")
    records = [
        Parameter("tau_c", 1.0, stderr=0.01),
        Parameter("tau_s", 1.5, stderr=0.01),
        Parameter(
            "w_s",
            0.1,
            stderr=nan,
            note="not determined: w_s and delta trade off",
            not_determined=True,
        ),
        Parameter("tau_v", 0.2, stderr=0.01, bounds=(0.0, 5.0), low_open=True),
        Parameter(
            "delta",
            2.0,
            stderr=0.3,
            bounds=(0.5, 10.0),
            high_open=True,
            note="reaches the bound delta <= 10",
        ),
    ]
    fitted = FittedModel(
        model="stribeck",
        parameters={p.name: p for p in records},
        convergence={"converged": True, "certified_by": "optimizer"},
        metrics={"rmse": 0.02, "scatter": 0.01, "rmse_over_scatter": 2.0},
        operating_range={"velocity": [0.1, 2.0]},
        provenance={"directions": [0]},
    )
    trust = assess_trust(fitted)
    assert trust.level == "with caveats"
    assert trust.not_determined == ["w_s"]
    assert list(trust.open_sides) == ["delta"]  # tau_v is open at 0 only: consistent with zero
    assert "misses by 2x" in trust.line() and "in-sample" in trust.line()
    assert trust.range == "speed 0.1 to 2 rad/s (either direction)"


@pytest.mark.slow  # 2 s measured under load (default run kept short)
def test_report_of_a_per_direction_rbf_network(leadscrew, tmp_path):
    from fricid.fitted import FittedModel
    from fricid.report.rbf import coefficient_names, hidden_layer

    fitted = FittedModel.load(fit(leadscrew, "rbf").save(tmp_path / "rbf.json"))
    assert fitted.state["symmetry"] == "per_direction"
    # the design matrix reproduces the two networks' prediction, sign of motion included
    A = hidden_layer(fitted, leadscrew.X)
    names = coefficient_names(fitted.state)
    assert A.shape == (len(leadscrew), len(names))
    assert any(n.startswith("pos ") for n in names) and any(n.startswith("neg ") for n in names)
    doc = model_report(fitted, leadscrew, trust=assess_trust(fitted, leadscrew), bootstrap=50)
    write_document(doc, tmp_path / "rep")
    titles = [s.title for s in doc.sections]
    assert titles[:3] == ["Can I trust this?", "Friction against velocity", "Residuals"]
    main = {getattr(i, "name", None) for i in doc.sections[titles.index("Parameters")].items}
    assert "prediction_ci" in main and "parameters" not in main  # the weights: an appendix
    assert any(t.startswith("Appendix") for t in titles)
    ci = __import__("pandas").read_csv(tmp_path / "rep" / "prediction_ci.csv")
    assert (ci["velocity [rad/s]"] < 0).any() and (ci["velocity [rad/s]"] > 0).any()
    pred = np.sign(ci["predicted [N m]"])
    assert (pred == np.sign(ci["velocity [rad/s]"])).all()
    assert (ci["95% CI low [N m]"] <= ci["predicted [N m]"] + 1e-12).all()
    assert (ci["95% CI high [N m]"] >= ci["predicted [N m]"] - 1e-12).all()
