"""LuGre from a log that never slides: the pre-sliding route (:mod:`._presliding`) run and its
result written as a model file that says which parameters the log determines and why the
others are not.

What such a log determines ([CW95] section II; Astrom and Canudas de Wit 2008): the bristle
stiffness sigma_0 and the pre-sliding damping, which is ``sigma_1 + sigma_2`` (the two act on
``dz/dt`` and ``v``, equal to first order below break-away). It does not determine:

* the sliding friction, ``tau_c``, ``tau_s``, ``w_s``, ``delta`` and ``sigma_2``: the joint never
  slides, so the Stribeck curve is never traced (its value at rest only sets the creep rate,
  and whether that value is ``tau_s`` the log cannot tell);
* J: a creep excites nothing near the bristle resonance (it only shapes the sub-sample
  response; sigma_0's and sigma_1's intervals are the union over the J the log does not
  reject, :mod:`._presliding`);
* p_x and p_y: over micro-radians the gravity torque is a constant, the torque at which the
  bristles are unloaded (recorded as ``torque_offset``), and its stiffness adds to sigma_0's
  (``p_x sin q + p_y cos q`` at rest, at most the gravity torque's amplitude; sigma_0 includes
  it).

So the model file holds sigma_0 and sigma_1 with their intervals; sigma_1 is the damping
``sigma_1 + sigma_2`` with its note saying so, unless ``static=`` (a ``stribeck`` fit from
constant-velocity sweeps, the classic order of LuGre identification: [CW95] section IV) gives
sigma_2, which is then subtracted (its interval's ends from both intervals' opposite ends);
the sliding parameters are taken from ``static=`` when given, else recorded as not determined
(values that reproduce the log: ``tau_c = tau_s`` at the bristles' level seen, ``sigma_2 =
0``, ``w_s`` and ``delta`` at the model's defaults; no standard error, no interval), and J,
p_x and p_y are left out of the joint's table with the reason in
``provenance["trajectory"]["presliding"]["not_determined"]``.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import replace
from typing import Any

from ... import __version__
from ...errors import DataQualityWarning, IdentifiabilityWarning, user_stacklevel
from ...fitted import FittedModel, OptimizerRecord
from ...io.atomic import created_timestamp
from ...metrics import fit_statistics, metrics
from ...models import get_model, lugre
from ...samples import RawLog
from ._data import Series, temperature_range
from ._filtered import ParallelFilter
from ._outcome import converged
from ._presliding import CUTOFF, RESOLVED_COUNTS, bias_check, presliding_route, widen
from ._result import NO_INTERVAL, _records, _withheld

__all__ = ["fit_presliding"]

#: The static part of LuGre, as the ``stribeck`` model names it.
_STRIBECK = {"sigma_2": "tau_v", "tau_c": "tau_c", "tau_s": "tau_s", "w_s": "w_s"}
_STRIBECK["delta"] = "delta"


def fit_presliding(
    log: RawLog,
    series: Series,
    encoder: dict[str, Any],
    *,
    method: str,
    seed: int,
    max_evals: int | None,
    cluster_time: float,
    n_sub: int,
    parallel: ParallelFilter | None,
    static: Any,
    v_slide: float,
    gravity: str,
    t_start: float,
) -> FittedModel:
    """LuGre's sigma_0 and sigma_1 from a log that never slides (module notes); ``static``:
    an optional ``stribeck`` :class:`~fricid.fitted.FittedModel` from sweeps."""
    filt = parallel or ParallelFilter(cutoff=CUTOFF, trim=0.5)
    stage, info = presliding_route(
        series, encoder, method, seed, max_evals, cluster_time, n_sub, filt, log.source
    )
    check = bias_check(series, stage, info, encoder, method, seed, cluster_time, n_sub, filt)
    notes = widen(stage, check, ("sigma_0", "sigma_1"))
    for n in ("sigma_0", "sigma_1"):  # one end at the box: a bound, not an interval
        i = stage.names.index(n)
        (lo, hi), (b_lo, b_hi) = (stage.low[i], stage.high[i]), stage.bounds[i]
        if (lo <= b_lo or hi >= b_hi) and not notes.get(n, "").startswith("not determined"):
            end = f"lower end {b_lo:.4g}" if lo <= b_lo else f"upper end {b_hi:.4g}"
            notes[n] = (
                f"not determined: its 95 % interval [{lo:.4g}, {hi:.4g}] reaches the search "
                f"box's {end}; the log bounds it on one side only"
            )
    convergence = converged([("presliding", stage)], method, max_evals)
    ok = bool(convergence["converged"])
    table = stage.table()
    damping = dict(table["sigma_1"])
    final = {n: table[n] for n in ("sigma_0", "sigma_1")}
    why = _why(info, v_slide)
    bounds = {n: [float(b) for b in stage.bounds[stage.names.index(n)]] for n in final}
    if static is not None:
        final.update(_from_sweeps(static, final["sigma_1"]))
        notes.update({n: f"from the sweeps' stribeck fit ({s})" for n, s in _STRIBECK.items()})
        bounds.update({n: list(static.parameters[s].bounds or ()) for n, s in _STRIBECK.items()})
        bounds = {n: b for n, b in bounds.items() if b}
    else:
        nan = float("nan")
        level = float(info["bristle_level"])
        defaults = {p.name: p.default for p in lugre.PARAMETERS}
        values = {"sigma_2": 0.0, "tau_c": level, "tau_s": level}
        values.update(w_s=defaults["w_s"], delta=defaults["delta"])
        for n, v in values.items():
            final[n] = {"value": v, "stderr": nan, "ci95_low": nan, "ci95_high": nan}
            notes[n] = f"not determined: {why[n]}"
    said = (
        "the pre-sliding damping less the sweeps' sigma_2"
        if static is not None
        else "the pre-sliding damping sigma_1 + sigma_2 (a log that never slides does not "
        "separate them; sigma_1 is this less sigma_2)"
    )
    if not notes.get("sigma_1", "").startswith("not determined"):
        notes["sigma_1"] = "; ".join(x for x in (said, notes.get("sigma_1")) if x)
    if not ok:
        final = _withheld(final)
    parameters = _records(
        list(lugre.PARAM_NAMES),
        final,
        get_model("lugre").units,
        bounds,
        ok,
        note="" if ok else NO_INTERVAL,
        notes=notes,
    )
    for n in final if static is None and not ok else ():  # not determined, converged or not
        if n in why:
            parameters[n] = replace(parameters[n], note=notes[n], not_determined=True)
    y, resid = info["y"], info["residual"]
    lost = {
        n: notes[n].removeprefix("not determined: ")
        for n in ("sigma_0", "sigma_1")
        if notes.get(n, "").startswith("not determined")
    }
    record = _record(stage, info, check, damping, encoder, {**lost, **why}, series, filt, static)
    fitted = FittedModel(
        model="lugre",
        parameters=parameters,
        ci_method="cluster-robust, union over J" if ok else "",
        optimizer=OptimizerRecord(
            method=method,
            seed=seed,
            status=int(stage.result.status),
            message=str(stage.result.message),
            nfev=int(stage.result.nfev),
            max_evals=int(max_evals) if max_evals is not None else int(stage.result.nfev),
        ),
        convergence=convergence,
        metrics=metrics(y, y - resid),
        statistics=fit_statistics(y, y - resid, len(stage.names)),
        statistics_note="torque as sigma_0 times the low-passed position error (pre-sliding)",
        operating_range={
            "velocity": [-info["max_speed"], info["max_speed"]],
            **temperature_range(log, series),
        },
    )
    fitted.provenance = {
        "source": log.source,
        "n_samples": int(series.time.size),
        "directions": [-1, 1],
        "fricid_version": __version__,
        "created": created_timestamp(),
        "trajectory": {
            "route": "presliding",
            "static_from": "sweeps" if static is not None else "none (the log never slides)",
            "resampled": series.resampled,
            "sample_rate": 1.0 / series.dt,
            "v_slide": v_slide,
            "gravity": gravity,
            "joint": {},
            "routes": {
                "presliding": {
                    "parameters": table if ok else _withheld(table),
                    "rms": stage.rms,
                    "seconds": stage.seconds,
                    "clusters": stage.clusters,
                    "nfev": int(stage.result.nfev),
                    "converged": bool(stage.result.success),
                }
            },
            "seconds": time.perf_counter() - t_start,
            "encoder": encoder,
            "estimator": {
                "name": "pre-sliding output error (the joint simulated under the logged "
                "torque, the position residual low-passed on both sides)",
                "bias": _bias_text(check, record["determined"]),
            },
            "presliding": record,
        },
    }
    _warn(record, encoder)
    return fitted


def _why(info: dict[str, Any], v_slide: float) -> dict[str, str]:
    """Why each parameter the log does not determine is not (module notes)."""
    never = (
        f"the log never slides (speeds up to {info['max_speed']:.3g} rad/s, under "
        f"v_slide = {v_slide:g} rad/s), so it does not trace the sliding friction"
    )
    return {
        "sigma_2": f"{never}; below break-away it acts with sigma_1 (their sum is sigma_1's "
        "value); value 0",
        "tau_c": f"{never}; value: the bristles' level seen at rest",
        "tau_s": f"{never}; the level at rest ({info['bristle_level']:.4g} N m) sets only the "
        "creep rate and is tau_s only if the creep is slower than w_s; value: that level",
        "w_s": f"{never}; value: the model's default",
        "delta": f"{never}; value: the model's default",
        "inertia": "a creep excites nothing near the bristle resonance sqrt(sigma_0 / J); "
        "sigma_0's and sigma_1's intervals hold for every J the log does not reject",
        "p_x": "over micro-radians the gravity torque is a constant (the torque offset); its "
        "stiffness is inside sigma_0",
        "p_y": "as p_x",
    }


def _from_sweeps(static: Any, damping: dict[str, float]) -> dict[str, dict[str, float]]:
    """The sliding parameters from the sweeps' ``stribeck`` fit and sigma_1 as the damping
    less their sigma_2 (the interval's ends from the opposite ends, module notes)."""
    out = {}
    for n, s in _STRIBECK.items():
        p = static.parameters[s]
        out[n] = {"value": p.value, "stderr": p.stderr, "ci95_low": p.ci95[0]}
        out[n]["ci95_high"] = p.ci95[1]
    s2 = out["sigma_2"]
    out["sigma_1"] = {
        "value": damping["value"] - s2["value"],
        "stderr": math.hypot(damping["stderr"], s2["stderr"]),
        "ci95_low": max(damping["ci95_low"] - s2["ci95_high"], 0.0),
        "ci95_high": damping["ci95_high"] - s2["ci95_low"],
    }
    return out


def _record(stage, info, check, damping, encoder, why, series, filt, static) -> dict[str, Any]:
    """``provenance["trajectory"]["presliding"]``: what is determined and why, the nuisance
    estimates, the encoder's resolution, the timing the damping rests on, the check."""
    v = dict(zip(stage.names, stage.values, strict=True))
    determined = [n for n in ("sigma_0", "sigma_1") if n not in why]  # an interval at the box
    determined += list(_STRIBECK) if static is not None else []
    skip = () if static is None else tuple(_STRIBECK)
    lag = v["sigma_1"] / v["sigma_0"]
    return {
        "determined": determined,
        "not_determined": {n: w for n, w in why.items() if n not in skip},
        "damping": damping,
        "nuisance": {n: stage.table()[n] for n in ("load_ratio", "torque_offset", "inertia")},
        "bristle_level": info["bristle_level"],
        "deflection": info["deflection"],
        "deflection_counts": info["deflection_counts"],
        "span_counts": info["span_counts"],
        "resolved_from_counts": RESOLVED_COUNTS,
        "torque_noise": info["torque_noise"],
        "filter": info["filter"],
        "max_speed": info["max_speed"],
        "lag": lag,
        "lag_periods": lag / series.dt,
        "skew_sensitivity": v["sigma_0"] * 1e-3,
        "timing": f"the damping is a lag of sigma_1 / sigma_0 = {1e3 * lag:.3g} ms "
        f"({lag / series.dt:.3g} periods) of the position behind the torque; a skew of the "
        f"torque and position channels by 1 ms moves sigma_1 by {v['sigma_0'] * 1e-3:.3g} "
        "N m s/rad (the drive is taken to hold each logged torque until the next sample)",
        "inertia_profile": [
            {
                "inertia": r["inertia"],
                "sigma_0": r["sigma_0"],
                "sigma_1": r["sigma_1"],
                "ci95_sigma_0": [r["low"][0], r["high"][0]],
                "ci95_sigma_1": [r["low"][1], r["high"][1]],
                "sse": r["sse"],
                "accepted": r["accepted"],
            }
            for r in info["inertia_profile"]
        ],
        "check": check,
        "encoder_counts_per_rev": encoder.get("counts_per_rev"),
    }


def _bias_text(check: dict[str, Any], determined: list[str]) -> str:
    """The bias check in a line: each determined parameter's estimate simulated again at
    the estimate, its relative move and whether its interval was kept or widened."""
    if "skipped" in check:
        return f"not checked ({check['skipped']})"
    rows = check["parameters"]
    parts = [
        f"{n} {100 * rows[n]['relative']:+.2g} % (interval {rows[n].get('verdict', 'kept')})"
        for n in ("sigma_0", "sigma_1")
        if n in rows and n in determined
    ]
    if not parts:
        return "nothing determined to check"
    return "simulated at the estimate with the log's torque noise and encoder: " + ", ".join(parts)


def _warn(record: dict[str, Any], encoder: dict[str, Any]) -> None:
    """One line naming what the log does not determine; one when the encoder hardly
    resolves the deflection."""
    missing = ", ".join(record["not_determined"])
    warnings.warn(
        f"the log never slides (up to {record['max_speed']:.3g} rad/s): identified by the "
        f"pre-sliding route, which determines {', '.join(record['determined'])}; not "
        f"determined: {missing} (see provenance['trajectory']['presliding'])",
        IdentifiabilityWarning,
        stacklevel=user_stacklevel(),
    )
    counts = record["deflection_counts"]
    if counts is not None and counts < RESOLVED_COUNTS:
        q = encoder["quantum"]
        warnings.warn(
            f"the encoder ({encoder['counts_per_rev']:.10g} counts/rev, {q:.3g} rad a count) "
            f"resolves the bristles' largest deflection ({record['deflection']:.3g} rad) in "
            f"{counts:.3g} counts (resolved from {RESOLVED_COUNTS:g}): sigma_0 and sigma_1 rest "
            "on the rounding; their intervals include the bias simulated through this encoder",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
