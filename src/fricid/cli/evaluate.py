"""``fricid evaluate``: metrics of a model file on samples."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ._app import app, console, handle_errors
from ._options import ModelFile
from ._paths import check_paths


@app.command("evaluate")
@handle_errors
def evaluate_command(
    model: ModelFile,
    samples: Annotated[Path, typer.Argument(help="Friction samples, CSV or Parquet.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the metrics as JSON.")] = False,
) -> None:
    """Evaluate a model file on samples: RMSE [N m] beside the samples' measurement scatter
    (with a verdict), RMSE and R^2 of the friction's magnitude per direction, SSE [N m^2],
    RMSPE, mean and max absolute error [N m], and the BAS-RBFNN paper's Table 1 fitness (R^2 of
    the signed friction, "fitness": it flatters per-direction samples)."""
    from ..fitted import FittedModel
    from ..identify import evaluate, measurement_scatter
    from ..io import read_samples
    from ..metrics import verdict

    check_paths(inputs={"MODEL": model, "SAMPLES": samples})
    fitted = FittedModel.load(model)
    data = read_samples(samples)
    result = evaluate(fitted, data)
    if as_json:
        console.print_json(json.dumps(result))
        return
    table = Table(title=f"{fitted.model} on {samples.name}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for key, value in result.items():
        label = "fitness (paper Table 1, signed)" if key == "fitness" else key
        table.add_row(label, f"{value:.6g}")
    console.print(table)
    if "rmse_over_scatter" in result:
        scatter = measurement_scatter(data)
        console.print(
            f"RMSE {result['rmse']:.4g} N m, scatter {scatter.describe()}: "
            f"{verdict(result['rmse_over_scatter'])}",
            highlight=False,
            markup=False,
            soft_wrap=True,
        )
