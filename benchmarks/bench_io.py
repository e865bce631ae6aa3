"""Peak memory of extracting friction samples from a large raw log, read in chunks.

A raw log of ``--rows`` rows (the BAS-RBFNN paper's full campaign on the virtual joint,
``fricid.sim.preset("paper1", "full")``, cut at a velocity set-point after ``--rows`` rows; the
whole campaign is about 74 million rows) is written to a Parquet file chunk by chunk, then
extracted in a fresh process with ``fricid.extract.extract(fricid.io.iter_rawlog(path,
chunk_rows))``. Each stage runs in its own process, which reports its peak resident memory
(``VmHWM``) and its resident memory after the imports; ``--whole`` adds the same extraction
from ``read_rawlog`` (the whole log in memory) for contrast.

    python benchmarks/bench_io.py                       # 5 million rows (make bench)
    python benchmarks/bench_io.py --rows 50000000       # the issue's 50 million rows

The Parquet file needs about 30 bytes per row of disk (1.5 GB at 50 million rows); it is
removed afterwards unless ``--keep``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _memory() -> dict[str, float]:
    """Resident memory now and at its peak [MB], from /proc (Linux)."""
    out = {}
    with open("/proc/self/status", encoding="ascii") as fh:
        for line in fh:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                out[key] = int(value.split()[0]) / 1024.0
    return out


def _campaign(rows: int):
    """The paper1 full campaign, cut at the first set-point boundary after ``rows`` rows."""
    from fricid.sim import preset, simulate

    scenario = preset("paper1", "full")
    n = 0
    for log in simulate(scenario, seed=0, chunk="setpoint"):
        yield log
        n += len(log)
        if n >= rows:
            return


def stage_generate(path: Path, rows: int) -> dict:
    from fricid.io import write_rawlog

    counted = {"rows": 0, "chunks": 0}

    def counting():
        for log in _campaign(rows):
            counted["rows"] += len(log)
            counted["chunks"] += 1
            yield log

    t0 = time.perf_counter()
    write_rawlog(counting(), path)
    return {
        **counted,
        "seconds": time.perf_counter() - t0,
        "file_mb": path.stat().st_size / 2**20,
        **_memory(),
    }


def stage_extract(path: Path, chunk_rows: int, whole: bool) -> dict:
    import numpy as np

    from fricid.extract import extract
    from fricid.io import iter_rawlog, read_rawlog
    from fricid.sim import preset

    options = preset("paper1", "full").extract_options()
    baseline = _memory()["VmRSS"]
    t0 = time.perf_counter()
    logs = read_rawlog(path) if whole else iter_rawlog(path, chunk_rows=chunk_rows)
    result = extract(logs, **options)
    seconds = time.perf_counter() - t0
    d = result.diagnostics
    return {
        "rows": int(d.rows),
        "chunks": int(d.chunks),
        "segments": int(d.segments),
        "samples": len(result.samples),
        "friction_range": [
            float(np.min(result.samples.friction)),
            float(np.max(result.samples.friction)),
        ],
        "seconds": seconds,
        "baseline_mb": baseline,
        **_memory(),
    }


def _run_stage(*args: str) -> dict:
    res = subprocess.run(
        [sys.executable, __file__, "--stage", *args], capture_output=True, text=True, check=False
    )
    if res.returncode != 0:
        sys.stderr.write(res.stderr)
        raise SystemExit(f"stage {args[0]} failed (exit {res.returncode})")
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=5_000_000, help="rows of the log")
    parser.add_argument("--chunk-rows", type=int, default=1_000_000, help="rows per chunk")
    parser.add_argument("--dir", type=Path, default=None, help="where to write the log")
    parser.add_argument("--keep", action="store_true", help="keep the Parquet file")
    parser.add_argument(
        "--whole",
        action="store_true",
        help="also extract from the whole log in memory, for contrast",
    )
    parser.add_argument("--stage", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    if args.stage:  # a child process: one stage, one JSON line on stdout
        kind, path = args.stage[0], Path(args.stage[1])
        if kind == "generate":
            out = stage_generate(path, int(args.stage[2]))
        else:
            out = stage_extract(path, int(args.stage[2]), kind == "whole")
        print(json.dumps(out))
        return

    tmp = tempfile.mkdtemp(prefix="fricid-bench-io-", dir=args.dir)
    path = Path(tmp) / "paper1_log.parquet"
    try:
        gen = _run_stage("generate", str(path), str(args.rows))
        print(
            f"log: {gen['rows']:,} rows in {gen['chunks']} set-point chunks, "
            f"{gen['file_mb']:.0f} MB Parquet, written in {gen['seconds']:.1f} s "
            f"(peak RSS {gen['VmHWM']:.0f} MB)"
        )
        runs = [("chunked", _run_stage("extract", str(path), str(args.chunk_rows)))]
        if args.whole:
            runs.append(("whole", _run_stage("whole", str(path), str(args.chunk_rows))))
        for name, r in runs:
            how = (
                f"iter_rawlog(chunk_rows={args.chunk_rows:,})"
                if name == "chunked"
                else "read_rawlog (whole log)"
            )
            print(
                f"extract from {how}: {r['rows']:,} rows -> {r['samples']} samples "
                f"({r['segments']} segments) in {r['seconds']:.1f} s "
                f"({r['rows'] / r['seconds'] / 1e6:.2f} M rows/s); "
                f"peak RSS {r['VmHWM']:.0f} MB (after imports {r['baseline_mb']:.0f} MB)"
            )
    finally:
        if args.keep:
            print(f"kept {path}")
        else:
            path.unlink(missing_ok=True)
            Path(tmp).rmdir()


if __name__ == "__main__":
    main()
