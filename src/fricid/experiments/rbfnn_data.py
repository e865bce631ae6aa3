"""The BAS-RBFNN study's data: the ``paper1`` preset's samples and the virtual joint's true
friction at them (re-exported by :mod:`fricid.experiments.rbfnn_study`), in a module below
the study and its tuning, which both draw data here."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..samples import FrictionSamples

__all__ = ["paper1_data", "true_friction"]


def paper1_data(
    size: str = "full", seed: int = 0, data: str = "simulate"
) -> tuple[FrictionSamples, np.ndarray, float]:
    """Samples of the ``paper1`` preset, the true friction at their rows, and the noise floor.

    ``data="simulate"`` runs the virtual joint and extraction (eq. 9-13); ``"oracle"`` adds
    Gaussian noise of :func:`fricid.sim.expected_noise_std` to the true friction (fast).
    The noise floor is the RMS of that expected standard deviation [N m].
    """
    from ..sim import expected_noise_std, preset, true_samples

    scenario = preset("paper1", size)
    truth = true_samples(scenario)
    sd = expected_noise_std(scenario)
    floor = float(np.sqrt(np.mean(sd**2)))
    if data == "oracle":
        rng = np.random.default_rng(seed)
        samples = replace(
            truth,
            friction=truth.friction + rng.normal(0.0, sd),
            source=f"oracle paper1/{size} + noise, seed {seed}",
        )
        return samples, truth.friction.copy(), floor
    if data != "simulate":
        raise ConfigError(f"data must be 'simulate' or 'oracle'; got {data!r}")
    from ..extract import extract
    from ..sim import simulate

    result = extract(simulate(scenario, seed=seed), **scenario.extract_options())
    samples = replace(result.samples, source=f"virtual joint paper1/{size}, seed {seed}")
    return samples, true_friction(samples, scenario, truth), floor


def true_friction(
    samples: FrictionSamples, scenario: Any, truth: FrictionSamples | None = None
) -> np.ndarray:
    """The virtual joint's true friction at the rows of ``samples`` [N m].

    Parameters
    ----------
    samples : FrictionSamples
        Extracted samples of ``scenario``.
    scenario : fricid.sim.Scenario
        The simulated scenario (its joint's law is the truth).
    truth : FrictionSamples, optional
        :func:`fricid.sim.true_samples` of ``scenario``, if already at hand.

    Returns
    -------
    numpy.ndarray
        The oracle's friction when the samples lie on the design's grid, else the law
        evaluated at the samples' points (half the difference of the two directions, [B]
        eq. 11).
    """
    from ..sim import true_samples

    truth = true_samples(scenario) if truth is None else truth
    if len(samples) == len(truth) and np.allclose(
        samples.velocity, truth.velocity, rtol=0.05, atol=1e-3
    ):
        return truth.friction.copy()
    law = scenario.joint.law  # rows not on the design's grid: evaluate the law at the samples
    v, load, temp = samples.velocity, samples.load, samples.temperature
    return 0.5 * (law(v, load, temp) - law(-v, load, temp))
