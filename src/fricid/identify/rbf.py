"""The RBF neural network friction model of the BAS-RBFNN paper (section 3) as a scikit-learn
regressor, its trainers, and its :class:`~fricid.fitted.FittedModel` (identification layer;
the network's mathematics, prediction from a stored state, lives in :mod:`fricid.models.rbf`).

:class:`RBFNetRegressor` is a three-layer network: Gaussian hidden units (eq. 14) and a linear
output (eq. 15) with an optional bias, on inputs that are standardised inside the estimator.
It is trained by one of

* ``trainer="lsq"``: k-means centres, the p-nearest-neighbour width rule and output weights by
  (ridge) linear least squares; the standard fast recipe and the paper's "RBFNN" (Table 3);
* ``trainer="bas"`` (BAS-RBFNN, eq. 18-21), ``"ga"`` (GA-RBFNN, Table 4, Fig. 9) or any other
  method of :data:`fricid.optim.METHODS`: the network's parameters are searched by
  :func:`fricid.optim.minimize`, minimising the training mean squared error (eq. 16-17, an
  :class:`~fricid.identify.problem.IdentificationProblem` with loss ``mse``), until a target
  MSE or the epoch budget (:mod:`fricid.identify._rbf_search`). Two encodings of the search
  vector:

  - ``"full"``: centres, widths *and* output weights (and bias) are all searched, as the
    paper's section 3.3 describes ("BAS is used to optimize the network parameters");
  - ``"hybrid"``: centres and widths are searched; for every candidate the output weights are
    the ridge least-squares solution, computed for the whole candidate batch at once.

:func:`fricid.models.rbf.predict_state` evaluates a network stored in a
:class:`~fricid.fitted.FittedModel`'s ``state`` (plain lists, JSON-ready);
:func:`to_fitted_model` builds that model from a fitted estimator, and :func:`fit_rbf` does
both from :class:`~fricid.samples.FrictionSamples` (as ``fricid.identify.fit(samples, "rbf")``
does).

Reading of the paper (where it is unclear, DESIGN.md "Faithful and honest")
--------------------------------------------------------------------------
* **Target MSE.** The paper trains to "MSE 0.0001" (section 4.3) and reports mean absolute
  errors of about 0.001 N m (Tables 3, 4). An MSE of 1e-4 N m^2 would be an RMSE of 10 mN m,
  ten times those errors, so the MSE cannot be in N m^2. We read it as the MSE of the target
  mapped linearly onto [-1, 1] (MATLAB's ``mapminmax``, the Neural Network Toolbox default):
  ``target_mse=1e-4`` then means an RMSE of 1 % of half the friction range. On the
  ``paper1`` virtual joint (friction 0.14-0.41 N m) that is 1.35 mN m RMSE, about 1.1 mN m
  mean absolute error: the paper's 0.0011 N m. ``mse_history_`` and ``target_mse`` use this
  scale; multiply by ``target_scale_ ** 2`` for N m^2.
* **Epoch.** The paper counts "epochs" of BAS and GA (Fig. 9) without defining them. Here one
  epoch is ``evals_per_epoch`` candidate evaluations (one candidate network scored on the
  whole training set is one evaluation): one generation of a GA whose population is
  ``evals_per_epoch`` plus its elites, and ``evals_per_epoch / 3`` iterations of fricid's
  default BAS (the position and both antennae), or ``evals_per_epoch / 2`` with the option
  ``evaluate_position=False`` that the BAS-RBFNN study uses (the two antennae of eq. 19, all
  eq. 18-21 need). So epochs compare the methods at equal cost.
* **Which encoding are the paper's figures?** Section 3.3 says BAS optimises "the weights and
  biases" of the network, and Fig. 3 puts the network's parameters in the beetle's position:
  the paper *describes* ``encoding="full"``. Its *results* (Table 3: BAS-RBFNN 2.6 times more
  accurate than RBFNN; Fig. 9: the target MSE reached within a few hundred epochs) are what
  the ``hybrid`` encoding achieves on our virtual joint, and not what ``full`` achieves: with
  80 centres (401 coordinates) the full encoding started from the ``lsq`` network never
  improved it in 300 epochs (its least-squares weights are large and cancel each other, so
  any step of the beetle in weight space makes the fit worse), and started at random it
  ended three orders of magnitude above the target (``fricid bench rbfnn``, Table 4). We
  therefore read the paper's figures as the hybrid encoding (or, equivalently, as BAS
  tuning centres and widths around a least-squares output layer).

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling the
    Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper), eq. 14-21,
    Tables 3-4, Fig. 9-10.
[MD] J. Moody, C. J. Darken, "Fast learning in networks of locally-tuned processing units",
    Neural Computation 1(2), 1989 (k-means centres, p-nearest-neighbour widths).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from datetime import UTC, datetime
from numbers import Integral, Real
from typing import Any, ClassVar

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.cluster import KMeans
from sklearn.exceptions import ConvergenceWarning as SklearnConvergenceWarning
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval, InvalidParameterError, StrOptions
from sklearn.utils.validation import check_is_fitted, validate_data

from .. import __version__
from ..errors import ConfigError, DataError, IgnoredArgumentWarning
from ..fitted import FittedModel
from ..metrics import fit_statistics, metrics
from ..models import INPUTS
from ..models import _rbf_core as core
from ..models.rbf import STATE_KIND, check_inputs, mse_z, predict_state, predict_z
from ..optim import METHODS
from ..samples import FrictionSamples, samples_hash
from ._rbf_search import search_network

__all__ = ["LSQ_IGNORES", "TRAINERS", "RBFNetRegressor", "fit_rbf", "to_fitted_model"]

#: The trainers of the paper: ``lsq`` (RBFNN), ``bas`` (BAS-RBFNN), ``ga`` (GA-RBFNN); every
#: other method of :data:`fricid.optim.METHODS` is accepted too.
TRAINERS = ("lsq", "bas", "ga")

#: Parameters of :class:`RBFNetRegressor` that only an optimiser trainer uses, with their
#: defaults: set to anything else with ``trainer="lsq"`` they are ignored, with an
#: :class:`~fricid.errors.IgnoredArgumentWarning`.
LSQ_IGNORES: dict[str, Any] = {
    "encoding": "hybrid",
    "init": "kmeans",
    "max_epochs": 500,
    "evals_per_epoch": 30,
    "method_options": None,
}

#: k-means places the centres using at most ``max(_KMEANS_MIN, _KMEANS_PER_CENTRE * m)``
#: samples (a random subset of larger sets): centres need a representative sample, not all.
_KMEANS_MIN = 2000
_KMEANS_PER_CENTRE = 25


class RBFNetRegressor(RegressorMixin, BaseEstimator):
    """Gaussian radial basis function network (BAS-RBFNN paper, eq. 14-15), scikit-learn style.

    ``y(x) = sum_i w_i exp(-||z(x) - c_i||^2 / (2 sigma_i^2)) + b`` with ``z(x)`` the
    standardised input (after an optional asinh warp of the first column, the velocity).

    Parameters
    ----------
    n_centers : int, default 20
        Number of hidden units m (Gaussian centres). At most the number of training samples.
    trainer : str, default "lsq"
        ``"lsq"``: k-means centres (on at most ``max(2000, 25 m)`` samples, a random subset
        of larger sets), nearest-neighbour widths, ridge least-squares weights (the paper's
        "RBFNN"). ``"bas"`` (BAS-RBFNN), ``"ga"`` (GA-RBFNN) or any other method
        of :data:`fricid.optim.METHODS`: search the network's parameters with that optimiser.
    encoding : {"hybrid", "full"}, default "hybrid"
        Search vector of an optimiser trainer: ``"full"`` = centres, log-widths, output weights
        and bias (the paper's section 3.3); ``"hybrid"`` = centres and log-widths, with the
        output weights solved by ridge least squares for each candidate. Ignored by ``lsq``
        (like ``init``, ``max_epochs``, ``evals_per_epoch`` and ``method_options``: set to
        anything but their defaults with ``lsq``, ``fit`` warns with
        :class:`~fricid.errors.IgnoredArgumentWarning`).
    init : {"kmeans", "random"}, default "kmeans"
        Start of the search: ``"kmeans"`` starts from the ``lsq`` network (passed to the
        optimiser as ``x0``; the result is never worse than it); ``"random"`` leaves the
        start to the optimiser (uniform in the search box). Ignored by ``lsq``.
    width_factor : float, default 1.0
        Multiplies the width heuristic ``sigma_i = RMS distance from c_i to its two nearest
        centres`` [MD]. Wider Gaussians give smoother fits (and worse conditioning).
    alpha : float, default 1e-10
        Ridge penalty on the output weights: minimise ``mean(e^2) + alpha ||w||^2`` on the
        scaled target (``0``: plain least squares, with the SVD's rank cut-off). Hybrid
        candidates are scored with at least 1e-12.
    fit_bias : bool, default True
        Add a bias to the linear output (eq. 15 has none).
    velocity_scale : float or None, default None
        If given [rad/s], the first input column (fricid's velocity) is replaced by
        ``asinh(v / velocity_scale)`` before standardisation: logarithmic for
        ``|v| >> velocity_scale``, linear and odd through zero. It spreads the Stribeck region
        (the paper samples low velocities densely for the same reason, section 2.2) so fewer
        Gaussians fit it. None: plain standardisation, as the paper.
    target_mse : float or None, default 1e-4
        Stop an optimiser trainer once the training MSE of the target mapped onto [-1, 1]
        reaches this value (the paper's 0.0001; see the module notes). None: use the whole
        budget.
    max_epochs : int, default 500
        Budget of an optimiser trainer, in epochs.
    evals_per_epoch : int, default 30
        Candidate evaluations per epoch (a GA generation; see the module notes).
    method_options : dict or None, default None
        Options for the optimiser (``fricid.optim.minimize(..., options=...)``).
    random_state : int, RandomState instance or None, default None
        Seeds k-means and the optimiser; an int makes ``fit`` reproducible bit for bit.
        None draws fresh entropy from the OS (numpy's global random state is never used).

    Attributes
    ----------
    centers_ : ndarray (m, n_features_in_)
        Centres c_i in standardised input units.
    widths_ : ndarray (m,)
        Widths sigma_i in standardised input units.
    weights_ : ndarray (m,)
        Output weights w_i, in units of y.
    bias_ : float
        Output bias, units of y (0 when ``fit_bias=False``).
    input_shift_, input_scale_ : ndarray (n_features_in_,)
        Standardisation ``z = (warp(x) - input_shift_) / input_scale_``.
    target_scale_ : float
        Half the range of the training target: MSEs on the [-1, 1] scale times
        ``target_scale_ ** 2`` are in units of y squared.
    train_mse_ : float
        Final training MSE on the [-1, 1] scale.
    initial_mse_ : float
        Training MSE of the ``lsq`` network the search started from (NaN for
        ``init="random"``; equal to ``train_mse_`` for ``lsq``).
    mse_history_ : ndarray (n_epochs_,)
        Best training MSE ([-1, 1] scale) after each epoch (empty for ``lsq``; NaN for an
        epoch that ended before the optimiser's first batch of evaluations did).
    n_epochs_ : int
        Epochs run (0 for ``lsq``).
    n_evals_ : int
        Candidate networks evaluated (0 for ``lsq``).
    epochs_to_target_ : int or None
        First epoch whose best MSE reached ``target_mse`` (0 if the start already did);
        None if it was not reached or there was no target.
    n_features_in_ : int
    feature_names_in_ : ndarray of str (only when X had string column names)

    Examples
    --------
    >>> from fricid.identify.rbf import RBFNetRegressor
    >>> net = RBFNetRegressor(n_centers=40, random_state=0)
    >>> net.fit(samples.X, samples.y).predict(samples.X)  # doctest: +SKIP
    >>> cross_val_score(RBFNetRegressor(), samples.X, samples.y, cv=5)  # doctest: +SKIP
    """

    _parameter_constraints: ClassVar[dict[str, list[Any]]] = {
        "n_centers": [Interval(Integral, 1, None, closed="left")],
        "trainer": [str],
        "encoding": [StrOptions({"hybrid", "full"})],
        "init": [StrOptions({"kmeans", "random"})],
        "width_factor": [Interval(Real, 0, None, closed="neither")],
        "alpha": [Interval(Real, 0, None, closed="left")],
        "fit_bias": ["boolean"],
        "velocity_scale": [Interval(Real, 0, None, closed="neither"), None],
        "target_mse": [Interval(Real, 0, None, closed="neither"), None],
        "max_epochs": [Interval(Integral, 1, None, closed="left")],
        "evals_per_epoch": [Interval(Integral, 1, None, closed="left")],
        "method_options": [dict, None],
        "random_state": ["random_state"],
    }

    def __init__(
        self,
        n_centers: int = 20,
        *,
        trainer: str = "lsq",
        encoding: str = "hybrid",
        init: str = "kmeans",
        width_factor: float = 1.0,
        alpha: float = 1e-10,
        fit_bias: bool = True,
        velocity_scale: float | None = None,
        target_mse: float | None = 1e-4,
        max_epochs: int = 500,
        evals_per_epoch: int = 30,
        method_options: dict[str, Any] | None = None,
        random_state: int | np.random.RandomState | None = None,
    ) -> None:
        self.n_centers = n_centers
        self.trainer = trainer
        self.encoding = encoding
        self.init = init
        self.width_factor = width_factor
        self.alpha = alpha
        self.fit_bias = fit_bias
        self.velocity_scale = velocity_scale
        self.target_mse = target_mse
        self.max_epochs = max_epochs
        self.evals_per_epoch = evals_per_epoch
        self.method_options = method_options
        self.random_state = random_state

    # -- validation ----------------------------------------------------------------------
    def _check_params(self) -> str:
        """Validate the parameters (sklearn's constraints, raised as :class:`ConfigError`);
        return the trainer's name, lower-cased."""
        try:
            self._validate_params()
        except InvalidParameterError as exc:
            raise ConfigError(str(exc)) from None
        trainer = self.trainer.strip().lower()
        if trainer == "lsq":
            ignored = [
                name for name, default in LSQ_IGNORES.items() if getattr(self, name) != default
            ]
            if ignored:
                warnings.warn(
                    f"RBFNetRegressor(trainer='lsq') ignores {', '.join(ignored)}: they set up "
                    "an optimiser trainer (bas, ga, ...)",
                    IgnoredArgumentWarning,
                    stacklevel=3,
                )
        else:
            if trainer not in METHODS:
                raise ConfigError(
                    f"The 'trainer' parameter of RBFNetRegressor must be 'lsq' or a method of "
                    f"fricid.optim ({', '.join(METHODS)}). Got {self.trainer!r} instead."
                )
        return trainer

    def _warp(self, X: np.ndarray) -> np.ndarray:
        if self.velocity_scale is None:
            return X
        X = X.copy()
        X[:, 0] = np.arcsinh(X[:, 0] / self.velocity_scale)
        return X

    def _standardise(self, X: np.ndarray) -> np.ndarray:
        return (self._warp(X) - self.input_shift_) / self.input_scale_

    # -- fitting -------------------------------------------------------------------------
    def fit(self, X, y) -> RBFNetRegressor:
        """Train the network on inputs ``X (n, d)`` and targets ``y (n,)``.

        Raises
        ------
        ConfigError
            A parameter is invalid, or ``n_centers`` exceeds the number of samples.
        DataError
            An input column has zero variance (it cannot be standardised).
        ValueError
            ``X`` or ``y`` is empty, has NaN or infinity, or has the wrong shape (sklearn's
            ``validate_data``).
        """
        trainer = self._check_params()
        X, y = validate_data(self, X, y, y_numeric=True, ensure_min_samples=2, dtype=np.float64)
        n, d = X.shape
        m = int(self.n_centers)
        if m > n:
            raise ConfigError(
                f"n_centers={m} exceeds the number of training samples ({n}); an RBF network "
                "needs at most one centre per sample"
            )
        Xw = self._warp(X)
        shift = Xw.mean(axis=0)
        scale = Xw.std(axis=0)
        flat = np.flatnonzero(~(scale > 1e-12 * np.maximum(1.0, np.abs(shift))))
        if flat.size:
            j = int(flat[0])
            name = str(self.feature_names_in_[j]) if hasattr(self, "feature_names_in_") else f"{j}"
            raise DataError(
                f"the input has zero variance (every value {X[0, j]!r}): it carries no "
                "information and cannot be standardised; drop the column",
                column=name,
            )
        self.input_shift_, self.input_scale_ = shift, scale
        Z = (Xw - shift) / scale

        # the target on [-1, 1] (mapminmax), or scaled only when there is no bias to absorb
        # the shift
        if self.fit_bias:
            mid = 0.5 * (float(y.max()) + float(y.min()))
            half = 0.5 * (float(y.max()) - float(y.min()))
        else:
            mid, half = 0.0, float(np.max(np.abs(y)))
        if not half > 0:
            half = 1.0
        t = (y - mid) / half
        self.target_scale_ = half

        # None: fresh OS entropy, never numpy's global RandomState (DESIGN.md, "Randomness")
        rs = (
            np.random.RandomState()
            if self.random_state is None
            else check_random_state(self.random_state)
        )
        kmeans_seed = int(rs.randint(np.iinfo(np.int32).max))
        search_seed = int(rs.randint(np.iinfo(np.int32).max))
        spread = math.sqrt(d)
        n_kmeans = max(_KMEANS_MIN, _KMEANS_PER_CENTRE * m)
        Zk = Z if n <= n_kmeans else Z[rs.permutation(n)[:n_kmeans]]

        with warnings.catch_warnings():
            # duplicate points: fewer distinct clusters than centres; the width floor and
            # the ridge penalty cope, the user learns of it through the fit's accuracy
            warnings.simplefilter("ignore", SklearnConvergenceWarning)
            km = KMeans(n_clusters=m, n_init=1, random_state=kmeans_seed)
            C0 = km.fit(Zk).cluster_centers_
        s0 = core.nn_widths(C0, float(self.width_factor), spread)
        w0, b0 = core.lstsq_weights(
            core.design(Z, C0, s0), t, float(self.alpha), bool(self.fit_bias)
        )
        mse0 = mse_z(Z, t, C0, s0, w0, b0)

        self.n_epochs_ = 0
        self.n_evals_ = 0
        self.mse_history_ = np.empty(0)
        self.initial_mse_ = mse0
        if trainer == "lsq":
            C, s, w, b, mse = C0, s0, w0, b0, mse0
            self.epochs_to_target_ = (
                0 if self.target_mse is not None and mse0 <= self.target_mse else None
            )
        else:
            C, s, w, b, mse = search_network(
                self, trainer, Z, t, (C0, s0, w0, b0, mse0), search_seed
            )

        self.centers_ = C
        self.widths_ = s
        self.weights_ = w * half
        self.bias_ = float(b * half + mid)
        self.train_mse_ = float(mse)
        return self

    # -- prediction ----------------------------------------------------------------------
    def predict(self, X) -> np.ndarray:
        """Network output (eq. 14-15) at inputs ``X (n, n_features_in_)``."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return predict_z(
            self._standardise(X), self.centers_, self.widths_, self.weights_, self.bias_
        )


# -- the model file ----------------------------------------------------------------------


def _state(est: RBFNetRegressor, inputs: Sequence[str]) -> dict[str, Any]:
    return {
        "kind": STATE_KIND,
        "inputs": list(inputs),
        "velocity_scale": None if est.velocity_scale is None else float(est.velocity_scale),
        "input_shift": est.input_shift_.tolist(),
        "input_scale": est.input_scale_.tolist(),
        "centers": est.centers_.tolist(),
        "widths": est.widths_.tolist(),
        "weights": est.weights_.tolist(),
        "bias": float(est.bias_),
        "fit_bias": bool(est.fit_bias),
        "trainer": str(est.trainer).lower(),
        "encoding": None if str(est.trainer).lower() == "lsq" else est.encoding,
        "n_epochs": int(est.n_epochs_),
        "epochs_to_target": est.epochs_to_target_,
        "target_mse": est.target_mse,
        "train_mse_scaled": float(est.train_mse_),
        "target_scale": float(est.target_scale_),
        "mse_history": est.mse_history_.tolist(),
    }


def _n_numbers(est: RBFNetRegressor) -> int:
    """Fitted numbers of a network (centres, widths, weights, bias): its ``nvarys``."""
    return int(est.centers_.size + est.widths_.size + est.weights_.size + bool(est.fit_bias))


def to_fitted_model(
    estimator: RBFNetRegressor, samples: FrictionSamples, inputs: Sequence[str] = INPUTS
) -> FittedModel:
    """A :class:`~fricid.fitted.FittedModel` (``model="rbf"``) of an estimator fitted on
    ``samples.X[:, inputs]``, with metrics on ``samples`` and provenance as ``identify.fit``
    records them; ``state`` holds the network as plain lists (see :func:`predict_state`).

    ``history`` is the per-epoch best SSE [N m^2] against evaluations, for optimiser trainers.
    """
    names = check_inputs(inputs)
    check_is_fitted(estimator)
    if estimator.n_features_in_ != len(names):
        raise ConfigError(
            f"the estimator was fitted on {estimator.n_features_in_} input "
            f"columns, but inputs names {len(names)}: {', '.join(names)}"
        )
    if estimator.velocity_scale is not None and names[0] != "velocity":
        raise ConfigError("velocity_scale warps the first input, which must be 'velocity'")
    state = _state(estimator, names)
    X = samples.X
    y_hat = predict_state(state, X)
    trainer = state["trainer"]
    n = len(samples)
    history = None
    if estimator.mse_history_.size:
        per_epoch = int(estimator.evals_per_epoch)
        evals = per_epoch * np.arange(1, estimator.mse_history_.size + 1)
        sse = estimator.mse_history_ * estimator.target_scale_**2 * n
        history = np.column_stack([evals, sse]).tolist()
    rs = estimator.random_state
    return FittedModel(
        model="rbf",
        params={},
        metrics=metrics(samples.y, y_hat),
        statistics=fit_statistics(samples.y, y_hat, _n_numbers(estimator)),
        method=trainer if trainer == "lsq" else f"{trainer}/{estimator.encoding}",
        seed=int(rs) if isinstance(rs, Integral) else None,
        nfev=int(estimator.n_evals_),
        history=history,
        operating_range={
            name: [float(X[:, INPUTS.index(name)].min()), float(X[:, INPUTS.index(name)].max())]
            for name in INPUTS
        },
        provenance={
            "source": samples.source,
            "n_samples": n,
            "samples_sha256_16": samples_hash(samples),
            "directions": list(samples.directions()),
            "fricid_version": __version__,
            "created": datetime.now(UTC).isoformat(timespec="seconds"),
            "estimator": "fricid.identify.rbf.RBFNetRegressor",
            "estimator_params": {
                k: v
                for k, v in estimator.get_params().items()
                if k != "random_state" or isinstance(v, Integral | None)
            },
        },
        state=state,
    )


def fit_rbf(samples: FrictionSamples, inputs: Sequence[str] = INPUTS, **params: Any) -> FittedModel:
    """Train an :class:`RBFNetRegressor` (keyword ``params``) on ``samples`` and return it as
    a :class:`~fricid.fitted.FittedModel` (see :func:`to_fitted_model`).

    ``inputs`` selects the columns (any subset of velocity, load, temperature, in that
    order or another).
    """
    names = check_inputs(inputs)
    X = samples.X[:, [INPUTS.index(name) for name in names]]
    est = RBFNetRegressor(**params).fit(X, samples.y)
    return to_fitted_model(est, samples, names)
