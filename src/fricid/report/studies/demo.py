"""The demo's files: samples, models, Table 1 and a Markdown summary.

Writes :func:`fricid.experiments.demo.run_demo`'s result into a folder, every file atomically
(:mod:`fricid.io.atomic`, :func:`fricid.io.write_samples`, :meth:`FittedModel.save`).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ...experiments.demo import DemoResult
from ...experiments.paper_numbers import table1_rmse_unit
from ...extract import ExtractionResult
from ...io import atomic_write, write_samples

__all__ = ["summary_markdown", "write_demo"]


def write_demo(result: DemoResult, out: str | Path) -> Path:
    """Write the demo into ``out`` (created).

    Parameters
    ----------
    result : fricid.experiments.demo.DemoResult
        The demo.
    out : path-like
        Receives ``samples.csv``, ``samples_by_direction.csv``, one ``<model>.json`` per
        model, ``table1.csv`` and ``summary.md``.

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_samples(result.samples, out / "samples.csv")
    write_samples(result.extraction.by_direction, out / "samples_by_direction.csv")
    for name, fitted in result.models.items():
        fitted.save(out / f"{name}.json")
    with atomic_write(out / "table1.csv", "w") as fh:
        result.table.to_csv(fh, index=False)
    with atomic_write(out / "summary.md", "w") as fh:
        fh.write(
            summary_markdown(result.table, result.extraction, result.true_gravity, result.seconds)
        )
    return out


def summary_markdown(
    table: pd.DataFrame,
    result: ExtractionResult,
    truth: tuple[float, float],
    seconds: dict[str, float],
) -> str:
    """The demo's summary as Markdown."""
    lines = ["# fricid demo: virtual joint, paper1 preset", "", "## Extraction", ""]
    lines += [f"    {line}" for line in result.summary().splitlines()]
    lines += [
        "",
        f"True gravity coefficients: p_x = {truth[0]:.5g}, p_y = {truth[1]:.5g} N m.",
        "",
        "## Table 1 (BAS-RBFNN paper), ours beside the paper's",
        "",
    ]
    lines.append(
        table.to_markdown(index=False, floatfmt=".4g")
        if _has_tabulate()
        else "```\n" + table.to_string(index=False) + "\n```"
    )
    lines += [
        "",
        table1_rmse_unit() + " Compare fitness, RMSPE and the ordering.",
        "",
        "## Time",
        "",
    ]
    lines += [f"- {k}: {v:.2f} s" for k, v in seconds.items()]
    return "\n".join(lines) + "\n"


def _has_tabulate() -> bool:
    try:
        import tabulate  # noqa: F401
    except ImportError:
        return False
    return True
