"""The ``presliding`` route of :mod:`fricid.identify.dynamic.trajectory`: LuGre's bristle
stiffness and damping from a log that never slides (creep, small oscillations below
break-away).

Why a route of its own. Below break-away LuGre is a spring-damper ([CW95] section II: "for
small displacements the model behaves like a spring"; Astrom and Canudas de Wit 2008,
"Revisiting the LuGre friction model", IEEE Control Systems 28(6), section "Presliding"):
with ``z`` far below ``g(v) / sigma_0`` the bristles move with the joint, ``dz/dt ~ v``, and
the friction is ``sigma_0 (q - q_0) + (sigma_1 + sigma_2) v``. Such a log never reaches the
speeds at which the other routes' sliding samples begin, so they refuse it ("only 0 samples
slide"), and it cannot tell the sliding friction (tau_c, tau_s, w_s, delta, sigma_2) at all.

The model. The joint ``J qdd = u - c - F`` (``c`` the torque at which the bristles are
unloaded: the gravity torque at rest and any offset of the torque sensor) with LuGre's
friction at a constant level ``g(v) = g_0``: over pre-sliding speeds (``|v| << w_s``) the
Stribeck curve is its value at rest, so ``g_0`` is ``tau_s`` there, but the log cannot tell
whether it is (it never reaches ``w_s``), and ``g_0`` only sets how fast the joint creeps
under load (the drift ``sigma_0 |v| z / g_0`` of the position away from the bristles, [CW95]
eq. 2). It is searched as the load ratio ``rho = max |u - c| / g_0`` in ``[0, 0.99]``. The
damping is one coefficient: ``sigma_1 dz/dt + sigma_2 v`` are ``(sigma_1 + sigma_2) v`` to
first order in ``z / (g_0 / sigma_0)`` and a pre-sliding log determines their sum
(``sigma_1`` with ``sigma_2`` folded in; :mod:`._presliding_fit` says how it is reported).
Simulated by :func:`fricid.models.lugre.simulate_joint` (exact per sub-step for any
stiffness) under the logged torque held over each period, as the filtered route assumes
(the drive holds ``u_i`` until sample ``i + 1``).

Why J. The damping shows only as a lag of the position behind the torque, ``sigma_1 /
sigma_0`` (0.17 ms for sigma_0 = 2e4 N m/rad, sigma_1 = 3.4 N m s/rad): a fraction of a 1 kHz
period. How a held torque reaches the sampled position within a period depends on the
bristle resonance ``sqrt(sigma_0 / J)`` against the rate (settled within a period when it is
fast, the held steps smoothed, a lag of half a period, when it is slow), so J is searched
with the others, on a log scale over resonances of 0.1 to 10 per period (above four times the
cut-off), and sigma_0's and sigma_1's intervals are the union over the J the log does not
reject (:data:`PROFILE_POINTS`). A creep excites nothing near the resonance: J is reported
not determined.

Errors in the torque. The logged torque drives the simulation, so its noise does too, and
the simulated bristles creep under it as the real ones do not (each noise wiggle moves the
joint a little; measured on ``benchmarks/_lugre_truth.py``'s geared creep, 20 s, true
position: sigma_1 came out x50 with the raw torque). Both the torque driving the simulation
and the position residual are therefore low-passed by one zero-phase Butterworth
(:class:`._filtered.ParallelFilter`, :data:`CUTOFF` Hz by default, parallel filtering as in
the filtered route) and the residual decimated. What noise stays below the cut-off still
biases the damping (the same log: +28 % at 5 Hz with J known), which the check by simulation
at the estimate (:func:`bias_check`) measures.

Uncertainty: the cluster-robust covariance of the position residual (blocks of
``cluster_time`` seconds, :func:`._data.cluster_covariance`), t quantiles with G - 1 degrees
of freedom, log scale for sigma_0, the damping and J; then the check by simulation at the
estimate (the joint with the estimate as its truth under the low-passed logged torque, the
torque's noise added at the level read from the log, the position read through the log's
encoder, identified again): a parameter's bias beyond one standard error widens its interval
to cover the corrected value too, a gross one flags it not determined
(:data:`._outcome.WIDEN`, :data:`._outcome.GROSS`: the conventions of the filtered route).

Known model error. The constant level and the constant gravity torque are approximations:
the Stribeck curve falls at creep speeds when ``w_s`` is low, and the gravity's stiffness
acts on the joint's creep. On the benchmark's slow_stribeck joint (``w_s`` 5 mrad/s, gravity
stiffness 3e-4 of sigma_0) the noise-free fit put sigma_1 30 % low (seeds 14-15, narrow
intervals); with noise and the encoder its intervals covered it (14 of 16 claimed, seeds
10-19). Searching both as nuisances made the noise-free fit exact (5.06 for 5.1) but, on
seeds 20-29 of ``bench_lugre.py --kinds creep``, covered sigma_1 on 18 of 23 claimed fits
(this route: 28 of 31 on seeds 10-19) with 27 not determined, in nearly twice the time: not kept.

Closed loop. A drive holding position under PD logs a torque that reacts to the encoder's
rounding; the simulation takes the logged torque as the applied one, which it is, but the
rounding then enters both the input and the output. Its effect on the simulated position is
the loop's stiffness over sigma_0 (small for a loop softer than the bristles); the check by
simulation is open-loop and does not measure it, and no closed-loop creep has been measured.

The encoder. Rounding to ``Delta`` (2 pi / counts per revolution) is comparable to the
deflection ``max |u - c| / sigma_0`` on a geared joint (2^17 counts/rev: 4.8e-5 rad against
5e-5 rad at 1 N m and sigma_0 = 2e4 N m/rad): a log whose position spans fewer than
:data:`MIN_SPAN_COUNTS` counts is refused (the encoder does not see the bristles), and one
whose deflection is under :data:`RESOLVED_COUNTS` counts is fitted with a warning naming the
numbers; the check by simulation reads the position through the same encoder.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ...errors import DataError
from ...models import lugre
from ...optim import minimize
from ..problem import ResidualProblem
from ..static.convergence import POLISH_EVALS_PER_PARAM, RESOLVE_SE, noise_ftol
from ..static.uncertainty import jacobian
from ._data import Series, blocks, cluster_covariance, torque_noise
from ._filtered import LOG_BOX, ParallelFilter
from ._outcome import GROSS, WIDEN
from ._rate import quantise
from ._routes import SEARCH_SHARE, _run, _Stage, _t975

__all__ = ["CUTOFF", "MIN_SPAN_COUNTS", "NAMES", "RESOLVED_COUNTS", "presliding_route"]

#: The default cut-off [Hz] of the low-pass on the torque and the position residual.
CUTOFF = 5.0

#: Fewest encoder counts the logged position must span (else the log is refused).
MIN_SPAN_COUNTS = 3.0

#: Counts of the largest deflection below which the fit warns that the encoder hardly
#: resolves the bristles (as :data:`._output.RESOLVED_COUNTS`).
RESOLVED_COUNTS = 10.0

#: Resonances ``sqrt(sigma_0 / J)`` per sample period spanned by J's search box (the lower end
#: raised to keep the resonance :data:`RESONANCE_OVER_CUTOFF` times above the cut-off: a
#: resonance in the filter's band would be a joint that does not creep quasi-statically).
RESONANCE_BOX = (0.1, 10.0)
RESONANCE_OVER_CUTOFF = 4.0

#: Values of J (log-spaced over its box) at which sigma_0's and sigma_1's intervals are found
#: again with J held; their union is reported (module notes).
PROFILE_POINTS = 4

#: The chi-square quantile (one degree of freedom, 95 %) of the likelihood-ratio test by
#: which a held J joins the union: ``SSE_J <= SSE (1 + 3.84 k / (n - p))``, ``k`` the
#: residuals' design effect (:func:`_long_run`).
CHI2_95 = 3.841

#: Searched parameters, in order (sigma_1: the damping with sigma_2 folded in).
NAMES = ("sigma_0", "sigma_1", "load_ratio", "torque_offset", "inertia")
_LOG = np.array([True, True, False, False, True])

#: The damping's search box as the lag ``sigma_1 / sigma_0`` it makes, in sample periods (at
#: the start's sigma_0): from far below what any log resolves to far above a creep's lag.
LAG_BOX = (1e-4, 100.0)

#: Polishes of the search's result, as the convergence certificate polishes it
#: (:func:`fricid.identify.static.convergence.certify`), while one still lowers the SSE by
#: more than the certificate resolves: the residual is a simulation whose bristle rate is
#: frozen over each sub-step, not smooth at the scale of a tenth of a standard error, and lm
#: stopped short of points the certificate's polish then found.
RESTARTS = 6

#: Sub-steps per period of the check's simulation (as :data:`._rate.SUB_STEPS`).
CHECK_SUB_STEPS = 16


def _positions(U: np.ndarray, w: np.ndarray, dt: float, n_sub: int) -> np.ndarray:
    """Simulated positions ``(k, n)`` of candidates ``U (k, 5)`` (search coordinates) under
    the torque ``w`` (before the offset), from rest at the force balance."""
    U = np.atleast_2d(U)
    s0, d, J = 10.0 ** U[:, 0], 10.0 ** U[:, 1], 10.0 ** U[:, 4]
    rho, c = U[:, 2], U[:, 3]
    load = np.max(np.abs(w[None, :] - c[:, None]), axis=1)
    g0 = load / np.maximum(rho, 1e-9)
    theta = np.column_stack([s0, d, np.zeros(len(U)), g0, g0, np.ones(len(U)), np.ones(len(U))])
    # the offset as a constant "gravity" p_x cos q, q within micro-radians of 0 (cos q = 1
    # to 1e-9): every candidate in one batch under the same torque
    sim = lugre.simulate_joint(
        theta, J, -c, 0.0, dt, w, q0=0.0, v0=0.0, z0=(w[0] - c) / s0, n_sub=n_sub
    )
    return np.atleast_2d(sim["position"])


def _natural(x: np.ndarray, logs: np.ndarray) -> np.ndarray:
    return np.where(logs, 10.0 ** np.where(logs, x, 0.0), x)


def presliding_route(
    series: Series,
    encoder: dict[str, Any],
    method: str,
    seed: int,
    max_evals: int | None,
    cluster_time: float,
    n_sub: int,
    filt: ParallelFilter,
    source: str | None = None,
    start: np.ndarray | None = None,
) -> tuple[_Stage, dict[str, Any]]:
    """sigma_0, the damping, the load ratio, the torque offset and J from a pre-sliding log
    (module notes).

    Returns the stage (:data:`NAMES`, then ``position_offset`` [rad]; natural units) and the
    route's record: the filter, the torque's noise, the encoder's resolution, the filtered
    torque and residuals (``y``, ``residual`` [N m]: sigma_0 times the position residual,
    the torque the bristles would need to follow the measured position).

    Raises
    ------
    DataError
        Too short for the filter, a position that spans too few counts, or one that does
        not follow the torque.
    """

    t0 = time.perf_counter()
    dt, n = series.dt, series.time.size
    rate = 1.0 / dt
    q, u = series.position, series.torque
    quantum = encoder.get("quantum")
    span = float(np.ptp(q))
    levels = np.unique(q)
    if not quantum and levels.size <= MIN_SPAN_COUNTS:  # too few steps to read a quantum from
        seen = (
            f"takes {levels.size} distinct values over the whole log (steps of "
            f"{np.min(np.diff(levels)):.3g} rad)"
            if levels.size > 1
            else f"never changes over the whole log ({levels[0]:.6g} rad)"
        )
        raise DataError(
            f"the position {seen}: the encoder does not resolve the pre-sliding deflection; "
            "sigma_0 and sigma_1 need a finer encoder or a larger torque below break-away",
            file=source,
        )
    if quantum and round(span / quantum) < MIN_SPAN_COUNTS:
        raise DataError(
            f"the position spans {span / quantum:.3g} counts of the encoder ({quantum:.3g} rad, "
            f"{encoder['counts_per_rev']:.10g} counts/rev) over the whole log: the encoder "
            f"does not resolve the pre-sliding deflection (at least {MIN_SPAN_COUNTS:g} counts "
            "needed); sigma_0 and sigma_1 need a finer encoder or a larger torque below "
            "break-away",
            file=source,
        )
    low, keep = filt.lowpass(rate), filt.kept(rate, n)
    if keep.size < 30:
        raise DataError(
            f"the log ({n * dt:.3g} s) is too short for the pre-sliding route's filter "
            f"({filt.cutoff:g} Hz): it needs {2 * filt.trim:g} s trimmed and 30 decimated "
            "samples besides",
            file=source,
        )
    w = low(u)
    scale = float(quantum) if quantum else max(span, 1e-12) / 100.0
    y = low(q)[keep] / scale

    def full(P):
        """Residuals of ``P (k, 6)``: the searched five and the position offset."""
        P = np.atleast_2d(P)
        sim = _positions(P[:, :5], w, dt, n_sub)
        return y[None, :] - low(sim)[:, keep] / scale - P[:, 5:6] / scale

    def projected(U):
        R = y[None, :] - low(_positions(U, w, dt, n_sub))[:, keep] / scale
        R = R - R.mean(axis=1, keepdims=True)
        return np.where(np.isfinite(R), R, 1e6)

    slope = np.polyfit(w[keep], q[keep], 1)[0]
    if not slope > 0:
        raise DataError(
            "the position does not follow the torque (it moves against it): no bristle "
            "stiffness to identify; is the torque's sign the position's?",
            file=source,
        )
    s0 = 1.0 / slope
    slowest = max(RESONANCE_BOX[0], RESONANCE_OVER_CUTOFF * 2.0 * math.pi * filt.cutoff * dt)
    box = np.array(
        [
            LOG_BOX["sigma_0"],
            tuple(math.log10(s0 * dt * r) for r in LAG_BOX),
            (0.0, 0.99),
            (float(w.min()), float(w.max())),
            tuple(math.log10(s0 * (dt / r) ** 2) for r in (RESONANCE_BOX[1], slowest)),
        ]
    )
    search = ResidualProblem(projected, box, NAMES, y)
    if start is None:
        grid = [
            [math.log10(s0), math.log10(s0 * dt * f), 0.3, float(np.median(w)), jl]
            for f in (0.1, 1.0)
            for jl in (math.log10(s0 * (dt / r) ** 2) for r in (0.3, 1.0, 3.0))
        ]
        grid = np.clip(np.array(grid), box[:, 0], box[:, 1])
        x0 = grid[int(np.argmin(search.evaluate(grid)))]
    else:
        x0 = np.clip(start, box[:, 0], box[:, 1])
    ftol = noise_ftol(search, SEARCH_SHARE)
    result = _run(search, method, x0, seed, max_evals, 1, ftol)
    for _ in range(RESTARTS):  # lm stops early in the flat valleys of J and the load ratio
        again = minimize(  # as the convergence certificate polishes (convergence.certify)
            search.evaluate,
            box,
            method="lm",
            x0=np.clip(result.x, box[:, 0], box[:, 1]),
            options={"n_starts": 1, "ftol": ftol},
            max_evals=POLISH_EVALS_PER_PARAM * (len(NAMES) + 1),
            residuals=search.residuals,
            seed=0,
        )
        again.nfev += result.nfev
        gained = float(result.fun) - float(again.fun)
        if gained <= RESOLVE_SE**2 * float(again.fun) / max(y.size - len(NAMES), 1):
            break  # kept where it was: the certificate's polish from there gains as little
        result = again
    u_hat = np.asarray(result.x, dtype=float)
    r_hat = projected(u_hat)[0]
    labels = blocks(n, max(round(cluster_time * rate), 1))[keep]
    logs = np.concatenate([_LOG, [False]])
    box_all = np.vstack([box, [-np.inf, np.inf]])

    def offset_at(U):
        return float(np.mean(y - low(_positions(U, w, dt, n_sub))[0, keep] / scale)) * scale

    p_hat = np.concatenate([u_hat, [offset_at(u_hat)]])
    cov, se, g, low_u, high_u = _intervals(full, p_hat, labels, box_all)
    profile = []
    if start is None:  # the estimate's own check (bias_check) needs the point estimate only
        sse = float(r_hat @ r_hat)
        limit = sse * (1.0 + CHI2_95 * _long_run(r_hat) / max(r_hat.size - len(NAMES) - 1, 1))
        for jl in np.linspace(box[4, 0], box[4, 1], PROFILE_POINTS):
            row = _at_inertia(jl, u_hat, projected, full, offset_at, labels, box_all, y, method)
            row["inertia"] = 10.0**jl
            row["accepted"] = bool(row["sse"] <= limit)
            profile.append(row)
            if row["accepted"]:
                low_u[:2] = np.minimum(low_u[:2], np.log10(row["low"]))
                high_u[:2] = np.maximum(high_u[:2], np.log10(row["high"]))
    values = _natural(p_hat, logs)
    stderr = np.where(logs, values * math.log(10.0) * se, se)
    s0_hat = float(values[0])
    stage = _Stage(
        [*NAMES, "position_offset"],
        values,
        stderr,
        _natural(low_u, logs),
        _natural(high_u, logs),
        cov,
        result,
        time.perf_counter() - t0,
        g,
        {"position_filtered": float(np.sqrt(np.mean(r_hat**2))) * scale},
        np.column_stack([_natural(box_all[:, 0], logs), _natural(box_all[:, 1], logs)]),
        search,
    )
    load = float(np.max(np.abs(w - values[3])))
    info = {
        "filter": filt.describe(rate),
        "inertia_profile": profile,
        "torque_noise": torque_noise(u),
        "span_counts": span / quantum if quantum else None,
        "deflection": load / s0_hat,
        "deflection_counts": load / s0_hat / quantum if quantum else None,
        "bristle_level": load / max(float(values[2]), 1e-9),
        "max_speed": float(np.max(np.abs(np.gradient(low(q), dt)))),
        "y": low(u)[keep] - values[3],
        "residual": s0_hat * scale * r_hat,
        "w": w,
        "scale": scale,
    }
    return stage, info


def _intervals(full, p_hat, labels, box):
    """Cluster-robust covariance, standard errors, clusters and the 95 % interval's ends of
    ``p_hat`` (search coordinates) in ``box``."""
    Jm, r0 = jacobian(full, p_hat)
    cov, se, g = cluster_covariance(Jm, r0, labels)
    tq = _t975(g - 1)
    return (
        cov,
        se,
        g,
        np.maximum(p_hat - tq * se, box[:, 0]),
        np.minimum(p_hat + tq * se, box[:, 1]),
    )


def _at_inertia(jl, u_hat, projected, full, offset_at, labels, box, y, method) -> dict[str, Any]:
    """sigma_0 and sigma_1 with J held at ``10**jl``: estimates, 95 % intervals (natural
    units) and the SSE, for the union of intervals over J (module notes)."""

    def with_j(U):
        U = np.atleast_2d(U)
        return np.column_stack([U[:, :4], np.full(len(U), jl), U[:, 4:]])

    sub = ResidualProblem(lambda U: projected(with_j(U)), box[:4], NAMES[:4], y)
    result = _run(sub, method, np.clip(u_hat[:4], *box[:4].T), 0, None, 1, noise_ftol(sub))
    u4 = np.asarray(result.x, dtype=float)
    p = np.concatenate([u4, [offset_at(with_j(u4)[0])]])
    keep = [0, 1, 2, 3, 5]
    _, _, _, lo, hi = _intervals(lambda P: full(with_j(P)), p, labels, box[keep])
    return {
        "sigma_0": 10.0 ** u4[0],
        "sigma_1": 10.0 ** u4[1],
        "low": 10.0 ** lo[:2],
        "high": 10.0 ** hi[:2],
        "sse": float(sub.evaluate(u4[None, :])[0]),
    }


def _long_run(r: np.ndarray) -> float:
    """The residuals' long-run variance over their variance (Bartlett weights up to a tenth
    of their length; Newey and West 1987), at least 1: the design effect by which correlated
    residuals widen a likelihood-ratio threshold."""
    r = r - r.mean()
    lags = max(min(r.size // 10, 50), 1)
    var = float(r @ r)
    if var <= 0:
        return 1.0
    ac = [float(r[:-k] @ r[k:]) / var for k in range(1, lags + 1)]
    return max(1.0, 1.0 + 2.0 * sum((1 - k / (lags + 1)) * a for k, a in enumerate(ac, 1)))


def bias_check(
    series: Series,
    stage: _Stage,
    info: dict[str, Any],
    encoder: dict[str, Any],
    method: str,
    seed: int,
    cluster_time: float,
    n_sub: int,
    filt: ParallelFilter,
) -> dict[str, Any]:
    """Each parameter's bias by simulation at the estimate (module notes): ``{"parameters":
    {name: {"bias", "relative", "corrected", "scale"}}, "seconds"}`` or ``{"skipped": why}``."""
    from ...errors import FricidError

    t0 = time.perf_counter()
    dt, w = series.dt, info["w"]
    U = np.where(_LOG, np.log10(np.maximum(stage.values[:5], 1e-300)), stage.values[:5])
    sim = _positions(U, w, dt, CHECK_SUB_STEPS)[0] + stage.values[5]
    if not np.isfinite(sim).all():
        return {"skipped": "the simulation at the estimate diverged"}
    rng = np.random.default_rng([int(seed), 17])
    torque = w + rng.standard_normal(w.size) * info["torque_noise"]
    quantum = encoder.get("quantum")
    position = quantise(sim, quantum, encoder.get("offset", 0.0)) if quantum else sim
    again = Series(series.time, position, series.velocity, torque, series.temperature, dt, False)
    try:
        redo, _ = presliding_route(
            again, encoder, method, seed, None, cluster_time, n_sub, filt, start=U
        )
    except FricidError as exc:
        return {"skipped": f"the re-identification failed: {exc}"}
    out = {}
    for i, name in enumerate(NAMES):
        v, r = float(stage.values[i]), float(redo.values[i])
        if _LOG[i]:
            b = math.log10(r) - math.log10(v)
            out[name] = {"bias": b, "relative": 10.0**b - 1.0, "scale": "log10"}
            out[name]["corrected"] = v * 10.0 ** (-b)
        else:
            rel = (r - v) / abs(v) if v else float("nan")
            out[name] = {"bias": r - v, "relative": rel, "scale": "linear", "corrected": 2 * v - r}
    return {"parameters": out, "seconds": time.perf_counter() - t0}


def widen(stage: _Stage, check: dict[str, Any], names: tuple[str, ...]) -> dict[str, str]:
    """Widen ``stage``'s intervals of ``names`` (in place) by the check's biases, or flag a
    parameter not determined, by the filtered route's rule (:func:`._outcome.calibrate`);
    returns the notes."""
    notes: dict[str, str] = {}
    for name in names:
        row = check.get("parameters", {}).get(name)
        if row is None:
            continue
        i = stage.names.index(name)
        b, log = row["bias"], row["scale"] == "log10"
        v = float(stage.values[i])
        se = float(stage.stderr[i]) / (v * math.log(10.0)) if log else float(stage.stderr[i])
        row["in_stderr"] = abs(b) / se if se > 0 else float("inf")
        row["verdict"] = "kept"
        if not (math.isfinite(se) and abs(b) > WIDEN * se):
            continue
        lo, hi, box = stage.low[i], stage.high[i], stage.bounds[i]
        if log:
            lo, hi, box = np.log10(lo), np.log10(hi), np.log10(box)
        size = abs(b) if log else abs(b) / max(abs(v), 1e-300)
        said = f"{100 * row['relative']:+.3g} %, {row['in_stderr']:.2g} standard errors"
        if size > GROSS["log10" if log else "linear"]:
            row["verdict"] = "not determined"
            notes[name] = (
                "not determined: the simulation at the estimate (the log's torque noise and "
                f"encoder) biases it by {said}"
            )
        else:
            row["verdict"] = "widened"
            notes[name] = f"interval widened by the bias simulated at the estimate ({said})"
        lo, hi = max(min(lo, lo - b), box[0]), min(max(hi, hi - b), box[1])
        stage.low[i], stage.high[i] = (10.0**lo, 10.0**hi) if log else (lo, hi)
    return notes
