"""The scikit-learn estimator of the RBF network, :class:`RBFNetRegressor` (BAS-RBFNN paper,
eq. 14-21): the ``lsq`` recipe here, the optimiser trainers in
:mod:`fricid.identify.learned._rbf_search`.
Public home and the reading of the paper: :mod:`fricid.identify.learned.rbf`.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
from sklearn import config_context
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.cluster import KMeans
from sklearn.exceptions import ConvergenceWarning as SklearnConvergenceWarning
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted, validate_data

from ...errors import ConfigError, DataError, IgnoredArgumentWarning, user_stacklevel
from ...models import _rbf_core as core
from ...models.rbf import mse_z, predict_z, tail_columns
from ...optim import METHODS
from ._rbf_params import check_params
from ._rbf_search import search_network

__all__ = ["LSQ_IGNORES", "TRAINERS", "RBFNetRegressor"]

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


def _kmeans_plusplus(Xc: np.ndarray, m: int, seed: int) -> np.ndarray:
    """Indices of scikit-learn's k-means++ seeds (Arthur and Vassilvitskii 2007, greedy with
    ``2 + ln m`` local trials) on the centred data ``Xc`` from ``RandomState(seed)``, drawn as
    scikit-learn draws them (the first seed by ``choice`` with equal weights, one uniform, then
    each seed's trials: one stream, :func:`_uniforms`) and computed by its operations in one
    compiled loop (:func:`fricid.identify.learned._kmeans_kernel.plusplus`), without its per-call
    input
    validation and per-centre numpy calls (which took most of the time of the small sets'
    cross-validation)."""
    from ._kmeans_kernel import plusplus

    n = Xc.shape[0]
    trials = 2 + int(np.log(m))
    u = _uniforms(seed, 1 + (m - 1) * trials)
    cdf = np.cumsum(np.full(n, 1.0 / n))  # RandomState.choice(n, p=...)'s, as it forms it
    cdf /= cdf[-1]
    first = int(cdf.searchsorted(u[0], side="right"))
    return plusplus(np.ascontiguousarray(Xc, dtype=float), first, u[1:].reshape(m - 1, trials))


#: Uniform streams of :func:`_uniforms`, by seed (a few, the longest drawn so far).
_STREAMS: dict[int, np.ndarray] = {}


def _uniforms(seed: int, k: int) -> np.ndarray:
    """The first ``k`` draws of ``RandomState(seed).random_sample()`` (what ``uniform`` and
    ``choice`` consume), memoised per seed: the cross-validated structure search places
    centres 20-40 times per network from the same seed, and each new ``RandomState`` costs
    about 0.1 ms, more than the seeding of a small set."""
    u = _STREAMS.get(seed)
    if u is None or u.size < k:
        if len(_STREAMS) >= 16:
            _STREAMS.clear()
        u = np.random.RandomState(seed).random_sample(max(k, 4096))
        u.flags.writeable = False
        _STREAMS[seed] = u
    return u[:k]


#: The random state handed to ``KMeans`` started from given seeds: its ``fit`` makes a
#: ``RandomState`` of whatever it is given (0.4 ms from an int), and Lloyd's iterations from
#: given seeds draw nothing from it, so one instance serves every call (a test checks that it
#: is never drawn from).
_LLOYD_RANDOM_STATE = np.random.RandomState(0)


def kmeans_centres(Z: np.ndarray, m: int, seed: int) -> np.ndarray:
    """The centres of ``KMeans(n_clusters=m, n_init=1, random_state=seed).fit(Z)``: its
    k-means++ seeds drawn from its random stream and computed on the data centred as
    ``KMeans.fit`` centres it (:func:`_kmeans_plusplus`, compiled: its sums round differently
    from scikit-learn's BLAS calls, so where two candidate seeds tie within rounding it may
    take the other one, on 1 of 30 random problems without duplicate points,
    ``tests/identify/learned/test_hybrid_speed.py``), then scikit-learn's own Lloyd iterations from
    them,
    through its public API (``KMeans(init=seeds, n_init=1, algorithm="lloyd")``, which
    centres, sets the tolerance and iterates as the default fit does; its input and parameter
    checks skipped by scikit-learn's public ``config_context``: the network's ``fit`` has
    checked the data); ``KMeans`` itself when ``m`` is not between 1 and the number of points
    (its error message).

    Duplicate points can leave fewer distinct clusters than centres: scikit-learn's
    convergence warning is silenced (the width floor and the ridge penalty cope, the user
    learns of it through the fit's accuracy).
    """
    X = np.array(Z, dtype=float, order="C", copy=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SklearnConvergenceWarning)
        if X.ndim != 2 or not 1 <= m <= X.shape[0]:
            return KMeans(n_clusters=m, n_init=1, random_state=seed).fit(X).cluster_centers_
        seeds = X[_kmeans_plusplus(X - X.mean(axis=0), m, seed)]
        lloyd = KMeans(m, init=seeds, n_init=1, algorithm="lloyd", random_state=_LLOYD_RANDOM_STATE)
        with config_context(assume_finite=True, skip_parameter_validation=True):
            return lloyd.fit(X).cluster_centers_


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
    linear_tail : bool, default False
        Add a linear term on the raw (unwarped) inputs and the first input (the velocity)
        times each other one: ``y = Phi w + T(X) a + b`` with ``T(X) = [x_1 .. x_d, x_1 x_2
        .. x_1 x_d]`` (:func:`fricid.models.rbf.tail_columns`). Far from the centres the
        Gaussians vanish and the network returns to ``T(X) a + b`` (for ``|v|``: Coulomb plus
        viscous friction, both linear in load and temperature) instead of the bias alone.
        ``lsq`` solves weights and ``a`` together by ridge least squares (the columns
        standardised, so the penalty treats them alike; the bias is then always fitted); an
        optimiser trainer fits ``T(X) a + b`` first and searches the network on its residual.
    tail_order : {1, 2}, default 1
        2 adds the velocity times each other input squared to the linear tail
        (:func:`fricid.models.rbf.tail_terms`).
    linear_magnitude : tuple of int, default ()
        Columns the linear tail takes as absolute values (``fit_rbf``: the load,
        :func:`fricid.models.rbf.magnitude_columns`).
    velocity_stretch : float, default 1.0
        Multiplies the first standardised input (the velocity): above 1 the Gaussians are
        narrower in velocity than in load and temperature (anisotropic units, as an ARD
        kernel's length scales), where friction changes fastest (the Stribeck region). Stored
        in ``input_scale_`` (divided by it), so prediction needs nothing new.
    velocity_scale : float or None, default None
        If given [rad/s], the first input column (fricid's velocity) is replaced by
        ``asinh(v / velocity_scale)`` before standardisation: logarithmic for
        ``|v| >> velocity_scale``, linear and odd through zero. It spreads the Stribeck region
        (the paper samples low velocities densely for the same reason, section 2.2) so fewer
        Gaussians fit it. None: plain standardisation, as the paper.
    target_mse : float or None, default 1e-4
        Stop an optimiser trainer once the training MSE of the target mapped onto [-1, 1]
        reaches this value (the paper's 0.0001; see :mod:`fricid.identify.learned.rbf`). None: use
        the whole
        budget.
    max_epochs : int, default 500
        Budget of an optimiser trainer, in epochs.
    evals_per_epoch : int, default 30
        Candidate evaluations per epoch (a GA generation; see :mod:`fricid.identify.learned.rbf`).
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
        Output bias, units of y (0 when ``fit_bias=False`` and no linear tail).
    linear_ : ndarray (2 n_features_in_ - 1,) or (0,)
        Coefficients ``a`` of the linear tail's columns
        (:func:`fricid.models.rbf.tail_columns`), units of y per unit of the column (empty
        without ``linear_tail``).
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
    status_, message_ : int or None, str
        The optimiser's ``status`` and ``message`` (``fricid.optim.OptimizeResult``; 2,
        "stopped by the callback", when the target MSE was reached); None and "" for ``lsq``
        or a start that already met the target.
    epochs_to_target_ : int or None
        First epoch whose best MSE reached ``target_mse`` (0 if the start already did);
        None if it was not reached or there was no target.
    n_features_in_ : int
    feature_names_in_ : ndarray of str (only when X had string column names)

    Examples
    --------
    >>> from fricid.identify.learned.rbf import RBFNetRegressor
    >>> net = RBFNetRegressor(n_centers=40, random_state=0)
    >>> net.fit(samples.X, samples.y).predict(samples.X)  # doctest: +SKIP
    >>> cross_val_score(RBFNetRegressor(), samples.X, samples.y, cv=5)  # doctest: +SKIP
    """

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
        linear_tail: bool = False,
        linear_magnitude: tuple[int, ...] = (),
        tail_order: int = 1,
        velocity_stretch: float = 1.0,
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
        self.linear_tail = linear_tail
        self.linear_magnitude = linear_magnitude
        self.tail_order = tail_order
        self.velocity_stretch = velocity_stretch
        self.velocity_scale = velocity_scale
        self.target_mse = target_mse
        self.max_epochs = max_epochs
        self.evals_per_epoch = evals_per_epoch
        self.method_options = method_options
        self.random_state = random_state

    # -- validation ----------------------------------------------------------------------
    def _check_params(self) -> str:
        """Validate the parameters (:func:`._rbf_params.check_params`, scikit-learn's wording,
        raised as :class:`ConfigError`); return the trainer's name, lower-cased."""
        check_params(self)
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
                    stacklevel=user_stacklevel(),
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
                f"{m} centres (n_centers; --centers on the command line) exceed the "
                f"number of training samples ({n}); an RBF network needs at most one centre "
                "per sample"
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
        scale = scale.copy()
        scale[0] /= float(self.velocity_stretch)
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

        C0 = kmeans_centres(Zk, m, kmeans_seed)
        s0 = core.nn_widths(C0, float(self.width_factor), spread)
        L, lin_shift, lin_scale = (
            _linear_columns(X, tuple(self.linear_magnitude), int(self.tail_order))
            if self.linear_tail
            else (None, None, None)
        )
        a = np.zeros(L.shape[1] if L is not None else 0)
        if L is not None and trainer == "lsq":
            wa, b0 = core.lstsq_weights(
                np.hstack([core.design(Z, C0, s0), L]), t, float(self.alpha), True
            )
            w0, a = wa[:m], wa[m:]
        else:
            if L is not None:  # optimiser trainers: the linear tail first, the network after
                a, b_lin = core.lstsq_weights(L, t, 0.0, True)
                t = t - (L @ a + b_lin)
            w0, b0 = core.lstsq_weights(
                core.design(Z, C0, s0), t, float(self.alpha), bool(self.fit_bias)
            )
            if L is not None:
                b0 += b_lin
                t = t + (L @ a + b_lin)
        t_net = t - L @ a if L is not None else t
        mse0 = mse_z(Z, t_net, C0, s0, w0, b0)

        self.n_epochs_ = 0
        self.n_evals_ = 0
        self.status_, self.message_ = None, ""
        self.mse_history_ = np.empty(0)
        self.initial_mse_ = mse0
        if trainer == "lsq":
            C, s, w, b, mse = C0, s0, w0, b0, mse0
            self.epochs_to_target_ = (
                0 if self.target_mse is not None and mse0 <= self.target_mse else None
            )
        else:
            C, s, w, b, mse = search_network(
                self, trainer, Z, t_net, (C0, s0, w0, b0, mse0), search_seed
            )

        self.centers_ = C
        self.widths_ = s
        self.weights_ = w * half
        self.bias_ = float(b * half + mid)
        self.linear_ = np.zeros(L.shape[1] if L is not None else 0)
        if L is not None:
            # y = half (Phi w + b + ((x - shift) / scale) a) + mid: raw-input coefficients
            self.linear_ = a * half / lin_scale
            self.bias_ -= float(self.linear_ @ lin_shift)
        self.train_mse_ = float(mse)
        return self

    # -- prediction ----------------------------------------------------------------------
    def predict(self, X) -> np.ndarray:
        """Network output (eq. 14-15) at inputs ``X (n, n_features_in_)``."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        out = predict_z(
            self._standardise(X), self.centers_, self.widths_, self.weights_, self.bias_
        )
        if not np.any(self.linear_):
            return out
        return out + tail_columns(X, self.linear_magnitude, int(self.tail_order)) @ self.linear_


def _linear_columns(
    X: np.ndarray, magnitude: tuple[int, ...] = (), order: int = 1
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The linear tail's columns (:func:`fricid.models.rbf.tail_columns`) standardised, their
    shift and scale."""
    X = tail_columns(X, magnitude, order)
    shift = X.mean(axis=0)
    scale = X.std(axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    return (X - shift) / scale, shift, scale
