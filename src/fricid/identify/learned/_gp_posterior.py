"""The Gaussian process's posterior at fixed hyperparameters (:mod:`fricid.identify.learned.gp`):
the kernel matrix, a jittered Cholesky factor, the posterior with the mean's coefficients
estimated with it, its smoother's trace, and the held-out calibration of its prediction
intervals (:func:`heldout_scale`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from ._conformal import INTERVAL_LEVELS, conformal_half_widths

__all__ = ["heldout_scale"]

#: Relative jitter on the diagonal of the inducing points' kernel matrix.
_JITTER = 1e-8

#: Most tenfold increases of the jitter :func:`_cholesky` tries.
_JITTER_STEPS = 6


def _cholesky(M: np.ndarray, scale: float) -> tuple[tuple[np.ndarray, bool], float]:
    """``cho_factor`` of the symmetric ``M`` with ``jitter * I`` added, and that jitter:
    ``_JITTER * scale``, raised tenfold (up to :data:`_JITTER_STEPS` times) while the
    factorisation fails. Long length scales make the kernel matrix of close inducing points
    numerically singular (its smallest eigenvalues fall below rounding); the jitter restores
    it, as the nugget of R&W section 3.4.3 does."""
    eye = np.eye(len(M))
    for k in range(_JITTER_STEPS + 1):
        jitter = _JITTER * scale * 10.0**k
        try:
            return cho_factor(M + jitter * eye, lower=True), jitter
        except np.linalg.LinAlgError:
            if k == _JITTER_STEPS:
                raise
    raise AssertionError("unreachable")  # pragma: no cover


def _kernel_matrix(A: np.ndarray, B: np.ndarray, lengths: np.ndarray, s2: float) -> np.ndarray:
    d2 = np.sum(((A[:, None, :] - B[None, :, :]) / lengths) ** 2, axis=2)
    return s2 * np.exp(-0.5 * d2)


def _posterior(
    P: np.ndarray,
    Z: np.ndarray,
    t: np.ndarray,
    A: np.ndarray,
    lengths: np.ndarray,
    s2: float,
    noise: float,
    exact: bool,
) -> tuple[np.ndarray, ...]:
    """The posterior on stored points ``P`` of targets ``t`` at ``Z`` with the mean's basis
    ``A (n, q)`` estimated with it (R&W section 2.7, eq. 2.41-2.42, with the prior ``b = 0``,
    ``B = I`` on the correction ``dbeta``, ``A`` standardised by the caller): ``(alpha, B, G,
    C, dbeta)``.

    ``dbeta`` corrects the least-squares mean, ``alpha`` weighs the points, and the variance
    is ``s2 - k^T B k + (h - G k)^T C (h - G k)`` for a kernel vector ``k`` and basis ``h``.
    Exact: ``K = K_nn + noise I`` (R&W eq. 2.25-2.26); else DTC on the points, with
    ``K~^-1 = (Q_nn + noise I)^-1`` by the Woodbury identity (Quinonero-Candela & Rasmussen
    2005, eq. 20-21).
    """
    m = len(P)
    Kmm = _kernel_matrix(P, P, lengths, s2)
    if exact:
        factor = cho_factor(Kmm + (noise + 1e-10) * np.eye(m), lower=True)
        M = cho_solve(factor, A)  # K^-1 H^T
        gain = M.T  # H K^-1
        B = cho_solve(factor, np.eye(m))
        weights = lambda r: cho_solve(factor, r)  # noqa: E731
    else:
        Kmn = _kernel_matrix(P, Z, lengths, s2)
        Kj_factor, jitter = _cholesky(Kmm, s2)
        Kj = Kmm + jitter * np.eye(m)
        S = noise * Kj + Kmn @ Kmn.T
        Sigma, _ = _cholesky(S, float(np.trace(S)) / m)
        M = (A - Kmn.T @ cho_solve(Sigma, Kmn @ A)) / noise
        gain = cho_solve(Sigma, Kmn @ A).T  # H K_nm (noise K_mm + K_mn K_nm)^-1
        B = cho_solve(Kj_factor, np.eye(m)) - noise * cho_solve(Sigma, np.eye(m))
        weights = lambda r: cho_solve(Sigma, Kmn @ r)  # noqa: E731
    cov = np.linalg.inv(A.T @ M + np.eye(A.shape[1]))  # the prior B = I (module notes)
    cov = 0.5 * (cov + cov.T)
    dbeta = cov @ (M.T @ t)
    alpha = weights(t - A @ dbeta)
    return alpha, 0.5 * (B + B.T), gain, cov, dbeta


def _smoother_trace(
    P: np.ndarray,
    Z: np.ndarray,
    A: np.ndarray,
    lengths: np.ndarray,
    s2: float,
    noise: float,
    exact: bool,
) -> float:
    """The effective degrees of freedom of the posterior mean at the training points: the
    trace of the linear map ``S`` from targets to fitted values, at these hyperparameters,
    the mean's basis ``A (n, q)`` estimated with it (R&W section 2.6; ESL eq. 3.50 for its
    ridge form).

    With ``dbeta = C M^T t`` and ``alpha = W (t - A dbeta)`` (:func:`_posterior`) the fit at
    the points is ``A dbeta + K_zp alpha``, so ``tr S = tr(C M^T A) + tr(W K_zp) -
    tr(C M^T K_zp W A)``, formed from ``m x m`` and ``n x q`` products only.
    """
    m = len(P)
    Kmm = _kernel_matrix(P, P, lengths, s2)
    if exact:
        factor = cho_factor(Kmm + (noise + 1e-10) * np.eye(m), lower=True)
        M = cho_solve(factor, A)
        w_kzp = cho_solve(factor, Kmm)
        kzp_w_a = Kmm @ M
    else:
        Kmn = _kernel_matrix(P, Z, lengths, s2)
        _, jitter = _cholesky(Kmm, s2)
        S = noise * (Kmm + jitter * np.eye(m)) + Kmn @ Kmn.T
        Sigma, _ = _cholesky(S, float(np.trace(S)) / m)
        M = (A - Kmn.T @ cho_solve(Sigma, Kmn @ A)) / noise
        w_kzp = cho_solve(Sigma, Kmn @ Kmn.T)
        kzp_w_a = Kmn.T @ cho_solve(Sigma, Kmn @ A)
    cov = np.linalg.inv(A.T @ M + np.eye(A.shape[1]))
    return float(np.trace(cov @ (M.T @ A)) + np.trace(w_kzp) - np.trace(cov @ (M.T @ kzp_w_a)))


#: Samples up to which the calibration leaves one out; above, ten folds.
LOO_MAX = 60


def heldout_scale(
    Z: np.ndarray,
    A: np.ndarray,
    As: np.ndarray,
    g: np.ndarray,
    hyper: tuple[np.ndarray, float, float],
    y_scale: float,
    levels=INTERVAL_LEVELS,
) -> tuple[dict, np.ndarray]:
    """Multipliers of the predictive standard deviation that make the GP's intervals cover
    held-out samples: the normalised (studentised) conformal scores of cross-validation
    (Lei et al. 2018, section 5.2; with cross-validation folds, the CV+ reading of Barber et
    al. 2021).

    Each fold refits the whole posterior without its samples at the fitted hyperparameters
    ``hyper = (lengths, s2, noise)``, the least-squares mean included (the exact posterior,
    :func:`_posterior` on the fold's points): ``z_i = |g_i - mean_i| / sqrt(var_i + noise)``
    with the latent variance and the white noise of the refitted process. The multiplier at
    ``level`` is the ``ceil((n + 1) level)``-th smallest ``z``, or the Student-t fall-back
    when ``n`` is too small for it
    (:func:`~fricid.identify.learned._conformal.conformal_half_widths`); the same quantile of
    the plain residuals ``|g_i - mean_i|`` is the half-width below which the interval does not
    shrink. The interval ``mean -+ max(k sqrt(std^2 + noise_std^2), half_width)`` so covers
    about ``level`` of new samples even where maximum likelihood drove the noise to zero and
    the standard deviation with it (ten samples per direction on three inputs: coverage
    0.54-0.84 with the multiplier alone). ``A`` is the raw basis of the least-squares mean,
    ``As`` its standardised form (the correction's). The held-out errors ``|g_i - mean_i|``
    [N m] come back beside the record (the local spread of the model's intervals,
    :func:`fricid.identify._intervals.local_record`).
    """
    lengths, s2, noise = hyper
    n = len(g)
    folds = np.arange(n) if n <= LOO_MAX else np.arange(n) % 10
    z = np.empty(n)
    r = np.empty(n)
    for k in np.unique(folds):
        out = folds == k
        tr = ~out
        coef = np.linalg.lstsq(A[tr], g[tr], rcond=None)[0]
        t = (g[tr] - A[tr] @ coef) / y_scale
        P = Z[tr]
        alpha, B, gain, cov, dbeta = _posterior(P, P, t, As[tr], lengths, s2, noise, True)
        K = _kernel_matrix(Z[out], P, lengths, s2)
        mean = A[out] @ coef + y_scale * (As[out] @ dbeta + K @ alpha)
        hb = As[out] - K @ gain.T
        var = s2 - np.einsum("nm,mk,nk->n", K, B, K) + np.einsum("nq,qr,nr->n", hb, cov, hb)
        r[out] = np.abs(g[out] - mean)
        z[out] = r[out] / (y_scale * np.sqrt(np.maximum(var, 0.0) + noise))
    scale = conformal_half_widths(z, levels)
    how = "leave-one-out" if n <= LOO_MAX else "10-fold"
    return {
        "levels": list(levels),
        "scale": scale,
        "half_width": conformal_half_widths(r, levels),
        "method": f"normalised conformal, {how} refits at the fitted hyperparameters (CV+)",
    }, r
