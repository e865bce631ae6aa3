"""The long fuzz run of every reader (issues 12 and 25): damaged files, outcomes counted.

Each case damages an undamaged file of one reader with one to three mutations (truncation,
byte flips, random bytes, binary junk, not-UTF-8, huge numbers, NaN/inf text, empty and
header-only files, wrong field counts, trailing empty fields, BOM, CRLF, bad metadata,
corrupt MCAP length fields; for MATLAB files their header, tags, dimensions and classes
word by word, decompression bombs, every MATLAB type in place of a variable and the HDF5
constructs of v7.3 files; byte flips in Parquet and MCAP files with checksums) and
classifies the outcome as the test suite does (``tests/fuzzing.py``): a clean error (a
FricidError on one line naming the file), a valid result, a traceback (any other exception)
or a wrong answer (a result that breaks the invariants, other values after damage to a file
whose checksums cover it, a RuntimeWarning, a multi-line message or one not naming the
file, a case over 2 GB of peak memory or 60 s). The ``channels`` row draws folders of
per-channel files and patterns (:func:`fuzzing.channels_case`).

Run::

    PYTHONPATH=src python benchmarks/fuzz_readers.py --cases 200 --seed 0

It prints one row per reader and the totals (cases, clean errors, valid results,
tracebacks, wrong answers, the slowest case, time), the process's peak memory, then the
first failures, and exits with status 1 if there was any traceback or wrong answer.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from fuzzing import READERS, RngChooser, Workspace, channels_case, peak_bytes

NAMES = [*READERS, "channels"]


def _one(work: Workspace, name: str, rng: np.random.Generator) -> str:
    """One case of reader ``name``: "error" or "valid" (anything else raises)."""
    if name == "channels":
        work.n += 1
        return channels_case(work.folder / f"channels{work.n}", RngChooser(rng))[0]
    return work.run(READERS[name], RngChooser(rng))[0]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=200, help="cases per reader")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--readers", nargs="*", default=NAMES, choices=NAMES)
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="fricid-fuzz-"))
    work = Workspace(folder)
    failures: list[str] = []
    totals = dict.fromkeys(("cases", "errors", "valid", "tracebacks", "wrong"), 0)
    slowest = 0.0
    start = time.perf_counter()
    print(
        f"{'reader':<20}{'cases':>7}{'errors':>8}{'valid':>7}{'tracebacks':>12}{'wrong':>7}"
        f"{'slowest [s]':>13}{'time [s]':>10}"
    )
    try:
        for name in args.readers:
            rng = np.random.default_rng([args.seed, NAMES.index(name)])
            row = dict.fromkeys(totals, 0)
            row_start, row_slowest = time.perf_counter(), 0.0
            for i in range(args.cases):
                row["cases"] += 1
                case_start = time.perf_counter()
                try:
                    outcome = _one(work, name, rng)
                    row["errors" if outcome == "error" else "valid"] += 1
                except AssertionError as exc:  # WrongAnswer, limits and the oracle's checks
                    row["wrong"] += 1
                    failures.append(f"{name} case {i}: wrong answer: {exc}")
                except Exception:
                    row["tracebacks"] += 1
                    failures.append(f"{name} case {i}: traceback:\n{traceback.format_exc()}")
                row_slowest = max(row_slowest, time.perf_counter() - case_start)
            for key in totals:
                totals[key] += row[key]
            slowest = max(slowest, row_slowest)
            print(
                f"{name:<20}{row['cases']:>7}{row['errors']:>8}{row['valid']:>7}"
                f"{row['tracebacks']:>12}{row['wrong']:>7}{row_slowest:>13.2f}"
                f"{time.perf_counter() - row_start:>10.1f}"
            )
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    took = time.perf_counter() - start
    print(
        f"{'total':<20}{totals['cases']:>7}{totals['errors']:>8}{totals['valid']:>7}"
        f"{totals['tracebacks']:>12}{totals['wrong']:>7}{slowest:>13.2f}{took:>10.1f}"
    )
    print(
        f"cases tried {totals['cases']}, clean errors {totals['errors']}, valid results "
        f"{totals['valid']}, tracebacks {totals['tracebacks']}, wrong answers {totals['wrong']}, "
        f"peak memory {peak_bytes() / 2**20:.0f} MiB, slowest case {slowest:.2f} s, "
        f"time {took:.0f} s (seed {args.seed})"
    )
    for text in failures[:10]:
        print("\n" + text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
