"""Identification: samples + model + optimiser -> :class:`~fricid.fitted.FittedModel`.

* :func:`fit`, :func:`evaluate` (:mod:`fricid.identify._fit`): least-squares identification of
  any model, the RBF network included (``fit(samples, "rbf", method="bas")``);
* :class:`IdentificationProblem` (:mod:`fricid.identify.problem`): model, data, loss, bounds
  and fixed parameters, evaluated for a batch of candidates; the one place the objective is
  written;
* :func:`jacobian_uncertainty` (:mod:`fricid.identify.uncertainty`): standard errors and
  covariance by an SVD pseudo-inverse, as scipy's ``curve_fit``; what ``fit`` reports of
  them (:func:`~fricid.identify.uncertainty.assess`: nothing for an unconverged fit or a
  degenerate optimum);
* :func:`profile_intervals` (:mod:`fricid.identify.profile`): profile-likelihood 95 %
  intervals inside the search box;
* :mod:`fricid.identify.rbf`: the RBF network's scikit-learn estimator and trainers
  (imported on use: it needs scikit-learn).
"""

from __future__ import annotations

from ..samples import samples_hash
from ._fit import evaluate, fit
from .problem import IdentificationProblem
from .profile import profile_intervals
from .uncertainty import jacobian_uncertainty

__all__ = [
    "IdentificationProblem",
    "evaluate",
    "fit",
    "jacobian_uncertainty",
    "profile_intervals",
    "samples_hash",
]
