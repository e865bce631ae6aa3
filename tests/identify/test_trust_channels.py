"""A static campaign whose velocity column is in the wrong unit: the extraction says so and
the trust verdict is "no" (``fricid.identify._diagnostics.channel_problems``), also when the
log arrives in chunks."""

from __future__ import annotations

import itertools
import warnings
from dataclasses import replace

import numpy as np
import pytest

from fricid.errors import DataQualityWarning
from fricid.extract import extract
from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.sim import preset, simulate_log


@pytest.fixture(scope="module")
def campaign():
    spec = preset("paper2", "quick")
    return spec, simulate_log(spec, seed=11)


def _trust(samples):
    return assess_trust(fit(samples, "stribeck"), samples)


def test_a_velocity_in_degrees_labelled_radians_is_not_trusted(campaign):
    spec, log = campaign
    clean = extract(log, **spec.extract_options())
    assert "channel_problems" not in clean.samples.meta
    assert not any("derivative" in r for r in _trust(clean.samples).reasons)
    wrong = replace(log, velocity=log.velocity * 180 / np.pi)
    with pytest.warns(DataQualityWarning, match="not the position's derivative"):
        got = extract(wrong, **spec.extract_options())
    (problem,) = got.samples.meta["channel_problems"]
    assert "degrees against radians" in problem
    trust = _trust(got.samples)
    assert trust.level == "no"
    assert "degrees against radians" in trust.reasons[0]


def test_a_velocity_integrated_into_the_position_is_not_judged(campaign):
    spec, log = campaign
    wrong = replace(
        log,
        velocity=log.velocity * 3.0,
        meta={**log.meta, "position_source": "integrated velocity"},
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataQualityWarning)
        got = extract(wrong, **spec.extract_options())
    assert "channel_problems" not in got.samples.meta


def test_a_log_in_chunks_is_judged_once_per_source(campaign):
    spec, log = campaign
    wrong = replace(log, velocity=-log.velocity * 9.549296585513721)  # rpm labelled rad/s
    edges = np.linspace(0, len(wrong), 5).astype(int)
    chunks = [wrong.slice(a, b) for a, b in itertools.pairwise(edges)]
    with pytest.warns(DataQualityWarning):
        got = extract(chunks, **spec.extract_options())
    (problem,) = got.samples.meta["channel_problems"]
    assert "reversed sign and units rpm against rad/s" in problem


def test_a_reversed_torque_sign_is_named_instead_of_misfit_advice(campaign):
    spec, log = campaign
    flipped = replace(log, current=-log.current)
    got = extract(flipped, **spec.extract_options())
    trust = _trust(got.samples)
    assert trust.level == "no"
    assert "the friction opposes the velocity at" in trust.reasons[0]
    assert "sign is reversed" in trust.reasons[0]
    assert trust.what_to_do == ""  # not "fit a learned model"
    clean = extract(log, **spec.extract_options())
    assert not any("opposes" in r for r in _trust(clean.samples).reasons)


def test_a_coarse_encoder_velocity_is_warned_at_extraction(campaign):
    spec, log = campaign
    step = 2 * np.pi / 2**12
    q = np.round(log.position / step) * step
    dt = float(np.median(np.diff(log.time)))
    coarse = replace(log, position=q, velocity=np.r_[0.0, np.diff(q) / dt])
    with pytest.warns(DataQualityWarning, match="finite difference at a coarse encoder"):
        extract(coarse, **spec.extract_options())
