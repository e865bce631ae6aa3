"""What a trajectory identification reports beside its parameters: convergence of its stages,
LuGre's passivity (Barabanov and Ortega 2000), and the log rate's bias of sigma_0, sigma_1.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ...errors import FricidWarning
from ...models import lugre

__all__ = [
    "RATE_BIAS",
    "RATE_BIAS_WARN",
    "PassivityWarning",
    "RateBiasWarning",
    "converged",
    "passivity",
    "warn_rate_bias",
]


class PassivityWarning(FricidWarning):
    """An identified dynamic friction model is not passive (it could create energy)."""


class RateBiasWarning(FricidWarning):
    """The log's rate biases sigma_0 or sigma_1 by a sizeable part of their intervals."""


#: Rate-bias checks of the ``filtered`` route: ``warn`` estimates it and warns, ``off`` not.
RATE_BIAS = ("warn", "off")

#: Warn when the estimated rate bias exceeds this many standard errors (log10 scale).
RATE_BIAS_WARN = 0.5


def warn_rate_bias(stage, rb: dict[str, Any]) -> None:
    """One line when the rate bias of sigma_0 or sigma_1 is a sizeable part of its interval."""
    parts = []
    if "skipped" in rb:
        return
    for i, n in enumerate(("sigma_0", "sigma_1")):
        se_log = stage.stderr[i] / (stage.values[i] * np.log(10.0))
        if abs(rb[n]["log10_bias"]) > RATE_BIAS_WARN * se_log:
            parts.append(f"{n} {100 * rb[n]['relative']:+.2g} %")
    if parts:
        warnings.warn(
            f"logging at {rb['log_rate']:.6g} Hz biases {', '.join(parts)}, as estimated by "
            "simulation at the estimate (the break-away between samples; over half a "
            "standard error; corrected values in the provenance): log at "
            f"{10 * rb['log_rate']:.6g} Hz or faster to remove it",
            RateBiasWarning,
            stacklevel=3,
        )


def passivity(names: list[str], values, low, high) -> dict[str, Any]:
    """[BO00] margin at the estimate and at the least favourable corner of the intervals."""
    p = dict(zip(names, values, strict=True))
    worst = dict(p)
    lo, hi = dict(zip(names, low, strict=True)), dict(zip(names, high, strict=True))
    for n, side in (("sigma_1", hi), ("sigma_2", lo), ("tau_c", lo), ("tau_s", hi)):
        if np.isfinite(side[n]):
            worst[n] = side[n]
    at = float(lugre.passivity_margin(np.array([p[n] for n in lugre.PARAM_NAMES])))
    corner = float(lugre.passivity_margin(np.array([worst[n] for n in lugre.PARAM_NAMES])))
    return {
        "condition": "sigma_1 <= 4 sigma_2 tau_c / (tau_s - tau_c) (Barabanov and Ortega 2000)",
        "margin": at if np.isfinite(at) else None,
        "passive": bool(at >= 0),
        "margin_worst_in_ci95": corner if np.isfinite(corner) else None,
        "passive_across_ci95": bool(corner >= 0),
    }


def converged(results: list, method: str) -> dict[str, Any]:
    """The convergence verdict of the optimiser stages ``results``: converged when every stage
    did (certified by the optimiser's own test), else the reason and advice."""
    ok = all(bool(r.success) for r in results)
    out: dict[str, Any] = {"converged": ok, "certified_by": "optimizer"}
    if not ok:
        out["reason"] = "a stage of the trajectory identification stopped before converging"
        out["advice"] = f"raise --max-evals, or use --method lm (ran '{method}')"
    return out
