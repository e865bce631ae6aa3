"""``fricid bench stribeck``: the RWSAVSBAS paper's study (Table 1, Fig. 6) as a benchmark."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ._app import bench_app, console, handle_errors
from ._progress import QuietOption
from ._study_options import out_option, print_written, quick_option, seed_option, study_progress


@bench_app.command(
    "stribeck", short_help="The RWSAVSBAS paper's Table 1 and Fig. 6 on the paper2 preset."
)
@handle_errors
def stribeck_command(
    runs: Annotated[int, typer.Option(min=1, help="Runs per method (the paper: 8).")] = 8,
    out: Annotated[
        Path | None,
        out_option(
            "Folder for the tables (CSV) and the convergence plot (PNG); created if missing. "
            "Default: print only.",
            folder=True,
        ),
    ] = None,
    quick: Annotated[
        bool,
        quick_option(
            "Reduced budgets (RWSAVSBAS 100 x 100 with its schedule compressed ten-fold, "
            "30,101 evaluations per run, the equal-budget rows alike; baselines 3,000): a "
            "check, not the paper's settings."
        ),
    ] = False,
    seed: Annotated[
        int, seed_option("Base seed of the runs (run r uses seed + r).", non_negative=True)
    ] = 0,
    quiet: QuietOption = False,
) -> None:
    """Compare the optimisers of the RWSAVSBAS paper's Table 1 and Fig. 6 on the simulated
    paper2 preset, at equal budgets first.

    Fits the Stribeck model (delta = 1) to the preset's 17 samples. Every method evaluates
    candidates with the same compiled objective. First every method at RWSAVSBAS's evaluation
    count (the headline: VSBAS, IBAS, BAS, GA and DE with as many evaluations as RWSAVSBAS),
    then VSBAS, IBAS and BAS at the paper's 1000 iterations, then dual annealing and CMA-ES
    at a smaller budget; each row's average, max and min SSE beside the paper's, its ratio to
    the exact global optimum (variable projection), evaluations and wall time. Then the
    readings of RWSAVSBAS the paper leaves open, bas+lm against lm from the same random
    starts, and RWSAVSBAS's compiled loop against evaluating as many candidates in batches.
    Progress goes to stderr (--quiet: none).

    Budgets rather than times: 8 runs per method; RWSAVSBAS 1000 x 100 iterations (301,001
    evaluations per run) and every equal-budget row as many; dual annealing and CMA-ES
    10,000 (--quick: 30,101 and 3,000); benchmarks/bench_stribeck.py times it.
    """
    from ..experiments.stribeck_study import run_study
    from ..report.studies.stribeck import report_text, write_outputs

    t0 = time.perf_counter()
    written = None
    with study_progress(t0, quiet=quiet) as (progress, status):
        result = run_study(seed=seed, runs=runs, quick=quick, progress=progress)
        if out is not None:
            status.update(f"writing {escape(str(out))}")
            written = write_outputs(result, out)
    console.print(escape(report_text(result)), highlight=False, soft_wrap=True)
    print_written(written, t0)
