"""The optimiser-driven trainers of the RBF network (BAS-RBFNN, GA-RBFNN; the BAS-RBFNN paper,
section 3.3, eq. 16-21): the network's parameters searched with :func:`fricid.optim.minimize`
on an :class:`~fricid.identify.problem.IdentificationProblem`.

Two encodings of the search vector ``theta`` (one candidate network):

* ``"full"``: centres ``(m, d)``, log-widths ``(m,)``, output weights ``(m,)`` and the bias;
  the network's output is a plain prediction (:class:`FullNetwork`);
* ``"hybrid"``: centres and log-widths; the output weights (and bias) of each candidate are
  its ridge least-squares solution on the training target (:class:`HybridNetwork`, a
  variable-projection model whose ``fused_mse`` is :class:`~fricid.models._rbf_core.RidgeScorer`).

Used by :class:`fricid.identify.learned.rbf.RBFNetRegressor`; see that module for the reading of the
paper (target MSE, epochs, encodings).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import ConfigError
from ...models import _rbf_core as core
from ...models.rbf import mse_z
from ...optim import METHODS, minimize
from ..problem import IdentificationProblem

__all__ = ["FullNetwork", "HybridNetwork", "method_options", "search_network"]

logger = logging.getLogger(__name__)

#: Ridge penalty floor used when scoring hybrid candidates by the normal equations.
SEARCH_ALPHA_FLOOR = 1e-12

#: ``(C (m, d), sigma (m,), w (m,), b, mse)`` of one network, on the scaled target.
Network = tuple[np.ndarray, np.ndarray, np.ndarray, float, float]


class _Encoding:
    """Centres and log-widths at the front of a search vector of ``m`` units in ``d`` inputs."""

    def __init__(self, m: int, d: int) -> None:
        self.m, self.d = m, d
        self.n_cw = m * d + m

    def unpack(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Centres ``(k, m, d)`` and widths ``(k, m)`` of candidates ``theta (k, p)``."""
        m, d = self.m, self.d
        C = theta[:, : m * d].reshape(-1, m, d)
        s = np.exp(theta[:, m * d : self.n_cw])
        return C, s


class FullNetwork(_Encoding):
    """``"full"`` encoding: ``theta = [C, log sigma, w, b]``; ``predict(theta (k, p), Z)`` is
    each candidate network's output ``(k, n)`` (eq. 14-15), in chunks of candidates."""

    def __init__(self, m: int, d: int, fit_bias: bool) -> None:
        super().__init__(m, d)
        self.fit_bias = bool(fit_bias)

    def predict(self, theta: np.ndarray, Z: np.ndarray) -> np.ndarray:
        theta = np.atleast_2d(theta)
        m, n_cw = self.m, self.n_cw
        out = np.empty((theta.shape[0], Z.shape[0]))
        for sl in core.chunks(theta.shape[0], Z.shape[0], m):
            C, s = self.unpack(theta[sl])
            w = theta[sl, n_cw : n_cw + m]
            b = theta[sl, n_cw + m] if self.fit_bias else np.zeros(len(w))
            out[sl] = core.output(core.design(Z, C, s), w, b)
        return out


class HybridNetwork(_Encoding):
    """``"hybrid"`` encoding: ``theta = [C, log sigma]``; the output layer of each candidate is
    the ridge least-squares fit (penalty ``alpha``) to the training target ``t``.

    ``predict(theta, Z)`` is the network's output with those weights (design, batched ridge,
    output); ``fused_mse(theta, Z, t)`` the same network's mean squared error without the
    output (:class:`~fricid.models._rbf_core.RidgeScorer`: the inner loop of BAS-RBFNN).
    """

    def __init__(self, m: int, d: int, Z: np.ndarray, t: np.ndarray, alpha: float, bias: bool):
        super().__init__(m, d)
        self.t, self.alpha, self.fit_bias = t, float(alpha), bool(bias)
        self.scorer = core.RidgeScorer(Z, t, self.alpha, self.fit_bias)

    def predict(self, theta: np.ndarray, Z: np.ndarray) -> np.ndarray:
        C, s = self.unpack(np.atleast_2d(theta))
        Phi = core.design(Z, C, s)
        w, b = core.ridge_weights_batch(Phi, self.t, self.alpha, self.fit_bias)
        return core.output(Phi, w, b)

    def fused_mse(self, theta: np.ndarray, Z: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self.scorer(*self.unpack(np.atleast_2d(theta)))


def method_options(
    method: str, given: Mapping[str, Any] | None, max_evals: int, per_epoch: int
) -> dict[str, Any]:
    """The optimiser's options: the user's, plus defaults that tie the method to epochs.

    A method with an ``n_iter`` option (the beetle family) gets enough iterations for the
    whole budget (the budget, not ``n_iter``, ends the run); the GA gets
    ``pop_size = evals_per_epoch + n_elite``, so one generation is one epoch.
    """
    opts = dict(given or {})
    known = METHODS[method].options
    if "n_iter" in known and "n_iter" not in opts:
        opts["n_iter"] = max_evals
    if method == "ga" and "pop_size" not in opts:
        opts["pop_size"] = per_epoch + int(opts.get("n_elite", known.get("n_elite", 0)))
    return opts


def _bounds(Z: np.ndarray, m: int, full: bool, w_max: float, fit_bias: bool) -> np.ndarray:
    """The search box: centres within the data's box widened by 10 %, log-widths from 1 % to
    100 % of its diagonal, output weights (full encoding) within ``+- w_max``."""
    d = Z.shape[1]
    lo, hi = Z.min(axis=0), Z.max(axis=0)
    span = hi - lo
    diag = float(np.sqrt(np.sum(span**2)))
    bounds = [(lo[j] - 0.1 * span[j], hi[j] + 0.1 * span[j]) for j in range(d)] * m
    bounds += [(math.log(0.01 * diag), math.log(diag))] * m
    if full:
        bounds += [(-w_max, w_max)] * (m + int(fit_bias))
    return np.asarray(bounds, dtype=float)


def search_network(est: Any, method: str, Z: np.ndarray, t: np.ndarray, start: Network, seed: int):
    """Search the network's parameters with ``fricid.optim.minimize`` (eq. 18-21 for BAS).

    ``est`` is the :class:`~fricid.identify.learned.rbf.RBFNetRegressor` being fitted: its
    parameters
    are read, and its training record (``mse_history_``, ``n_epochs_``, ``n_evals_``,
    ``epochs_to_target_``, ``initial_mse_``) written. Returns the best network on the scaled
    target, never worse than ``start`` when the search started from it.
    """
    C0, s0, w0, b0, mse0 = start
    d = Z.shape[1]
    m = C0.shape[0]
    full = est.encoding == "full"
    fit_bias = bool(est.fit_bias)
    alpha = float(est.alpha)
    target = est.target_mse
    per_epoch = int(est.evals_per_epoch)
    init = est.init == "kmeans"
    if not init:
        est.initial_mse_ = float("nan")

    w_max = max(4.0, 2.0 * float(np.max(np.abs(w0)))) if init else 4.0
    b_arr = _bounds(Z, m, full, w_max, fit_bias)
    if full:
        model: FullNetwork | HybridNetwork = FullNetwork(m, d, fit_bias)
    else:
        model = HybridNetwork(m, d, Z, t, max(alpha, SEARCH_ALPHA_FLOOR), fit_bias)
    problem = IdentificationProblem(model, (Z, t), loss="mse", bounds=b_arr)

    x0 = None
    if init:
        if target is not None and mse0 <= target:
            est.epochs_to_target_ = 0
            return start
        parts = [C0.ravel(), np.log(s0)]
        if full:
            parts += [w0, [b0]] if fit_bias else [w0]
        x0 = np.clip(np.concatenate(parts), b_arr[:, 0], b_arr[:, 1])

    def stop(res: Mapping[str, Any]) -> bool:
        return target is not None and float(res["fun"]) <= target

    max_evals = int(est.max_epochs) * per_epoch
    options = method_options(method, est.method_options, max_evals, per_epoch)
    logger.debug(
        "RBF search: %s/%s, %d parameters, %d evaluations",
        method,
        est.encoding,
        b_arr.shape[0],
        max_evals,
    )
    # The search scores many small networks, one BLAS product each: threading them costs
    # more than it gains (measured: 0.26 s single-threaded against 0.49 s on 2 cores), so
    # BLAS runs on one thread during the search, whatever the process uses elsewhere.
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        res = minimize(
            problem.evaluate,
            b_arr,
            method=method,
            seed=seed,
            max_evals=max_evals,
            options=options,
            callback=stop,
            x0=x0,
        )
    # the run ends by the target (the callback), the budget or the method's own end; any of
    # them leaves a usable network, unless no candidate had a finite error
    if not np.all(np.isfinite(res.x)):
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
    est.mse_history_ = history
    est.n_epochs_ = n_epochs
    est.n_evals_ = nfev
    est.status_, est.message_ = int(res.status), str(res.message)
    reached = np.flatnonzero(history <= target) if target is not None else np.empty(0)
    est.epochs_to_target_ = int(reached[0]) + 1 if reached.size else None

    theta = np.asarray(res.x, dtype=float)[None, :]
    C, s = model.unpack(theta)
    C, s = C[0], s[0]
    if full:
        w = theta[0, model.n_cw : model.n_cw + m].copy()
        b = float(theta[0, model.n_cw + m]) if fit_bias else 0.0
    else:
        w, b = core.lstsq_weights(core.design(Z, C, s), t, alpha, fit_bias)
    mse = mse_z(Z, t, C, s, w, b)
    if init and mse0 < mse:  # the search never beat its start
        return start
    return C, s, w, b, mse
