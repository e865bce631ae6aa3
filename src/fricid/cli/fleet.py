"""``fricid fleet``: identify every joint of a manifest, locally or on a Dask cluster."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from ._app import app, console, err_console, handle_errors, plural
from ._options import out_option
from ._paths import check_paths
from ._progress import QuietOption, progress_bar

_MAX_LISTED = 20


def _short(text: str, n: int = 110) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 3] + "..."


def _summary(run, manifest_path: Path) -> Table:
    table = Table(
        title=f"fricid fleet {escape(str(manifest_path))}: {plural(len(run.records), 'joint')} "
        f"in {run.seconds:.1f} s ({run.executor}, {plural(run.workers, 'worker')})",
        title_justify="left",
    )
    table.add_column("joints")
    table.add_column("count", justify="right")
    table.add_row("in the manifest", str(len(run.records)))
    table.add_row("identified now", str(run.computed - run.failed))
    table.add_row("unchanged since the last run (skipped)", str(run.skipped))
    table.add_row(
        "failed (see the table below)", str(run.failed), style="red" if run.failed else None
    )
    trust = getattr(run, "table", None)
    if trust is not None and "trust" in trust:
        counts = trust["trust"].value_counts()
        table.add_row(
            "fits trusted: yes / with caveats / no (column trust)",
            " / ".join(str(int(counts.get(k, 0))) for k in ("yes", "with caveats", "no")),
        )
    if run.computed and run.seconds > 0:
        table.add_row("processed per minute", f"{60.0 * run.computed / run.seconds:.1f}")
    return table


def _failures(run) -> Table:
    table = Table(title=f"failed joints ({run.failed})", title_justify="left")
    for name in ("robot", "joint", "stage", "error"):
        table.add_column(name, overflow="fold")
    for robot, joint, stage, error in run.failures[:_MAX_LISTED]:
        table.add_row(escape(robot), escape(joint), stage, escape(_short(error)))
    if run.failed > _MAX_LISTED:
        table.add_row("...", f"{run.failed - _MAX_LISTED} more", "", "see results.csv")
    return table


def _drift_table(drift) -> Table:
    n = int(drift.joints["drifted"].sum()) if len(drift.joints) else 0
    table = Table(
        title=f"drift against the baseline: {n} of {len(drift.joints)} joint fits drifted",
        title_justify="left",
    )
    for name in ("joint", "model", "flagged parameters", "worst move / CI", "friction change"):
        table.add_column(name, justify="right" if "change" in name or "/" in name else "left")
    for r in drift.drifted.head(_MAX_LISTED).itertuples():
        table.add_row(
            escape(f"{r.robot}/{r.joint}"),
            r.model,
            r.flagged,
            f"{r.worst_ratio:.2f}",
            f"{1e3 * r.friction_change_max:.2f} mN m ({100 * r.friction_change_rel:.1f} %)",
        )
    return table


def _manifest_help() -> str:
    from ..fleet._manifest_schema import describe_columns

    return describe_columns()


@app.command("fleet", epilog=_manifest_help())
@handle_errors
def fleet_command(
    manifest: Annotated[
        Path,
        typer.Argument(
            help=(
                "Manifest, .csv or .yaml: one row per joint with robot, joint, log (relative to "
                "the manifest: a file, an EPOS folder or a ROS 2 bag folder or .mcap file) and "
                "any column below (every reader and reader option of `fricid extract`); a "
                "dimensional column names its unit ('positions [deg]'). The JSON Schema "
                "fricid/schemas/manifest.schema.json defines every column; docs/manifest.md "
                "describes the format with examples and a table of the columns."
            ),
        ),
    ],
    out: Annotated[
        Path | None,
        out_option(
            "Output folder: records/, models/ (one model JSON per joint and model), results/ "
            "(Parquet, partitioned by robot and date), results.csv, drift files. Default: "
            "<manifest name>-results in the current directory."
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            "-j",
            help=("Local worker processes (default: every core); 1 runs in this process."),
        ),
    ] = None,
    cluster: Annotated[
        str | None,
        typer.Option(
            help=(
                "Run on Dask instead: local:N starts a LocalCluster of N worker processes on "
                "loopback; tcp://HOST:PORT uses an existing scheduler (its workers must see the "
                "logs at the manifest's paths)."
            )
        ),
    ] = None,
    baseline: Annotated[
        Path | None,
        typer.Option(
            help=(
                "Previous results (an output folder, its results/ or results.csv) to compare with: "
                "flags parameters that moved by more than their combined 95 % CIs and reports the "
                "change of predicted friction; writes drift_joints.csv, drift_params.csv, "
                "drift.png."
            ),
        ),
    ] = None,
    min_change: Annotated[
        float,
        typer.Option(
            help=(
                "Friction change [N m] a joint with flagged parameters needs to count as drifted."
            )
        ),
    ] = 0.0,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help=(
                "Recompute every joint (default: skip joints whose log content and settings are "
                "unchanged since they last succeeded)."
            ),
        ),
    ] = False,
    date: Annotated[
        str | None,
        typer.Option(
            help=("Measurement date YYYY-MM-DD of joints whose row gives none (default: today).")
        ),
    ] = None,
    quiet: QuietOption = False,
) -> None:
    """Identify every joint of many robots: extract then fit each joint of the manifest
    (exactly as `fricid extract` and `fricid fit` do), in parallel, and write one model file
    per joint and model plus a results table with parameters, 95 % confidence intervals,
    metrics, timing and the log's content hash. A joint that fails is reported (table and
    summary) and the rest completes; re-running skips unchanged joints, so an interrupted
    run resumes. Progress goes to stderr, piped too (a line per tenth of the joints with the
    time left; --quiet: none). Exit status 0 when every joint succeeded, 1 when some failed,
    2 for a bad manifest or option."""
    from ..fleet import compare, make_executor, read_manifest, read_results, run_fleet
    from ..fleet import write_drift as write_drift_files

    check_paths(
        inputs={"MANIFEST": manifest, "--baseline": baseline},
        folders={"--baseline"},
        out_dirs={"--out": out},
    )
    spec = read_manifest(manifest)
    out = out or Path(f"{manifest.stem}-results")
    before = read_results(baseline) if baseline is not None else None
    with (
        make_executor(workers, cluster) as executor,
        progress_bar("identifying joints", total=len(spec), unit="joints", quiet=quiet) as advance,
    ):
        run = run_fleet(
            spec, out, executor=executor, force=force, date=date, progress=lambda event: advance()
        )
    console.print(_summary(run, manifest))
    if run.failed:
        console.print(_failures(run))
    err_console.print(f"wrote {escape(str(run.results))}/ and {escape(str(run.results_csv))}")
    if before is not None:
        drift = compare(read_results(run.results), before, min_change=min_change)
        paths = write_drift_files(drift, out)
        if len(drift.drifted):
            console.print(_drift_table(drift))
        else:
            console.print(
                f"drift against the baseline: none of {len(drift.joints)} joint fits drifted"
            )
        if drift.new or drift.missing:
            err_console.print(
                f"not compared: {len(drift.new)} new or failed in the baseline, "
                f"{len(drift.missing)} missing or failed now"
            )
        err_console.print("wrote " + ", ".join(escape(str(p)) for p in paths.values()))
    if run.failed:
        raise typer.Exit(code=1)
