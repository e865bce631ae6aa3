"""Every Stribeck shape of the arm at once, after the block search of :mod:`._solve`.

The block search (:func:`._solve.search_shapes`) moves one joint and direction's ``(w_s,
delta)`` at a time, every other column held. The blocks are coupled (a joint's two directions
near its reversals, every joint through the shared base parameters), so that coordinate
descent crawls along the valleys of the sum of squares: on a noise-free open-loop Panda log
(``tests/identify/dynamic/_arm_truth.py``, the designed excitation, seed 0) its three sweeps
left joint 3's filtered residual 180 times the one at the true shapes (1.6e-3 against 8.8e-6 N
m), with the shapes' intervals far from the truth (``w_s`` 0.007 against 0.056), and eight
sweeps still 34 times.

:func:`polish_shapes` then moves all the shapes together by Levenberg-Marquardt on the
variable-projection residual (Golub and Pereyra 1973), with Kaufman's (1975) Jacobian: the
shapes' columns (:func:`._solve.shape_rows`, as the intervals use them) less their projection on the
linear columns. The shapes are searched as ``(log w_s, delta)`` inside the search box; a step
is taken only when it lowers the weighted sum of squares, so the polish never loses, and
keeps every Stribeck excess within what the log allows (:func:`._friction.excess_cap`).

The torque's delay (``arm._torque_delay``) is one more linear column here, the torque's
change per sample: estimated with the starting shapes, a delay held fixed kept the shapes in
a wrong valley. Noise-free on the double pendulum (``tests/identify/dynamic/
test_arm_polish.py``), the polish with the delay held stopped at a weighted sum of squares of
81.8 with joint 2's ``w_s`` 0.044 against 0.069 (the delay then -0.008 samples against 0);
with the delay free it went from 5.49 to 0.012, every shape within 0.3 % of the truth.
"""

from __future__ import annotations

import numpy as np

from ._friction import DELTA_BOX, W_S_BOX, JointFriction
from ._signals import ArmSignals
from ._solve import excess_index, lstsq, shape_rows, stack

__all__ = ["polish_shapes"]

#: Most Levenberg-Marquardt iterations, and the relative drop of the sum of squares below
#: which the polish stops.
ITERATIONS = 40
TOLERANCE = 1e-9

_LO = np.array([np.log(W_S_BOX[0]), DELTA_BOX[0]])
_HI = np.array([np.log(W_S_BOX[1]), DELTA_BOX[1]])


def _blocks(frictions: list[JointFriction], mask: np.ndarray) -> list[tuple[int, str]]:
    return [
        (j, d)
        for j, jf in enumerate(frictions)
        if jf.stribeck and mask[:, j].any()
        for d in jf.directions
    ]


def _get(frictions, blocks) -> np.ndarray:
    return np.array(
        [[np.log(frictions[j].shapes[d][0]), frictions[j].shapes[d][1]] for j, d in blocks]
    )


def _put(frictions, blocks, x: np.ndarray) -> None:
    for (j, d), (lw, e) in zip(blocks, np.clip(x, _LO, _HI), strict=True):
        frictions[j].shapes[d] = (float(np.exp(lw)), float(e))


def _state(sig, Yb, frictions, mask, sigma):
    """The stack, its weighted columns (with the torque's change per sample, so that the
    torque's delay moves with the shapes), the solution, residual and sum of squares."""
    st = stack(Yb, sig, frictions, mask)
    dtau = st.residualise(sig.dtau[st.row_time, st.row_joint])
    A, y = st.weighted(sigma)
    A = np.column_stack([A, dtau / sigma[st.row_joint]])
    theta = lstsq(A, y)
    r = y - A @ theta
    return st, A, theta, r, float(r @ r)


def _within_caps(frictions: list[JointFriction], st, theta: np.ndarray) -> bool:
    """Every Stribeck excess at most what the log allows (``JointFriction.excess_max``)."""
    return all(
        theta[excess_index(st, j, k)] <= jf.excess_max
        for j, jf in enumerate(frictions)
        if jf.stribeck
        for k in range(len(jf.directions))
    )


def polish_shapes(
    sig: ArmSignals,
    Yb: np.ndarray,
    frictions: list[JointFriction],
    mask: np.ndarray,
    sigma: np.ndarray,
) -> dict[str, float]:
    """Move every Stribeck shape together (module notes), in place; returns the weighted
    sum of squares before and after and the iterations taken (the fit's provenance keeps it
    as ``shape_polish``)."""
    blocks = _blocks(frictions, mask)
    if not blocks:
        return {}
    joints = sorted({j for j, _ in blocks})
    st, A, theta, r, ssr = _state(sig, Yb, frictions, mask, sigma)
    start, lam, taken = ssr, 1e-3, 0
    within = _within_caps(frictions, st, theta)
    for _ in range(ITERATIONS):
        taken += 1
        J = shape_rows(sig, frictions, st, theta, sigma, joints, log_w=True)
        norms = np.linalg.norm(A, axis=0)
        norms[norms == 0] = 1.0
        coef, *_ = np.linalg.lstsq(A / norms, J, rcond=1e-10)
        Jt = J - (A / norms) @ coef  # Kaufman: the linear columns projected out
        g, H = Jt.T @ r, Jt.T @ Jt
        x = _get(frictions, blocks).ravel()
        damp = np.diag(np.diag(H)) + 1e-12 * np.trace(H) * np.eye(H.shape[0])
        improved = False
        for _ in range(8):
            step = np.linalg.lstsq(H + lam * damp, g, rcond=None)[0]
            _put(frictions, blocks, (x + step).reshape(-1, 2))
            trial = _state(sig, Yb, frictions, mask, sigma)
            inside = _within_caps(frictions, trial[0], trial[2])
            if trial[-1] < ssr and (inside or not within):  # never out of the caps
                improved, within = True, inside
                break
            lam *= 4.0
        if not improved:
            _put(frictions, blocks, x.reshape(-1, 2))
            break
        drop = (ssr - trial[-1]) / ssr
        st, A, theta, r, ssr = trial
        lam = max(lam / 3.0, 1e-9)
        if drop < TOLERANCE:
            break
    return {"before": start, "after": ssr, "iterations": taken}
