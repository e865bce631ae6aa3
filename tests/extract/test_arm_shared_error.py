"""An arm's identified gravity travels with its joints' samples, into a file and back, and
into the intervals of a law fitted to them (fricid.extract.arm,
fricid.identify.static.shared_error)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from _arm_sweeps import Law, arm_sweeps, perturbed
from fricid.extract.arm import extract_arm
from fricid.identify import fit
from fricid.identify.static.shared_error import shared_covariance
from fricid.io import read_samples, write_samples
from fricid.robot import RigidBodyModel, example_urdf

LAWS = {"joint1": Law(0.10, 0.08, 0.05, 0.04), "joint2": Law(0.06, 0.07, 0.03, 0.035)}


@pytest.fixture(scope="module")
def extraction():
    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    poses = {
        "joint1": [np.array([0.0, q]) for q in (-0.9, 0.0, 0.9)],
        "joint2": [np.array([q, 0.0]) for q in (-0.9, 0.0, 0.9)],
    }
    log = arm_sweeps(truth, spans, poses, LAWS, seed=4, rate=100.0)
    ident = perturbed(truth, np.random.default_rng(104))
    return extract_arm(log, ident), extract_arm(log, ident, identify=False)


def _fit(samples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, "coulomb_viscous_asym")


def test_each_level_records_its_share_of_the_gravity_error(extraction):
    """The samples carry beta's covariance and each level's regressor row; the shared variance
    of a sample is part of its level's (noise plus shared)."""
    res, _ = extraction
    for joint in LAWS:
        bd = res[joint].by_direction
        m = len(res.gravity.names)
        g = bd.meta["gravity"]
        assert len(g["covariance"]) == m and all(len(lv["regressor"]) == m for lv in g["levels"])
        cov = shared_covariance(bd)
        assert cov.shape == (len(bd), len(bd))
        assert np.all(np.linalg.eigvalsh(cov) > -1e-15)
        se = {
            (lv["direction"], round(abs(lv["velocity"]), 2)): lv["friction_se"]
            for lv in g["levels"]
        }
        level_se = np.array(
            [se[(int(d), round(abs(v), 2))] for d, v in zip(bd.direction, bd.velocity, strict=True)]
        )
        assert np.all(np.diag(cov) <= level_se**2 * (1 + 1e-9))
        assert np.all(np.diag(cov) > 0)


def test_the_law_intervals_include_it_and_survive_a_file(extraction, tmp_path):
    res, urdf = extraction
    bd = res["joint1"].by_direction
    fitted = _fit(bd)
    share = fitted.provenance["shared_error"]["variance_share"]
    # nearly an offset per direction: the Coulomb levels take most of it
    assert share["f_c_pos"] > share["beta_pos"] > 0 and share["f_c_neg"] > share["beta_neg"] > 0
    line = next(x for x in fitted.report().splitlines() if "every sample shares" in x)
    assert "base gravity parameters" in line and f"f_c_pos {100 * share['f_c_pos']:.0f} %" in line
    back = read_samples(write_samples(bd, tmp_path / "joint1.csv"))
    again = _fit(back)
    for name, p in fitted.parameters.items():
        assert again.parameters[name].ci95 == pytest.approx(p.ci95, rel=1e-6), name
    # the URDF's masses trusted: nothing identified, nothing shared
    assert "shared_error" not in _fit(urdf["joint1"].by_direction).provenance
