"""The rows of the RWSAVSBAS study (:mod:`.stribeck_study`): methods, budgets, readings.

[R] B. Kou et al., "A New Parameter Identification Method for Industrial Robots with
Friction", Machines 10(5) 349, 2022, section 4.1 gives the settings of VSBAS, IBAS and
RWSAVSBAS. :func:`method_specs` lists every row of the study in the table's order
(:data:`GROUPS`): every method at RWSAVSBAS's evaluation count first (the headline: the
comparison at equal work), then [R]'s methods at [R]'s budgets, then the baselines at a
budget that fits the stated time. :func:`readings` lists the readings of RWSAVSBAS where [R]
is unclear.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["GROUPS", "MethodSpec", "method_specs", "paper_options", "readings"]


@dataclass
class MethodSpec:
    """One row of the study: a method, its options and budget per run."""

    label: str
    method: str
    options: dict[str, Any]
    max_evals: int | None = None
    paper: str | None = None
    setting: str = ""
    group: str = "paper budget"


#: The groups of :func:`method_specs`, in the table's order (the headline first).
GROUPS = ("equal budget", "paper budget", "baseline")


def paper_options(quick: bool) -> dict[str, Any]:
    """RWSAVSBAS at [R] 4.1 (quick: the same schedule compressed ten-fold)."""
    if not quick:
        return {}
    return {"n_outer": 100, "eta": 0.98**10, "cooling": 0.95**10, "h_outer": 100.0}


def _specs(quick: bool) -> list[MethodSpec]:
    """The rows: every method at RWSAVSBAS's evaluation count first (the headline), then
    [R]'s methods at [R]'s budgets, then the baselines that cannot afford that count here.

    The equal-budget beetles stretch their schedule ``k``-fold (``k`` = 100, quick 10) to
    spend the budget: each per-iteration decay factor to the power ``1 / k``, BAS's antenna
    floor ``d_inc / (1 - eta_d)`` kept.
    """
    rws = paper_options(quick)
    k = 10 if quick else 100
    n_rws = 1 + (100 if quick else 1000) * 301
    eq_iter = -(-(n_rws - 1) // 3)  # cut at n_rws evaluations by the budget
    eq_eta = 0.98 ** (1.0 / k)
    bas_eta = 0.95 ** (1.0 / k)
    base = 3000 if quick else 10_000
    rws_setting = (
        "1000 x 100, step0 0.1, eta 0.98, c 3, T0 1e4 x 0.95"
        if not quick
        else "quick: 100 x 100, schedule compressed x10"
    )
    eq = f"{eq_iter} it., eta 0.98^(1/{k})"
    equal = "equal budget"
    return [
        MethodSpec(
            "RWSAVSBAS", "rwsavsbas", {**rws, "jit": False}, None, "RWSAVSBAS", rws_setting, equal
        ),
        MethodSpec(
            "VSBAS (equal evals)",
            "vsbas",
            {"n_iter": eq_iter, "eta": eq_eta},
            n_rws,
            None,
            eq,
            equal,
        ),
        MethodSpec(
            "IBAS (equal evals)", "ibas", {"n_iter": eq_iter, "eta": eq_eta}, n_rws, None, eq, equal
        ),
        MethodSpec(
            "BAS (equal evals)",
            "bas",
            {
                "n_iter": eq_iter,
                "eta_step": bas_eta,
                "eta_d": bas_eta,
                "d_inc": 0.01 * (1.0 - bas_eta) / 0.05,
            },
            n_rws,
            None,
            f"{eq_iter} it., eta 0.95^(1/{k}), d0 0.2, step0 0.5",
            equal,
        ),
        MethodSpec("GA (equal evals)", "ga", {}, n_rws, None, "pop 40, SBX, poly. mutation", equal),
        MethodSpec("DE (scipy, equal evals)", "de", {}, n_rws, None, "best1bin, pop 60", equal),
        MethodSpec("VSBAS", "vsbas", {}, None, "VSBAS", "1000 it., step0 0.1, eta 0.98, c 3"),
        MethodSpec("IBAS", "ibas", {}, None, "IBAS", "1000 it., step 0.3->0.1, eta 0.98, c 3"),
        MethodSpec("BAS", "bas", {}, None, None, "eq. 18-21, 1000 it., d0 0.2, step0 0.5"),
        MethodSpec(
            "dual annealing (scipy)", "dual_annealing", {}, base, None, "defaults", "baseline"
        ),
        MethodSpec("CMA-ES (cma)", "cmaes", {}, base, None, "sigma0 0.3, restarts", "baseline"),
    ]


def method_specs(quick: bool = False) -> list[MethodSpec]:
    """The methods the study compares, in the table's order (:data:`GROUPS`), full or quick."""
    return _specs(quick)


def readings(quick: bool) -> list[tuple[str, dict[str, Any]]]:
    return [
        ("default: wander along b, P counts, G updated at once", {}),
        ("wander: independent random direction", {"wander": "random"}),
        ("wander: literal, same offset on every coordinate", {"wander": "diagonal"}),
        ("P: uniform random phase", {"phase": "random"}),
        ("G updated only after each inner loop (3.2 D)", {"best_update": "outer"}),
    ]
