"""Synthetic averaged samples for the learned models' tests (not a test module)."""

from __future__ import annotations

import numpy as np

from fricid.samples import FrictionSamples


def averaged_samples(v, temp, friction, noise: float, rng) -> FrictionSamples:
    """Samples at speeds ``v`` and temperatures ``temp``: ``friction`` plus Gaussian noise of
    ``noise`` N m, as the mean of 100 raw samples of standard deviation ``10 noise``."""
    return FrictionSamples(
        velocity=v,
        load=None,
        temperature=temp,
        friction=friction + noise * rng.normal(size=v.size),
        std=np.full(v.size, noise * 10),
        count=np.full(v.size, 100),
        source="syn.csv",
    )
