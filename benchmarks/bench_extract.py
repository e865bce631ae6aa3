"""Extraction against the streaming floor, at three sizes (1x, 4x, 16x rows).

The floor is one pass of pyarrow ``iter_batches`` over the raw log's five columns (time,
position, velocity, current, temperature) that groups them, as ``np.bincount`` sums per
(position bin, direction): what any tool must spend to read the log and touch every value.
Extraction is :func:`fricid.workflow.load_joint` on the same file (what ``fricid extract``
does, without writing the 330-row result): segmentation, median filter, settling, outlier
and rail checks, binning, the eq. 7 gravity fit.

The sizes are the BAS-RBFNN paper's full campaign on the virtual joint (``fricid simulate
--preset paper1 --size full``, 79 million rows, 16x) and its first quarter and sixteenth (4x,
1x; the rows of the first temperatures, cut mid-run). Each measurement runs in a fresh
subprocess, which first does the same work on the quick campaign (imports and first calls
outside the timing), then reports the wall time and CPU time (user + system) of the work alone
and its peak resident memory (``ru_maxrss``, imports included). The logs are written by
another subprocess, so the parent stays small (Linux counts the parent's resident size at the
fork in a child's ``ru_maxrss``). Repeats are interleaved (floor, extraction, floor, ...) and
the minimum of each is shown, so a machine busy with other work penalises both alike; the load
average is printed before and after. The floor reads without pyarrow's pre-buffering, as
fricid does (pre-buffering reads whole row groups ahead: more memory, no faster).

    python benchmarks/bench_extract.py                      # simulates the campaign (~1 min)
    python benchmarks/bench_extract.py --log full.parquet   # an existing full campaign
    python benchmarks/bench_extract.py --size reduced       # 1.2 M rows x 1, 4, 16 (quick)

With ``--size reduced`` the 1x log is the reduced campaign and the 4x and 16x logs repeat it
end to end (time shifted). The logs are written to ``--workdir`` (default: a temporary folder,
removed afterwards); the full campaign needs about 3.5 GB of disk with its prefixes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COLUMNS = ["time", "position", "velocity", "current", "temperature"]
SCALES = (1, 4, 16)


# --------------------------------------------------------------------------- measured work


def floor(path: str) -> int:
    """One streaming pass grouping the log's columns: rows per (position bin, direction)
    and the sums of every column, from pyarrow's record batches (default batch size)."""
    import numpy as np
    import pyarrow.parquet as pq

    edges = np.linspace(-np.pi, np.pi, 361)  # 1-degree position bins
    groups = 2 * (edges.size + 1)
    count = np.zeros(groups)
    sums = np.zeros((len(COLUMNS), groups))
    rows = 0
    for batch in pq.ParquetFile(path, pre_buffer=False).iter_batches(columns=COLUMNS):
        cols = [batch.column(i).to_numpy() for i in range(len(COLUMNS))]
        key = 2 * np.searchsorted(edges, cols[1]) + (cols[2] > 0)
        count += np.bincount(key, minlength=groups)
        for j, values in enumerate(cols):
            sums[j] += np.bincount(key, weights=values, minlength=groups)
        rows += batch.num_rows
    assert count.sum() == rows
    return rows


def extraction(path: str) -> int:
    """``fricid extract``'s work: the log read in chunks and extracted."""
    from fricid.workflow import load_joint

    data = load_joint(path)
    return data.extraction.diagnostics.rows


def child(kind: str, path: str, warm: str) -> None:
    """Run one measurement in this (fresh) process and print it as JSON; the imports and
    first calls are made on the small log ``warm`` first, outside the timing."""
    work = extraction if kind == "extract" else floor
    work(warm)
    before = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    rows = work(path)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    print(
        json.dumps(
            {
                "rows": rows,
                "wall": wall,
                "cpu": cpu,
                "maxrss_mb": after.ru_maxrss / 1024.0,
                "minflt": after.ru_minflt - before.ru_minflt,
            }
        )
    )


def _run(*args: str) -> str:
    """This script in a fresh process (``src`` first on the path); its standard output."""
    env = dict(os.environ)
    src = str(Path(__file__).resolve().parents[1] / "src")
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    out = subprocess.run(
        [sys.executable, __file__, *args], capture_output=True, text=True, env=env, check=True
    )
    return out.stdout


def measure(kind: str, path: Path, warm: Path) -> dict:
    return json.loads(_run("--child", kind, str(path), str(warm)).strip().splitlines()[-1])


# --------------------------------------------------------------------------- the logs


def simulate(size: str, path: Path) -> None:
    """``fricid simulate --preset paper1 --size SIZE`` (seed 0), in a fresh process."""
    code = "from fricid.cli import main; main()"
    cmd = [sys.executable, "-c", code, "simulate", "--preset", "paper1", "--size", size]
    subprocess.run([*cmd, "-q", "--out", str(path)], check=True)


def prefix(src: Path, dst: Path, rows: int) -> None:
    """The first ``rows`` rows of a Parquet log, its metadata kept (fricid's writer: the
    integrity record the reader checks)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from fricid.io._parquet import META_KEY, write_parquet

    pf = pq.ParquetFile(src)

    def tables():
        left = rows
        for batch in pf.iter_batches(batch_size=1 << 18):
            if left <= 0:
                break
            batch = batch.slice(0, left)
            left -= batch.num_rows
            yield pa.Table.from_batches([batch])

    write_parquet(dst, pf.schema_arrow.metadata[META_KEY], tables())


def repeat(src: Path, dst: Path, times: int) -> None:
    """A Parquet log repeated end to end, each copy shifted to continue in time (fricid's
    writer: the integrity record the reader checks)."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    from fricid.io._parquet import META_KEY, write_parquet

    pf = pq.ParquetFile(src)
    table = pf.read()
    t = table.column("time")
    span = pc.max(t).as_py() - pc.min(t).as_py() + 1.0
    shifted = (table.set_column(0, "time", pc.add(t, pa.scalar(k * span))) for k in range(times))
    write_parquet(dst, pf.schema_arrow.metadata[META_KEY], shifted)


def make(size: str, log: str | None, workdir: Path) -> None:
    """Write the quick campaign (the warm-up log) and the three logs to ``workdir``; print
    them as JSON, smallest first: [[scale, path], ...]."""
    import pyarrow.parquet as pq

    simulate("quick", workdir / "quick.parquet")
    if size == "reduced":
        base = workdir / "reduced.parquet"
        simulate("reduced", base)
        out = [(1, base)]
        for k in SCALES[1:]:
            repeat(base, workdir / f"reduced_x{k}.parquet", k)
            out.append((k, workdir / f"reduced_x{k}.parquet"))
    else:
        full = Path(log) if log else workdir / "full.parquet"
        if not log:
            simulate("full", full)
        n = pq.ParquetFile(full).metadata.num_rows
        out = []
        for k in SCALES[:-1]:
            part = workdir / f"full_{k}of{SCALES[-1]}.parquet"
            prefix(full, part, n * k // SCALES[-1])
            out.append((k, part))
        out.append((SCALES[-1], full))
    print(json.dumps([[k, str(p)] for k, p in out]))


# --------------------------------------------------------------------------- the table


def table(results: dict[int, dict[str, list[dict]]], sizes: list[tuple[int, Path]]) -> str:
    head = (
        f"{'size':>4} {'rows':>11} | {'floor s':>7} {'extract s':>9} {'ratio':>5} | "
        f"{'floor MB':>8} {'extract MB':>10} {'ratio':>5} | {'floor CPU':>9} "
        f"{'extract CPU':>11} | {'ns/row':>6}"
    )
    lines = [head, "-" * len(head)]
    for k, _ in sizes:
        f = {key: min(r[key] for r in results[k]["floor"]) for key in ("wall", "maxrss_mb")}
        e = {key: min(r[key] for r in results[k]["extract"]) for key in ("wall", "maxrss_mb")}
        rows = results[k]["extract"][0]["rows"]
        # CPU use of the fastest run of each (user + system over wall)
        fb = min(results[k]["floor"], key=lambda r: r["wall"])
        eb = min(results[k]["extract"], key=lambda r: r["wall"])
        lines.append(
            f"{k:>3}x {rows:>11,} | {f['wall']:>7.2f} {e['wall']:>9.2f} "
            f"{e['wall'] / f['wall']:>5.2f} | {f['maxrss_mb']:>8.0f} {e['maxrss_mb']:>10.0f} "
            f"{e['maxrss_mb'] / f['maxrss_mb']:>5.2f} | {fb['cpu'] / fb['wall']:>9.2f} "
            f"{eb['cpu'] / eb['wall']:>11.2f} | {e['wall'] / rows * 1e9:>6.0f}"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", choices=("full", "reduced"), default="full")
    parser.add_argument("--log", help="an existing full paper-1 campaign (Parquet)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workdir", help="keep the logs here (default: a temporary folder)")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--make", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(*args.child)
        return
    if args.make:
        make(args.make[0], args.make[1] or None, Path(args.make[2]))
        return
    results, sizes = run(args.size, args.log, args.repeats, args.workdir)
    print(
        f"min of {args.repeats} interleaved runs, each in a fresh process; cores: {os.cpu_count()}"
    )
    print(table(results, sizes))
    print(
        "time per row, relative to the smallest log: "
        + ", ".join(f"{p:.2f}" for p in per_row(results, sizes))
    )


def run(
    size: str, log: str | None, repeats: int, workdir: str | None = None
) -> tuple[dict[int, dict[str, list[dict]]], list[tuple[int, Path]]]:
    """Write the logs and measure floor and extraction on each, ``repeats`` interleaved runs
    (the load average printed before and after); the logs are removed unless ``workdir``."""
    folder = Path(workdir or tempfile.mkdtemp(prefix="fricid-bench-extract-"))
    folder.mkdir(parents=True, exist_ok=True)
    try:
        made = _run("--make", size, log or "", str(folder))
        sizes = [(k, Path(p)) for k, p in json.loads(made.strip().splitlines()[-1])]
        warm = folder / "quick.parquet"
        print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        results: dict[int, dict[str, list[dict]]] = {
            k: {"floor": [], "extract": []} for k, _ in sizes
        }
        for _ in range(repeats):
            for k, path in sizes:
                for kind in ("floor", "extract"):
                    results[k][kind].append(measure(kind, path, warm))
        print(f"load average after:  {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        return results, sizes
    finally:
        if not workdir:
            shutil.rmtree(folder, ignore_errors=True)


def per_row(results: dict[int, dict[str, list[dict]]], sizes: list[tuple[int, Path]]) -> list:
    """Extraction's time per row at each size, relative to the smallest log."""
    e = [min(r["wall"] for r in results[k]["extract"]) for k, _ in sizes]
    n = [results[k]["extract"][0]["rows"] for k, _ in sizes]
    rate = [w / r for w, r in zip(e, n, strict=True)]
    return [x / rate[0] for x in rate]


if __name__ == "__main__":
    main()
