"""Identification: samples or a trajectory log + model + method ->
:class:`~fricid.fitted.FittedModel`.

One public entry, :func:`fit` (:mod:`fricid.identify.dispatch`, an explicit table of the kinds
of identification), over three rooms that share :class:`IdentificationProblem`
(:mod:`fricid.identify.problem`, the one place the objective is written):

* :mod:`fricid.identify.static`: analytic laws by least squares (BAS-RBFNN paper eq. 1-4,
  RWSAVSBAS paper eq. 7 and 11), their uncertainty and profile intervals, variable
  projection, and ``model="auto"`` (the family chosen by held-out error);
* :mod:`fricid.identify.learned`: the RBF network (plain, BAS-RBFNN, GA-RBFNN), the hybrid and
  the Gaussian process (imported on use: they need scikit-learn);
* :mod:`fricid.identify.dynamic`: LuGre, Dahl and static laws with inertia and gravity from any
  trajectory.

What every room's result is judged by lives here too, computed once: :func:`validate`
(held-out RMSE, leave one velocity level out or k-fold), :func:`measurement_scatter` and the
trust verdict (:mod:`fricid.identify.trust`: :func:`assess_trust` returns one :class:`Trust`
record, which ``fricid fit``, the fleet and ``fricid report`` read and never recompute).
"""

from __future__ import annotations

from ..samples import samples_hash
from ._advice import torque_unit_mismatch, unit_mismatches, velocity_unit_mismatch
from ._heldout import is_own_samples
from ._scatter import Scatter, measurement_scatter, sample_weights
from .dispatch import KINDS, fit, kind_of
from .problem import IdentificationProblem
from .static.least_squares import evaluate
from .static.profile import profile_intervals
from .static.select import select
from .static.uncertainty import jacobian_uncertainty
from .trust import Trust, assess_trust
from .validate import Validation, validate

__all__ = [
    "KINDS",
    "IdentificationProblem",
    "Scatter",
    "Trust",
    "Validation",
    "assess_trust",
    "evaluate",
    "fit",
    "is_own_samples",
    "jacobian_uncertainty",
    "kind_of",
    "measurement_scatter",
    "profile_intervals",
    "sample_weights",
    "samples_hash",
    "select",
    "torque_unit_mismatch",
    "unit_mismatches",
    "validate",
    "velocity_unit_mismatch",
]
