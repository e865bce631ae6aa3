"""The output-error step of the ``filtered`` route for a coarse encoder: every LuGre parameter
with J, p_x, p_y by the torque the joint needs to follow the measured motion in simulation.

Why. The filtered route drives the bristle state with the measured motion; read through an
encoder whose count is comparable to the bristles' deflection at break-away (``tau_s /
sigma_0``; 1.9 counts for a geared joint at 2^17 counts/rev) or whose one count per sample
is faster than the Stribeck velocity, that drive is wrong by the quantisation at every
reversal and rest, and the equation error is biased however long the log (an
errors-in-variables bias, not a variance: measured on the independent simulator of
``benchmarks/bench_lugre.py``, geared joint, PD-tracked trapezoid, 2^17 counts/rev, 20 s:
sigma_0 -68 %, sigma_1 x39, tau_s +34 %; with the true position every parameter within its
interval).

How (DIDIM: Gautier, Janot and Vandanjon 2013, "A new closed-loop output error method for
parameter identification of robot dynamics", IEEE TCST 21(2)). The joint with the
candidate's parameters is simulated (:func:`fricid.models.lugre.simulate_joint`, ``n_sub``
sub-steps per period) under the measured torque as a feed-forward plus a PD loop tracking the
measured position (gains for :data:`BANDWIDTH` Hz at damping :data:`DAMPING` with the
starting J), so it stays on the measured motion without integrating it open loop; the
residual is the measured torque minus the simulated motor torque (minus the PD's correction),
both low-pass filtered and decimated as in the filtered route. The quantised position enters
only as the loop's reference, whose rounding error the loop filters; the bristle state
evolves with the simulated, continuous motion. Started from the filtered route's estimate;
intervals from the cluster-robust covariance of this residual (blocks of ``cluster_time``).

Measured (the same logs, 20 s, started from the filtered estimate): geared chirp sigma_1
+257 % -> +43 %, tau_s +32 % -> +2 %, w_s +40 % -> -3 %; cdw95 chirp sigma_0 -69 % -> -1 %,
sigma_1 -60 % -> -3 %, tau_c +115 % -> +1 %; the Stribeck trio stays undetermined where the
Stribeck velocity is below the encoder's resolution per sample (cdw95: 1 mrad/s).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...models import lugre
from ..problem import ResidualProblem
from ..static.convergence import noise_ftol, settle
from ..static.uncertainty import jacobian
from ._data import Series, blocks, cluster_covariance
from ._filtered import LOG_BOX, ParallelFilter
from ._routes import JOINT_PARAMS, SEARCH_SHARE, _run, _Stage, _t975

__all__ = ["BANDWIDTH", "DAMPING", "RESOLVED_COUNTS", "needs_output_error", "output_error"]

#: The tracking loop's bandwidth [Hz] and damping ratio.
BANDWIDTH = 10.0
DAMPING = 0.7

#: Counts of the bristles' deflection at break-away below which the encoder does not resolve
#: the bristles (the equation error's drive is then wrong by a sizeable part of it).
RESOLVED_COUNTS = 10.0

#: The fraction of the Stribeck velocity below which one count per sample is too coarse. The
#: estimate it is judged at is the equation error's, whose sigma_0 the coarse encoder biases
#: low (the deflection then looks resolved: a geared trapezoid at 2^17 counts/rev read 11.9
#: counts where the truth has 1.9), so the speed test carries a margin of two.
SPEED_FRACTION = 0.5

#: The second start's sigma_1 as a fraction of the bristles' critical damping
#: ``2 sqrt(sigma_0 J)``. The first start, the filtered route's estimate, can hold sigma_1 at
#: its lower bound, where its log-scale column vanishes: on the independent simulator's geared
#: chirp (2^17 counts/rev, 20 s) the search then ended at 20 times the truth's SSE (sigma_1
#: at 1e-3, w_s +64 %, delta +83 %); from the regression's static part with this damping it
#: reached the truth's SSE with sigma_0 -2.9 %, sigma_1 +1.9 %, J -0.07 %.
SECOND_DAMPING = 0.1

#: A coordinate within this share of its range from a face of the box is on the face.
AT_FACE = 1e-6

#: Evaluation budget of the output-error search when none is given (400 left 4 of 18
#: benchmark fits short of a certified optimum: the polish still moved them 0.2 standard
#: errors).
MAX_EVALS = 1000


def needs_output_error(stage: _Stage, encoder: dict[str, Any], dt: float) -> dict[str, Any]:
    """Whether the encoder is too coarse for the equation error at the estimate ``stage``:
    the bristles' deflection at break-away ``tau_s / sigma_0`` in counts (below
    :data:`RESOLVED_COUNTS`), or one count per sample against the Stribeck velocity (faster
    than :data:`SPEED_FRACTION` of it)."""
    quantum = encoder.get("quantum")
    if not quantum:
        return {"needed": False, "why": "no quantisation found"}
    v = dict(zip(stage.names, stage.values, strict=True))
    tau_s = min(x for n, x in v.items() if lugre.symmetric_name(n) == "tau_s")  # the weaker
    counts = tau_s / (v["sigma_0"] * quantum)
    per_sample = quantum / dt
    needed = bool(counts < RESOLVED_COUNTS or per_sample > SPEED_FRACTION * v["w_s"])
    return {
        "needed": needed,
        "breakaway_counts": float(counts),
        "count_per_sample_speed": float(per_sample),
        "why": f"bristle deflection at break-away {counts:.3g} counts (resolved from "
        f"{RESOLVED_COUNTS:g}); one count per sample {per_sample:.3g} rad/s against "
        f"{SPEED_FRACTION:g} w_s = {SPEED_FRACTION * v['w_s']:.3g} rad/s",
    }


def output_error(
    series: Series,
    stage: _Stage,
    gravity: str,
    method: str,
    seed: int,
    max_evals: int | None,
    cluster_time: float,
    n_sub: int,
    filt: ParallelFilter,
    second: Mapping[str, float] | None = None,
) -> tuple[_Stage, np.ndarray, np.ndarray]:
    """The output-error (DIDIM) step from the filtered route's ``stage`` (module notes).

    ``second``: values by name for a second start (the regression's static part and J; its
    sigma_1 at :data:`SECOND_DAMPING` of the bristles' critical damping), run when the first
    is doubtful (:func:`_doubtful`: on a face of the box); the start with the lower SSE is
    carried on (both SSEs in the result's ``starts``). Returns the stage (LuGre's
    parameters, symmetric or per direction, then J, p_x, p_y as ``stage``'s), the filtered
    measured torque and the residual at the estimate (decimated samples).
    """

    t0 = time.perf_counter()
    dt, n = series.dt, series.time.size
    rate = 1.0 / dt
    low, keep = filt.lowpass(rate), filt.kept(rate, n)
    q, u = series.position, series.torque
    reference = (q, np.gradient(q, dt))
    y = low(u)[keep]
    names = list(stage.names)
    d = names.index("inertia")  # the law's parameters come first
    nd = len(names) - d
    is_log = np.array([nm in LOG_BOX for nm in names])
    start = np.asarray(stage.values, dtype=float)
    J0 = float(start[d])
    wn = 2.0 * math.pi * BANDWIDTH
    gains = (J0 * wn**2, 2.0 * DAMPING * J0 * wn)

    def natural(U):
        U = np.atleast_2d(U)
        return np.where(is_log, 10.0 ** np.where(is_log, U, 0.0), U)

    def simulated(U):
        P = natural(U)
        k = len(P)
        p_x = P[:, d + 1] if nd >= 2 else np.zeros(k)
        p_y = P[:, d + 2] if nd >= 3 else np.zeros(k)
        sim = lugre.simulate_joint(
            P[:, :d],
            P[:, d],
            p_x,
            p_y,
            np.full(n, dt),
            u,
            q0=q[0],
            v0=reference[1][0],
            z0=0.0,
            reference=reference,
            gains=gains,
            n_sub=n_sub,
        )
        return np.atleast_2d(sim["torque"])

    def residuals(U):
        R = y[None, :] - low(simulated(U))[:, keep]
        return np.where(np.isfinite(R), R, 1e3 * (1.0 + np.abs(y).max()))

    box = _box(stage, is_log, start, float(np.max(np.abs(u))))
    x0 = np.clip(np.where(is_log, np.log10(np.maximum(start, 1e-300)), start), *box.T)
    search = ResidualProblem(residuals, box, names, y)
    ftol = noise_ftol(search, SEARCH_SHARE)  # each evaluation a simulation (module notes)
    result = _run(search, method, x0, seed, max_evals or MAX_EVALS, 1, ftol)
    if second and _doubtful(x0, np.asarray(result.x, dtype=float), box):
        x1 = _second_start(x0, names, second, box)
        other = _run(search, method, x1, seed, max_evals or MAX_EVALS, 1, ftol)
        nfev = int(result.nfev) + int(other.nfev)
        starts = {"filtered": float(result.fun), "regression": float(other.fun)}
        result = other if other.fun < result.fun else result
        result = type(result)({**result, "nfev": nfev, "starts": starts})
    result = settle(search, result, method, max_evals)
    u_hat = np.asarray(result.x, dtype=float)
    Jm, r0 = jacobian(residuals, u_hat)
    labels = blocks(n, max(round(cluster_time * rate), 1))[keep]
    cov, se, g = cluster_covariance(Jm, r0, labels)
    tq = _t975(g - 1)
    lo_u = np.maximum(u_hat - tq * se, box[:, 0])
    hi_u = np.minimum(u_hat + tq * se, box[:, 1])
    values = natural(u_hat)[0]
    stderr = np.where(is_log, values * math.log(10.0) * se, se)
    out = _Stage(
        names,
        values,
        stderr,
        natural(lo_u)[0],
        natural(hi_u)[0],
        cov,
        result,
        time.perf_counter() - t0,
        g,
        {"torque_filtered": float(np.sqrt(np.mean(r0**2)))},
        np.column_stack([natural(box[:, 0])[0], natural(box[:, 1])[0]]),
        search,
    )
    return out, y, r0


def _doubtful(x0: np.ndarray, x: np.ndarray, box: np.ndarray) -> bool:
    """Whether the first start calls for the second: it began or ended on a face of the box
    (where the first start's log-scale sigma_1 column vanishes, :data:`SECOND_DAMPING`). A
    first start that spent its budget inside the box is carried on by :func:`settle`'s
    polishes instead: on a geared chirp of 60 s at 1 kHz (2^17 counts/rev,
    ``benchmarks/bench_lugre.py``, seed 10) both starts had spent their 1000 evaluations in
    a flat valley, the second ended higher, and the fit was the first's polished, bit for
    bit the same without the second: 57.7 s instead of 86.4 s
    (``benchmarks/results/lugre_speed60.txt``): whether the search converged or spent its
    budget does not enter."""
    width = box[:, 1] - box[:, 0]

    def on_face(p: np.ndarray) -> bool:
        return bool(np.any(np.minimum(p - box[:, 0], box[:, 1] - p) <= AT_FACE * width))

    return on_face(x0) or on_face(x)


def _second_start(
    x0: np.ndarray, names: list[str], second: Mapping[str, float], box: np.ndarray
) -> np.ndarray:
    """The second start in the search's coordinates: ``x0`` with ``second``'s values, sigma_1
    at :data:`SECOND_DAMPING` of critical for the bristles (``2 zeta sqrt(sigma_0 J)``)."""
    x = x0.copy()
    for name, value in second.items():
        if name in names:
            x[names.index(name)] = value
    inertia = float(x[names.index("inertia")])
    damping = 2.0 * SECOND_DAMPING * math.sqrt(10.0 ** x[0] * max(inertia, 1e-300))
    x[names.index("sigma_1")] = math.log10(damping)
    return np.clip(x, box[:, 0], box[:, 1])


def _box(stage: _Stage, is_log: np.ndarray, start: np.ndarray, torque_span: float) -> np.ndarray:
    """The search box in the search's coordinates: the filtered route's for the law (log10
    for sigma_0, sigma_1), J within a factor of five, p_x and p_y within the gravity vector's
    length ``hypot(p_x, p_y)`` (so both reach zero) or 5 % of the torque span."""
    rows = []
    names = list(stage.names)
    gravity = math.hypot(*(start[names.index(n)] for n in ("p_x", "p_y") if n in names))
    for i, name in enumerate(stage.names):
        if is_log[i]:
            rows.append(LOG_BOX[name])
        elif name == "inertia":
            rows.append((0.2 * start[i], 5.0 * start[i]))
        elif name in JOINT_PARAMS:
            half = max(gravity, 0.05 * torque_span)
            rows.append((start[i] - half, start[i] + half))
        else:
            rows.append(tuple(stage.bounds[i]))
    return np.array(rows, dtype=float)
