"""The trust line of an export whose Coulomb-viscous projection (or LuGre mapping) misses the
model by more than the model's measurement scatter says the verdict is the model's and by how
many times the scatter what was exported misses it; beyond what the trust check passes
(NOISE_RATIO, MISS_RATIO) the line leads with the file's numbers' grade, never a bare "yes";
a lossless export's line is unchanged."""

from __future__ import annotations

import re
from dataclasses import replace

import pytest

from fricid.export import mjcf_text, project, ros2_yaml_text, urdf_text
from fricid.export.mjcf import lugre_mapping
from fricid.fitted import FittedModel

RANGE = {"velocity": [-4.0, 4.0], "load": [0.0, 0.0], "temperature": [25.0, 25.0]}
STRIBECK = {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026, "delta": 1.0}
LUGRE = dict(sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=1.0)
EXPORTS = (urdf_text, mjcf_text, ros2_yaml_text)


def trusted(fitted: FittedModel, scatter: float) -> FittedModel:
    """``fitted`` with a recorded "yes" verdict at 0.4x the ``scatter`` [N m]."""
    trust = {"level": "yes", "reasons": ["ok"], "heldout_ratio": 0.4, "scatter": scatter}
    return replace(fitted, trust=trust)


def trust_line(text: str) -> str:
    (line,) = [ln for ln in text.splitlines() if "trust verdict:" in ln]
    return line


def missed_by(line: str) -> float:
    found = re.search(r"miss(?:es)? the model by ([\d.e+-]+) times the scatter", line)
    assert found, line
    return float(found.group(1))


@pytest.mark.parametrize("export", EXPORTS)
def test_a_lossy_projection_says_the_verdict_is_the_models(export):
    model = FittedModel.from_values("stribeck", dict(STRIBECK), operating_range=RANGE)
    proj = project(model, per_direction=export is ros2_yaml_text)
    scatter = proj.rms_error / 1.1  # beyond the scatter, within what the check passes
    line = trust_line(export(trusted(model, scatter), max_loss=1.0))
    assert "verdict: yes (the model's: held-out error 0.4 times the scatter" in line, line
    assert "this projection misses the model by" in line
    assert missed_by(line) == pytest.approx(proj.rms_error / scatter, rel=1e-2)
    # within the scatter, the projection does not change what the verdict means
    line = trust_line(export(trusted(model, 2 * proj.rms_error), max_loss=1.0))
    assert line.endswith(
        "yes (held-out error 0.4 times the scatter); the model file gives the reasons"
    )


@pytest.mark.parametrize("export", EXPORTS)
@pytest.mark.parametrize(("times", "grade"), [(5.0, "NO"), (2.0, "with caveats")])
def test_numbers_that_fail_the_check_lead_the_line(export, times, grade):
    """A file whose numbers miss the model by more than MISS_RATIO (3) times its scatter
    does not lead with "yes": NO for them; between NOISE_RATIO (1.2) and 3, with caveats."""
    from fricid.identify.trust import MISS_RATIO
    from fricid.metrics import NOISE_RATIO

    assert NOISE_RATIO < 2.0 < MISS_RATIO < 5.0
    model = FittedModel.from_values("stribeck", dict(STRIBECK), operating_range=RANGE)
    proj = project(model, per_direction=export is ros2_yaml_text)
    line = trust_line(export(trusted(model, proj.rms_error / times), max_loss=1.0))
    assert f"trust verdict: {grade} for this file's numbers (they miss the model by" in line
    assert "; the model itself: yes, held-out error 0.4 times the scatter)" in line, line
    assert missed_by(line) == pytest.approx(times, rel=1e-2)
    assert "verdict: yes" not in line


@pytest.mark.parametrize("export", EXPORTS)
def test_a_lossless_projection_keeps_the_line(export):
    model = FittedModel.from_values(
        "coulomb_viscous", {"f_c": 0.3, "beta": 0.1}, operating_range=RANGE
    )
    line = trust_line(export(trusted(model, 1e-9)))
    assert line.endswith(
        "yes (held-out error 0.4 times the scatter); the model file gives the reasons"
    )


def test_a_lugre_mapping_that_misses_the_steady_state_says_so():
    model = FittedModel.from_values("lugre", dict(LUGRE), operating_range={"velocity": [-2, 2]})
    rms = lugre_mapping(model).rms_error
    line = trust_line(mjcf_text(trusted(model, rms / 1.1)))
    assert "mapping onto MuJoCo's LuGre misses the model by" in line, line
    assert missed_by(line) == pytest.approx(1.1, rel=1e-2)
    line = trust_line(mjcf_text(trusted(model, rms / 4.0)))
    assert "verdict: NO for this file's numbers (they miss the model by" in line, line
    assert missed_by(line) == pytest.approx(4.0, rel=1e-2)


def test_the_command_says_a_line_that_is_not_yes_on_stderr(tmp_path):
    """`fricid export` prints the file's trust line on stderr when it is not a plain yes (a
    file whose numbers miss the model by 5x the scatter was written with 'wrote ...' only), and
    a model file without a verdict gets a line saying so (it had none: read as trusted)."""
    from typer.testing import CliRunner

    from fricid.cli import app

    model = FittedModel.from_values("stribeck", dict(STRIBECK), operating_range=RANGE)
    scatter = project(model).rms_error / 5.0
    path = trusted(model, scatter).save(tmp_path / "m.json")
    runner = CliRunner()
    res = runner.invoke(app, ["export", str(path), "--to", "urdf", "-o", str(tmp_path / "m.urdf")])
    assert res.exit_code == 0, res.output
    assert "warning: trust verdict: NO for this file's numbers" in res.stderr, res.stderr
    bare = model.save(tmp_path / "bare.json")
    res = runner.invoke(app, ["export", str(bare), "--to", "c", "-o", str(tmp_path / "c")])
    assert res.exit_code == 0, res.output
    assert "warning: trust verdict: not recorded in the model file" in res.stderr
    assert "trust verdict: not recorded" in (tmp_path / "c" / "fricid_friction.c").read_text()
    fine = trusted(model, 10.0).save(tmp_path / "fine.json")  # yes: nothing more on stderr
    res = runner.invoke(app, ["export", str(fine), "--to", "yaml", "-o", str(tmp_path / "f.yaml")])
    assert "trust verdict" not in res.stderr
