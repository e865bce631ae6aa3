"""Numerical core of the RBF network (BAS-RBFNN paper, section 3.1): design matrices of
Gaussian units (eq. 14), the linear output layer (eq. 15) and its least-squares solution,
for one network or a batch of candidate networks at once.

Shapes: inputs ``Z (n, d)`` (already standardised), centres ``C (m, d)`` or a batch
``(k, m, d)``, widths ``sigma (m,)`` or ``(k, m)``, output weights ``w (m,)`` or ``(k, m)`` and
bias ``b`` scalar or ``(k,)``. Every function works on whole arrays; batches are processed in
chunks of candidates (never a loop over samples) so that memory stays near
:data:`CHUNK_ELEMENTS` floats per chunk.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

__all__ = [
    "CHUNK_ELEMENTS",
    "chunks",
    "design",
    "lstsq_weights",
    "nn_widths",
    "output",
    "ridge_weights_batch",
]

#: Largest design-matrix batch (candidates x samples x centres) built at once: 4 million
#: float64 values, 32 MB.
CHUNK_ELEMENTS = 4_000_000

#: Smallest width relative to the data's spread (guards duplicate centres).
MIN_WIDTH = 1e-3


def _sq_dist(Z: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Squared distances ``||z_j - c_i||^2``: ``(n, d), (..., m, d) -> (..., n, m)``."""
    zz = np.einsum("nd,nd->n", Z, Z)
    cc = np.einsum("...md,...md->...m", C, C)
    d2 = zz[:, None] + cc[..., None, :] - 2.0 * (Z @ np.swapaxes(C, -1, -2))
    return np.maximum(d2, 0.0)


def design(Z: np.ndarray, C: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """Hidden-layer outputs, eq. 14: ``phi_i(z) = exp(-||z - c_i||^2 / (2 sigma_i^2))``.

    ``(n, d), (..., m, d), (..., m) -> (..., n, m)``. The exponent is expanded as
    ``(2 z.c_i - ||z||^2 - ||c_i||^2) / (2 sigma_i^2)`` and formed by one matrix product of
    ``[z, ||z||^2, 1]`` with per-centre coefficients, then exponentiated in place: two passes
    over the result instead of one per term.
    """
    inv = 0.5 / np.square(sigma)  # (..., m)
    Zt = np.column_stack([Z, np.einsum("nd,nd->n", Z, Z), np.ones(Z.shape[0])])
    cc = np.einsum("...md,...md->...m", C, C)
    Ct = np.concatenate(
        [2.0 * C * inv[..., None], -inv[..., None], (-cc * inv)[..., None]], axis=-1
    )  # (..., m, d + 2)
    P = Zt @ np.swapaxes(Ct, -1, -2)
    np.minimum(P, 0.0, out=P)  # rounding may leave tiny positive exponents
    return np.exp(P, out=P)


def output(Phi: np.ndarray, w: np.ndarray, b) -> np.ndarray:
    """Network output, eq. 15 (plus a bias): ``y = Phi w + b``.

    ``(..., n, m), (..., m), scalar or (...) -> (..., n)``.
    """
    return (Phi @ w[..., :, None])[..., 0] + np.asarray(b)[..., None]


def nn_widths(C: np.ndarray, factor: float, scale: float, neighbours: int = 2) -> np.ndarray:
    """Width heuristic: ``sigma_i = factor * RMS distance from c_i to its nearest centres``.

    The p-nearest-neighbour rule of Moody and Darken (1989) with p = ``neighbours``; a lone
    centre gets ``factor * scale``. Widths are floored at ``MIN_WIDTH * scale`` so duplicate
    centres cannot give a zero width. ``scale`` is the data's typical spread (``sqrt(d)`` for
    standardised inputs).
    """
    m = C.shape[0]
    if m < 2:
        return np.full(m, factor * scale)
    p = min(neighbours, m - 1)
    D2 = _sq_dist(C, C)
    np.fill_diagonal(D2, np.inf)
    nearest = np.sort(D2, axis=1)[:, :p]
    sigma = factor * np.sqrt(np.mean(nearest, axis=1))
    return np.maximum(sigma, MIN_WIDTH * scale)


def lstsq_weights(
    Phi: np.ndarray, t: np.ndarray, alpha: float, fit_bias: bool
) -> tuple[np.ndarray, float]:
    """Output weights of one network by (ridge) linear least squares.

    Minimises ``mean((t - Phi w - b)^2) + alpha ||w||^2``; the bias is not penalised and is
    eliminated by centring. With ``alpha > 0`` the normal equations
    ``(A^T A / n + alpha I) w = A^T r / n`` are solved by Cholesky (the penalty bounds their
    condition number); with ``alpha = 0`` an SVD least-squares solver works on ``A`` itself
    (the normal equations would square its condition number), cutting singular values below
    machine precision.
    """
    n, m = Phi.shape
    if fit_bias:
        mu = Phi.mean(axis=0)
        tm = float(t.mean())
        A, r = Phi - mu, t - tm
    else:
        A, r = Phi, t
    w = None
    if alpha > 0:
        G = A.T @ A
        G /= n
        G[np.diag_indices(m)] += alpha
        try:
            w = scipy.linalg.solve(G, A.T @ r / n, assume_a="pos", check_finite=False)
        except (np.linalg.LinAlgError, scipy.linalg.LinAlgError):
            w = None
    if w is None:
        w = scipy.linalg.lstsq(A, r, lapack_driver="gelsd", check_finite=False)[0]
    b = tm - float(mu @ w) if fit_bias else 0.0
    return w, b


def ridge_weights_batch(
    Phi: np.ndarray, t: np.ndarray, alpha: float, fit_bias: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Output weights of a batch of networks, each by ridge least squares.

    ``Phi (k, n, m)``, ``t (n,)`` -> ``w (k, m)``, ``b (k,)``. The normal equations
    ``(A^T A / n + alpha I) w = A^T r / n`` (A, r centred when ``fit_bias``; the bias is not
    penalised) are solved for
    all k candidates at once (``np.linalg.solve`` on ``(k, m, m)``); a batch with a singular
    system falls back to the batched pseudo-inverse.
    """
    k, n, m = Phi.shape
    Pt = np.swapaxes(Phi, 1, 2)
    G = Pt @ Phi
    G /= n
    if fit_bias:
        # centring without a centred copy: cov = Phi^T Phi / n - mu mu^T, and
        # Phi^T (t - mean t) equals the centred product since the centred t sums to 0
        mu = Phi.mean(axis=1)  # (k, m)
        G -= mu[:, :, None] * mu[:, None, :]
        tm = float(t.mean())
        r = t - tm
    else:
        r = t
    idx = np.arange(m)
    G[:, idx, idx] += alpha
    rhs = (Pt @ r) / n  # (k, m)
    try:
        w = np.linalg.solve(G, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        w = (np.linalg.pinv(G, hermitian=True) @ rhs[..., None])[..., 0]
    b = tm - np.einsum("km,km->k", mu, w) if fit_bias else np.zeros(k)
    return w, b


def chunks(k: int, n: int, m: int) -> list[slice]:
    """Slices of a batch of ``k`` candidates with at most :data:`CHUNK_ELEMENTS` design-matrix
    values each."""
    step = max(1, CHUNK_ELEMENTS // max(1, n * m))
    return [slice(i, min(i + step, k)) for i in range(0, k, step)]
