"""The RWSAVSBAS paper's study, reproduced: Table 1 and Fig. 6 on the ``paper2`` preset.

[R] B. Kou et al., "A New Parameter Identification Method for Industrial Robots with
Friction", Machines 10(5) 349, 2022, section 4: the Stribeck model (eq. 7, delta = 1) is fitted
to 17 friction samples by minimising the SSE (eq. 11), 8 runs each of VSBAS, IBAS and
RWSAVSBAS at the settings of 4.1; Table 1 gives the average, largest and smallest final SSE,
Fig. 6 the average convergence curves.

:func:`run_study` does that on simulated data (the ``paper2`` preset of :mod:`fricid.sim`,
whose truth is [R]'s Table 2), adds BAS, GA, the scipy/cma baselines and ``bas+lm``, finds
the exact global optimum by variable projection, checks the readings of RWSAVSBAS that [R]
leaves open, and measures the optimiser's overhead against plain batched evaluation. It
returns tables (pandas DataFrames), the convergence data and computed claims; the text,
figure and files are :mod:`fricid.report.studies.stribeck`'s (``fricid bench stribeck`` and
``benchmarks/bench_stribeck.py`` print and write them). The problem itself (data, objective,
box, exact optimum) is :mod:`.stribeck_problem`, the rows (methods, budgets) :mod:`.stribeck_specs`.

Fairness. Every timed method evaluates candidates with the same objective code, the compiled
numba kernel of fricid's analytic fits, :func:`fricid.models._kernels.loss_kernel`, through
:func:`.stribeck_problem.sse_objective` (numpy only without numba): every
method here takes batches (or single points, which the kernel serves as batches of one), so
the kernel is the objective all of them can take, and the fastest; timing some on numpy and
one on the kernel measured the objective, not the algorithm. RWSAVSBAS's table row runs its
algorithm in Python like the others (``jit=False``); its compiled loop, algorithm and kernel
fused, is timed apart in :attr:`StudyResult.performance`. The table's first rows give every
method RWSAVSBAS's evaluation count (the headline: at equal work), then [R]'s budgets, then
the baselines that cannot afford that count in the stated time. BLAS runs on one thread for
every method (17 samples: threads only add overhead).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from ..errors import ConfigError
from ..optim import JitObjective, OptimizeResult, minimize, minimize_runs
from .paper_numbers import RWSAVSBAS as PAPER_NUMBERS
from .stribeck_problem import (
    BOUNDS,
    FREE,
    StribeckProblem,
    global_optimum,
    paper2_samples,
    sse_objective,
)
from .stribeck_specs import GROUPS, MethodSpec, method_specs
from .stribeck_specs import paper_options as _paper_options
from .stribeck_specs import readings as _readings

__all__ = [
    "BOUNDS",
    "FREE",
    "GROUPS",
    "PAPER_TABLE1",
    "SUCCESS_RTOL",
    "MethodSpec",
    "StribeckProblem",
    "StudyResult",
    "global_optimum",
    "method_specs",
    "paper2_samples",
    "reproduced",
    "run_study",
    "sse_objective",
]

#: [R] Table 1: average, largest and smallest final SSE of 8 runs (from
#: :mod:`.paper_numbers`, the one place paper numbers live).
PAPER_TABLE1 = {
    row["label"]: (row["mean"], row["max"], row["min"]) for row in PAPER_NUMBERS["table1"].values()
}

#: A run "finds the optimum" when its SSE is within this relative distance of it.
SUCCESS_RTOL = 1e-3


@dataclass
class StudyResult:
    """What :func:`run_study` returns.

    Attributes
    ----------
    table : pandas.DataFrame
        [R] Table 1 and the baselines: one row per method (average, max, min SSE, the
        paper's, ratios to the optimum, runs at the optimum, evaluations, seconds per run).
    readings : pandas.DataFrame
        The readings of RWSAVSBAS where [R] is unclear, same columns.
    hybrid : pandas.DataFrame
        bas+lm against lm alone from the same random starts, run by run.
    convergence : pandas.DataFrame
        [R] Fig. 6: mean best-so-far SSE against evaluations per method.
    performance : dict
        Timings and the overhead ratios.
    optimum : dict
        The exact optimum (variable projection): parameters and ``sse``.
    claims : dict
        From :func:`reproduced`: per [R] Table 1 row, whether ours is within a factor 2.
    config : dict
        The settings of the run.
    results : dict
        Every run (:class:`~fricid.optim.OptimizeResult`) by label.
    """

    table: pd.DataFrame
    readings: pd.DataFrame
    hybrid: pd.DataFrame
    convergence: pd.DataFrame
    performance: dict[str, float]
    optimum: dict[str, float]
    claims: dict[str, bool]
    config: dict[str, Any]
    results: dict[str, list[OptimizeResult]] = field(repr=False, default_factory=dict)


def _summary(label: str, res: list[OptimizeResult], f_opt: float, seconds: float) -> dict:
    f = np.array([r.fun for r in res])
    ratio = f / f_opt
    return {
        "label": label,
        "mean_sse": float(f.mean()),
        "max_sse": float(f.max()),
        "min_sse": float(f.min()),
        "mean_ratio": float(ratio.mean()),
        "max_ratio": float(ratio.max()),
        "found": int(np.sum(ratio <= 1.0 + SUCCESS_RTOL)),
        "runs": len(res),
        "evals": int(max(r.nfev for r in res)),
        "seconds_per_run": seconds / len(res),
    }


def _curve(res: list[OptimizeResult], grid: np.ndarray) -> np.ndarray:
    """Mean over runs of the best-so-far SSE at each evaluation count of ``grid`` (a run that
    ended keeps its final value; NaN before every run has a value or after all have ended)."""
    out = np.full((len(res), grid.size), np.nan)
    for i, r in enumerate(res):
        h = r.history
        if not len(h):
            continue
        idx = np.searchsorted(h[:, 0], grid, side="right") - 1
        ok = idx >= 0
        out[i, ok] = h[idx[ok], 1]
    mean = out.mean(axis=0)
    mean[grid > max(r.nfev for r in res)] = np.nan
    return mean


def _time_batches(fun: Callable[[np.ndarray], Any], X: np.ndarray, n_batches: int) -> float:
    t = time.perf_counter()
    for chunk in np.array_split(X, n_batches):
        fun(np.ascontiguousarray(chunk))
    return time.perf_counter() - t


def run_study(
    seed: int = 0,
    runs: int = 8,
    quick: bool = False,
    data_seed: int = 0,
    progress: Callable[[str], None] | None = None,
    time_numpy: bool = True,
    repeats: int = 3,
) -> StudyResult:
    """Run the study; see the module docstring.

    Parameters
    ----------
    seed : int
        Base seed of the optimiser runs (run ``r`` uses ``seed + r``).
    runs : int
        Runs per method ([R]: 8).
    quick : bool
        Reduced budgets (RWSAVSBAS 100 x 100 with its schedule compressed ten-fold,
        baselines 3000 evaluations) for a fast check.
    data_seed : int
        Seed of the simulated measurement.
    progress : callable, optional
        Called with a short message before each stage (for a progress display).
    time_numpy : bool
        Also time RWSAVSBAS on its numpy path (the generic one) for the overhead ratios.
    repeats : int
        The overhead timings (compiled RWSAVSBAS runs against batched evaluation) are
        interleaved and repeated this many times; the best of each is reported.

    Returns
    -------
    StudyResult
        Tables, convergence data, performance numbers, the exact optimum and claims.

    Raises
    ------
    ConfigError
        If ``runs`` is not a positive integer.
    """
    if isinstance(runs, bool) or not isinstance(runs, int | np.integer) or runs < 1:
        raise ConfigError(f"runs must be a positive integer; got {runs!r}")
    from threadpoolctl import threadpool_limits

    # 17 samples: BLAS threads only add overhead (scipy's L-BFGS-B inside dual annealing ran
    # 3-7x slower with them on a loaded 2-core machine), so every method runs on one
    with threadpool_limits(limits=1):
        return _run(seed, runs, quick, data_seed, progress, time_numpy, repeats)


def _run(
    seed: int,
    runs: int,
    quick: bool,
    data_seed: int,
    progress: Callable[[str], None] | None,
    time_numpy: bool,
    repeats: int,
) -> StudyResult:
    """:func:`run_study`'s body, on one BLAS thread."""

    def say(msg: str) -> None:
        if progress is not None:
            progress(msg)

    say("simulating the paper2 preset and extracting its 17 samples")
    v, y = paper2_samples(data_seed)
    problem = StribeckProblem(v, y)
    say("global optimum by variable projection")
    theta_opt, f_opt = global_optimum(problem)
    fast = sse_objective(problem, jit=True)
    plain = sse_objective(problem, jit=False)
    compiled = isinstance(fast, JitObjective)
    objective_code = "compiled kernel" if compiled else "numpy"
    bounds = problem.bounds
    results: dict[str, list[OptimizeResult]] = {}
    rows = []
    perf: dict[str, float] = {}

    # compile the kernel and RWSAVSBAS's compiled loop once, outside every timing
    if compiled:
        say("compiling the objective kernel and RWSAVSBAS's loop (numba)")
        t = time.perf_counter()
        fast(bounds[:, 0][None])
        minimize_runs(fast, bounds, "rwsavsbas", seed=seed, runs=runs, options={"n_outer": 1})
        perf["compile_seconds"] = time.perf_counter() - t

    specs = method_specs(quick)
    for spec in specs:
        say(f"{spec.label}: {runs} runs ({spec.group})")
        t = time.perf_counter()
        res = minimize_runs(
            fast,
            bounds,
            spec.method,
            seed=seed,
            runs=runs,
            max_evals=spec.max_evals,
            options=spec.options,
        )
        seconds = time.perf_counter() - t
        results[spec.label] = res
        row = _summary(spec.label, res, f_opt, seconds)
        row["group"] = spec.group
        row["method"] = spec.method
        row["setting"] = spec.setting
        row["objective"] = objective_code
        paper = PAPER_TABLE1.get(spec.paper) if spec.paper else None
        row["paper_mean"], row["paper_max"], row["paper_min"] = paper or (np.nan,) * 3
        rows.append(row)
        if spec.label == "RWSAVSBAS":
            perf["rws_loop_seconds"] = seconds
            perf["rws_evals_per_run"] = float(res[0].nfev)
    table = pd.DataFrame(rows).set_index("label")

    # the other readings of RWSAVSBAS
    rws_opts = _paper_options(quick)
    reading_rows = []
    for label, extra in _readings(quick):
        say(f"RWSAVSBAS reading: {label}")
        t = time.perf_counter()
        res = (
            results["RWSAVSBAS"]
            if not extra
            else minimize_runs(
                fast,
                bounds,
                "rwsavsbas",
                seed=seed,
                runs=runs,
                options={**rws_opts, **extra, "jit": False},
            )
        )
        seconds = perf["rws_loop_seconds"] if not extra else time.perf_counter() - t
        results[f"reading: {label}"] = res
        reading_rows.append(_summary(label, res, f_opt, seconds))
    readings = pd.DataFrame(reading_rows).set_index("label")

    # overhead: all runs of RWSAVSBAS against evaluating as many candidates in big batches;
    # interleaved and repeated, best of each (other processes' load then hits all alike)
    n_total = int(perf["rws_evals_per_run"]) * runs
    X = bounds[:, 0] + np.random.default_rng(seed).random((n_total, 4)) * (
        bounds[:, 1] - bounds[:, 0]
    )
    n_batches = max(1, n_total // 100_000)
    times: dict[str, list[float]] = {"batch_numpy": [], "batch_kernel": [], "rws_jit": []}
    out = np.empty(-(-n_total // n_batches) + 1)

    def kernel_call(chunk: np.ndarray) -> None:
        fast.jit_kernel(chunk, out[: len(chunk)], fast.jit_data)

    for rep in range(repeats):
        say(
            f"timing {n_total} evaluations in {n_batches} batches against all runs "
            f"({rep + 1}/{repeats})"
        )
        times["batch_numpy"].append(_time_batches(plain, X, n_batches))
        if compiled:
            kernel_call(X[:10])
            times["batch_kernel"].append(_time_batches(kernel_call, X, n_batches))
            t = time.perf_counter()
            minimize_runs(fast, bounds, "rwsavsbas", seed=seed, runs=runs, options=rws_opts)
            times["rws_jit"].append(time.perf_counter() - t)
    perf["batch_numpy_seconds"] = min(times["batch_numpy"])
    if compiled:
        perf["rws_jit_seconds"] = min(times["rws_jit"])
        perf["ratio_loop_vs_jit"] = perf["rws_loop_seconds"] / perf["rws_jit_seconds"]
        perf["batch_kernel_seconds"] = min(times["batch_kernel"])
        perf["ratio_jit_vs_kernel_batches"] = perf["rws_jit_seconds"] / perf["batch_kernel_seconds"]
        perf["ratio_jit_vs_numpy_batches"] = perf["rws_jit_seconds"] / perf["batch_numpy_seconds"]
    perf["repeats"] = float(repeats)
    perf["batches"] = float(n_batches)
    if time_numpy:
        say("RWSAVSBAS on the generic numpy path (same runs, for the overhead ratio)")
        t = time.perf_counter()
        res_np = minimize_runs(plain, bounds, "rwsavsbas", seed=seed, runs=runs, options=rws_opts)
        perf["rws_numpy_seconds"] = time.perf_counter() - t
        perf["ratio_numpy_vs_numpy_batches"] = (
            perf["rws_numpy_seconds"] / perf["batch_numpy_seconds"]
        )
        a = np.array([r.fun for r in res_np])
        b = np.array([r.fun for r in results["RWSAVSBAS"]])
        perf["numpy_vs_jit_max_rel_diff"] = float(np.max(np.abs(a - b) / b))
        results["RWSAVSBAS (numpy path)"] = res_np

    # bas+lm and lm alone from the same random starts
    say(f"bas+lm and lm from the same random starts: {runs} runs each")
    t = time.perf_counter()
    hyb = minimize_runs(None, bounds, "bas+lm", seed=seed, runs=runs, residuals=problem.residuals)
    t_hyb = time.perf_counter() - t
    lm_res = []
    for r in range(runs):
        u0 = np.random.default_rng(seed + r).random(4)  # the first draw of bas+lm's run r
        x0 = bounds[:, 0] + u0 * (bounds[:, 1] - bounds[:, 0])
        lm_res.append(
            minimize(
                None,
                bounds,
                "lm",
                seed=seed + r,
                x0=x0,
                options={"n_starts": 1},
                residuals=problem.residuals,
            )
        )
    results["bas+lm"], results["lm (same starts)"] = hyb, lm_res
    hybrid = pd.DataFrame(
        {
            "run": np.arange(runs),
            "seed": [seed + r for r in range(runs)],
            "bas+lm_sse": [h.fun for h in hyb],
            "bas+lm_evals": [h.nfev for h in hyb],
            "bas+lm_found": [h.fun <= f_opt * (1 + SUCCESS_RTOL) for h in hyb],
            "lm_sse": [h.fun for h in lm_res],
            "lm_evals": [h.nfev for h in lm_res],
            "lm_found": [h.fun <= f_opt * (1 + SUCCESS_RTOL) for h in lm_res],
        }
    ).set_index("run")
    perf["hybrid_seconds_per_run"] = t_hyb / runs
    perf["hybrid_max_evals_fraction_of_rws"] = float(
        hybrid["bas+lm_evals"].max() / perf["rws_evals_per_run"]
    )

    # convergence curves (Fig. 6): mean best-so-far SSE against evaluations
    n_max = max(int(r.nfev) for res in results.values() for r in res)
    grid = np.unique(np.round(np.geomspace(1, n_max, 400)).astype(int))
    curves = []
    for label in [s.label for s in specs] + ["bas+lm"]:
        mean = _curve(results[label], grid)
        keep = np.isfinite(mean)
        curves.append(pd.DataFrame({"label": label, "nfev": grid[keep], "mean_sse": mean[keep]}))
    convergence = pd.concat(curves, ignore_index=True)

    optimum = dict(zip(FREE, map(float, theta_opt), strict=True))
    optimum["sse"] = f_opt
    claims = reproduced(table)
    config = {
        "seed": seed,
        "runs": runs,
        "quick": quick,
        "data_seed": data_seed,
        "bounds": {n: tuple(map(float, b)) for n, b in zip(FREE, bounds, strict=True)},
        "success_rtol": SUCCESS_RTOL,
        "jit": compiled,
    }
    return StudyResult(table, readings, hybrid, convergence, perf, optimum, claims, config, results)


def reproduced(table: pd.DataFrame) -> dict[str, bool]:
    """For each of [R]'s Table 1 rows: is our average SSE within a factor 2 of the paper's?

    Parameters
    ----------
    table : pandas.DataFrame
        :attr:`StudyResult.table` (index: method labels, column ``mean_sse``).

    Returns
    -------
    dict
        ``{"VSBAS": bool, "IBAS": bool, "RWSAVSBAS": bool}``: true when
        ``0.5 < ours / paper < 2``.
    """
    out = {}
    for label, (paper, _, _) in PAPER_TABLE1.items():
        ratio = float(table.loc[label, "mean_sse"]) / paper
        out[label] = bool(0.5 < ratio < 2.0)
    return out
