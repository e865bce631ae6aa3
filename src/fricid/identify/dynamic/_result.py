"""The result of a trajectory identification as a model file: parameters with their
intervals, the stages' records, the joint's inertia and gravity, and what was checked.

Intervals are given only for a fit whose every stage is certified converged
(:func:`._outcome.converged`), as for an analytic fit
(:func:`fricid.identify.static.uncertainty.assess`): otherwise the standard errors and 95 %
intervals are withheld (NaN, and the reason in each parameter record's ``note``), in the
parameters, the
joint's table and every route's, and a :class:`~fricid.errors.ConvergenceWarning` says why.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import replace
from typing import Any

import numpy as np

from ... import __version__
from ...errors import ConvergenceWarning, user_stacklevel
from ...fitted import FittedModel, OptimizerRecord, Parameter, is_not_determined
from ...io.atomic import created_timestamp
from ...metrics import fit_statistics, metrics
from ...models import get_model, lugre
from ...samples import RawLog
from ._data import Series, temperature_range
from ._outcome import PassivityWarning, converged, lugre_caveat, passivity
from ._rate import delay_caveat
from ._routes import DYNAMIC_MODELS, JOINT_PARAMS
from ._window import bias_caveat

__all__ = ["build_result"]

#: The note of a parameter whose interval is withheld (as an analytic fit's).
NO_INTERVAL = "no interval: the fit did not converge (see the convergence block)"

#: The entries of a parameter's table that an unconverged fit does not give.
_INTERVAL_KEYS = ("stderr", "ci95_low", "ci95_high")

#: An interval's end within this share of its search range's width from the range's end is at
#: that end (rounding in the search's coordinates).
EDGE = 1e-9

#: A value within this share of a bound (of the range's width for a bound of 0) is at it.
AT_BOUND = 1e-6


#: The note on the intervals of a Dahl or static law fitted to a trajectory (printed beside
#: them, ``provenance["trajectory"]["intervals_note"]``; not a caveat of the verdict, which a
#: second log grades by the predictions): unlike LuGre's, they are not calibrated on another
#: simulator's logs. Measured: ``dahl`` on the foreign
#: trapezoid (``../shared/data/foreign/lugre``, 1 kHz, 2^20 counts/rev; a LuGre joint, J
#: 0.02) put J at 0.01965 [0.01937, 0.01993] under "with caveats" for want of a scatter only.
INTERVALS_NOTE = (
    "these intervals hold where the joint's friction follows this law: they are not "
    "calibrated on another simulator's logs as LuGre's are, and a law that is not the "
    "joint's (Dahl's or a static law on a joint with bristle dynamics) moves the inertia, the "
    "gravity and the levels beyond them (on another simulator's LuGre joint, Dahl's J "
    "0.01965 [0.01937, 0.01993] for 0.02); a LuGre fit of the same log says how far"
)


def _withheld(table: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """A parameter table without its standard errors and intervals (NaN)."""
    nan = float("nan")
    return {
        n: {k: (nan if k in _INTERVAL_KEYS else v) for k, v in row.items()}
        for n, row in table.items()
    }


def build_result(
    key: str,
    route: str,
    log: RawLog,
    series: Series,
    vf: np.ndarray,
    y: np.ndarray,
    yhat: np.ndarray,
    *,
    n_joint: int,
    stages: dict[str, Any],
    fits: list,
    final: dict[str, dict[str, float]],
    bounds_out: dict[str, list[float]],
    options: dict[str, Any],
    sim_info: dict[str, Any],
) -> FittedModel:
    """The :class:`~fricid.fitted.FittedModel` of a trajectory identification: the final
    parameter table, the stages' convergence (``fits``: each search, named, in order), the
    joint's J and gravity, LuGre's passivity and the provenance
    (``provenance["trajectory"]``); no intervals unless converged (module notes)."""
    method, seed, max_evals = options["method"], options["seed"], options["max_evals"]
    rename = options.get("rename", {})
    convergence = converged(fits, method, max_evals, rename) if fits else None
    ok = convergence is None or convergence["converged"]
    if not ok:
        warnings.warn(
            f"identifying '{key}' from the trajectory did not converge: "
            f"{convergence['reason']}; {convergence['advice']}; its intervals are withheld",
            ConvergenceWarning,
            stacklevel=user_stacklevel(),
        )
        final = _withheld(final)
    static, derivative = options["static"], options["derivative"]
    v_slide, gravity, t_start = options["v_slide"], options["gravity"], options["t_start"]
    rate = 1.0 / series.dt
    stage1 = stages["regression"]
    param_names = list(get_model(key).param_names)
    is_lugre = key in ("lugre", "lugre_asym")
    values = np.array([final[n]["value"] for n in param_names])
    low = np.array([final[n]["ci95_low"] for n in param_names])
    high = np.array([final[n]["ci95_high"] for n in param_names])
    fitted = FittedModel(
        model=key,
        parameters=one_sided(
            unresolved_rise(
                _records(
                    param_names,
                    final,
                    get_model(key).units,
                    bounds_out,
                    None if convergence is None else convergence["converged"],
                    note="" if ok else NO_INTERVAL,
                    notes=options.get("notes") or {},
                )
            ),
            dynamic=key in DYNAMIC_MODELS,
        ),
        ci_method=(
            "cluster-robust" + (", two-step" if key == "lugre" and route != "filtered" else "")
        )
        if ok
        else "",
        optimizer=OptimizerRecord(
            method=method,
            seed=seed,
            status=int(fits[-1][1].result.status) if fits else None,
            message=str(fits[-1][1].result.message) if fits else "",
            nfev=int(sum(st.result.nfev for _, st in fits)),
            max_evals=_budget(fits, max_evals),
        ),
        convergence=convergence,
        metrics={
            **metrics(y, yhat),
            **{
                f"sim_rmse_{k}": v
                for k, v in stages.get("simulation", stage1).rms.items()
                if k != "torque"
            },
        },
        statistics=fit_statistics(y, yhat, len(param_names) + n_joint),
        operating_range={
            "velocity": [float(vf.min()), float(vf.max())],
            **temperature_range(log, series),
        },
    )
    last_regression = [st for name, st in stages.items() if name.startswith("refinement")]
    joint_tab = {
        n: row for n, row in (last_regression or [stage1])[-1].table().items() if n in JOINT_PARAMS
    }
    for name in ("filtered", "output_error"):
        if name in stages:
            joint_tab = {n: r for n, r in stages[name].table().items() if n in JOINT_PARAMS}
    if "simulation_joint" in stages:
        joint_tab.update(
            {n: r for n, r in stages["simulation_joint"].table().items() if n in JOINT_PARAMS}
        )
    if not ok:
        joint_tab = _withheld(joint_tab)
    info: dict[str, Any] = {
        "route": route,
        "static_from": "sweeps"
        if static is not None
        else ("the same joint estimate" if route == "filtered" else "regression"),
        "derivative": {**derivative.describe(rate), **_bias(options.get("window_bias"))},
        "resampled": series.resampled,
        "sample_rate": rate,
        "v_slide": v_slide,
        "gravity": gravity,
        "joint": joint_tab,
        "routes": {
            name: {
                "parameters": st.table() if ok else _withheld(st.table()),
                "rms": st.rms,
                "seconds": st.seconds,
                "clusters": st.clusters,
                "nfev": int(st.result.nfev) if st.result is not None else 0,
                "converged": bool(st.result.success) if st.result is not None else None,
            }
            for name, st in stages.items()
        },
        "seconds": time.perf_counter() - t_start,
        **sim_info,
    }
    direction, gravity_note = options.get("direction", ("", ""))
    caveats = [
        bias_caveat(options.get("window_bias")),
        direction,
        lugre_caveat(key == "lugre_asym") if is_lugre else "",
        delay_caveat(sim_info.get("torque_delay")),
    ]
    if any(caveats):
        info["caveats"] = [c for c in caveats if c]
    if gravity_note:
        info["gravity_note"] = gravity_note
    if not is_lugre:  # a note, not a caveat: a second log's verdict grades the predictions
        info["intervals_note"] = INTERVALS_NOTE
    if is_lugre:
        info["passivity"] = passivity(param_names, values, low, high)
        if not info["passivity"]["passive"]:
            warnings.warn(
                f"the identified LuGre model is not passive (margin "
                f"{info['passivity']['margin']:.3g} N m s/rad): {info['passivity']['condition']}",
                PassivityWarning,
                stacklevel=user_stacklevel(),
            )
    fitted.provenance = {
        "source": log.source,
        "n_samples": int(series.time.size),
        # the directions it moved in: a log that never reverses identifies one side only
        "directions": [d for d in (-1, 1) if np.any(np.sign(vf) == d)] or [-1, 1],
        "fricid_version": __version__,
        "created": created_timestamp(),
        "trajectory": info,
    }
    return fitted


def _bias(record: dict[str, Any] | None) -> dict[str, Any]:
    """The derivative window's predicted biases, for the provenance (:mod:`._window`)."""
    return {} if record is None else {"bias": record}


def _budget(fits: list, max_evals: int | None) -> int | None:
    """The evaluation budget: ``max_evals``, else the last search's evaluations (None with no
    search)."""
    if not fits:
        return None
    return int(max_evals) if max_evals is not None else int(fits[-1][1].result.nfev)


def one_sided(params: dict[str, Parameter], dynamic: bool) -> dict[str, Parameter]:
    """A dynamic law's parameter whose 95 % interval reaches one end of its search range
    flagged not determined (issue 26: "parameters at the box edge or with open intervals
    flagged as not determined"), its note giving the one bound the data set; the interval is
    kept in the record. Measured on ``benchmarks/bench_lugre.py`` (tuning seeds 0-2, 10 s,
    108 fits): 51 such intervals, 43 of them holding the truth but none a statement of where
    it lies: sigma_2 at 3e-9 in [0, 2.0] for 0.4, tau_c 1.47 in [0, 3.7] for 1, sigma_0 at the
    search range's top, 1e7 for 1e5. A static law's open end stays a flag (a viscous term
    consistent with zero is a statement), and an interval open at both ends is "not
    identified" already."""
    if not dynamic:
        return params
    out = dict(params)
    for name, p in params.items():
        if p.not_determined or not p.one_bound or p.bounds is None:
            continue
        side, end = ("lower", p.bounds[0]) if p.low_open else ("upper", p.bounds[1])
        why = (
            f"not determined: its 95 % interval reaches the search range's {side} end "
            f"({end:.4g}), so the data bound it on one side only ({p.one_bound}"
            + (f" {p.unit})" if p.unit else ")")
        )
        out[name] = replace(p, note=why if not p.note else f"{why}; {p.note}", not_determined=True)
    return out


def unresolved_rise(params: dict[str, Parameter]) -> dict[str, Parameter]:
    """``tau_s`` and ``delta`` flagged not determined where the data admit a Stribeck rise at
    any lower speed: ``w_s`` not identified, or its 95 % interval open at the lower end of its
    search range. A narrower rise is then a taller one as well fitted (the samples that would
    show it are below the velocity the log resolves), so the break-away torque is not bounded
    by the data; what ``tau_s`` estimates is the friction at the slowest speeds resolved.
    Measured on ``benchmarks/bench_lugre.py`` (seeds 0-2, 10 s, 108 fits): of the 44 fits
    it now flags, 25 had claimed a closed interval for ``tau_s`` in a converged fit, and 6 of
    those covered the truth (cdw95, w_s = 1 mrad/s: tau_s at tau_c, 58 to 390 half-widths
    off)."""
    w_s = params.get("w_s")
    rise = [n for n in params if lugre.symmetric_name(n) in ("tau_s", "delta")]
    if w_s is None or not rise or not np.isfinite(w_s.value):
        return params
    if all(params[n].not_determined for n in rise if n.startswith("tau_s")):
        return params  # said already (the rate bias's check)
    if not (w_s.low_open or w_s.note.startswith("not identified")):
        return params
    out = dict(params)
    why = (
        "not determined: the Stribeck velocity w_s is not bounded below by the data (its 95 % "
        "interval reaches the search range's lower end), so a narrower, taller rise fits as "
        "well; the value is the friction at the slowest speeds the log resolves"
    )
    for n in rise:
        if not out[n].not_determined:
            out[n] = replace(out[n], note=why, not_determined=True)
    return out


def _at(value: float, bound: float, box) -> bool:
    """Whether ``value`` is at ``bound`` (:data:`AT_BOUND`): relative to the bound, or for a
    bound of 0 to the range's width (3.4e-36 in [0, 2] is at 0; 150 in [100, 1e8] is not at
    100, as a test against the width would have it on a log-scaled range)."""
    scale = abs(bound) if bound != 0 else box[1] - box[0]
    return bool(abs(value - bound) <= AT_BOUND * scale)


def _records(
    names: list[str],
    final: dict[str, dict[str, float]],
    units: dict[str, str],
    bounds: dict[str, list[float]],
    converged: bool | None,
    note: str = "",
    notes: dict[str, str] | None = None,
) -> dict[str, Parameter]:
    """One :class:`~fricid.fitted.Parameter` per name of the final table: value, standard
    error, the cluster-robust 95 % interval (its ends open where they reach the search box,
    within :data:`EDGE` of its width: an end 0.20000000000000018 of a range from 0.2 is the
    range's), and at a bound where the value is at one (:func:`_at`); ``note`` says why an
    interval is missing (an unconverged fit's: no end is then open); ``notes`` a parameter's
    own (the bias check's: widened, or not determined). A parameter whose interval spans the
    whole search box is not identified, as an analytic fit says it."""
    out = {}
    for n in names:
        row, box = final[n], bounds.get(n)
        value, se = float(row["value"]), float(row["stderr"])
        low, high = float(row["ci95_low"]), float(row["ci95_high"])
        reach = 0.0 if box is None else EDGE * (box[1] - box[0])  # rounding at the ends
        low_open = box is not None and not note and bool(low <= box[0] + reach)
        high_open = box is not None and not note and bool(high >= box[1] - reach)
        why = note or (notes or {}).get(n, "")
        if low_open and high_open:  # as an analytic fit says it (static.uncertainty)
            why = (
                "not identified: the 95 % interval spans the whole search range "
                f"[{box[0]:.4g}, {box[1]:.4g}]"
            )
        out[n] = Parameter(
            n,
            value,
            unit=units.get(n, ""),
            bounds=None if box is None else (float(box[0]), float(box[1])),
            stderr=se,
            ci95=(low, high),
            ci95_halfwidth=(high - low) / 2,
            low_open=low_open,
            high_open=high_open,
            at_bound=box is not None and any(_at(value, b, box) for b in box),
            note=why,
            not_determined=is_not_determined(why, se, converged),
        )
    return out
