"""The trust line of an export whose Coulomb-viscous projection (or LuGre mapping) misses the
model by more than the model's measurement scatter says the verdict is the model's and by how
many times the scatter what was exported misses it; a lossless export's line is unchanged."""

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
    found = re.search(r"misses the model by ([\d.e+-]+) times the scatter", line)
    assert found, line
    return float(found.group(1))


@pytest.mark.parametrize("export", EXPORTS)
def test_a_lossy_projection_says_the_verdict_is_the_models(export):
    model = FittedModel.from_values("stribeck", dict(STRIBECK), operating_range=RANGE)
    proj = project(model, per_direction=export is ros2_yaml_text)
    scatter = proj.rms_error / 5.0
    line = trust_line(export(trusted(model, scatter), max_loss=1.0))
    assert "the model's: held-out error 0.4 times the scatter" in line, line
    assert missed_by(line) == pytest.approx(proj.rms_error / scatter, rel=1e-2)
    # within the scatter, the projection does not change what the verdict means
    line = trust_line(export(trusted(model, 2 * proj.rms_error), max_loss=1.0))
    assert line.endswith(
        "yes (held-out error 0.4 times the scatter); the model file gives the reasons"
    )


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
    line = trust_line(mjcf_text(trusted(model, rms / 3.0)))
    assert "mapping onto MuJoCo's LuGre misses the model by" in line, line
    assert missed_by(line) == pytest.approx(3.0, rel=1e-2)
