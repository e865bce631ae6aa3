"""Identification: samples + model + optimiser -> :class:`~fricid.fitted.FittedModel`.

* :func:`fit`, :func:`evaluate` (:mod:`fricid.identify._fit`): least-squares identification of
  any model, the RBF network included (``fit(samples, "rbf", method="bas")``);
* :class:`IdentificationProblem` (:mod:`fricid.identify.problem`): model, data, loss, bounds
  and fixed parameters, evaluated for a batch of candidates; the one place the objective is
  written;
* :func:`validate` (:mod:`fricid.identify.validate`): held-out RMSE (leave one velocity
  level out, k-fold) beside the measurement scatter estimated from the data
  (:func:`measurement_scatter`), with a verdict;
* :func:`select` (:mod:`fricid.identify.select`): ``fit(samples, "auto")``, the candidate
  families compared by held-out error;
* :func:`jacobian_uncertainty` (:mod:`fricid.identify.uncertainty`): standard errors and
  covariance by an SVD pseudo-inverse, as scipy's ``curve_fit``; what ``fit`` reports of
  them (:func:`~fricid.identify.uncertainty.assess`: nothing for an unconverged fit or a
  degenerate optimum);
* :func:`profile_intervals` (:mod:`fricid.identify.profile`): profile-likelihood 95 %
  intervals inside the search box;
* :mod:`fricid.identify.rbf`: the RBF network's scikit-learn estimator and trainers
  (imported on use: it needs scikit-learn); :mod:`fricid.identify.hybrid`: an analytic
  backbone plus an RBF residual (``fit(samples, "hybrid")``).
"""

from __future__ import annotations

from ..samples import samples_hash
from ._fit import evaluate
from ._scatter import Scatter, measurement_scatter, sample_weights
from .problem import IdentificationProblem
from .profile import profile_intervals
from .select import fit, select
from .uncertainty import jacobian_uncertainty
from .validate import Validation, validate

__all__ = [
    "IdentificationProblem",
    "Scatter",
    "Validation",
    "evaluate",
    "fit",
    "jacobian_uncertainty",
    "measurement_scatter",
    "profile_intervals",
    "sample_weights",
    "samples_hash",
    "select",
    "validate",
]
