"""The RBF neural network friction model of the BAS-RBFNN paper (section 3), as a scikit-learn
regressor, and its home in fricid's JSON model file.

:class:`RBFNetRegressor` is a three-layer network: Gaussian hidden units (eq. 14) and a linear
output (eq. 15) with an optional bias, on inputs that are standardised inside the estimator.
It is trained by one of

* ``trainer="lsq"``: k-means centres, the p-nearest-neighbour width rule and output weights by
  (ridge) linear least squares; the standard fast recipe and the paper's "RBFNN" (Table 3);
* ``trainer="bas"`` (BAS-RBFNN, eq. 18-21), ``"ga"`` (GA-RBFNN, Table 4, Fig. 9) or any other
  method of :data:`fricid.optim.METHODS`: the network's parameters are searched by
  :func:`fricid.optim.minimize`, minimising the training mean squared error (eq. 16-17), until
  a target MSE or the epoch budget. Two encodings of the search vector:

  - ``"full"``: centres, widths *and* output weights (and bias) are all searched, as the
    paper's section 3.3 describes ("BAS is used to optimize the network parameters");
  - ``"hybrid"``: centres and widths are searched; for every candidate the output weights are
    the ridge least-squares solution, computed for the whole candidate batch at once.

:func:`predict_state` evaluates a network stored in a :class:`~fricid.fitted.FittedModel`'s
``state`` (plain lists, JSON-ready); :func:`to_fitted_model` builds that model from a fitted
estimator, and :func:`fit_rbf` does both from :class:`~fricid.samples.FrictionSamples`.

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

import logging
import math
import warnings
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from numbers import Integral, Real
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.cluster import KMeans
from sklearn.exceptions import ConvergenceWarning
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval, InvalidParameterError, StrOptions
from sklearn.utils.validation import check_is_fitted, validate_data

from ..errors import ConfigError, DataError
from . import _rbf_core as core
from ._base import INPUTS

if TYPE_CHECKING:
    from ..fitted import FittedModel
    from ..samples import FrictionSamples

__all__ = [
    "STATE_KIND",
    "TRAINERS",
    "RBFNetRegressor",
    "fit_rbf",
    "predict_state",
    "to_fitted_model",
]

logger = logging.getLogger(__name__)

#: The trainers of the paper: ``lsq`` (RBFNN), ``bas`` (BAS-RBFNN), ``ga`` (GA-RBFNN); every
#: other method of :data:`fricid.optim.METHODS` is accepted too.
TRAINERS = ("lsq", "bas", "ga")

#: ``state["kind"]`` of an RBF network in a model file.
STATE_KIND = "gaussian_rbf"

#: k-means places the centres using at most ``max(_KMEANS_MIN, _KMEANS_PER_CENTRE * m)``
#: samples (a random subset of larger sets): centres need a representative sample, not all.
_KMEANS_MIN = 2000
_KMEANS_PER_CENTRE = 25

#: Ridge penalty floor used when scoring hybrid candidates by the normal equations.
_SEARCH_ALPHA_FLOOR = 1e-12


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
        output weights solved by ridge least squares for each candidate. Ignored by ``lsq``.
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
    >>> from fricid.models import RBFNetRegressor
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
        if trainer != "lsq":
            from ..optim import METHODS

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
            warnings.simplefilter("ignore", ConvergenceWarning)
            km = KMeans(n_clusters=m, n_init=1, random_state=kmeans_seed)
            C0 = km.fit(Zk).cluster_centers_
        s0 = core.nn_widths(C0, float(self.width_factor), spread)
        w0, b0 = core.lstsq_weights(
            core.design(Z, C0, s0), t, float(self.alpha), bool(self.fit_bias)
        )
        mse0 = _mse(Z, t, C0, s0, w0, b0)

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
            C, s, w, b, mse = self._search(trainer, Z, t, (C0, s0, w0, b0, mse0), search_seed)

        self.centers_ = C
        self.widths_ = s
        self.weights_ = w * half
        self.bias_ = float(b * half + mid)
        self.train_mse_ = float(mse)
        return self

    def _search(
        self,
        method: str,
        Z: np.ndarray,
        t: np.ndarray,
        start: tuple[np.ndarray, np.ndarray, np.ndarray, float, float],
        seed: int,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
        """Search the network's parameters with ``fricid.optim.minimize`` (eq. 18-21 for BAS)."""
        from ..optim import minimize

        C0, s0, w0, b0, mse0 = start
        n, d = Z.shape
        m = C0.shape[0]
        full = self.encoding == "full"
        fit_bias = bool(self.fit_bias)
        alpha = float(self.alpha)
        alpha_search = max(alpha, _SEARCH_ALPHA_FLOOR)
        target = self.target_mse
        per_epoch = int(self.evals_per_epoch)
        init = self.init == "kmeans"
        if not init:
            self.initial_mse_ = float("nan")

        lo, hi = Z.min(axis=0), Z.max(axis=0)
        span = hi - lo
        diag = float(np.sqrt(np.sum(span**2)))
        bounds = [(lo[j] - 0.1 * span[j], hi[j] + 0.1 * span[j]) for j in range(d)] * m
        bounds += [(math.log(0.01 * diag), math.log(diag))] * m
        n_cw = m * d + m
        w_max = max(4.0, 2.0 * float(np.max(np.abs(w0)))) if init else 4.0
        if full:
            bounds += [(-w_max, w_max)] * (m + int(fit_bias))
        b_arr = np.asarray(bounds, dtype=float)

        def unpack(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            C = theta[:, : m * d].reshape(-1, m, d)
            s = np.exp(theta[:, m * d : n_cw])
            return C, s

        scorer = None if full else core.RidgeScorer(Z, t, alpha_search, fit_bias)

        def objective(theta: np.ndarray) -> np.ndarray:
            """Training MSE of each candidate network (eq. 16-17 up to a factor 2 / n)."""
            theta = np.atleast_2d(theta)
            if scorer is not None:  # hybrid: ridge least-squares weights per candidate
                return scorer(*unpack(theta))
            out = np.empty(theta.shape[0])
            for sl in core.chunks(theta.shape[0], n, m):
                C, s = unpack(theta[sl])
                Phi = core.design(Z, C, s)
                w = theta[sl, n_cw : n_cw + m]
                b = theta[sl, n_cw + m] if fit_bias else np.zeros(len(w))
                r = core.output(Phi, w, b) - t
                out[sl] = np.einsum("kn,kn->k", r, r) / n
            return out

        x0 = None
        if init:
            if target is not None and mse0 <= target:
                self.epochs_to_target_ = 0
                return C0, s0, w0, b0, mse0
            parts = [C0.ravel(), np.log(s0)]
            if full:
                parts += [w0, [b0]] if fit_bias else [w0]
            x0 = np.clip(np.concatenate(parts), b_arr[:, 0], b_arr[:, 1])

        def stop(res: Mapping[str, Any]) -> bool:
            return target is not None and float(res["fun"]) <= target

        max_evals = int(self.max_epochs) * per_epoch
        options = _method_options(method, self.method_options, max_evals, per_epoch)
        logger.debug(
            "RBF search: %s/%s, %d parameters, %d evaluations",
            method,
            self.encoding,
            b_arr.shape[0],
            max_evals,
        )
        # The search scores many small networks, one BLAS product each: threading them costs
        # more than it gains (measured: 0.26 s single-threaded against 0.49 s on 2 cores), so
        # BLAS runs on one thread during the search, whatever the process uses elsewhere.
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            res = minimize(
                objective,
                b_arr,
                method=method,
                seed=seed,
                max_evals=max_evals,
                options=options,
                callback=stop,
                x0=x0,
            )
        if not res.success or not np.all(np.isfinite(res.x)):
            raise ConfigError(f"training the RBF network with '{method}' failed: {res.message}")
        nfev = int(res.nfev)
        n_epochs = max(1, math.ceil(nfev / per_epoch))
        hist = np.asarray(res.history, dtype=float).reshape(-1, 2)
        marks = per_epoch * np.arange(1, n_epochs + 1)
        idx = np.searchsorted(hist[:, 0], marks, side="right") - 1
        best = np.where(idx >= 0, hist[np.maximum(idx, 0), 1], np.inf)
        if init:
            best = np.minimum(best, mse0)
        history = np.minimum.accumulate(best)
        history[~np.isfinite(history)] = np.nan  # no complete batch yet (a GA's first population)
        self.mse_history_ = history
        self.n_epochs_ = n_epochs
        self.n_evals_ = nfev
        reached = np.flatnonzero(history <= target) if target is not None else np.empty(0)
        self.epochs_to_target_ = int(reached[0]) + 1 if reached.size else None

        theta = np.asarray(res.x, dtype=float)[None, :]
        C, s = unpack(theta)
        C, s = C[0], s[0]
        if full:
            w = theta[0, n_cw : n_cw + m].copy()
            b = float(theta[0, n_cw + m]) if fit_bias else 0.0
        else:
            w, b = core.lstsq_weights(core.design(Z, C, s), t, alpha, fit_bias)
        mse = _mse(Z, t, C, s, w, b)
        if init and mse0 < mse:  # the search never beat its start
            return C0, s0, w0, b0, mse0
        return C, s, w, b, mse

    # -- prediction ----------------------------------------------------------------------
    def predict(self, X) -> np.ndarray:
        """Network output (eq. 14-15) at inputs ``X (n, n_features_in_)``."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return _predict_z(
            self._standardise(X), self.centers_, self.widths_, self.weights_, self.bias_
        )


def _method_options(
    method: str, given: Mapping[str, Any] | None, max_evals: int, per_epoch: int
) -> dict[str, Any]:
    """The optimiser's options: the user's, plus defaults that tie the method to epochs.

    A method with an ``n_iter`` option (the beetle family) gets enough iterations for the
    whole budget (the budget, not ``n_iter``, ends the run); the GA gets
    ``pop_size = evals_per_epoch + n_elite``, so one generation is one epoch.
    """
    from ..optim import METHODS

    opts = dict(given or {})
    known = METHODS[method].options
    if "n_iter" in known and "n_iter" not in opts:
        opts["n_iter"] = max_evals
    if method == "ga" and "pop_size" not in opts:
        opts["pop_size"] = per_epoch + int(opts.get("n_elite", known.get("n_elite", 0)))
    return opts


def _mse(
    Z: np.ndarray, t: np.ndarray, C: np.ndarray, s: np.ndarray, w: np.ndarray, b: float
) -> float:
    r = _predict_z(Z, C, s, w, b) - t
    return float(r @ r) / r.size


def _predict_z(Z: np.ndarray, C: np.ndarray, s: np.ndarray, w: np.ndarray, b: float) -> np.ndarray:
    """Output for standardised inputs, in row blocks so the design matrix stays small."""
    n, m = Z.shape[0], C.shape[0]
    rows = max(1, core.CHUNK_ELEMENTS // max(1, m))
    if n <= rows:
        return core.output(core.design(Z, C, s), w, b)
    return np.concatenate(
        [core.output(core.design(Z[i : i + rows], C, s), w, b) for i in range(0, n, rows)]
    )


# -- the model file ------------------------------------------------------------------------


def _state_array(state: Mapping[str, Any], key: str, shape: tuple[int | None, ...]) -> np.ndarray:
    if key not in state:
        raise DataError(f"RBF model state lacks '{key}'", column=f"state.{key}")
    try:
        arr = np.asarray(state[key], dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"RBF model state '{key}' is not numeric", column=f"state.{key}") from None
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        raise DataError(
            f"RBF model state '{key}' has shape {arr.shape}, expected "
            f"{tuple('*' if s is None else s for s in shape)}",
            column=f"state.{key}",
        )
    if not np.isfinite(arr).all():
        raise DataError(f"RBF model state '{key}' has non-finite values", column=f"state.{key}")
    return arr


def predict_state(state: Mapping[str, Any] | None, X) -> np.ndarray:
    """Friction [N m] of a stored RBF network at ``X (n, 3)``: velocity [rad/s], load [N m],
    temperature [degC] (``FrictionSamples.X``); eq. 14-15.

    ``state`` is ``FittedModel.state`` as :func:`to_fitted_model` writes it. A malformed state
    or ``X`` without three columns raises :class:`DataError`.
    """
    if not isinstance(state, Mapping):
        raise DataError("an RBF model needs its network in 'state' (an object)")
    if state.get("kind", STATE_KIND) != STATE_KIND:
        raise DataError(
            f"unknown RBF state kind {state.get('kind')!r}; expected '{STATE_KIND}'",
            column="state.kind",
        )
    inputs = state.get("inputs")
    if (
        not isinstance(inputs, Sequence)
        or isinstance(inputs, str)
        or not inputs
        or any(name not in INPUTS for name in inputs)
        or len(set(inputs)) != len(inputs)
    ):
        raise DataError(
            f"RBF model state 'inputs' must be distinct names among "
            f"{', '.join(INPUTS)}; got {inputs!r}",
            column="state.inputs",
        )
    d = len(inputs)
    shift = _state_array(state, "input_shift", (d,))
    scale = _state_array(state, "input_scale", (d,))
    centers = _state_array(state, "centers", (None, d))
    m = centers.shape[0]
    widths = _state_array(state, "widths", (m,))
    weights = _state_array(state, "weights", (m,))
    bias = float(_state_array(state, "bias", ()))
    if (scale <= 0).any() or (widths <= 0).any():
        raise DataError("RBF model state has non-positive input scales or widths", column="state")
    vscale = state.get("velocity_scale")
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != len(INPUTS):
        raise DataError(
            f"inputs must have shape (n, 3): velocity, load, temperature; got {X.shape}"
        )
    Xs = X[:, [INPUTS.index(name) for name in inputs]]
    if vscale is not None:
        if inputs[0] != "velocity" or not float(vscale) > 0:
            raise DataError(
                "RBF model state 'velocity_scale' needs velocity as the first "
                "input and a positive value",
                column="state.velocity_scale",
            )
        Xs = Xs.copy()
        Xs[:, 0] = np.arcsinh(Xs[:, 0] / float(vscale))
    return _predict_z((Xs - shift) / scale, centers, widths, weights, bias)


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


def _check_inputs(inputs: Sequence[str]) -> list[str]:
    names = [str(name).strip().lower() for name in inputs]
    if not names or any(n not in INPUTS for n in names) or len(set(names)) != len(names):
        raise ConfigError(
            f"inputs must be distinct names among {', '.join(INPUTS)}; got {list(inputs)!r}"
        )
    return names


def to_fitted_model(
    estimator: RBFNetRegressor, samples: FrictionSamples, inputs: Sequence[str] = INPUTS
) -> FittedModel:
    """A :class:`~fricid.fitted.FittedModel` (``model="rbf"``) of an estimator fitted on
    ``samples.X[:, inputs]``, with metrics on ``samples`` and provenance as ``identify.fit``
    records them; ``state`` holds the network as plain lists (see :func:`predict_state`).

    ``history`` is the per-epoch best SSE [N m^2] against evaluations, for optimiser trainers.
    """
    from .. import __version__
    from ..fitted import FittedModel
    from ..metrics import metrics
    from ..samples import samples_hash

    names = _check_inputs(inputs)
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
            "estimator": "fricid.models.RBFNetRegressor",
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
    names = _check_inputs(inputs)
    X = samples.X[:, [INPUTS.index(name) for name in names]]
    est = RBFNetRegressor(**params).fit(X, samples.y)
    return to_fitted_model(est, samples, names)
