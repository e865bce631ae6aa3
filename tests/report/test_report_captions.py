"""The report's captions name only the inputs the model uses: a curve over velocity holds a
model's load and temperature at their median, and a model of velocity alone holds nothing
(its captions spoke of "the median load and temperature" all the same)."""

from __future__ import annotations

import numpy as np
import pytest

from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.report import Figure, Table, model_report
from fricid.report.band import held_at
from fricid.samples import FrictionSamples


@pytest.fixture(scope="module")
def samples() -> FrictionSamples:
    """Friction growing with load and falling with temperature, both varying."""
    rng = np.random.default_rng(0)
    speeds = np.geomspace(0.01, 2.0, 8)
    v, load, temp = (
        a.ravel() for a in np.meshgrid(np.r_[speeds, -speeds], [0.0, 5.0, 10.0], [20.0, 40.0])
    )
    size = (0.3 + 0.02 * load + 0.2 * np.exp(-((np.abs(v) / 0.1) ** 2)) + 0.05 * np.abs(v)) * (
        1.0 - 0.004 * (temp - 25.0)
    )
    friction = np.sign(v) * size + rng.normal(0.0, 0.002, v.size)
    return FrictionSamples(velocity=v, load=load, temperature=temp, friction=friction)


def _captions(fitted, samples) -> str:
    doc = model_report(fitted, samples, trust=assess_trust(fitted, samples, max_work=1))
    items = [i for sec in doc.sections for i in sec.items if isinstance(i, Figure | Table)]
    return " ".join(i.caption for i in items)


@pytest.mark.parametrize(
    ("family", "said", "unsaid"),
    [
        ("stribeck", (), ("median load", "median temperature")),
        ("msk", ("each band's median load.",), ("median load and", "median temperature")),
        ("vlt", ("each band's median load and temperature", "at the median load and"), ()),
    ],
)
def test_captions_name_only_the_inputs_the_model_uses(samples, family, said, unsaid):
    fitted = fit(samples, family, "lm")
    captions = _captions(fitted, samples)
    assert "95 % of new measured samples" in captions  # the prediction band is there
    for words in said:
        assert words in captions, family
    for words in unsaid:
        assert words not in captions, family


def test_held_at_names_the_held_inputs_in_order():
    assert held_at(("velocity",)) == ""
    assert held_at(("temperature", "velocity")) == "the median temperature"
    assert held_at(("velocity", "load", "temperature"), "each band's") == (
        "each band's median load and temperature"
    )
