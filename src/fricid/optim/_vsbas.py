"""Variable-step beetle antennae search (VSBAS).

References
----------
[R] B. Kou et al., "A New Parameter Identification Method for Industrial Robots with
    Friction", Machines 10(5) 349, 2022 (the RWSAVSBAS paper), sections 3.1.3 and 4.1.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ._api import positive_option, register
from ._bas import BeetleSolver, check_ratio

__all__ = ["VSBAS"]


@register
class VSBAS(BeetleSolver):
    """Variable-step BAS: the BAS loop (:class:`~fricid.optim._bas.BeetleSolver`) with
    ``step <- step * eta`` after every iteration ([R] 3.1.3) and the antenna length tied to the
    step, ``d = step / c`` ([R] 4.1: "the ratio of the step of the beetle to the distance d0
    between the antennae was set to three"). [R] 4.1 gives step0 = 0.1, eta = 0.98, c = 3 and
    1000 iterations; we read the step in unit-box units (the paper does not say which box its
    steps live in) and ``d`` as the distance from the beetle to each antenna.

    Options
    -------
    n_iter : iterations (1000); ``3 n_iter + 1`` evaluations.
    step0, eta, c : initial step (0.1), step factor (0.98), step / antenna-length ratio (3).
    xtol : converged when the last step is at most this (1e-6; the paper's schedule ends at
        1.7e-10).
    """

    name = "vsbas"
    summary = "variable-step BAS (RWSAVSBAS paper 3.1.3, 4.1): step *= eta, antenna = step / c"
    options: ClassVar[dict[str, Any]] = {
        "n_iter": 1000,
        "step0": 0.1,
        "eta": 0.98,
        "c": 3.0,
        "xtol": 1e-6,
    }

    def validate(self) -> None:
        super().validate()
        positive_option(self.opts, "step0", self.name)
        check_ratio(self.opts, self.name)

    def schedule(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        o = self.opts
        step = float(o["step0"]) * float(o["eta"]) ** np.arange(n)
        return step / float(o["c"]), step
