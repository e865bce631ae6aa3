"""A samples file whose friction header names the wrong torque unit (N m numbers under
``friction [mN m]``) is told as such where a model meets it, instead of a 1e5 % relative error
and R² near minus a million with no hint; honest samples, and a drive whose friction is merely
larger, are told nothing."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.identify import fit, torque_unit_mismatch, unit_mismatches, velocity_unit_mismatch
from fricid.identify.trust import assess_trust
from fricid.io import epos_steady_samples, read_samples, write_samples
from fricid.report import model_report


@pytest.fixture(scope="module")
def files(leadscrew_dir, tmp_path_factory):
    """The lead screw's samples as written (N m), the same under ``friction [mN m]``, and a
    model identified on the honest ones."""
    folder = tmp_path_factory.mktemp("unit")
    honest = write_samples(epos_steady_samples(leadscrew_dir), folder / "honest.csv")
    text = honest.read_text(encoding="utf-8")
    assert text.count("friction [N m]") == 1
    damaged = folder / "damaged.csv"
    damaged.write_text(text.replace("friction [N m]", "friction [mN m]"), encoding="utf-8")
    fitted = fit(read_samples(honest), "stribeck_asym")
    model = folder / "model.json"
    fitted.save(model)
    return honest, damaged, fitted, model


def test_a_header_in_the_wrong_unit_is_named(files):
    honest, damaged, fitted, _ = files
    assert torque_unit_mismatch(fitted, read_samples(honest)) is None
    said = torque_unit_mismatch(fitted, read_samples(damaged))
    assert said is not None
    assert "predicts 1000x the measured friction" in said
    assert "friction column's header in damaged.csv" in said
    assert "numbers in N m under a header in mN m" in said


def test_the_reverse_factor_and_an_honest_larger_friction(files):
    honest, _, fitted, _ = files
    samples = read_samples(honest)
    mnm = samples.__class__(
        velocity=samples.velocity, load=None, temperature=None, friction=1e3 * samples.friction
    )
    said = torque_unit_mismatch(fitted, mnm)
    assert said is not None and "numbers in mN m under a header in N m" in said
    # another drive, 1000x the friction but its own shape: no ratio close to 1000 everywhere
    speed = np.abs(samples.velocity) / np.abs(samples.velocity).max()
    other = samples.__class__(
        velocity=samples.velocity,
        load=None,
        temperature=None,
        friction=1e3 * samples.friction * (0.7 + 0.6 * speed),
    )
    assert torque_unit_mismatch(fitted, other) is None


def test_report_says_why_its_errors_mean_nothing(files, tmp_path):
    honest, damaged, fitted, model = files
    for path, told in ((honest, False), (damaged, True)):
        samples = read_samples(path)
        doc = model_report(fitted, samples, trust=assess_trust(fitted, samples, max_work=1))
        assert ("torque unit" in doc.meta) is told
        notes = [i.text for s in doc.sections for i in s.items if hasattr(i, "kind")]
        assert any("do not measure the model" in n for n in notes) is told
    out = tmp_path / "rep"
    result = CliRunner().invoke(app, ["-q", "report", str(model), str(damaged), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "warning: the model predicts 1000x" in result.stderr
    assert "header in damaged.csv" in (out / "report.md").read_text(encoding="utf-8")


def test_evaluate_says_so_too(files):
    honest, damaged, _, model = files
    runner = CliRunner()
    for path, told in ((honest, False), (damaged, True)):
        res = runner.invoke(app, ["evaluate", str(model), str(path)], terminal_width=200)
        assert res.exit_code == 0, res.output
        text = " ".join(res.output.split())
        assert ("likely names the wrong torque unit" in text) is told
        # the model's own samples: an in-sample error, said so beside the verdict
        own = "in-sample: these are the samples the model was identified on"
        assert (own in text) is not told, text


def _speeds_under(samples, factor):
    """The samples with their velocities as a header ``factor`` times too small reads them."""
    return samples.__class__(
        velocity=samples.velocity * factor,
        load=None,
        temperature=None,
        friction=samples.friction,
        direction=samples.direction,
        source="ls_rpm.csv",
    )


def test_a_velocity_header_in_the_wrong_unit_is_named(files, tmp_path):
    """rad/s numbers under ``velocity [rpm]`` read 0.105x too slow: the model misses them by a
    lot, and the samples' speeds times 9.549 follow it; honest samples, and the same samples
    with the friction of another drive, are told nothing."""
    honest, _, fitted, model = files
    samples = read_samples(honest)
    assert velocity_unit_mismatch(fitted, samples) is None
    said = velocity_unit_mismatch(fitted, _speeds_under(samples, 2 * np.pi / 60))
    assert said is not None and "times 9.549" in said
    assert "numbers in rad/s under a header in rpm" in said and "ls_rpm.csv" in said
    deg = velocity_unit_mismatch(fitted, _speeds_under(samples, np.pi / 180))
    assert deg is not None and "numbers in rad/s under a header in deg/s" in deg
    other = samples.__class__(
        velocity=samples.velocity,
        load=None,
        temperature=None,
        friction=samples.friction * (1.5 + np.abs(samples.velocity)),
        direction=samples.direction,
    )
    assert unit_mismatches(fitted, other) == {}
    text = honest.read_text(encoding="utf-8")
    assert text.count("velocity [rad/s]") == 1
    rpm = tmp_path / "rpm.csv"
    rpm.write_text(text.replace("velocity [rad/s]", "velocity [rpm]"), encoding="utf-8")
    res = CliRunner().invoke(app, ["evaluate", str(model), str(rpm)], terminal_width=200)
    assert res.exit_code == 0, res.output
    assert "likely names the wrong unit (numbers in rad/s under a header in rpm" in " ".join(
        res.output.split()
    )
