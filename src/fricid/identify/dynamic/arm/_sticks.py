"""What a joint does while it sticks, left to nuisance columns of its own rows.

In closed loop a joint sticks at its stops and reversals (its drive builds up torque while it
rests), and the friction there is whatever holds it, which no law of velocity gives. The
low-pass spreads that misfit over the rows about the stop (:mod:`._rows`), and the rows kept
beyond the reversal window still hold its tail: on MuJoCo's stepping of the exported Panda
(``benchmarks/bench_robot.py --truth mujoco``, tuning seeds 50-61) the Coulomb levels of
joints 4 and 5 came out about one standard error high on average, their intervals covering
83 % instead of 95 %, and a window of 1.5 periods for every joint removed that bias.

Seen from a row a period of the cut-off or more away, a stick of some tens of milliseconds
is nearly an impulse: the filtered misfit there is the filter's response to the misfit's
first two moments over the stick (its integral and its centred first moment), up to terms
of order ``(stick length x cut-off)^2``. So each stop of each joint gets two columns, the
indicator of the stop and a centred ramp over it, through the torque's filters
(:func:`stick_columns`), on that joint's rows only, and the fit projects them out of the
joint's rows (Frisch-Waugh-Lovell: the estimate and its sandwich covariance are those of the
regression with the columns in it; :class:`._solve.Stack`). They cost each joint a degree of
freedom per column, which its noise estimate counts.

Measured on the same logs with and without them (``benchmarks/results/robot.txt``, blocks 1
and 1b, 4 and 4b): on MuJoCo (100 seeds) the intervals of joints 5 and 6 covered 94.5 and
94.8 % instead of 89.0 and 90.5 %, on fricid's simulator (40 seeds) joint 6's 95.0 % instead
of 85.0 %; the price is precision where the stops are many (joint 1's viscous coefficient
0.35-0.37 % off in the median instead of 0.18-0.21 %).
"""

from __future__ import annotations

import numpy as np

from ._filter_cov import impulse_response
from ._signals import ArmSignals

__all__ = ["MERGE_PERIODS", "project_out", "stick_basis", "stick_columns", "stops"]

#: Stops closer than this [periods of the cut-off] are one.
MERGE_PERIODS = 0.1
#: Singular values below this fraction of the largest are dropped from a joint's basis.
RANK_TOL = 1e-9
#: A joint's stick columns are left out where they would take more than this share of its rows.
MAX_SHARE = 0.25


def stops(near: np.ndarray, gap: int) -> list[tuple[int, int]]:
    """The runs ``[a, b)`` of ``near`` (a boolean series), those less than ``gap`` samples
    apart merged."""
    edges = np.diff(np.concatenate([[0], near.astype(np.int8), [0]]))
    runs = list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True))
    merged: list[tuple[int, int]] = []
    for a, b in runs:
        if merged and a - merged[-1][1] < gap:
            merged[-1] = (merged[-1][0], int(b))
        else:
            merged.append((int(a), int(b)))
    return merged


def stick_columns(sig: ArmSignals, near: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each joint's stick columns (N, 2 k) at the kept rows for its ``k`` stops, the slow or
    reversing samples ``near`` (full rate, (N_full, n)): each stop's indicator and centred
    ramp through the torque's filters (module notes), summed from the filters' impulse
    response over the rows within its reach (the same as filtering the columns at the log's
    rate, away from the log's ends, which the kept rows are; a long log's many stops cost no
    full-rate column each)."""
    h = impulse_response(sig)
    half = (h.size - 1) // 2
    k = np.arange(-half, half + 1)
    H = np.concatenate([[0.0], np.cumsum(h)])  # H[m]: the sum of h over offsets below m - half
    K = np.concatenate([[0.0], np.cumsum(k * h)])
    rows = sig.rows()
    gap = max(round(MERGE_PERIODS * sig.rate / sig.cutoff), 1)
    out = []
    for j in range(near.shape[1]):
        runs = stops(near[:, j], gap)
        X = np.zeros((rows.size, 2 * len(runs)))
        for i, (a, b) in enumerate(runs):
            lo, hi = np.searchsorted(rows, [a - half, b + half])
            t = rows[lo:hi]
            # the samples s in [a, b) reach row t through offsets t - s in [t - b + 1, t - a]
            m1 = np.clip(t - b + 1 + half, 0, h.size)
            m2 = np.clip(t - a + 1 + half, 0, h.size)
            level, moment = H[m2] - H[m1], K[m2] - K[m1]
            X[lo:hi, 2 * i] = level
            if b - a > 2:  # the ramp alpha + beta s from -1 at a to 1 at b - 1
                beta = 2.0 / (b - 1 - a)
                X[lo:hi, 2 * i + 1] = (beta * (t - a) - 1.0) * level - beta * moment
        out.append(X)
    return tuple(out)


def stick_basis(columns: np.ndarray) -> np.ndarray | None:
    """An orthonormal basis (m, k) of a joint's stick ``columns`` on its rows (m, 2 stops),
    or None where there are none, or where they would take more than :data:`MAX_SHARE` of the
    rows."""
    norms = np.linalg.norm(columns, axis=0)
    keep = norms > RANK_TOL * max(float(norms.max(initial=0.0)), 1e-300)
    if not keep.any():
        return None
    U, s, _ = np.linalg.svd(columns[:, keep] / norms[keep], full_matrices=False)
    Q = U[:, s > RANK_TOL * s[0]]
    return Q if Q.shape[1] <= MAX_SHARE * columns.shape[0] else None


def project_out(x: np.ndarray, columns: np.ndarray) -> tuple[np.ndarray, int]:
    """``x`` (m,) with a joint's stick ``columns`` (m, 2 stops) on the same rows projected
    out, and the degrees of freedom they took."""
    Q = stick_basis(columns)
    return (x, 0) if Q is None else (x - Q @ (Q.T @ x), Q.shape[1])
