"""``fricid evaluate``: metrics of a model file on samples."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ._app import app, console, handle_errors
from ._paths import check_paths


@app.command("evaluate")
@handle_errors
def evaluate_command(
    model: Annotated[
        Path,
        typer.Argument(help="Model file (JSON, from `fricid fit`)."),
    ],
    samples: Annotated[Path, typer.Argument(help="Friction samples, CSV or Parquet.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the metrics as JSON.")] = False,
) -> None:
    """Evaluate a model file on samples: fitness (R^2), SSE [N m^2], RMSE [N m], RMSPE,
    mean and max absolute error [N m]."""
    from ..fitted import FittedModel
    from ..identify import evaluate
    from ..io import read_samples

    check_paths(inputs={"MODEL": model, "SAMPLES": samples})
    fitted = FittedModel.load(model)
    result = evaluate(fitted, read_samples(samples))
    if as_json:
        console.print_json(json.dumps(result))
        return
    table = Table(title=f"{fitted.model} on {samples.name}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for key, value in result.items():
        table.add_row(key, f"{value:.6g}")
    console.print(table)
