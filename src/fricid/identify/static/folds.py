"""Held-out refits of one analytic model, every fold at once.

Validating a model (:func:`fricid.identify.validate.validate`) refits it with each fold of the
samples left out. Started from the model's optimum on all the samples (a fold leaves out a
little of the data, so its optimum is near), the refits are independent least-squares problems
of the same size: :func:`refit_folds` solves them together by Levenberg-Marquardt (Marquardt's
scaling; Nocedal and Wright 2006, sec. 10.3), each fold's residuals those of the problem on all
samples with the held-out rows weighted 0, every iteration one batched evaluation of the
residuals for every fold's Jacobian (forward differences) and one for every fold's trial step;
a parameter at a bound that the descent direction pushes outward is held there for the step (an
active set, as a projected method keeps it). Steps are cut at the search box of the problem on
all samples (a fold's own fit would scale its box to its own data; that differs only for an
optimum at a bound). A fold whose iteration does not end at a point no step improves is
reported, for a fit of its own.
"""

from __future__ import annotations

import numpy as np

from ..problem import IdentificationProblem

__all__ = ["MAX_ITER", "refit_folds"]

#: Iterations at most (each: two batched residual evaluations).
MAX_ITER = 200

#: A step lowering the SSE by less than this fraction ends a fold's iteration (converged).
FTOL = 1e-12

#: A step moving every parameter by less than this fraction ends a fold's iteration.
XTOL = 1e-10

#: Damping at which a fold that finds no lower SSE is at a minimum (converged).
LAMBDA_MAX = 1e10

_FD = 1e-7


def _sse(problem: IdentificationProblem, T: np.ndarray, W: np.ndarray) -> np.ndarray:
    r = problem.residuals(T) * W
    out = np.sum(r * r, axis=1)
    return np.where(np.isfinite(out), out, np.inf)


def refit_folds(
    problem: IdentificationProblem, train: np.ndarray, x0: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares optimum of ``problem`` on each fold's training rows, from ``x0``.

    Parameters
    ----------
    problem : IdentificationProblem
        The problem on all samples (loss ``sse``, no weights).
    train : ndarray of bool (k, n)
        Per fold, the rows it is fitted to.
    x0 : ndarray (p,)
        The start of every fold: the optimum on all samples (free parameters).

    Returns
    -------
    x : ndarray (k, p)
        Each fold's optimum (free parameters).
    converged : ndarray of bool (k,)
        False where the iteration did not end at a point no step improves.
    """
    k = train.shape[0]
    p = x0.size
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
    W = train.astype(float)
    X = np.repeat(np.asarray(x0, dtype=float)[None, :], k, axis=0)
    sse = _sse(problem, X, W)
    lam = np.full(k, 1e-3)
    done = np.zeros(k, dtype=bool)
    converged = np.zeros(k, dtype=bool)
    eye = np.eye(p)
    for _ in range(MAX_ITER):
        act = np.flatnonzero(~done)
        if act.size == 0:
            break
        Xa, Wa = X[act], W[act]
        h = _FD * np.maximum(np.abs(Xa), 1e-3)
        h = np.where(Xa + h <= hi, h, -h)
        T = np.vstack([Xa, (Xa[:, None, :] + h[:, :, None] * eye).reshape(-1, p)])
        R = problem.residuals(T)
        r = R[: act.size] * Wa
        J = (R[act.size :].reshape(act.size, p, -1) * Wa[:, None, :] - r[:, None, :]) / h[
            :, :, None
        ]  # (m, p, n)
        J = np.nan_to_num(J, nan=0.0, posinf=0.0, neginf=0.0)
        r = np.nan_to_num(r, nan=0.0, posinf=0.0, neginf=0.0)
        A = np.einsum("mpn,mqn->mpq", J, J)
        g = np.einsum("mpn,mn->mp", J, r)
        # a parameter at a bound that the descent direction (-g) pushes out stays there
        held = ((Xa <= lo) & (g > 0)) | ((Xa >= hi) & (g < 0))
        free = (~held).astype(float)
        A = A * free[:, :, None] * free[:, None, :] + eye * held[:, :, None]
        g = g * free
        D = np.maximum(np.einsum("mpp->mp", A), 1e-300)
        M = A + lam[act, None, None] * D[:, :, None] * eye
        try:
            delta = -np.linalg.solve(M, g[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            delta = -(np.linalg.pinv(M) @ g[:, :, None])[:, :, 0]
        trial = np.clip(Xa + delta, lo, hi)
        new = _sse(problem, trial, Wa)
        better = new < sse[act]
        gain = sse[act] - new
        X[act[better]] = trial[better]
        small = np.all(np.abs(trial - Xa) <= XTOL * (np.abs(Xa) + XTOL * (hi - lo)), axis=1)
        stop_ok = better & ((gain <= FTOL * np.maximum(sse[act], 1e-300)) | small)
        sse[act[better]] = new[better]
        lam[act] = np.where(better, lam[act] * 0.3, lam[act] * 10.0)
        stuck = ~better & (lam[act] >= LAMBDA_MAX)
        done[act[stop_ok | stuck]] = True
        converged[act[stop_ok | stuck]] = True
    return X, converged & np.isfinite(sse)
