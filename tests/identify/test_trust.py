"""``fricid.identify.trust``: the one trust record, where each number came from, when a stored
record is reused, and the same verdict from ``fricid fit``, the fleet and ``fricid report``."""

from __future__ import annotations

import json
import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.cli.simulate import design_hints
from fricid.fitted import FittedModel
from fricid.identify import fit, trust
from fricid.identify.trust import (
    FROM_FIT,
    IN_SAMPLE,
    KFOLD_HERE,
    LOVO_INTERIOR,
    MISS_RATIO,
    NEW_SAMPLES,
    RUN_HERE,
    Trust,
    assess_trust,
)
from fricid.identify.validate import interior_rmse
from fricid.io import epos_steady_samples, write_rawlog, write_samples
from fricid.samples import FrictionSamples
from fricid.sim import preset, simulate
from fricid.workflow import fit_samples

runner = CliRunner()


@pytest.fixture(scope="module")
def leadscrew(leadscrew_dir):
    return epos_steady_samples(leadscrew_dir)


@pytest.fixture(scope="module")
def fitted(leadscrew):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(leadscrew, "stribeck_asym")


def _no_validation(monkeypatch):
    """Make any validation run by the trust check fail the test."""

    def boom(*args, **kwargs):
        raise AssertionError("the stored trust record should have been reused")

    monkeypatch.setattr(trust, "run_validation", boom)


# -- the record and its sources ------------------------------------------------------------------


def test_sources_say_where_the_ratio_came_from(fitted, leadscrew):
    here = assess_trust(fitted, leadscrew)
    assert (here.heldout_source, here.heldout_scheme, here.held_out) == (
        RUN_HERE,
        LOVO_INTERIOR,
        True,
    )
    assert here.validation["scheme"] == "lovo"  # every fold kept; graded on the interior ones
    inner = interior_rmse(here.validation["folds"])
    assert here.heldout_ratio == pytest.approx(inner / here.validation["scatter"])
    # no validation run: the in-sample ratio, never labelled held out
    inside = assess_trust(fitted, leadscrew, validate=False)
    assert (inside.heldout_source, inside.heldout_scheme, inside.held_out) == (IN_SAMPLE, "", False)
    assert inside.heldout_ratio == pytest.approx(fitted.metrics["rmse_over_scatter"])
    assert "no held-out validation (in-sample error only)" in inside.line()
    # the fit's own validation is used as it is, and named so
    validated, record = fit_samples(leadscrew, "stribeck_asym", validate="kfold:4")
    assert (record.heldout_source, record.heldout_scheme) == (FROM_FIT, "kfold:4")
    assert record.heldout_ratio == validated.validation["ratio"]
    assert validated.trust == record.to_dict()


def test_record_round_trips_and_is_reused_from_the_model_file(
    fitted, leadscrew, tmp_path, monkeypatch
):
    record = assess_trust(fitted, leadscrew)
    assert not record.reused
    again = Trust.from_dict(json.loads(json.dumps(record.to_dict())))
    assert again.to_dict() == record.to_dict()
    model = replace(fitted, trust=record.to_dict())
    model.provenance = {**model.provenance, "warnings": ["added after the record"]}
    loaded = FittedModel.load(model.save(tmp_path / "m.json"))
    _no_validation(monkeypatch)
    reused = assess_trust(loaded, leadscrew)
    assert reused.reused and reused.to_dict() == record.to_dict()


def test_record_is_recomputed_for_other_samples_options_or_model(fitted, leadscrew):
    record = assess_trust(fitted, leadscrew, validate=False)  # no lovo: quick to recompute
    model = replace(fitted, trust=record.to_dict())
    assert assess_trust(model, leadscrew, validate=False).reused
    # other samples: one row fewer, or the same values with other standard errors
    fewer = leadscrew.subset(np.arange(len(leadscrew)) > 0)
    other_std = replace(leadscrew, std=leadscrew.std * 2.0)
    # another model, another record format, a record that does not parse
    tau_c = model.parameters["tau_c_pos"]
    edited = replace(
        model,
        parameters={**model.parameters, "tau_c_pos": replace(tau_c, value=tau_c.value * 1.01)},
    )
    old = replace(model, trust={**record.to_dict(), "version": 0})
    broken = replace(model, trust={"level": 3})
    for m, s in ((model, fewer), (model, other_std), (edited, leadscrew), (old, leadscrew)):
        assert not assess_trust(m, s, validate=False).reused
    assert not assess_trust(model, leadscrew, validate=False, reuse=False).reused
    assert not assess_trust(model, leadscrew, validate=False, max_work=10).reused
    assert not assess_trust(model, None, validate=False).reused
    again = assess_trust(broken, leadscrew, validate=False)
    assert not again.reused and again.to_dict() == record.to_dict()
    # a record of the right key but of types the report cannot read is not used either
    for bad in ({"reasons": "text"}, {"open_sides": ["a"]}, {"heldout_ratio": "1"}):
        odd = replace(model, trust={**record.to_dict(), **bad})
        assert not assess_trust(odd, leadscrew, validate=False).reused
    # other options: a record without lovo is not the one a default report shows
    assert assess_trust(model, leadscrew).heldout_source == RUN_HERE


# -- the same verdict everywhere ------------------------------------------------------------------


def _report(model: Path, samples: Path, out: Path) -> tuple[str, str]:
    """``fricid report``: (the Trust line it prints, the report's Markdown)."""
    res = runner.invoke(app, ["report", str(model), str(samples), "--out", str(out)])
    assert res.exit_code == 0, res.output
    line = next(x for x in res.stderr.splitlines() if x.startswith("Trust:"))
    return line, (out / "report.md").read_text(encoding="utf-8")


def _ratio(md: str) -> float:
    """The error ratio of the report's trust section: its RMSE over its scatter (3 digits)."""
    m = re.search(r"RMSE (?:\([^)]*\) )?([0-9.e+-]+) N m against a scatter of ([0-9.e+-]+) N m", md)
    return float(m.group(1)) / float(m.group(2))


def _level(line: str) -> str:
    return re.match(r"Trust: (yes|with caveats|no), because", line).group(1)


def _fresh(model: Path, samples: Path) -> Trust:
    """The record `fricid report` computes when the model file carries none."""
    from fricid.io import read_samples

    fitted = FittedModel.load(model)
    assert fitted.trust is not None
    fitted.trust = None
    return assess_trust(fitted, read_samples(samples))


@pytest.mark.slow  # about 25 s: a fleet of two joints, two extractions, two reports
def test_fleet_row_and_report_agree(tmp_path, leadscrew_dir):
    """A fleet row and `fricid report` on the fleet's model file and the same samples give the
    same held-out ratio and verdict: the paper-1 virtual joint's vlt (validated by the trust
    check itself) and the EPOS lead screw's stribeck_asym (the manifest's validate)."""
    from fricid.fleet import SerialExecutor, read_results, run_fleet

    sc = preset("paper1", "reduced")
    hints = design_hints(sc)
    chunks = (replace(c, meta={**c.meta, "design": hints}) for c in simulate(sc, seed=3))
    log = write_rawlog(chunks, tmp_path / "paper1.parquet")
    (tmp_path / "m.yaml").write_text(
        f"joints:\n  - robot: virtual\n    joint: j1\n    log: {log}\n    model: vlt\n"
        f"  - robot: leadscrew\n    joint: axis\n    log: {leadscrew_dir}\n    reader: epos\n"
        "    flip_sign: true\n    nominal_torque [mN m]: 9.84\n    model: stribeck_asym\n"
        "    validate: lovo\n",
        encoding="utf-8",
    )
    run = run_fleet(tmp_path / "m.yaml", tmp_path / "out", executor=SerialExecutor())
    assert run.failed == 0
    table = read_results(tmp_path / "out" / "results.csv").set_index("robot")
    extract = {
        "virtual": ["extract", str(log)],
        "leadscrew": ["extract", str(leadscrew_dir), "--format", "epos", "--flip-sign"],
    }
    sources = {"virtual": RUN_HERE, "leadscrew": FROM_FIT}
    for robot, args in extract.items():
        row = table.loc[robot]
        samples = tmp_path / f"{robot}.parquet"
        assert runner.invoke(app, [*args, "-o", str(samples)]).exit_code == 0
        model = tmp_path / "out" / row["model_file"]
        line, md = _report(model, samples, tmp_path / f"{robot}-report")
        assert row["heldout_source"] == sources[robot] and row["heldout_scheme"] == LOVO_INTERIOR
        assert _level(line) == row["trust"]
        assert row["verdict"] in md and "read from the model file" in md
        assert _ratio(md) == pytest.approx(row["heldout_ratio"], rel=1e-2)
        # computed afresh, as the report computes it without a stored record: the same
        fresh = _fresh(model, samples)
        assert fresh.line() == line and fresh.heldout_ratio == row["heldout_ratio"]
    # the lovo-validated vlt misses by far more than its in-sample ratio said
    vlt = table.loc["virtual"]
    saved = json.loads((tmp_path / "out" / vlt["model_file"]).read_text())
    assert vlt["trust"] == "no" and vlt["heldout_ratio"] > saved["metrics"]["rmse_over_scatter"]


@pytest.mark.slow  # 2 s measured under load (default run kept short)
def test_fit_validate_lovo_and_report_agree(leadscrew, tmp_path):
    """`fricid fit --validate lovo` prints the verdict it stores; `fricid report` on the same
    samples reads the same record, and computing it again gives the same line."""
    samples = write_samples(leadscrew, tmp_path / "s.csv")
    model = tmp_path / "m.json"
    res = runner.invoke(
        app,
        ["fit", str(samples), "-m", "stribeck_asym", "--validate", "lovo", "-o", str(model)],
    )
    assert res.exit_code == 0, res.output
    block = res.stdout.split("[[Trust]]\n", 1)[1].splitlines()
    fit_line = block[0].strip()
    assert f"[the fit's --validate ({LOVO_INTERIOR})]" in block[1]
    stored = json.loads(model.read_text())
    assert stored["trust"]["heldout_source"] == FROM_FIT
    inner = interior_rmse(stored["validation"]["folds"]) / stored["validation"]["scatter"]
    assert stored["trust"]["heldout_ratio"] == pytest.approx(inner)
    line, md = _report(model, samples, tmp_path / "r")
    assert line == fit_line and "read from the model file" in md
    assert _ratio(md) == pytest.approx(inner, rel=1e-2)
    assert _fresh(model, samples).line() == fit_line


@pytest.mark.slow  # 2 s measured under load (default run kept short)
def test_fit_without_validate_stores_the_lovo_the_report_would_run(leadscrew, tmp_path):
    samples = write_samples(leadscrew, tmp_path / "s.csv")
    model = tmp_path / "m.json"
    res = runner.invoke(app, ["fit", str(samples), "-m", "stribeck", "-o", str(model)])
    assert res.exit_code == 0, res.output
    stored = json.loads(model.read_text())
    assert stored["validation"] is None and stored["trust"]["heldout_source"] == RUN_HERE
    line, _ = _report(model, samples, tmp_path / "r")
    assert line.startswith(f"Trust: {stored['trust']['level']}, because")
    assert pd.notna(stored["trust"]["heldout_ratio"])


def test_run_joint_takes_fricid_fits_options_and_gives_the_same_model(leadscrew_dir, tmp_path):
    """run_joint with --validate, --loss, --f-scale, --weights, --intervals: the model, its
    validation and its trust record are fricid fit's, bit for bit."""
    from fricid.workflow import run_joint

    options = {"validate": "kfold:4", "loss": "soft_l1", "weights": "std", "intervals": "jacobian"}
    run = run_joint(
        leadscrew_dir,
        reader="epos",
        reader_options={"flip_sign": True},
        models=("stribeck_asym",),
        f_scale=5e-5,
        **options,
    )
    joint = run.fits["stribeck_asym"]
    assert joint.loss["loss"] == "soft_l1" and joint.loss["weights"] == "std"
    assert joint.ci_method == "jacobian" and joint.validation["scheme"] == "kfold:4"
    assert run.trust["stribeck_asym"].to_dict() == joint.trust
    samples = write_samples(run.used["stribeck_asym"], tmp_path / "s.csv")
    flags = [f"--{k}={v}" for k, v in options.items()]
    model = tmp_path / "m.json"
    args = ["fit", str(samples), "-m", "stribeck_asym", "--f-scale", "5e-5", *flags]
    res = runner.invoke(app, [*args, "-o", str(model), "--quiet"])
    assert res.exit_code == 0, res.output
    by_hand = FittedModel.load(model)
    assert by_hand.params == joint.params and by_hand.validation == joint.validation
    assert by_hand.trust == joint.trust


def _linear_joint(speed: np.ndarray, seed: int) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    v = np.r_[-speed, speed]
    y = np.sign(v) * (0.3 + 0.1 * np.abs(v)) + rng.normal(0.0, 0.01, v.size)
    return FrictionSamples(velocity=v, load=None, temperature=None, friction=y)


def test_a_gap_between_measured_speeds_is_a_caveat():
    holed = _linear_joint(np.r_[np.linspace(0.1, 1.0, 8), np.linspace(4.0, 6.0, 5)], 5)
    trust = assess_trust(fit(holed, "coulomb_viscous"), holed)
    assert trust.level != "yes"
    assert any("no speed measured between 1 and 4 rad/s (v > 0)" in r for r in trust.reasons)
    even = _linear_joint(np.linspace(0.1, 6.0, 13), 5)
    reasons = assess_trust(fit(even, "coulomb_viscous"), even).reasons
    assert not any("no speed measured" in r for r in reasons)


def test_a_temperature_law_at_one_temperature_is_told_to_record_another(leadscrew_dir):
    """stribeck_temp on the lead screw at its one temperature was told to fit a learned model
    ("more data will not help"): a second temperature, or no temperature law, is the remedy."""
    from fricid.identify._advice import misfit_advice

    at_25 = epos_steady_samples(leadscrew_dir, temperature=25.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit(at_25, "stribeck_temp")
    record = assess_trust(model, at_25)
    assert record.level == "no"
    advice = record.what_to_do
    assert "the samples hold one temperature (25 degC)" in advice and "at least two" in advice
    assert "record at another temperature" in advice
    assert "--model stribeck or --model stribeck_asym" in advice
    assert "learned" not in advice and "will not help" not in advice
    # the model file alone (its operating range) tells the same
    assert misfit_advice(model, None, record.scatter, 3.0) == advice
    # at two temperatures the law is determined: the other readings, as before
    two = FrictionSamples(
        velocity=np.tile(at_25.velocity, 2),
        load=0.0,
        temperature=np.repeat([25.0, 45.0], len(at_25)),
        friction=np.tile(at_25.friction, 2),
        count=np.tile(at_25.count, 2),
        std=np.tile(at_25.std, 2),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        both = fit(two, "stribeck_temp")
    other = misfit_advice(both, None, record.scatter, 3.0, two)
    assert "one temperature" not in other
    assert other.startswith("the stribeck_temp family cannot follow these data")


def test_vlt_at_one_temperature_is_offered_the_load_law_without_temperature():
    """vlt (load and temperature, eq. 4) at one temperature keeps its load law in msk (eq. 3):
    stribeck would drop it."""
    from fricid.identify._advice import _without_temperature

    assert _without_temperature("vlt") == "--model msk"
    assert _without_temperature("vlt_asym") == "--model msk_asym"
    assert _without_temperature("stribeck_temp_asym") == "--model stribeck_asym"


def test_a_verdict_on_interior_levels_names_the_end_levels_it_leaves_out(fitted, leadscrew):
    """The lead screw's stribeck_asym is graded on its interior speed levels (0.41x); held
    out, its slowest level misses by 2.25x the scatter: the verdict says so, with the speeds,
    and that those folds are extrapolations it does not grade."""
    record = assess_trust(fitted, leadscrew)
    assert record.level == "yes" and record.heldout_scheme == LOVO_INTERIOR
    folds = sorted(record.validation["folds"], key=lambda f: f["speed"])
    ratios = [folds[i]["rmse"] / record.scatter for i in (0, -1)]
    assert ratios[0] > 2.0  # the measured miss the verdict must not hide
    (reason,) = record.reasons
    assert f"on the {len(folds) - 2} interior speed levels" in reason
    assert f"slowest ({folds[0]['speed']:.3g} rad/s) is missed by {ratios[0]:.3g}x" in reason
    assert f"fastest ({folds[-1]['speed']:.3g} rad/s) by {ratios[1]:.3g}x" in reason
    assert "extrapolations, not graded" in reason


def test_samples_the_model_was_not_identified_on_grade_the_model_itself(
    fitted, leadscrew, tmp_path
):
    """A report of the lead screw's model on samples of a worn joint (friction x1.3) said
    "Trust: yes (0.53x)": it re-ran leave-one-velocity-out, which refits the family on the new
    samples, while the model file itself misses them by about 15x the scatter. On samples it
    was not identified on, the model's own error is the held-out one graded."""
    worn = replace(leadscrew, friction=1.3 * leadscrew.friction)
    record = assess_trust(fitted, worn)
    error = float(np.sqrt(np.mean((fitted.predict(worn.X, warn=False) - worn.y) ** 2)))
    assert record.heldout_source == NEW_SAMPLES and record.held_out
    assert record.heldout_rmse == pytest.approx(error, rel=1e-12)
    assert record.heldout_ratio > MISS_RATIO and record.level == "no"
    assert "on these samples, not the set it was identified on" in record.line()
    # its own samples: as before (lovo, interior levels)
    own = assess_trust(fitted, leadscrew)
    assert own.heldout_source == RUN_HERE and own.level == "yes"
    # its own rows in another order are its own samples, not other samples
    reordered = assess_trust(fitted, leadscrew.subset(np.arange(len(leadscrew))[::-1]))
    assert reordered.heldout_source != NEW_SAMPLES and reordered.level == "yes"
    # some of its own rows among others: judged on the others only
    half = np.arange(len(leadscrew)) % 2 == 0
    mixed = type(leadscrew).concatenate([leadscrew.subset(half), worn.subset(~half)])
    record = assess_trust(fitted, mixed)
    new = worn.subset(~half)
    error = float(np.sqrt(np.mean((fitted.predict(new.X, warn=False) - new.y) ** 2)))
    assert record.heldout_source == NEW_SAMPLES
    assert record.heldout_rmse == pytest.approx(error, rel=1e-12)
    assert any(r.startswith(f"{half.sum()} of 32 rows are rows the model") for r in record.reasons)
    # one direction's model (fit --direction pos) on a file of both: its own rows are judged,
    # and what it makes of the other side is said
    pos = fit(leadscrew.subset(leadscrew.direction > 0), "stribeck")
    mine = assess_trust(pos, leadscrew)
    assert mine.heldout_source in (RUN_HERE, KFOLD_HERE)  # its own rows: validated as fit
    assert mine.level != "yes"
    assert any("16 rows of a direction the model was not identified on" in r for r in mine.reasons)
    # ... and on a worn joint's file of both: the other side is left out of the grade
    both = assess_trust(pos, worn)
    assert both.heldout_source == NEW_SAMPLES
    inside = worn.subset(worn.velocity > 0)
    error = float(np.sqrt(np.mean((pos.predict(inside.X, warn=False) - inside.y) ** 2)))
    assert both.heldout_rmse == pytest.approx(error, rel=1e-12)
    assert any(r.startswith("16 of 32 rows lie outside the range") for r in both.reasons)
