"""Improved beetle antennae search (IBAS) with a bounded step.

References
----------
[R] B. Kou et al., "A New Parameter Identification Method for Industrial Robots with
    Friction", Machines 10(5) 349, 2022 (the RWSAVSBAS paper), section 4.1 and its ref. [21].
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ._api import positive_option, register
from ._bas import BeetleSolver, check_ratio

__all__ = ["IBAS"]


@register
class IBAS(BeetleSolver):
    """Improved BAS with the step kept within ``[step_min, step_max]`` ([R] 4.1: 0.1 and 0.3,
    the other values as for RWSAVSBAS: eta = 0.98, c = 3, 1000 iterations).

    Our reading ([R] gives only the two limits): the step decays geometrically from
    ``step_max`` towards ``step_min``, ``step_t = step_min + (step_max - step_min) eta^t``, and
    the antenna length is ``step_t / c``; otherwise the BAS loop of
    :class:`~fricid.optim._bas.BeetleSolver`. Steps are in unit-box units, so the beetle never
    steps less than a tenth of the box: it finds the region of the optimum quickly but cannot
    refine it (the best point seen is kept), which is what [R] Table 1 shows for IBAS.

    Options
    -------
    n_iter : iterations (1000); ``3 n_iter + 1`` evaluations.
    step_min, step_max, eta, c : 0.1, 0.3, 0.98, 3.
    xtol : converged when the last step is at most this (1e-6): never with
        ``step_min > xtol``, since the step never falls below ``step_min``.
    """

    name = "ibas"
    summary = "improved BAS (RWSAVSBAS paper 4.1): step decays from step_max to step_min"
    options: ClassVar[dict[str, Any]] = {
        "n_iter": 1000,
        "step_min": 0.1,
        "step_max": 0.3,
        "eta": 0.98,
        "c": 3.0,
        "xtol": 1e-6,
    }

    def validate(self) -> None:
        super().validate()
        positive_option(self.opts, "step_min", self.name)
        positive_option(self.opts, "step_max", self.name)
        check_ratio(self.opts, self.name)

    def schedule(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        o = self.opts
        lo, hi = float(o["step_min"]), float(o["step_max"])
        step = lo + (hi - lo) * float(o["eta"]) ** np.arange(n)
        return step / float(o["c"]), step
