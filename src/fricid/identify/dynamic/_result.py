"""The result of a trajectory identification as a model file: parameters with their
intervals, the stages' records, the joint's inertia and gravity, and what was checked.
"""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np

from ... import __version__
from ...fitted import FittedModel
from ...io.atomic import created_timestamp
from ...metrics import fit_statistics, metrics
from ...models import get_model, lugre
from ...samples import RawLog
from ._data import Series
from ._outcome import PassivityWarning, converged, passivity
from ._routes import JOINT_PARAMS

__all__ = ["build_result"]


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
    results: list,
    final: dict[str, dict[str, float]],
    bounds_out: dict[str, list[float]],
    options: dict[str, Any],
    sim_info: dict[str, Any],
) -> FittedModel:
    """The :class:`~fricid.fitted.FittedModel` of a trajectory identification: the final
    parameter table, the stages' convergence, the joint's J and gravity, LuGre's passivity
    and the provenance (``provenance["trajectory"]``)."""
    method, seed, max_evals = options["method"], options["seed"], options["max_evals"]
    static, derivative = options["static"], options["derivative"]
    v_slide, gravity, t_start = options["v_slide"], options["gravity"], options["t_start"]
    rate = 1.0 / series.dt
    stage1 = stages["regression"]
    param_names = list(lugre.PARAM_NAMES) if key == "lugre" else list(get_model(key).param_names)
    values = np.array([final[n]["value"] for n in param_names])
    se = np.array([final[n]["stderr"] for n in param_names])
    low = np.array([final[n]["ci95_low"] for n in param_names])
    high = np.array([final[n]["ci95_high"] for n in param_names])
    fitted = FittedModel(
        model=key,
        params=dict(zip(param_names, map(float, values), strict=True)),
        units=dict(get_model(key).units),
        stderr=dict(zip(param_names, se, strict=True)),
        ci95={n: float((h - lo) / 2) for n, lo, h in zip(param_names, low, high, strict=True)},
        ci95_low=dict(zip(param_names, low, strict=True)),
        ci95_high=dict(zip(param_names, high, strict=True)),
        ci_method="cluster-robust"
        + (", two-step" if key == "lugre" and route != "filtered" else ""),
        metrics={
            **metrics(y, yhat),
            **{
                f"sim_rmse_{k}": v
                for k, v in stages.get("simulation", stage1).rms.items()
                if k != "torque"
            },
        },
        statistics=fit_statistics(y, yhat, len(param_names) + n_joint),
        method=method,
        seed=seed,
        nfev=int(sum(r.nfev for r in results)),
        bounds={n: b for n, b in bounds_out.items() if n in param_names},
        operating_range={
            "velocity": [float(vf.min()), float(vf.max())],
            "temperature": [float(series.temperature.min()), float(series.temperature.max())],
        },
        convergence=converged(results, method, max_evals) if results else None,
        status=int(results[-1].status) if results else None,
        message=str(results[-1].message) if results else "",
    )
    fitted.at_bound = [
        n
        for n in param_names
        if n in fitted.bounds
        and (
            np.isclose(final[n]["value"], fitted.bounds[n][0], rtol=1e-6, atol=0)
            or np.isclose(final[n]["value"], fitted.bounds[n][1], rtol=1e-6, atol=0)
        )
    ]
    fitted.ci_open = {
        n: [bool(lo <= fitted.bounds[n][0]), bool(h >= fitted.bounds[n][1])]
        for n, lo, h in zip(param_names, low, high, strict=True)
        if n in fitted.bounds
    }
    last_regression = [st for name, st in stages.items() if name.startswith("refinement")]
    joint_tab = {
        n: row for n, row in (last_regression or [stage1])[-1].table().items() if n in JOINT_PARAMS
    }
    if "filtered" in stages:
        joint_tab = {n: r for n, r in stages["filtered"].table().items() if n in JOINT_PARAMS}
    if "simulation_joint" in stages:
        joint_tab.update(
            {n: r for n, r in stages["simulation_joint"].table().items() if n in JOINT_PARAMS}
        )
    info: dict[str, Any] = {
        "route": route,
        "static_from": "sweeps"
        if static is not None
        else ("the same joint estimate" if route == "filtered" else "regression"),
        "derivative": derivative.describe(rate),
        "resampled": series.resampled,
        "sample_rate": rate,
        "v_slide": v_slide,
        "gravity": gravity,
        "joint": joint_tab,
        "routes": {
            name: {
                "parameters": st.table(),
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
    if key == "lugre":
        info["passivity"] = passivity(param_names, values, low, high)
        if not info["passivity"]["passive"]:
            warnings.warn(
                f"the identified LuGre model is not passive (margin "
                f"{info['passivity']['margin']:.3g} N m s/rad): {info['passivity']['condition']}",
                PassivityWarning,
                stacklevel=2,
            )
    fitted.provenance = {
        "source": log.source,
        "n_samples": int(series.time.size),
        "directions": [-1, 1],
        "fricid_version": __version__,
        "created": created_timestamp(),
        "trajectory": info,
    }
    return fitted
