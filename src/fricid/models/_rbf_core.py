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

__all__ = [
    "CHUNK_ELEMENTS",
    "RidgeScorer",
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
    import scipy.linalg  # here, not at import: the command line starts without it

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


class RidgeScorer:
    """Training MSE of a batch of networks whose output weights are each network's ridge
    least-squares solution: the objective of the ``hybrid`` encoding.

    ``RidgeScorer(Z, t, alpha, fit_bias)(C (k, m, d), sigma (k, m)) -> mse (k,)``, where
    ``mse = mean((Phi w + b - t)^2)`` with ``w, b`` from :func:`ridge_weights_batch`'s normal
    equations. The same quantity as ``design`` + ``ridge_weights_batch`` + ``output``, with the
    work and the memory traffic per candidate cut to what the normal equations need (this is
    the inner loop of BAS-RBFNN and GA-RBFNN):

    * the design matrix is built transposed, ``(k, m + 2, n)``, in a buffer kept between calls,
      whose last two rows are ones and the centred target; one ``syrk`` (``B B^T``, one BLAS
      call per candidate) then gives ``Phi^T Phi``, the column sums ``Phi^T 1`` and
      ``Phi^T (t - mean t)`` together, instead of separate passes over ``Phi`` for the mean
      and the right-hand side;
    * the inputs' ``[z, ||z||^2, 1]`` expansion is computed once, not per call;
    * the exponent is not clamped at 0 (``design`` clamps it; a pass over the buffer, ~10 %
      of the time): the expansion's rounding can only leave exponents a few rounding errors
      of its terms above 0 (1e-13 within the search's bounds), basis values of 1 + 1e-13;
    * the MSE is the mean squared residual ``Phi w + b - t`` (one more pass), not the
      shortcut ``var(t) - w.h - alpha ||w||^2``, which is first-order in the error of ``w``
      and ~3 times less accurate on ill-conditioned designs (condition numbers of ``Phi^T
      Phi`` reach 1e13 on the paper1 data).

    Everything stays float64: with such condition numbers float32 normal equations carry
    no information (their ``Phi^T Phi`` errors, ~1e-7, exceed its small eigenvalues).
    Candidates are processed in chunks of at most :data:`CHUNK_ELEMENTS` buffer values.
    """

    def __init__(self, Z: np.ndarray, t: np.ndarray, alpha: float, fit_bias: bool) -> None:
        Z = np.asarray(Z, dtype=np.float64)
        t = np.asarray(t, dtype=np.float64)
        self.n, self.d = Z.shape
        self.alpha = float(alpha)
        self.fit_bias = bool(fit_bias)
        self.t = t
        self.t_mean = float(t.mean()) if fit_bias else 0.0
        self.t_c = t - self.t_mean
        # rows of [z, ||z||^2, 1]^T: the exponent is Ct @ Zt with Ct from the centres
        self.Zt = np.ascontiguousarray(
            np.vstack([Z.T, np.einsum("nd,nd->n", Z, Z)[None], np.ones((1, self.n))])
        )
        self._buf: np.ndarray | None = None

    def _buffer(self, k: int, m: int) -> np.ndarray:
        """``(k, m + 2, n)`` view of the work buffer: rows ``:m`` for the design, then ones
        and the centred target (written once per buffer)."""
        buf = self._buf
        if buf is None or buf.shape[0] < k or buf.shape[1] != m + 2:
            buf = np.empty((k, m + 2, self.n))
            buf[:, m] = 1.0
            buf[:, m + 1] = self.t_c
            self._buf = buf
        return buf[:k]

    def __call__(self, C: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        k, m, _ = C.shape
        out = np.empty(k)
        step = max(1, CHUNK_ELEMENTS // max(1, self.n * (m + 2)))
        for i in range(0, k, step):
            out[i : i + step] = self._score(C[i : i + step], sigma[i : i + step])
        return out

    def _score(self, C: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        k, m, _ = C.shape
        n = self.n
        inv = 0.5 / np.square(sigma)  # (k, m)
        cc = np.einsum("kmd,kmd->km", C, C)
        Ct = np.concatenate(
            [2.0 * C * inv[..., None], -inv[..., None], (-cc * inv)[..., None]], axis=-1
        )  # (k, m, d + 2)
        B = self._buffer(k, m)
        Phi_t = B[:, :m]  # (k, m, n): Phi transposed
        np.matmul(Ct, self.Zt, out=Phi_t)
        np.exp(Phi_t, out=Phi_t)
        G = B @ np.swapaxes(B, 1, 2)  # (k, m + 2, m + 2), syrk: B is one buffer
        G /= n
        h = G[:, :m, m + 1]  # Phi^T (t - mean t) / n
        if self.fit_bias:
            mu = G[:, :m, m].copy()  # column means of Phi
            A = G[:, :m, :m]
            A -= mu[:, :, None] * mu[:, None, :]  # covariance of the centred design
        else:
            mu = np.zeros((k, m))
            A = G[:, :m, :m]
        idx = np.arange(m)
        A[:, idx, idx] += self.alpha
        try:
            w = np.linalg.solve(A, h[..., None])
        except np.linalg.LinAlgError:
            w = np.linalg.pinv(A, hermitian=True) @ h[..., None]
        # residual Phi w + b - t = [w, -mu.w, -1] . [Phi; 1; t - mean t] (b = mean t - mu.w):
        # one product with the whole buffer
        v = np.empty((k, 1, m + 2))
        v[:, 0, :m] = w[..., 0]
        v[:, 0, m] = -np.einsum("km,km->k", mu, w[..., 0])
        v[:, 0, m + 1] = -1.0
        r = (v @ B)[:, 0, :]  # (k, n)
        return np.einsum("kn,kn->k", r, r) / n


def chunks(k: int, n: int, m: int) -> list[slice]:
    """Slices of a batch of ``k`` candidates with at most :data:`CHUNK_ELEMENTS` design-matrix
    values each."""
    step = max(1, CHUNK_ELEMENTS // max(1, n * m))
    return [slice(i, min(i + step, k)) for i in range(0, k, step)]
