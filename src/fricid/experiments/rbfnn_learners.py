"""The learners of the BAS-RBFNN study's Table 3 (:mod:`.rbfnn_study`): factories of
unfitted estimators by row label, and how each is fitted and described.

RBFNN (``lsq``) and BAS-RBFNN ([B] section 3, hybrid encoding) are
:class:`fricid.identify.learned.rbf.RBFNetRegressor`; the velocity-load-temperature model ([B] eq.
4)
is fitted by :func:`fricid.identify.fit`; scikit-learn's MLP and a Gaussian process are the
baselines the paper did not run.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from ..identify import fit as identify_fit
from ..identify.learned.rbf import RBFNetRegressor
from ..samples import FrictionSamples
from .rbfnn_config import MLP_BASE, StudyConfig

__all__ = [
    "SubsetGP",
    "describe",
    "fit_learner",
    "learners",
    "mlp_model",
    "search_network",
]


def _warp(velocity_scale: float | None):
    from sklearn.preprocessing import FunctionTransformer

    if velocity_scale is None:
        return FunctionTransformer()
    vs = float(velocity_scale)

    def warp(X: np.ndarray) -> np.ndarray:
        X = np.array(X, dtype=float)
        X[:, 0] = np.arcsinh(X[:, 0] / vs)
        return X

    return FunctionTransformer(warp)


def mlp_model(cfg: StudyConfig, options: dict[str, Any] | None = None, seed: int | None = None):
    """scikit-learn's ``MLPRegressor`` (ReLU, Adam) with early stopping on a validation split
    (:data:`~.rbfnn_config.MLP_BASE`) and the hidden layers and penalty of ``options``
    (default ``cfg.mlp_options``), on the same inputs as the RBF network (warped velocity,
    standardised) and a standardised target."""
    from sklearn.compose import TransformedTargetRegressor
    from sklearn.neural_network import MLPRegressor
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    opts = {**MLP_BASE, **(cfg.mlp_options if options is None else options)}
    net = MLPRegressor(random_state=cfg.seed if seed is None else seed, **opts)
    return TransformedTargetRegressor(
        regressor=make_pipeline(_warp(cfg.velocity_scale), StandardScaler(), net),
        transformer=StandardScaler(),
    )


class SubsetGP:
    """``GaussianProcessRegressor`` whose kernel hyperparameters are fitted on a random subset
    of ``subset`` points (an anisotropic squared-exponential kernel plus white noise, on
    standardised inputs and target), then conditioned on all training points with those
    hyperparameters. Fitting the hyperparameters on all 6615 points would cost minutes per
    fold (each likelihood evaluation is a 6615 x 6615 Cholesky factorisation)."""

    def __init__(self, velocity_scale: float | None, subset: int, seed: int) -> None:
        self.velocity_scale = velocity_scale
        self.subset = subset
        self.seed = seed

    def fit(self, X: np.ndarray, y: np.ndarray) -> SubsetGP:
        from sklearn.gaussian_process import GaussianProcessRegressor
        from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        kernel = ConstantKernel(1.0, (1e-3, 1e3)) * RBF(
            np.ones(X.shape[1]), (1e-2, 1e3)
        ) + WhiteKernel(1e-3, (1e-9, 1.0))
        rng = np.random.default_rng(self.seed)
        idx = rng.permutation(len(y))[: min(self.subset, len(y))]
        hyper = make_pipeline(
            _warp(self.velocity_scale),
            StandardScaler(),
            GaussianProcessRegressor(kernel, normalize_y=True, random_state=self.seed),
        )
        hyper.fit(X[idx], y[idx])
        learned = hyper[-1].kernel_
        self.model_ = make_pipeline(
            _warp(self.velocity_scale),
            StandardScaler(),
            GaussianProcessRegressor(learned, normalize_y=True, optimizer=None),
        )
        self.model_.fit(X, y)
        self.kernel_ = learned
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.model_.predict(X)


class _VLT:
    """The velocity-load-temperature model (eq. 4) fitted by ``identify.fit`` (``lm``), with
    the estimator interface the study uses."""

    def __init__(self, seed: int) -> None:
        self.seed = seed

    def fit(self, samples: FrictionSamples) -> _VLT:
        self.fitted_ = identify_fit(samples, "vlt", "lm", seed=self.seed)
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.fitted_.predict(X)


def learners(cfg: StudyConfig) -> dict[str, Callable[[], Any]]:
    """The models of Table 3, by label: factories of unfitted estimators."""
    out: dict[str, Callable[[], Any]] = {
        "RBFNN": lambda: RBFNetRegressor(**cfg.network(trainer="lsq")),
        "BAS-RBFNN": lambda: RBFNetRegressor(
            **cfg.network(trainer="bas", encoding="hybrid", method_options=dict(cfg.bas_options))
        ),
    }
    if cfg.large_centers:
        out[f"RBFNN-{cfg.large_centers}"] = lambda: RBFNetRegressor(
            **cfg.network(
                trainer="lsq", n_centers=cfg.large_centers, width_factor=cfg.large_width_factor
            )
        )
    if cfg.velocity_scale is not None:
        out["RBFNN, plain inputs"] = lambda: RBFNetRegressor(
            **cfg.network(trainer="lsq", velocity_scale=None)
        )
    out["VLT model"] = lambda: _VLT(cfg.seed)
    out["MLP"] = lambda: mlp_model(cfg)
    out["GP"] = lambda: SubsetGP(cfg.velocity_scale, cfg.gp_subset, cfg.seed)
    return out


def fit_learner(model: Any, samples: FrictionSamples) -> Any:
    """Fit one learner of :func:`learners` on ``samples`` and return it.

    The velocity-load-temperature model takes the samples themselves; the estimators take
    ``(X, y)``. Warnings raised while fitting (the MLP's convergence, the GP's bounds) are
    recorded, not silenced: ``model.fit_warnings_`` lists their categories and first lines,
    which the study counts and reports (Table 3's ``warnings`` column).
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fitted = model.fit(samples) if isinstance(model, _VLT) else model.fit(samples.X, samples.y)
    fitted.fit_warnings_ = [
        f"{w.category.__name__}: {str(w.message).splitlines()[0]}" for w in caught
    ]
    return fitted


def describe(label: str, cfg: StudyConfig) -> str:
    """The ``setup`` column of Table 3 for the learner ``label``."""
    m = cfg.n_centers
    return {
        "RBFNN": f"lsq: k-means, NN widths x{cfg.width_factor:g}, ridge; {m} centres",
        "BAS-RBFNN": f"bas/hybrid from the lsq net, to MSE {cfg.target_mse:g}; {m} centres",
        "RBFNN, plain inputs": "as RBFNN, without the velocity warp (the paper's inputs)",
        "VLT model": "eq. 4, Levenberg-Marquardt (8 starts)",
        "MLP": (
            f"sklearn MLP {cfg.mlp_options.get('hidden_layer_sizes')}, "
            f"alpha {cfg.mlp_options.get('alpha'):g}, early stopping"
        ),
        "GP": f"sklearn GP, SE-ARD + white; hyperparameters on {cfg.gp_subset} points",
    }.get(label, f"lsq; {cfg.large_centers} centres, widths x{cfg.large_width_factor:g}")


def search_network(
    cfg: StudyConfig,
    method: str,
    options: dict[str, Any],
    changes: dict[str, Any],
    seed: int,
) -> RBFNetRegressor:
    """The network of one Table 4 run: trained by ``method`` (``"bas"`` or ``"ga"``) with
    ``options``, hybrid encoding unless ``changes`` says otherwise, ``random_state`` ``seed``.

    The one place the study builds its optimiser-trained objective (the network's training
    MSE on the friction scaled to [-1, 1], the error of [B] eq. 16-17 as an MSE, section 4.3).
    """
    params = {"encoding": "hybrid", **changes}
    return RBFNetRegressor(
        **cfg.network(trainer=method, method_options=dict(options), random_state=seed, **params)
    )
