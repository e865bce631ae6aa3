"""The RWSAVSBAS paper's study (Table 1, Fig. 6) on the paper2 preset, with baselines.

Usage: ``python benchmarks/bench_stribeck.py [--quick] [--runs 8] [--seed 0] [--out DIR]``.
Prints the tables and the performance ratios; with ``--out DIR`` also writes the CSVs and
``fig6_convergence.png`` there. The study itself is
:func:`fricid.experiments.stribeck_study.run_study`; its text and files are
:mod:`fricid.report.studies.stribeck`'s.
"""

from __future__ import annotations

import argparse
import sys
import time

from fricid.experiments.stribeck_study import run_study
from fricid.report.studies.stribeck import report_text, write_outputs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="reduced budgets")
    parser.add_argument("--runs", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default=None, help="folder for CSV and PNG (default: none)")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)

    result = run_study(seed=args.seed, runs=args.runs, quick=args.quick, progress=progress)
    print(report_text(result))
    if args.out is not None:
        for path in write_outputs(result, args.out):
            print(f"wrote {path}", file=sys.stderr)
    print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
