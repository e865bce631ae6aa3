"""The compiled fast path of RWSAVSBAS (numba): one outer iteration of every run per call.

It mirrors :meth:`fricid.optim._rwsavsbas.RWSAVSBAS._outer_numpy` step by step, with the
directions, phases and Metropolis thresholds computed once per outer iteration by numpy and
shared by both paths: they follow the same algorithm on the same numbers and differ only by
rounding in the objective (a compiled kernel's scalar ``exp`` against numpy's vector one).
Imported only when a run uses it (importing numba takes a while).

Caching across processes: the objective's kernel reaches :func:`outer_iteration` as a
first-class *function pointer* (a numba ``cfunc`` of the fixed signature ``kernel(X (k, d),
out (k,), data)``, :func:`function_of`), never as a ``@njit`` dispatcher. numba types a
dispatcher argument as ``type(CPUDispatcher(<function ... at 0x...>))``, a name holding the
dispatcher's memory address, so the cache index never matched in a new process: every process
recompiled :func:`outer_iteration` (4-15 s) and added one more cache file (issue 14). The
pointer's type names only the signature, so the second process loads everything from the cache.
"""

from __future__ import annotations

import math

import numpy as np
from numba import typeof, types

from .._jit import cfunc, njit

__all__ = ["first_call", "function_of", "outer_iteration"]

#: ``(kernel, numba type of its data) -> cfunc``: one compilation (or cache load) per process.
_FUNCTIONS: dict[tuple, object] = {}


def function_of(kernel, data: tuple):
    """The kernel ``kernel(X, out, data)`` as a cached numba ``cfunc`` for ``data``'s type.

    ``X`` and ``out`` are typed as float64 arrays of any layout (2-d and 1-d). A kernel that
    numba cannot cache (not defined at a module's top level) is compiled without the cache.
    """
    dtype = typeof(tuple(data))
    key = (kernel, dtype)
    if key not in _FUNCTIONS:
        sig = types.void(
            types.Array(types.float64, 2, "A"), types.Array(types.float64, 1, "A"), dtype
        )
        py_func = getattr(kernel, "py_func", kernel)
        _FUNCTIONS[key] = cfunc(sig, cache=True)(py_func)  # in memory where no cache dir
    return _FUNCTIONS[key]


def first_call(args: tuple) -> tuple[tuple, object]:
    """``outer_iteration(*args)``, and the compiled entry point for arguments of these types.

    numba's dispatcher types every argument on every call; for the kernel's ``data`` tuple
    and the function pointer that costs about 0.25 ms (as much as an outer iteration of
    8 runs); the caller, whose arguments keep their types for the whole run (the same buffers,
    C-contiguous float64 arrays, Python scalars), calls the entry point directly. Falls back
    to the dispatcher when numba does not expose it.
    """
    result = outer_iteration(*args)
    sig = tuple(outer_iteration.typeof_pyval(a) for a in args)
    cres = outer_iteration.overloads.get(sig)
    entry = getattr(cres, "entry_point", None)
    return result, (outer_iteration if entry is None else entry)


@njit(cache=True)
def _evaluate(kernel, data, lower, span, P, k, X, out):
    """Evaluate the first ``k`` candidates of every run of ``P (R, 3, d)`` in one kernel call;
    non-finite values become +inf. Values land in ``out[r * k + j]``."""
    R, _, d = P.shape
    n = R * k
    for r in range(R):
        for j in range(k):
            for i in range(d):
                X[r * k + j, i] = lower[i] + P[r, j, i] * span[i]
    kernel(X[:n], out[:n], data)
    for m in range(n):
        if not math.isfinite(out[m]):
            out[m] = np.inf


@njit(cache=True)
def _offer(P, k, out, best_u, best_f):
    """The Objective's best-point bookkeeping (first minimum of each run's batch, strict)."""
    R, _, d = P.shape
    improved = False
    for r in range(R):
        jbest = 0
        fbest = out[r * k]
        for j in range(1, k):
            if out[r * k + j] < fbest:
                fbest = out[r * k + j]
                jbest = j
        if fbest < best_f[r]:
            best_f[r] = fbest
            for i in range(d):
                best_u[r, i] = P[r, jbest, i]
            improved = True
    return improved


@njit(cache=True)
def _clip(v):
    return min(max(v, 0.0), 1.0)


@njit(cache=True)
def outer_iteration(
    kernel,
    data,
    lower,
    span,
    x,
    G,
    fG,
    ibu,
    ibf,
    B,
    W,
    S,
    thr,
    step,
    c,
    immediate,
    remaining,
    nfev0,
    best_u,
    best_f,
    X,
    out,
    P,
    hist_n,
    hist_f,
):
    """One outer iteration (inner loop, best update, outer wandering) of every run.

    ``B, W (R, Q + 1, d)`` are the beetle's and the wandering directions, ``S (R, Q + 1)``
    the wandering phases ``sin(2 pi P / h)`` (the last column for the
    outer wandering) and ``thr (R, Q)`` the Metropolis thresholds ``-T log U``, both computed
    by the caller with numpy so that both paths use the very same numbers.

    Returns ``(used, n_hist, budget_hit)``: evaluations spent per run, snapshots written to
    ``hist_n``/``hist_f``, and whether the budget ran out (after spending it on a prefix of
    the last batch, as :class:`~fricid.optim._api.Objective` does).
    """
    R, d = x.shape
    Q = thr.shape[1]
    dist = step / c
    used = 0
    nh = 0
    for p in range(Q):
        # candidates: right antenna, left antenna, wandering antenna
        for r in range(R):
            s = S[r, p]
            for i in range(d):
                P[r, 0, i] = _clip(x[r, i] + dist * B[r, p, i])
                P[r, 1, i] = _clip(x[r, i] - dist * B[r, p, i])
                P[r, 2, i] = _clip(G[r, i] + (s * step) * W[r, p, i])
        k = 3
        if remaining - used < 3:
            k = remaining - used
            if k > 0:
                _evaluate(kernel, data, lower, span, P, k, X, out)
                used += k
                if _offer(P, k, out, best_u, best_f):
                    hist_n[nh] = nfev0 + used
                    hist_f[nh, :] = best_f
                    nh += 1
            return used, nh, True
        _evaluate(kernel, data, lower, span, P, 3, X, out)
        used += 3
        if _offer(P, 3, out, best_u, best_f):
            hist_n[nh] = nfev0 + used
            hist_f[nh, :] = best_f
            nh += 1
        for r in range(R):
            fr = out[r * 3]
            fl = out[r * 3 + 1]
            fw = out[r * 3 + 2]
            sgn = 0.0
            if fr > fl:
                sgn = 1.0
            elif fr < fl:
                sgn = -1.0
            fb = min(fr, fl)
            accept = fw <= fb
            if not accept:
                accept = (fw - fb) < thr[r, p]
            for i in range(d):
                if accept:
                    x[r, i] = P[r, 2, i]
                else:
                    x[r, i] = _clip(x[r, i] - step * sgn * B[r, p, i])
            jbest = 0
            fbest = fr
            if fl < fbest:
                fbest = fl
                jbest = 1
            if fw < fbest:
                fbest = fw
                jbest = 2
            if immediate:
                if fbest < fG[r]:
                    fG[r] = fbest
                    for i in range(d):
                        G[r, i] = P[r, jbest, i]
            elif fbest < ibf[r]:
                ibf[r] = fbest
                for i in range(d):
                    ibu[r, i] = P[r, jbest, i]
    # end of the inner loop: the outer loop updates the best ...
    if not immediate:
        for r in range(R):
            if ibf[r] < fG[r]:
                fG[r] = ibf[r]
                for i in range(d):
                    G[r, i] = ibu[r, i]
    # ... and wanders once around it
    for r in range(R):
        s = S[r, Q]
        for i in range(d):
            P[r, 0, i] = _clip(G[r, i] + (s * step) * W[r, Q, i])
    if remaining - used < 1:
        return used, nh, True
    _evaluate(kernel, data, lower, span, P, 1, X, out)
    used += 1
    if _offer(P, 1, out, best_u, best_f):
        hist_n[nh] = nfev0 + used
        hist_f[nh, :] = best_f
        nh += 1
    for r in range(R):
        if out[r] < fG[r]:
            fG[r] = out[r]
            for i in range(d):
                G[r, i] = P[r, 0, i]
    return used, nh, False
