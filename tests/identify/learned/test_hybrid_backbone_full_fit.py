"""The hybrid's backbone: the lean winner's full fit must reproduce the lean optimum. On a
dozen samples at one temperature (29.6-30.3 degC, sensor noise), the lean optimum of
``stribeck_temp_asym`` was degenerate (an Arrhenius energy of 7e5 K times a viscous
coefficient of 1e-35), the full fit from it could not hold it and ended at an RMSE of 5e10
N m, and the hybrid then failed with "impossible value 1e10 N m" in its residuals. The next
candidate by BIC is taken instead, and the table says why."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.identify import fit
from fricid.samples import FrictionSamples

X = np.array(
    [
        [-0.205317, -0.838328, 29.671721],
        [-0.205317, -0.247027, 29.875307],
        [0.205317, -0.650944, 29.678362],
        [0.205317, 0.087883, 30.047076],
        [-0.895035, -0.045693, 30.063329],
        [-0.895035, 0.577893, 29.701377],
        [0.895035, -0.260548, 29.616871],
        [0.895035, 0.858053, 29.934019],
        [-4.114298, 0.217703, 29.868743],
        [-4.114298, 0.885607, 30.076038],
        [4.114298, -0.733208, 30.296514],
        [4.114298, -0.01276, 29.999384],
    ]
)
Y = np.array(
    [
        *(-0.739716, -0.689678, 0.699413, 0.752644, -0.830211, -0.881044),
        *(0.916072, 0.891877, -1.076888, -1.078318, 1.127698, 1.133159),
    ]
)


@pytest.mark.slow  # 1.9 s, quiet machine (default run kept short)
def test_a_degenerate_lean_optimum_gives_way_to_the_next_backbone():
    samples = FrictionSamples(velocity=X[:, 0], load=X[:, 1], temperature=X[:, 2], friction=Y)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit(samples, "hybrid", seed=4)
    pred = model.predict(samples.X, warn=False)
    assert np.sqrt(np.mean((pred - Y) ** 2)) < 0.05  # the noise is 0.03 N m
    skipped = [row for row in model.state["backbone_selection"] if "full_fit" in row]
    assert skipped and "not taken" in skipped[0]["full_fit"]
    assert model.state["backbone"]["model"] != skipped[0]["model"]
