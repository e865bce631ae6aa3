"""``fricid evaluate``: metrics of a model file on samples."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ._app import app, console, err_console, handle_errors
from ._options import ModelFile
from ._paths import check_paths

#: How ``fricid evaluate`` labels each metric of :func:`fricid.identify.evaluate`, and the factor
#: from the library's value (SI; RMSPE a fraction) to the printed one. One convention for every
#: command and the report: RMSPE in percent, SSE in N^2 m^2 (the square of N m).
LABELS: dict[str, tuple[str, float]] = {
    "fitness": ("fitness (paper Table 1, signed R^2)", 1.0),
    "sse": ("SSE [N^2 m^2]", 1.0),
    "rmse": ("RMSE [N m]", 1.0),
    "rmspe": ("RMSPE [%]", 100.0),
    "mae": ("mean |error| [N m]", 1.0),
    "max_abs_error": ("max |error| [N m]", 1.0),
    "n": ("samples", 1.0),
    "scatter": ("scatter [N m]", 1.0),
    "rmse_over_scatter": ("RMSE / scatter", 1.0),
}


def metric_row(key: str, value: float) -> tuple[str, str]:
    """The label and the printed value of one metric (:data:`LABELS`; per-direction keys
    ``rmse_pos`` [N m], ``r2_magnitude_neg`` labelled by their direction)."""
    if key in LABELS:
        label, factor = LABELS[key]
        return label, f"{factor * value:.6g}"
    for d, where in (("_pos", "v > 0"), ("_neg", "v < 0"), ("_comb", "combined")):
        if key.endswith(d):
            base = key.removesuffix(d)
            name = {"rmse": "RMSE [N m]", "r2_magnitude": "R^2 of |F|"}.get(base, base)
            return f"{name}, {where}", f"{value:.6g}"
    if key == "r2_magnitude":
        return "R^2 of |F|, worst direction", f"{value:.6g}"
    return key, f"{value:.6g}"


@app.command("evaluate")
@handle_errors
def evaluate_command(
    model: ModelFile,
    samples: Annotated[Path, typer.Argument(help="Friction samples, CSV or Parquet.")],
    as_json: Annotated[
        bool,
        typer.Option(
            "--json",
            help=(
                "Print the metrics as JSON, as the library returns them: SI units, keys as in "
                "the model file's metrics (rmspe there is a fraction: 0.021 is 2.1 %)."
            ),
        ),
    ] = False,
) -> None:
    """Evaluate a model file on samples: RMSE [N m] beside the samples' measurement scatter
    (with a verdict), RMSE and R^2 of the friction's magnitude per direction, SSE [N^2 m^2],
    RMSPE [%], mean and max absolute error [N m], and the BAS-RBFNN paper's Table 1 fitness
    (R^2 of the signed friction, "fitness": it flatters per-direction samples)."""
    from ..export._trust import trust_of
    from ..fitted import FittedModel
    from ..identify import evaluate, is_own_samples, measurement_scatter, unit_mismatches
    from ..io import read_samples
    from ..metrics import rmspe_note, verdict

    check_paths(inputs={"MODEL": model, "SAMPLES": samples})
    fitted = FittedModel.load(model)
    data = read_samples(samples)
    result = evaluate(fitted, data)
    for why in unit_mismatches(fitted, data).values():  # every error below compares two units
        err_console.print(f"warning: {why}.", markup=False, highlight=False, soft_wrap=True)
    if as_json:
        console.print_json(json.dumps(result))
        return
    table = Table(title=f"{fitted.model} on {samples.name}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for key, value in result.items():
        table.add_row(*metric_row(key, value))
    console.print(table)
    said = rmspe_note(data.y, fitted.predict(data.X, warn=False))  # the RMSPE printed
    if said:
        console.print(f"note: {said}.", highlight=False, markup=False, soft_wrap=True)
    if "rmse_over_scatter" in result:
        scatter = measurement_scatter(data)
        level = trust_of(fitted)[0]
        own = (
            "; in-sample: these are the samples the model was identified on"
            + (f" (its trust verdict: {level})" if level else "")
            if is_own_samples(fitted, data)
            else ""
        )
        console.print(
            f"RMSE {result['rmse']:.4g} N m, scatter {scatter.describe()}: "
            f"{verdict(result['rmse_over_scatter'])}{own}",
            highlight=False,
            markup=False,
            soft_wrap=True,
        )
