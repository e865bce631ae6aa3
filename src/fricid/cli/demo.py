"""``fricid demo``: the whole chain on the virtual joint, at a reduced size."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape
from rich.table import Table

from ._app import app, console, err_console, handle_errors
from ._study_options import out_option, seed_option


@app.command("demo")
@handle_errors
def demo_command(
    out: Annotated[Path, out_option("Folder for samples, models and the summary.")] = Path(
        "fricid-demo"
    ),
    size: Annotated[
        str,
        typer.Option(
            help="Preset size: reduced (default, under a minute), "
            "quick, or full (the paper's 6615 operating points; "
            "minutes)."
        ),
    ] = "reduced",
    seed: Annotated[int, seed_option("Random seed.")] = 0,
    method: Annotated[str, typer.Option(help="Optimiser for the fits.")] = "lm",
) -> None:
    """Simulate the BAS-RBFNN paper's experiment on the virtual joint, extract the friction
    samples, fit the four analytic models and print a table like the paper's Table 1
    (fitness = R^2, RMSE, RMSPE in percent per model) with each model's trust verdict. Writes
    samples.csv, samples_by_direction.csv, one JSON model file per model, table1.csv and
    summary.md into --out."""
    from ..experiments.demo import run_demo
    from ..experiments.paper_numbers import table1_rmse_unit
    from ..report.studies.demo import write_demo

    t0 = time.perf_counter()
    res = run_demo(
        size=size,
        seed=seed,
        method=method,
        progress=lambda msg: err_console.print(f"[dim]{msg}[/]"),
    )
    written = write_demo(res, out)
    console.print(res.extraction.summary(), markup=False, highlight=False, soft_wrap=True)
    px, py = res.true_gravity
    console.print(f"true gravity:    p_x = {px:.5g}, p_y = {py:.5g} N m", highlight=False)

    table = Table(title="Table 1: performance of the models (paper's values in brackets)")
    columns = ("model", "fitness", "RMSE [mN m]", "RMSPE [%]", "max |err| [mN m]", "trust")
    for col in columns:
        table.add_column(escape(col), justify="left" if col == "model" else "right")

    def both(ours: float, paper: float, fmt: str) -> str:
        return f"{ours:{fmt}}" + ("" if np.isnan(paper) else f" [{paper:{fmt}}]")

    for row in res.table.itertuples():
        table.add_row(
            row.model,
            both(row.fitness, row.paper_fitness, ".4f"),
            both(row.rmse_mNm, row.paper_rmse, ".4g"),
            both(row.rmspe_percent, row.paper_rmspe_percent, ".2f"),
            f"{row.max_abs_error_mNm:.3g}",
            row.trust + (f" ({row.heldout_ratio:.3g}x)" if np.isfinite(row.heldout_ratio) else ""),
        )
    console.print(table)
    console.print(
        f"[dim]{table1_rmse_unit()} Compare fitness, RMSPE and the ordering. Trust: each "
        "model's verdict as `fricid fit` gives it (held-out error over the measurement "
        "scatter), saved in its file.[/]"
    )
    console.print(f"wrote {written}/ in {time.perf_counter() - t0:.1f} s")
