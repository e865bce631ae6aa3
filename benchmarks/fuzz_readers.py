"""The long fuzz run of every reader (issue 12): damaged files, outcomes counted.

Each case damages an undamaged file of one reader with one to three mutations (truncation,
byte flips, random bytes, binary junk, not-UTF-8, huge numbers, NaN/inf text, empty and
header-only files, wrong field counts, trailing empty fields, BOM, CRLF, bad metadata,
corrupt MCAP length fields) and classifies the outcome as the test suite does
(``tests/fuzzing.py``): a clean error (a FricidError on one line naming the file), a valid
result, a traceback (any other exception) or a wrong answer (a result that breaks the
invariants, a RuntimeWarning, a multi-line message or one not naming the file).

Run::

    PYTHONPATH=src python benchmarks/fuzz_readers.py --cases 200 --seed 0

It prints one row per reader and the totals, then the first failures, and exits with status
1 if there was any traceback or wrong answer.
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

from fuzzing import READERS, RngChooser, Workspace


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=200, help="cases per reader")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--readers", nargs="*", default=list(READERS), choices=list(READERS))
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="fricid-fuzz-"))
    work = Workspace(folder)
    failures: list[str] = []
    totals = dict.fromkeys(("cases", "errors", "valid", "tracebacks", "wrong"), 0)
    start = time.perf_counter()
    print(f"{'reader':<20}{'cases':>7}{'errors':>8}{'valid':>7}{'tracebacks':>12}{'wrong':>7}")
    try:
        for name in args.readers:
            rng = np.random.default_rng([args.seed, list(READERS).index(name)])
            row = dict.fromkeys(totals, 0)
            for i in range(args.cases):
                row["cases"] += 1
                try:
                    outcome, _kinds = work.run(READERS[name], RngChooser(rng))
                    row["errors" if outcome == "error" else "valid"] += 1
                except AssertionError as exc:  # WrongAnswer and the oracle's other checks
                    row["wrong"] += 1
                    failures.append(f"{name} case {i}: wrong answer: {exc}")
                except Exception:
                    row["tracebacks"] += 1
                    failures.append(f"{name} case {i}: traceback:\n{traceback.format_exc()}")
            for key in totals:
                totals[key] += row[key]
            print(
                f"{name:<20}{row['cases']:>7}{row['errors']:>8}{row['valid']:>7}"
                f"{row['tracebacks']:>12}{row['wrong']:>7}"
            )
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    print(
        f"{'total':<20}{totals['cases']:>7}{totals['errors']:>8}{totals['valid']:>7}"
        f"{totals['tracebacks']:>12}{totals['wrong']:>7}"
    )
    print(
        f"cases tried {totals['cases']}, clean errors {totals['errors']}, valid results "
        f"{totals['valid']}, tracebacks {totals['tracebacks']}, wrong answers {totals['wrong']} "
        f"({time.perf_counter() - start:.0f} s, seed {args.seed})"
    )
    for text in failures[:10]:
        print("\n" + text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
