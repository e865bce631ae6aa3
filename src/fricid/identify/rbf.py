"""The RBF network's trainers and scikit-learn estimator (identification layer).

Transitional re-export: the trainer and estimator move here from ``fricid.models.rbf``.
"""

from __future__ import annotations

from ..models.rbf import RBFNetRegressor, fit_rbf, to_fitted_model

__all__ = ["RBFNetRegressor", "fit_rbf", "to_fitted_model"]
