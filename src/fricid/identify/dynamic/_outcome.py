"""What a trajectory identification reports beside its parameters: convergence of its stages
(certified as an analytic fit's), LuGre's passivity (Barabanov and Ortega 2000), the bias of
the log's rate, encoder and closed loop found by simulation at the estimate, and what it does
to the intervals.

Calibration by that bias (:func:`calibrate`). The simulation at the estimate
(:mod:`._rate`: the joint with the estimate as its truth, tracking the measured motion under
PD, logged at the log's rate through the log's encoder, identified again by the same route)
gives each parameter's bias ``b`` in the search's coordinates (log10 for sigma_0, sigma_1).
It is not subtracted (for sigma_1 it over-corrects by about half, :mod:`._rate`, and it is
evaluated at a noisy estimate), but where it exceeds the parameter's standard error the 95 %
interval is widened to cover the corrected one as well: ``[min(lo, lo - b), max(hi, hi -
b)]`` (an interval for the truth under either reading: the estimate unbiased, or biased by
``b``). Where the bias is gross (:data:`GROSS`: more than a factor of two on the log scale, more
than the value itself on the linear one, or a corrected value outside the search box; not
for p_x and p_y, which may be zero) the parameter is flagged not determined: the estimator
cannot tell it from the log.

The claims of LuGre's intervals on logs fricid did not write (:data:`CALIBRATED_WIDENING`,
:data:`RESTING_WIDENING`, the coverage the caveat quotes) are here too; the module is longer
than 500 lines because it holds every statement the fit makes about its intervals beside the
parameters (convergence, passivity, the simulated bias, the calibrated widening and its
coverage), and the identification folder keeps to 15 modules.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ...errors import FricidWarning, user_stacklevel
from ...models import lugre
from ._routes import JOINT_UNITS

__all__ = [
    "CALIBRATED_WIDENING",
    "COVERAGE_GOAL",
    "LUGRE_ASYM_COVERAGE",
    "LUGRE_COVERAGE",
    "LUGRE_FOREIGN_COVERAGE",
    "RATE_BIAS",
    "RATE_BIAS_WARN",
    "RESTING",
    "RESTING_WIDENING",
    "PassivityWarning",
    "RateBiasWarning",
    "calibrate",
    "converged",
    "estimator",
    "lugre_caveat",
    "passivity",
    "warn_rate_bias",
    "widen_calibrated",
]


#: The claimed 95 % intervals of LuGre fits from a trajectory that held the truth, on an
#: independent simulator's logs over ten seeds (``benchmarks/bench_lugre.py --seeds 10
#: --first-seed 10 --duration 10 --kinds chirp_pd,trapezoid_pd,torque_steps --rates 1000,200
#: --cprs 131072,1048576 --no-foreign``, with the calibrated widening,
#: :data:`CALIBRATED_WIDENING` or :data:`RESTING_WIDENING` by the log's rest share; the last
#: report block of ``benchmarks/results/lugre_report10.txt``): per kind of log over all
#: parameters, per parameter over the three kinds (covered, claimed; J, p_x and p_y as well:
#: a new user read their intervals on the shared foreign logs as claims the caveat did not
#: cover), and the kinds' parameters below :data:`COVERAGE_GOAL` (kind, parameter, covered,
#: claimed). On the virtual joint's logs they held it 336 of 350 times; on no one else's.
LUGRE_COVERAGE = {
    "kinds": {
        "PD-tracked chirps": (793, 805),
        "PD-tracked trapezoids": (730, 763),
        "open-loop torque steps": (707, 734),
    },
    "parameters": {
        "sigma_0": (322, 338),
        "sigma_1": (101, 102),
        "sigma_2": (343, 354),
        "tau_c": (342, 349),
        "tau_s": (32, 34),
        "w_s": (33, 34),
        "delta": (10, 11),
        "J": (352, 360),
        "p_x": (343, 360),
        "p_y": (352, 360),
    },
    "short": [
        ("open-loop torque steps", "w_s", 0, 1),
        ("open-loop torque steps", "delta", 0, 1),
    ],
}

#: The claims that held the truth on the shared foreign logs (another simulator's, not this
#: project's: two PD-tracked chirps and two trapezoids, 2^17 and 2^20 counts/rev; the last
#: "coverage per truth" block of ``benchmarks/results/lugre_foreign.txt``): all of them, and
#: the parameters short of :data:`COVERAGE_GOAL` (name, covered, claimed). A new user found
#: the inertia's and p_x's intervals missing on the chirps while the caveat quoted only this
#: project's simulator.
LUGRE_FOREIGN_COVERAGE = {"all": (20, 24), "short": [("J", 2, 4), ("p_x", 2, 4)]}

#: The share of claims below which :func:`lugre_caveat` names a kind's parameter.
COVERAGE_GOAL = 0.9


#: The claimed 95 % intervals of ``lugre_asym`` fits (the levels per direction) that held the
#: truth, on the same independent simulator's logs with the friction the same or 10 % or 20 %
#: weaker backwards (``benchmarks/bench_direction.py --model lugre_asym --seeds 4
#: --first-seed 10``: 108 fits, three joints, PD-tracked chirps and trapezoids and open-loop
#: torque steps, 10 s at 1 kHz, 2^20 counts/rev; the last such block of
#: ``benchmarks/results/direction.txt``): covered and claimed over all parameters, then per
#: parameter, both directions' under the symmetric name.
LUGRE_ASYM_COVERAGE = {
    "all": (918, 941),
    "parameters": {
        "sigma_0": (105, 106),
        "sigma_1": (40, 40),
        "sigma_2": (207, 216),
        "tau_c": (214, 216),
        "tau_s": (22, 22),
        "w_s": (11, 11),
        "delta": (6, 6),
        "J": (107, 108),
        "p_x": (102, 108),
        "p_y": (104, 108),
    },
}


#: Each side of LuGre's 95 % intervals from a trajectory (the ``filtered`` route) is widened
#: about the estimate by these factors, on the scale the interval is formed (log10 for
#: sigma_0 and sigma_1), within the search box: the 0.95 quantile, over the closed claims of
#: an independent simulator's logs (the tuning seeds 0-5 of ``benchmarks/bench_lugre.py``, 216
#: fits over three truths, three kinds of log, two rates and two encoders; their "widening"
#: tables in ``benchmarks/results/lugre_claims.txt``), of the widening that would have held
#: the truth. The statistical intervals assume the model and the measurement model exact;
#: on logs fricid did not write the remaining biases (the quantised encoder, the closed
#: loop, the bristles' lag) are of the size of the intervals, and this is what they took.
#: Each claim's widening is the factor its run applied times the one it still needed
#: (``benchmarks/calib_lugre_widening.py``, its command beside its table there; seeds
#: 0-2 run with the factors of before the falling start, sigma_0 3.53, sigma_2 1.58, tau_c
#: 1.69, the inertia 1.70, p_x 1.24, p_y 1.52, nothing else widened; seeds 3-5 with those of
#: seeds 0-2 alone: sigma_0 2.13, which on the report seeds held sigma_0 in 89 % of the claims
#: and on a new user's simulator missed it 7 times where the factors before missed once).
#: sigma_1 and the Stribeck trio, unwidened before (their claims needed 4.5 to unbounded
#: factors), are widened too; the trio's quantiles rest on 12 (delta) to 32 (w_s) claims.
CALIBRATED_WIDENING = {
    "sigma_0": 2.37,
    "sigma_1": 4.43,
    "sigma_2": 1.42,
    "tau_c": 1.52,
    "tau_s": 1.99,
    "w_s": 4.53,
    "delta": 4.42,
    "inertia": 1.37,
    "p_x": 1.25,
    "p_y": 1.28,
}

#: A log that rests (:func:`fricid.identify.dynamic._data.rest_share`) at least this share of
#: its time takes :data:`RESTING_WIDENING`. Either side of it, on trapezoids with brief dwells
#: (seeds 30-35, ``benchmarks/results/lugre_brief.txt``): resting 12-20 %, the pooled factors
#: held 164 of 170 claims (each parameter 24 of 26 or more); 20-30 %, these 317 of 320.
RESTING = 0.2

#: The widening of a log that rests (PD-tracked trapezoids with their dwells, most open-loop
#: torque steps): each factor the larger of :data:`CALIBRATED_WIDENING`'s and the 0.95
#: quantile over the tuning claims of such logs alone (the tuning seeds 0-5 of
#: ``benchmarks/bench_lugre.py`` rerun at 878de01's fit code, 128 of the 216 logs resting:
#: every trapezoid, 56 of 72 torque steps; ``benchmarks/calib_lugre_widening.py --by-rest``,
#: its table in ``benchmarks/results/lugre_claims.txt``; the Stribeck trio's, on 8 claims or
#: none, CALIBRATED_WIDENING's). On the report seeds 10-19 the pooled factors had held the
#: trapezoids' sigma_0 in 100 of 115 claims and sigma_1 in 23 of 29, these 106 of 114 and
#: 22 of 23 (all of the trapezoids' claims: 711 of 770 before, 730 of 763 now; the torque
#: steps' 696 of 737 and 707 of 734; ``benchmarks/results/lugre_report10.txt``). The
#: chirps (rest shares 0-0.10) and the moving torque steps (0-0.10) needed less than the
#: pooled factors (sigma_0 1.67, sigma_2 0.92, the inertia 0.89) and keep them: those
#: quantiles would have held the report's chirps' w_s in 12 of 18 claims and tau_c in 107 of
#: 116, and the other simulator's logs 19 of 24 instead of 20 (``calib_lugre_widening.py
#: --hold``, ``benchmarks/results/lugre_claims.txt``).
RESTING_WIDENING = {
    **CALIBRATED_WIDENING,
    "sigma_0": 2.94,
    "sigma_1": 5.62,
    "sigma_2": 1.63,
    "tau_c": 1.80,
    "inertia": 1.61,
    "p_x": 1.37,
    "p_y": 1.52,
}

#: The widened parameters whose intervals are formed on a log10 scale.
LOG_WIDENED = ("sigma_0", "sigma_1")


def widen_calibrated(stage, rest: float = 0.0) -> dict[str, Any]:
    """Widen ``stage``'s intervals (in place) by :data:`CALIBRATED_WIDENING`, or by
    :data:`RESTING_WIDENING` where the log rests at least :data:`RESTING` of its time
    (``rest``, :func:`fricid.identify.dynamic._data.rest_share`); returns the record for the
    provenance: the factors, the rest share, and each parameter's interval before. The
    standard errors are scaled alike, so that the printed +- and interval agree."""
    resting = rest >= RESTING
    factors = RESTING_WIDENING if resting else CALIBRATED_WIDENING
    before = {}
    for i, name in enumerate(stage.names):
        base = lugre.symmetric_name(name)  # per direction: as one
        k = factors.get(base)
        lo, hi, v = float(stage.low[i]), float(stage.high[i]), float(stage.values[i])
        if k is None or not all(math.isfinite(x) for x in (lo, hi, v)):
            continue
        box = tuple(float(b) for b in stage.bounds[i])
        before[name] = [lo, hi]
        if base in LOG_WIDENED and min(lo, v) > 0:
            f, g = math.log10, lambda x: 10.0**x
        else:
            f, g = (lambda x: x), (lambda x: x)
        lo, hi = g(f(v) - k * (f(v) - f(lo))), g(f(v) + k * (f(hi) - f(v)))
        stage.low[i], stage.high[i] = max(lo, box[0]), min(hi, box[1])
        stage.stderr[i] = k * float(stage.stderr[i])
    return {
        "factors": dict(factors),
        "rest_share": float(rest),
        "resting": bool(resting),
        "before": before,
        "how": (
            "each side of the 95 % interval widened about the estimate (log10 scale for "
            "sigma_0 and sigma_1), within the search box, by the factor that held the truth in "
            "95 % of an independent simulator's claims (benchmarks/bench_lugre.py, tuning "
            "seeds 0-5)"
            + (
                f"; the log rests {100 * rest:.0f} % of its time, so the factors of logs "
                f"resting {100 * RESTING:.0f} % or more (the larger of the pooled ones and "
                "theirs)"
                if resting
                else ""
            )
        ),
    }


def _items(key: str) -> list[tuple[str, tuple[int, int]]]:
    return list(LUGRE_COVERAGE[key].items())


def lugre_caveat(per_direction: bool = False) -> str:
    """The caveat every LuGre fit from a trajectory carries: its intervals' coverage on logs
    fricid did not simulate, after the calibrated widening (:data:`LUGRE_COVERAGE`, measured
    on symmetric fits; ``per_direction``: a ``lugre_asym`` fit's, :data:`LUGRE_ASYM_COVERAGE`,
    as well)."""
    kinds = [f"{100 * c / n:.0f} % ({k})" for k, (c, n) in _items("kinds")]
    kinds = ", ".join(kinds[:-1]) + " and " + kinds[-1]
    each = ", ".join(f"{k} {100 * c / n:.0f} %" for k, (c, n) in _items("parameters"))
    short = [
        f"{name} on {kind} {c} of {n}" + (f" ({100 * c / n:.0f} %)" if n >= 10 else "")
        for kind, name, c, n in LUGRE_COVERAGE["short"]
    ]
    c, n = LUGRE_FOREIGN_COVERAGE["all"]
    foreign = f"{c} of {n}, " + ", ".join(
        f"{name} {c} of {n}" for name, c, n in LUGRE_FOREIGN_COVERAGE["short"]
    )
    return (
        "LuGre's intervals are widened by factors calibrated on an independent simulator's "
        f"logs with quantised encoders, and on other logs of it they held the truth in {kinds} "
        f"of the claims, not 95 % everywhere; per parameter, the inertia's and the gravity's "
        f"too: {each}; below {100 * COVERAGE_GOAL:.0f} %: {', '.join(short)} "
        "(benchmarks/bench_lugre.py); on another simulator's logs (the shared foreign data) "
        f"{foreign}" + (_per_direction_coverage() if per_direction else "")
    )


def _per_direction_coverage() -> str:
    c, n = LUGRE_ASYM_COVERAGE["all"]
    each = ", ".join(
        f"{k} {100 * c / n:.0f} %" for k, (c, n) in LUGRE_ASYM_COVERAGE["parameters"].items()
    )
    return (
        "; those were symmetric fits: with the levels per direction, on that simulator's 1 kHz "
        "logs (2^20 counts/rev) with the friction the same or 10-20 % weaker backwards, "
        f"{100 * c / n:.0f} % of the claims held: {each} (benchmarks/bench_direction.py); "
        "the levels' difference takes up any constant torque as well: a torque sensor's "
        "offset looks the same as a difference between the two directions' levels"
    )


class PassivityWarning(FricidWarning):
    """An identified dynamic friction model is not passive (it could create energy)."""


class RateBiasWarning(FricidWarning):
    """The log's rate biases sigma_0 or sigma_1 by a sizeable part of their intervals."""


#: Rate-bias checks of the ``filtered`` route: ``warn`` estimates it and warns, ``off`` not.
RATE_BIAS = ("warn", "off")

#: Warn when the estimated rate bias exceeds this many standard errors (log10 scale).
RATE_BIAS_WARN = 0.5

#: Widen an interval when the simulated bias exceeds this many standard errors.
WIDEN = 1.0

#: Gross biases (module notes): log10 scale, relative on the linear scale.
GROSS = {"log10": math.log10(2.0), "linear": 1.0}


def _search_se(stage, i: int, scale: str) -> float:
    """The standard error of parameter ``i`` in the search's coordinates."""
    se = float(stage.stderr[i])
    return se / (float(stage.values[i]) * math.log(10.0)) if scale == "log10" else se


def calibrate(stage, rb: dict[str, Any]) -> dict[str, str]:
    """Widen ``stage``'s intervals (in place) by the simulated bias, or flag a parameter not
    determined (module notes); returns the parameters' notes and records each verdict in
    ``rb["parameters"][name]["verdict"]`` (``kept``, ``widened``, ``not determined``)."""
    notes: dict[str, str] = {}
    for i, name in enumerate(stage.names):
        row = rb.get("parameters", {}).get(name)
        if row is None:
            continue
        b, scale = row["bias"], row["scale"]
        se = _search_se(stage, i, scale)
        row["in_stderr"] = abs(b) / se if se > 0 else float("inf")
        row["verdict"] = "kept"
        if not (math.isfinite(se) and abs(b) > WIDEN * se):
            continue
        lo, hi, box = stage.low[i], stage.high[i], stage.bounds[i]
        if scale == "log10":
            lo, hi, box = np.log10(lo), np.log10(hi), np.log10(box)
        size = abs(b) if scale == "log10" else abs(b) / max(abs(stage.values[i]), 1e-300)
        corrected = stage.values[i] * 10.0 ** (-b) if scale == "log10" else stage.values[i] - b
        outside = not (stage.bounds[i][0] <= corrected <= stage.bounds[i][1])
        said = f"{100 * row['relative']:+.3g} %, {row['in_stderr']:.2g} standard errors"
        if name not in ("p_x", "p_y") and (size > GROSS[scale] or outside):
            row["verdict"] = "not determined"
            notes[name] = (
                f"not determined: the simulation at the estimate (the log's rate and encoder, "
                f"PD-tracked) biases it by {said}"
            )
        else:
            row["verdict"] = "widened"
            notes[name] = f"interval widened by the bias simulated at the estimate ({said})"
        lo, hi = max(min(lo, lo - b), box[0]), min(max(hi, hi - b), box[1])
        if scale == "log10":
            lo, hi = 10.0**lo, 10.0**hi
        stage.low[i], stage.high[i] = lo, hi
    return notes


def _unit(name: str) -> str:
    """The unit of a LuGre trajectory fit's parameter (a law's, per direction too, or the
    joint's)."""
    law = {p.name: p.unit for p in lugre.PARAMETERS}
    return JOINT_UNITS.get(name) or law.get(lugre.symmetric_name(name), "")


def warn_rate_bias(stage, rb: dict[str, Any], notes: dict[str, str] | None = None) -> None:
    """One line when the simulated bias of a parameter is a sizeable part of its interval,
    with the numbers and what was done to the intervals."""
    if "skipped" in rb:
        return
    rows = rb.get("parameters") or {n: {**rb[n], "bias": rb[n]["log10_bias"]} for n in LOG2}
    parts = []
    for i, n in enumerate(stage.names):
        row = rows.get(n)
        if row is None:
            continue
        scale = row.get("scale", "log10")
        se = _search_se(stage, i, scale)
        if abs(row["bias"]) > RATE_BIAS_WARN * se:
            size = f"{abs(row['bias']) / se:.2g} se"
            value = float(stage.values[i])
            if scale == "linear" and not abs(value) > 2.0 * float(stage.stderr[i]):
                # a value not told from zero: its relative bias says nothing (p_x -57 %)
                parts.append(f"{n} {row['bias']:+.2g} {_unit(n)} ({size}; it is {value:.2g})")
            else:
                parts.append(f"{n} {100 * row['relative']:+.2g} % ({size})")
    if not parts:
        return
    cpr = rb.get("quantised")
    what = f"logging at {rb['log_rate']:.6g} Hz" + (
        f" through an encoder of {cpr:.8g} counts/rev" if cpr else ""
    )
    done = sorted(notes or {})
    warnings.warn(
        f"{what} biases {', '.join(parts)}, as estimated by simulation at the estimate "
        "under the log's drive (corrected values in the provenance, not applied)"
        + (f"; intervals widened or flagged not determined: {', '.join(done)}" if done else "")
        + f"; log at {10 * rb['log_rate']:.6g} Hz"
        + (" with a finer encoder" if cpr else "")
        + " to reduce it",
        RateBiasWarning,
        stacklevel=user_stacklevel(),
    )


#: sigma_0 and sigma_1, the parameters of a rate-bias record without every parameter's.
LOG2 = ("sigma_0", "sigma_1")


def estimator(
    key: str, route: str, sim_info: dict[str, Any], window: bool = False
) -> dict[str, str]:
    """Which estimator gave the parameters, and whether the bias of the log's rate, encoder
    and closed loop was checked by simulation at the estimate (or, ``window``, the encoder's
    bias of a static model's regression by its derivative window: :mod:`._window`)."""
    names = {
        "filtered": "IDIM-LS: parallel-filtered equation error (Gautier, Janot and "
        "Vandanjon 2013), the bristle state driven by the measured motion",
        "two_stage": "equation-error regression, then simulation error in windows",
        "joint": "simulation error in windows (every parameter)",
        "regression": "equation-error regression on the sliding samples",
    }
    name = names.get(route if key != "dahl" else "filtered", route)
    if (sim_info.get("output_error") or {}).get("applied"):
        name = (
            "DIDIM output error (Gautier, Janot and Vandanjon 2013): the joint simulated under "
            "the measured torque with PD tracking of the measured position, started from "
            + name.split(":")[0]
        )
    rb = sim_info.get("rate_bias")
    if rb is None and window:
        check = (
            "the encoder's noise in the acceleration checked (the derivative window's predicted "
            "biases); closed loop not checked: equation error under closed loop can be biased"
        )
    elif rb is None:
        check = "not checked: equation error under closed loop or a coarse encoder can be biased"
    elif "skipped" in rb:
        check = f"not checked: {rb['skipped']}"
    else:
        check = (
            "checked by simulation at the estimate (PD tracking the measured motion, the "
            "log's rate and encoder); intervals widened by it"
        )
    return {"name": name, "bias": check}


#: The side of each parameter's interval at which LuGre is least passive.
_LEAST_PASSIVE = {"sigma_1": 1, "sigma_2": 0, "tau_c": 0, "tau_s": 1}


def passivity(names: list[str], values, low, high) -> dict[str, Any]:
    """[BO00] margin at the estimate and at the least favourable corner of the intervals
    (``margin_worst_in_ci95`` and ``passive_across_ci95`` None when there are no intervals:
    a fit that did not converge); per direction, the smaller margin of the two."""
    p = dict(zip(names, values, strict=True))
    worst = dict(p)
    ends = dict(zip(names, zip(low, high, strict=True), strict=True))
    sides = 0
    for n in names:
        side = _LEAST_PASSIVE.get(lugre.symmetric_name(n))
        if side is not None and np.isfinite(ends[n][side]):
            worst[n] = ends[n][side]
            sides += 1
    law = lugre.ASYM_NAMES if "tau_c_pos" in p else lugre.PARAM_NAMES
    at = float(lugre.passivity_margin(np.array([p[n] for n in law])))
    corner = float(lugre.passivity_margin(np.array([worst[n] for n in law])))
    condition = "sigma_1 <= 4 sigma_2 tau_c / (tau_s - tau_c) (Barabanov and Ortega 2000)"
    if law is lugre.ASYM_NAMES:  # which direction, as each direction's own LuGre
        each = [
            float(
                lugre.passivity_margin(
                    np.array([p.get(f"{n}_{side}", p.get(n)) for n in lugre.PARAM_NAMES])
                )
            )
            for side in ("pos", "neg")
        ]
        condition += (
            f", in each direction (margin at the estimate forwards {each[0]:.3g}, backwards "
            f"{each[1]:.3g} N m s/rad)"
        )
    return {
        "condition": condition,
        "margin": at if np.isfinite(at) else None,
        "passive": bool(at >= 0),
        "margin_worst_in_ci95": corner if sides and np.isfinite(corner) else None,
        "passive_across_ci95": bool(corner >= 0) if sides else None,
    }


def _deciding(fits: list[tuple[str, Any]], rename: dict[str, str]) -> list[bool]:
    """Whether each search's estimate is reported: it is the last search of at least one
    parameter (``rename`` maps a stage's names onto the result's). The others were starts
    of a later search of all their parameters (the regression before the filtered route, the
    simulation before a refinement, every stage before ``joint``'s)."""
    covered: set[str] = set()
    out = []
    for _, stage in reversed(fits):
        names = {rename.get(n, n) for n in stage.names}
        out.append(not names <= covered)
        covered |= names | {lugre.symmetric_name(n) for n in names}  # per direction: both
    return out[::-1]


#: The stages whose every evaluation simulates the joint over the whole log: their polish stops
#: once a step gains under a tenth of what the certificate resolves
#: (:func:`fricid.identify.static.convergence.certify`'s ``noise_tolerance``).
SIMULATED_STAGES = ("filtered", "output_error", "presliding")


def converged(
    fits: list[tuple[str, Any]], method: str, max_evals, rename: dict[str, str] | None = None
) -> dict[str, Any]:
    """The convergence block of a trajectory identification: every search whose estimate is
    reported certified as an analytic fit is (:func:`fricid.identify.static.convergence.
    certify`: a short local least-squares polish from its result, on the problem it
    minimised), not by the optimiser's flag alone.

    Parameters
    ----------
    fits : list of (str, _Stage)
        Each search, named, in the order it ran (a stage's ``names``, ``problem`` and
        ``result``).
    method : str
        The optimiser (for the advice).
    max_evals : int or None
        The budget of each stage.
    rename : dict, optional
        A stage's parameter names onto the result's (the ``stribeck`` names of LuGre's
        static part).

    Returns
    -------
    dict
        As :func:`~fricid.identify.static.convergence.certify`'s block, over the reported
        stages (``converged`` when each is certified; ``polish_sse_ratio`` the lowest of
        theirs; ``nfev`` every search's, ``polish_nfev`` the polishes'; ``reason`` names the
        first that is not), with ``stages``: each search's own block, named; a search that
        only started a later one (``superseded``) is not polished, its optimiser's status
        recorded.
    """
    from ..static.convergence import advice, certify

    blocks = []
    for (name, stage), decides in zip(fits, _deciding(fits, rename or {}), strict=True):
        if decides:
            simulated = name in SIMULATED_STAGES  # its polish stops at the resolution
            block = certify(stage.problem, stage.result, noise_tolerance=simulated)
            blocks.append({"stage": name, **block})
        else:
            r = stage.result
            blocks.append(
                {
                    "stage": name,
                    "superseded": True,
                    "status": int(r.status),
                    "message": str(r.message),
                    "nfev": int(r.nfev),
                }
            )
    judged = [b for b in blocks if not b.get("superseded")]
    ok = all(b["converged"] for b in judged)
    last = fits[-1][1].result
    ratios = [b["polish_sse_ratio"] for b in judged if np.isfinite(b["polish_sse_ratio"])]
    if ok:
        by = "optimizer" if all(b["certified_by"] == "optimizer" for b in judged) else "polish"
    else:
        by = ""
    out = {
        "converged": ok,
        "status": int(last.status),
        "message": str(last.message),
        "nfev": int(sum(stage.result.nfev for _, stage in fits)),
        "max_evals": int(max_evals) if max_evals is not None else int(last.nfev),
        "polish_sse_ratio": float(min(ratios)) if ratios else float("nan"),
        "polish_nfev": int(sum(b["polish_nfev"] for b in judged)),
        "certified_by": by,
        "stages": blocks,
    }
    if not ok:
        first = next(b for b in judged if not b["converged"])
        out["reason"] = f"stage '{first['stage']}': {first['reason']}"
        out["advice"] = advice(method)
    return out
