"""What a trajectory identification reports beside its parameters: convergence of its stages
(certified as an analytic fit's), LuGre's passivity (Barabanov and Ortega 2000), and the log
rate's bias of sigma_0, sigma_1.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ...errors import FricidWarning, user_stacklevel
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
            stacklevel=user_stacklevel(),
        )


def passivity(names: list[str], values, low, high) -> dict[str, Any]:
    """[BO00] margin at the estimate and at the least favourable corner of the intervals
    (``margin_worst_in_ci95`` and ``passive_across_ci95`` None when there are no intervals:
    a fit that did not converge)."""
    p = dict(zip(names, values, strict=True))
    worst = dict(p)
    lo, hi = dict(zip(names, low, strict=True)), dict(zip(names, high, strict=True))
    sides = 0
    for n, side in (("sigma_1", hi), ("sigma_2", lo), ("tau_c", lo), ("tau_s", hi)):
        if np.isfinite(side[n]):
            worst[n] = side[n]
            sides += 1
    at = float(lugre.passivity_margin(np.array([p[n] for n in lugre.PARAM_NAMES])))
    corner = float(lugre.passivity_margin(np.array([worst[n] for n in lugre.PARAM_NAMES])))
    return {
        "condition": "sigma_1 <= 4 sigma_2 tau_c / (tau_s - tau_c) (Barabanov and Ortega 2000)",
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
        covered |= names
    return out[::-1]


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
            blocks.append({"stage": name, **certify(stage.problem, stage.result)})
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
