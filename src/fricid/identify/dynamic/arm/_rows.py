"""The rows each joint's torque equation is fitted on, and how far a stick's misfit reaches.

In closed loop a joint sticks at its reversals (its drive builds up torque while it rests),
and no friction column holds what it does there. The low-pass spreads that misfit over the
rows around it: a step's error through the zero-phase Butterworth filter of order 4 falls to
2 % of the step one period of the cut-off away, 0.5 % at 1.5 periods, 0.1 % at 2. How large
the misfit is depends on the joint: on a PD-tracked Panda (``benchmarks/bench_robot.py
--truth sim``, noiseless, the true parameters, seed 0) the residual within half a period of a
stop was 3 to 5 times the filtered noise on joints 1-4 and 14 to 79 times on the wrist
(joints 5-7), whose small inertias stick longest under the drive's gains; one period away
it was still 0.8 to 1.5 times the noise there, and the friction intervals of joints 5 and 6
covered the truth 74 and 84 % of the time (20 seeds) instead of 95 %.

So the window is each joint's own (:func:`adapted_windows`): after a first fit with the
given window, the joint's residuals are binned by their distance from its nearest stop or
reversal, and the window grows to the nearest step from which on no bin tested (one
starting at each step) has an RMS above the joint's far residual (beyond
:data:`FAR_PERIODS`) by more than :data:`EXCESS`, nor a residual along the joint's friction
columns that its noise does not explain (:func:`band_score`, a score test with the filter's
correlation). The second test finds what biases the friction: on MuJoCo's stepping of the
exported Panda (``--truth mujoco``, tuning seeds 50-61) the RMS test alone kept one period
for joints 4 and 5, whose bins there held a residual along the motion of 0.2 to 0.7 noise
std (an RMS excess of a few per cent), and their Coulomb levels came out one standard error
high on average. The held-out
log is treated alike (its windows at least the fit's): how long a joint sticks depends on the
motion, and rows within a stick's reach hold the stick, which no friction law predicts.

The windows stop at 1.5 periods (:data:`WINDOW_STEPS`). Allowed to 3 (tuning seeds 50-55
of that benchmark), one seed's shoulder joint took 3 periods, from an excess far from its
stops that its own sticks do not explain, and lost so many rows that its held-out error rose
to 3.3 times its noise; with the cap it kept one period (1.24), while the wrist's windows
still grew to 1.25-1.5 periods where the residual showed the misfit.

Whether a log was recorded in closed loop is read from the same misfit, unless the caller
says (:func:`stick_signature`, :func:`sticking`): after a fit without the window, a joint's
fitted rows within one period of a stop hold a residual along its friction columns at
p <= :data:`STICK_P` (:func:`band_score`), or an RMS over twice its far rows'
(:data:`STICK_EXCESS`). Tuned on the tests' double pendulum (20 s at 1 kHz, seeds 0-2 of
``make_log`` and ``make_pd_log``, Coulomb-viscous and Stribeck laws per direction): in
closed loop every one of 10 joint fits was beyond one threshold or both (p from 1e-191 to
0.023, excess from 0.27 to 7.96: p 7e-10 at the least excess, excesses 1.54 and 1.77 at
the two p above 1e-3); in open loop (12 joint fits) p >= 0.42 and the excess <= 0.42. Measured
on the Panda of ``benchmarks/bench_robot.py --detect`` (report seeds 0-9): the open-loop
truth with Stribeck laws 0 of 10 logs taken for closed loop, fricid's PD-tracked simulator
10 of 10.
"""

from __future__ import annotations

import numpy as np
import scipy.ndimage
import scipy.stats

from ._signals import ArmSignals

__all__ = [
    "MIN_SPEED",
    "VELOCITY_NOISE_FACTOR",
    "adapted_windows",
    "band_score",
    "closed_loop_text",
    "moving_rows",
    "near_stops",
    "sticking",
    "still_text",
    "stop_distance",
]

#: A joint's rows slower than this many times its filtered velocity noise are left out.
VELOCITY_NOISE_FACTOR = 20.0
#: ... and never slower than this [rad/s].
MIN_SPEED = 1e-3
#: The windows tried [periods of the cut-off] (module notes: no more than 1.5), and the width
#: of each bin tested beyond one.
WINDOW_STEPS = (1.0, 1.25, 1.5)
BIN_PERIODS = 0.5
#: Rows at least this far from a stop give the joint's far residual [periods].
FAR_PERIODS = 3.0
#: The largest excess of a bin's RMS residual over the far one that is left in.
EXCESS = 0.25
#: Fewest rows in a bin (or far) for its RMS to count.
MIN_BIN_ROWS = 50
#: The level of the test that a bin's residual holds nothing along the friction columns.
ALPHA = 0.05
#: A joint shows sticks at its reversals (:func:`sticking`) when the rows within one period of
#: them hold a residual along its friction columns at this p-value or below, or an RMS
#: residual this much above its far rows'.
STICK_P = 1e-3
STICK_EXCESS = 1.0


def near_stops(sig: ArmSignals) -> np.ndarray:
    """The slow or reversing samples (N_full, n) of each joint at the log's rate (the
    friction's velocity)."""
    v = sig.full_dq
    v_min = np.maximum(VELOCITY_NOISE_FACTOR * sig.friction_velocity_noise, MIN_SPEED)
    near = np.abs(v) < v_min[None, :]
    flip = np.diff(np.sign(v), axis=0) != 0  # a reversal between two samples
    near[1:] |= flip
    near[:-1] |= flip
    return near


def stop_distance(sig: ArmSignals, near: np.ndarray | None = None) -> np.ndarray:
    """Each kept row's distance (N, n) from its joint's nearest slow or reversing sample at
    the log's rate (:func:`near_stops`, when not given), in periods of the cut-off."""
    near = near_stops(sig) if near is None else near
    out = np.full(near.shape, np.inf)
    for j in range(near.shape[1]):
        if near[:, j].any():
            out[:, j] = scipy.ndimage.distance_transform_edt(~near[:, j])
    return out[sig.rows()] * sig.cutoff / sig.rate


def moving_rows(sig: ArmSignals, window=0.0, distance: np.ndarray | None = None) -> np.ndarray:
    """The rows (N, n) each joint's friction law is fitted on: the joint's filtered velocity
    above its threshold; with ``window > 0`` (one value, or one per joint), also at least
    ``window`` periods of the cut-off from a slow sample or a reversal at the log's rate.

    A velocity threshold on the row alone is not enough in closed loop: the low-pass spreads
    what happens at a reversal (a joint sticking while its drive builds up torque) over the
    rows around it, whose own velocity is well above any threshold; there the columns
    ``sign(dq_f)`` are not the filtered friction of the true motion (module notes). In open
    loop (no sticking) those rows are right and carry the Stribeck rise, which the window
    then loses. ``distance``: :func:`stop_distance` of ``sig``, when already at hand.
    """
    window = np.broadcast_to(np.asarray(window, dtype=float), (sig.dq.shape[1],))
    if not (window > 0).any():
        v_min = np.maximum(VELOCITY_NOISE_FACTOR * sig.velocity_noise, MIN_SPEED)
        return np.abs(sig.dq) >= v_min[None, :]
    distance = stop_distance(sig) if distance is None else distance
    return distance >= window[None, :]


def band_score(F: np.ndarray, r: np.ndarray, t: np.ndarray, rho: np.ndarray, s2: float):
    """(statistic, degrees of freedom) of the score test that a band's residuals ``r`` (its
    rows at decimated instants ``t``) hold nothing along the joint's friction columns ``F``:
    ``g = F' r`` against its covariance ``s2 F' R F`` for noise of variance ``s2`` with the
    filter's correlation ``R = rho(|t_a - t_b|)``; chi-square with the rank's degrees of freedom
    where the residuals are that noise."""
    g = F.T @ r
    lag = np.abs(t[:, None] - t[None, :])
    R = np.where(lag < rho.size, rho[np.minimum(lag, rho.size - 1)], 0.0)
    V = s2 * (F.T @ R @ F)
    w, U = np.linalg.eigh(V)
    keep = w > 1e-9 * max(float(w.max()), 1e-300)
    u = U[:, keep].T @ g
    return float(np.sum(u**2 / w[keep])), int(keep.sum())


def adapted_windows(
    distance: np.ndarray,
    residual: np.ndarray,
    window,
    columns: list[np.ndarray] | None = None,
    rho: np.ndarray | None = None,
) -> np.ndarray:
    """Each joint's window (n,) [periods] from its residuals (N, n) on all rows after a fit
    with ``window`` (one value, or one per joint; module notes): the smallest of
    :data:`WINDOW_STEPS` (at least ``window``) from which on every bin of :data:`BIN_PERIODS`
    starting at a step has an RMS residual within ``1 +`` :data:`EXCESS` of the far rows'
    (beyond :data:`FAR_PERIODS`) and, given each joint's friction ``columns`` (N, k_j) and the
    rows' correlation ``rho`` (:func:`._filter_cov.filter_correlation`), no residual along
    them (:func:`band_score` beyond chi-square's ``1 -`` :data:`ALPHA` quantile)."""
    n = residual.shape[1]
    out = np.broadcast_to(np.asarray(window, dtype=float), (n,)).copy()
    for j in range(n):
        steps = [w for w in WINDOW_STEPS if w >= out[j]]
        d, r = distance[:, j], residual[:, j]
        far = d >= FAR_PERIODS
        if far.sum() < MIN_BIN_ROWS or not steps:
            continue  # no far rows to compare with: keep the window given
        s2 = float(np.mean(r[far] ** 2))
        limit = (1.0 + EXCESS) * np.sqrt(s2)
        bad = []
        for i, lo in enumerate(steps):
            b = np.flatnonzero((d >= lo) & (d < lo + BIN_PERIODS))
            if b.size < MIN_BIN_ROWS:
                continue
            if np.sqrt(np.mean(r[b] ** 2)) > limit:
                bad.append(i)
            elif columns is not None and rho is not None:
                stat, dof = band_score(columns[j][b], r[b], b, rho, s2)
                if dof and stat > scipy.stats.chi2.ppf(1.0 - ALPHA, dof):
                    bad.append(i)
        if bad:
            out[j] = steps[min(bad[-1] + 1, len(steps) - 1)]
    return out


def stick_signature(
    distance: np.ndarray,
    residual: np.ndarray,
    moving: np.ndarray,
    columns: list[np.ndarray],
    rho: np.ndarray,
) -> list[dict[str, float]]:
    """Per joint, what its residuals (N, n) show on the fitted rows ``moving`` within one
    period of the cut-off of a stop or reversal (``distance`` < 1, :func:`stop_distance`),
    against its far rows (beyond :data:`FAR_PERIODS`): ``excess`` (their RMS over the far
    rows', less one) and ``p`` (:func:`band_score`'s p-value that they hold nothing along the
    joint's friction ``columns``). NaN where either part has under :data:`MIN_BIN_ROWS` rows."""
    out = []
    for j in range(residual.shape[1]):
        d, r = distance[:, j], residual[:, j]
        far = moving[:, j] & (d >= FAR_PERIODS)
        b = np.flatnonzero(moving[:, j] & (d < 1.0))
        if far.sum() < MIN_BIN_ROWS or b.size < MIN_BIN_ROWS:
            out.append({"excess": float("nan"), "p": float("nan"), "rows": int(b.size)})
            continue
        s2 = float(np.mean(r[far] ** 2))
        stat, dof = band_score(columns[j][b], r[b], b, rho, s2)
        p = float(scipy.stats.chi2.sf(stat, dof)) if dof else 1.0
        excess = float(np.sqrt(np.mean(r[b] ** 2) / s2) - 1.0)
        out.append({"excess": excess, "p": p, "rows": int(b.size)})
    return out


def sticking(signature: list[dict[str, float]]) -> list[int]:
    """The joints whose :func:`stick_signature` shows sticks at their reversals (module
    notes: :data:`STICK_P`, :data:`STICK_EXCESS`)."""
    return [
        j
        for j, s in enumerate(signature)
        if s["p"] <= STICK_P or s["excess"] > STICK_EXCESS  # NaN: not judged
    ]


def closed_loop_text(stuck: list[int], joints: tuple[str, ...], rise: list[bool]) -> str:
    """The fit's ``closed_loop`` provenance when fricid decided it (:func:`sticking`);
    ``rise[j]``: joint ``j``'s family has a Stribeck rise. Without one, the misfit near the
    reversals may be the rise the law misses as well as a stick (open-loop logs fitted with
    a Coulomb-viscous law were taken for closed loop), and the text says both."""
    if not stuck:
        return "not detected: no joint's residual shows sticks at its reversals"
    names = ", ".join(joints[j] for j in stuck)
    text = (
        f"detected: the residuals of {names} near their reversals hold a misfit, as a joint "
        "sticking while a position loop builds torque leaves, so the rows there were left "
        "out as for --closed-loop"
    )
    if all(rise[j] for j in stuck):
        return text
    return (
        f"{text}; a friction law without the Stribeck rise the data show leaves such a misfit "
        "too (on an open-loop log: --open-loop with a Stribeck family, e.g. --friction "
        "stribeck_asym)"
    )


def still_text(sig: ArmSignals, window: float = 0.0) -> str:
    """Why no row is kept: no motion, motion hidden under the encoder's velocity noise after
    the low-pass (a coarse encoder: a lower cut-off lets the motion through), or, with a
    reversal ``window``, no row that far from a stop."""
    fastest = np.abs(sig.dq).max(axis=0)
    floor = np.maximum(VELOCITY_NOISE_FACTOR * sig.velocity_noise, MIN_SPEED)
    if not (fastest >= MIN_SPEED).any():
        return "no joint moves in the log: nothing to identify"
    if window > 0 and (fastest >= floor).any():
        return (
            f"no row is {window:g} periods of the cut-off ({window / sig.cutoff:.3g} s at "
            f"{sig.cutoff:.3g} Hz) from its joint's nearest slow sample or reversal, so the "
            "closed-loop window leaves nothing to fit; the slow samples are those under "
            f"{np.array2string(floor, precision=3)} rad/s ({VELOCITY_NOISE_FACTOR:g}x the "
            "encoder's velocity noise): give a lower --cutoff (the noise falls with it), "
            "or fit without --closed-loop"
        )
    return (
        "no joint moves faster than its encoder's velocity noise lets it be seen: fastest "
        f"filtered speeds {np.array2string(fastest, precision=3)} rad/s against "
        f"{np.array2string(floor, precision=3)} ({VELOCITY_NOISE_FACTOR:g}x the noise of "
        f"encoder steps {np.array2string(sig.encoder_step, precision=3)} rad after the "
        f"low-pass at {sig.cutoff:.3g} Hz); a coarse encoder: give a lower --cutoff (a few "
        "times the motion's highest frequency) or --encoder-counts"
    )
