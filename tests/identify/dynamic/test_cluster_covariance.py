"""A parameter without effect leaves the others' intervals alone.

Fitted to a log without a Stribeck rise (truth Coulomb-viscous), a ``stribeck`` law's
``w_s`` and ``delta`` have no effect on the torque. Their NaN rows in the covariance had made
every standard error NaN: J, the gravity, tau_c and tau_v were printed "not determined" and
the verdict said no parameter was determined.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np
from tests._paths import REPO

from fricid.identify.dynamic._data import blocks, cluster_covariance
from fricid.identify.dynamic.trajectory import fit_trajectory

sys.path.insert(0, str(REPO / "benchmarks"))
from _encoder_truth import TRUTH, encoder_log


def test_a_column_without_effect_leaves_the_others_covariance_unchanged():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(400, 3))
    r = rng.normal(size=400)
    labels = blocks(400, 20)
    cov, se, g = cluster_covariance(J, r, labels)
    with_dead = np.column_stack([J[:, :2], np.zeros(400), J[:, 2]])
    cov4, se4, g4 = cluster_covariance(with_dead, r, labels)
    assert g4 == g and np.isnan(se4[2]) and np.isnan(cov4[2]).all()
    keep = [0, 1, 3]
    assert np.allclose(se4[keep], se) and np.allclose(cov4[np.ix_(keep, keep)], cov)


def test_stribeck_on_a_log_without_a_rise_keeps_the_intervals_it_has():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(encoder_log(0, 2.0**20), "stribeck")
    p = fitted.parameters
    assert len({n for n, par in p.items() if par.not_determined} & {"tau_s", "w_s", "delta"}) >= 2
    for mine, truth in (("tau_c", "f_c"), ("tau_v", "beta")):
        assert p[mine].ci95[0] <= TRUTH[truth] <= p[mine].ci95[1], (mine, p[mine])
    joint = fitted.provenance["trajectory"]["joint"]
    for name in ("inertia", "p_x", "p_y"):
        assert joint[name]["ci95_low"] <= TRUTH[name] <= joint[name]["ci95_high"], joint[name]
