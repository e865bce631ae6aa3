"""All Stribeck shapes of a whole-arm fit moved together (``arm._polish``) after the block
search: noise-free, the shapes come out at the truth, where the block search alone stops short."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _arm_truth import make_log, stribeck_law

pytest.importorskip("pinocchio")

import fricid.identify.dynamic.arm as arm
from fricid.robot import RigidBodyModel, example_urdf


@pytest.fixture(scope="module")
def case():
    path, joints = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, joints)
    rng = np.random.default_rng(4)
    laws = [stribeck_law(rng, scale=0.05) for _ in model.joints]
    log = make_log(model, laws, duration=20.0, seed=5, noise=1e-5, counts=2**30)
    return model, laws, log


def _shape_errors(fit, laws) -> list[float]:
    """Each shape's relative error; infinite where the fit gives none (not determined)."""
    return [
        abs((fit.friction[joint]["parameters"][name]["value"] or np.inf) / truth[name] - 1)
        for joint, (_, truth) in zip(fit.joints, laws, strict=True)
        for name in truth
        if name.startswith(("w_s", "delta"))
    ]


def test_the_shapes_come_out_at_the_truth(case):
    model, laws, log = case
    fit = arm.fit_arm(log, model, friction="stribeck_asym")
    assert max(_shape_errors(fit, laws)) < 0.01


@pytest.mark.slow
def test_the_block_search_alone_stops_short(case, monkeypatch):
    model, laws, log = case
    monkeypatch.setattr(arm, "polish_shapes", lambda *a, **k: {})
    fit = arm.fit_arm(log, model, friction="stribeck_asym")
    assert max(_shape_errors(fit, laws)) > 0.05
