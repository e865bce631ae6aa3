"""Trajectory logs of the virtual joint and its true LuGre model as a trajectory model file
would hold it, shared by the tests of trajectory predictions and reports (one simulation and
one compilation per process)."""

from __future__ import annotations

from functools import cache

import numpy as np

from fricid.fitted import FittedModel
from fricid.samples import RawLog
from fricid.sim import Joint
from fricid.sim import trajectory as tr

JOINT = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=0.01)
TRUTH = tr.LuGreTruth()


@cache
def multisine_log(seed: int, duration: float = 3.0) -> RawLog:
    """A multi-sine log of the virtual joint (LuGre truth, trajectory noise)."""
    return tr.simulate_trajectory(
        tr.multisine(duration=duration, seed=seed), TRUTH, JOINT, seed=seed
    )


def truth_model(**changes) -> FittedModel:
    """The virtual joint's truth (``changes`` applied) with the joint and filters a
    ``fit --trajectory`` records."""
    fitted = FittedModel.from_values(
        "lugre", {**TRUTH.params(), **changes}, operating_range={"velocity": [-2.0, 2.0]}
    )
    fitted.provenance["trajectory"] = {
        "route": "filtered",
        "joint": {"inertia": {"value": 0.01}, "p_x": {"value": 0.3}, "p_y": {"value": 0.1}},
        "derivative": {"method": "savgol", "source": "position", "window": 0.021, "order": 3},
        "parallel_filter": {
            "method": "butter",
            "cutoff": 20.0,
            "order": 4,
            "trim": 0.25,
            "decimate": 10,
        },
        "n_sub": 4,
    }
    return fitted
