"""The RWSAVSBAS study as ``fricid bench stribeck`` shows it: text, CSV tables and Fig. 6.

Renders :func:`fricid.experiments.stribeck_study.run_study`'s result: :func:`report_text` (the
printed report: [R] Table 1 beside ours, the readings of RWSAVSBAS, bas+lm, the performance
ratios), :func:`study_notes` (why ours differ from [R]), :func:`write_outputs` (the tables as
CSV and [R] Fig. 6 as PNG, each file written atomically).

[R] Kou et al., "A New Parameter Identification Method for Industrial Robots with Friction",
Machines 10(5) 349, 2022.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from ...experiments.stribeck_study import FREE, PAPER_TABLE1, SUCCESS_RTOL, StudyResult
from ...io.atomic import atomic_write
from .. import plots

__all__ = ["convergence_png", "report_text", "study_notes", "write_outputs"]


def study_notes(result: StudyResult) -> list[str]:
    """One line per [R] Table 1 row that the study does not reproduce, with the reason.

    Parameters
    ----------
    result : fricid.experiments.stribeck_study.StudyResult
        The study; its ``claims`` say which rows are reproduced (within a factor 2).

    Returns
    -------
    list of str
        The notes (a last one in quick mode; "none: ..." when every row is reproduced).
    """
    table, f_opt = result.table, result.optimum["sse"]
    quick, claims = result.config["quick"], result.claims
    notes = []
    why = {
        "VSBAS": (
            "the same failure mode as the paper's: the step 0.1 * 0.98^t lets the beetle travel "
            "at most 5 box widths and then freezes it wherever it is (runs range "
            "{lo:.2g} .. {hi:.2g}); the level depends on the search box, which [R] does not give"
        ),
        "IBAS": (
            "with steps of 0.1-0.3 of our box it reaches the optimum's region but cannot refine "
            "it; [R]'s steps are presumably in raw units, 0.1-0.3 against w_s = 0.066 rad/s and "
            "tau_v = 0.0026 N m s/rad, hence its far larger SSE"
        ),
    }
    for label, reason in why.items():
        ours = table.loc[label, "mean_sse"]
        paper = PAPER_TABLE1[label][0]
        if not claims[label]:
            text = reason.format(lo=table.loc[label, "min_sse"], hi=table.loc[label, "max_sse"])
            notes.append(
                f"{label}: average SSE {ours:.3g} against the paper's {paper:.3g}: {text}."
            )
    rws = table.loc["RWSAVSBAS", "mean_sse"]
    if not claims["RWSAVSBAS"]:
        notes.append(
            f"RWSAVSBAS: ours {rws:.3g} against the paper's 1.3e-4: the simulated noise gives an "
            f"optimum of {f_opt:.3g}; compare the ratio to the optimum, not the SSE."
        )
    if quick:
        notes.append("quick mode: reduced budgets, not the paper's settings.")
    if not notes:
        notes.append("none: every paper row is reproduced within a factor of 2.")
    return notes


def _fmt(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{x:.3g}"


def report_text(result: StudyResult) -> str:
    """The study as plain text: Table 1 beside the paper's, readings, bas+lm, performance."""
    t, p, o = result.table, result.performance, result.optimum
    runs = result.config["runs"]
    lines = [
        "RWSAVSBAS paper, Table 1, on the paper2 preset (simulated; 17 samples, delta = 1)",
        f"global optimum (variable projection): SSE {o['sse']:.6g} at "
        + ", ".join(f"{n} {o[n]:.5g}" for n in FREE),
        f"'found' = final SSE within {SUCCESS_RTOL:.1%} of the optimum; {runs} runs each",
        "",
        f"{'method':<24}{'avg SSE':>10}{'max':>10}{'min':>10}{'paper avg':>10}{'max':>8}"
        f"{'min':>9}{'avg/opt':>10}{'max/opt':>10}{'found':>7}{'evals':>9}{'s/run':>8}  setting",
    ]
    for label, r in t.iterrows():
        lines.append(
            f"{label:<24}{_fmt(r.mean_sse):>10}{_fmt(r.max_sse):>10}{_fmt(r.min_sse):>10}"
            f"{_fmt(r.paper_mean):>10}{_fmt(r.paper_max):>8}{_fmt(r.paper_min):>9}"
            f"{r.mean_ratio:>10.4g}{r.max_ratio:>10.4g}{int(r.found):>4}/{int(r.runs):<2}"
            f"{int(r.evals):>9}{r.seconds_per_run:>8.3g}  {r.setting}"
        )
    lines += ["", "why ours differ from the paper:"] + [f"  {n}" for n in study_notes(result)]
    lines += ["", "RWSAVSBAS readings (where [R] is unclear), settings of the RWSAVSBAS row:"]
    for label, r in result.readings.iterrows():
        lines.append(
            f"  {label:<54} avg/opt {r.mean_ratio:<10.5g} max/opt {r.max_ratio:<10.5g} "
            f"found {int(r.found)}/{int(r.runs)}"
        )
    h = result.hybrid
    lines += [
        "",
        "bas+lm against lm alone, from the same random starts:",
        f"  bas+lm: found {int(h['bas+lm_found'].sum())}/{len(h)}, at most "
        f"{int(h['bas+lm_evals'].max())} evaluations "
        f"({p['hybrid_max_evals_fraction_of_rws']:.2%} of RWSAVSBAS's "
        f"{int(p['rws_evals_per_run'])}), max SSE/opt {h['bas+lm_sse'].max() / o['sse']:.6g}",
        f"  lm alone: found {int(h['lm_found'].sum())}/{len(h)}, "
        f"{int(h['lm_evals'].median())} evaluations (median), "
        f"max SSE/opt {h['lm_sse'].max() / o['sse']:.4g}",
        "",
        "performance (wall time of all runs, same process):",
        f"  RWSAVSBAS, {runs} runs batched, compiled path: {p['rws_jit_seconds']:.3f} s"
        f" (best of {int(p['repeats'])})"
        + (f" (compile, once: {p['compile_seconds']:.2f} s)" if "compile_seconds" in p else ""),
    ]
    if "rws_numpy_seconds" in p:
        lines.append(
            f"  RWSAVSBAS, {runs} runs batched, numpy path:    {p['rws_numpy_seconds']:.3f} s "
            f"(final SSE within {p['numpy_vs_jit_max_rel_diff']:.1e} of the compiled path)"
        )
    n_total = int(p["rws_evals_per_run"]) * runs
    lines.append(
        f"  {n_total} evaluations in {int(p['batches'])} batches (best of {int(p['repeats'])}): "
        "numpy objective "
        f"{p['batch_numpy_seconds']:.3f} s"
        + (
            f", compiled kernel {p['batch_kernel_seconds']:.3f} s"
            if "batch_kernel_seconds" in p
            else ""
        )
    )
    if "ratio_jit_vs_kernel_batches" in p:
        lines.append(
            f"  ratio compiled runs / kernel batches: {p['ratio_jit_vs_kernel_batches']:.2f} "
            f"(target <= 2); compiled runs / numpy batches: "
            f"{p['ratio_jit_vs_numpy_batches']:.2f}"
        )
    if "ratio_numpy_vs_numpy_batches" in p:
        lines.append(
            f"  ratio numpy-path runs / numpy batches: {p['ratio_numpy_vs_numpy_batches']:.2f}"
        )
    return "\n".join(lines)


def convergence_png(result: StudyResult) -> bytes:
    """[R] Fig. 6: mean best-so-far SSE against evaluations of every method (and bas+lm), log
    axes, the exact optimum as a reference line (no min-max bands: eleven methods).

    Evaluations rather than [R]'s iterations: an RWSAVSBAS iteration costs about 300 of them,
    a VSBAS or IBAS iteration 3.
    """
    labels = [*result.table.index, "bas+lm"]
    hist = {
        str(label): [np.asarray(r.history) for r in result.results[label]]
        for label in labels
        if label in result.results
    }
    runs = result.config["runs"]
    return plots.convergence(
        hist,
        title=f"Average convergence over {runs} runs (RWSAVSBAS paper, Fig. 6)",
        reference={f"global optimum, SSE {result.optimum['sse']:.3g}": result.optimum["sse"]},
        log_x=True,
        band=False,
    )


def write_outputs(result: StudyResult, folder: str | os.PathLike[str]) -> list[Path]:
    """Write the study's tables and Fig. 6 into ``folder`` (created).

    Parameters
    ----------
    result : fricid.experiments.stribeck_study.StudyResult
        The study.
    folder : path-like
        Receives ``table1.csv``, ``readings.csv``, ``bas_lm.csv``, ``convergence.csv``,
        ``performance.csv`` and ``fig6_convergence.png``, each written atomically
        (:mod:`fricid.io.atomic`).

    Returns
    -------
    list of pathlib.Path
        The files, the figure last.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    perf = pd.DataFrame(
        {"value": list(result.performance.values())}, index=list(result.performance)
    )
    perf.index.name = "quantity"
    for name, df in (
        ("table1.csv", result.table),
        ("readings.csv", result.readings),
        ("bas_lm.csv", result.hybrid),
        ("convergence.csv", result.convergence),
        ("performance.csv", perf),
    ):
        path = folder / name
        with atomic_write(path, "w") as fh:
            df.to_csv(fh)
        written.append(path)
    path = folder / "fig6_convergence.png"
    with atomic_write(path, "wb") as fh:
        fh.write(convergence_png(result))
    written.append(path)
    return written
