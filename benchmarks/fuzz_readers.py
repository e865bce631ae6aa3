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
per-channel files and patterns (:func:`fuzzing.channels_case`). Two more
rows build their cases from a structure whose defects are known (``tests/fuzzing_structures.py``):
``urdf`` (random trees with cycles, self-loops, second parents, hostile numbers, DOCTYPEs and
encodings; eq. 7 of a joint) and ``trajectory`` (the virtual joint's 2 s multi-sine with
holes, moved stamps, lost rows and stuck currents; ``fit_trajectory``), where a valid result
from a defective case, or an absurd inertia or friction, is a wrong answer.

Every case runs under :mod:`tracemalloc`: the rows give the largest peak of traced memory of
one case and the longest case, and the summary the process's peak resident size.

Run::

    PYTHONPATH=src python benchmarks/fuzz_readers.py --cases 200 --seed 0

It prints one row per reader and the totals, then the first failures, and exits with status
1 if there was any traceback or wrong answer.
"""

from __future__ import annotations

import argparse
import resource
import shutil
import sys
import tempfile
import time
import traceback
from functools import partial
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from fuzzing import READERS, RngChooser, Workspace, channels_case
from fuzzing_structures import measured, run_trajectory, run_urdf

#: The rows built from a structure, beside the byte-damaged readers.
STRUCTURES = {"urdf": run_urdf, "trajectory": run_trajectory}
NAMES = [*READERS, "channels", *STRUCTURES]
COUNTS = ("cases", "errors", "valid", "tracebacks", "wrong")


def _case(work: Workspace, name: str, rng: np.random.Generator) -> tuple[str, float, float]:
    """One case of ``name``: its outcome, seconds and peak of traced memory [bytes]."""
    if name in STRUCTURES:
        work.n += 1
        call = partial(STRUCTURES[name], work.folder, RngChooser(rng), work.n)
    elif name == "channels":
        work.n += 1
        call = partial(channels_case, work.folder / f"channels{work.n}", RngChooser(rng))
    else:
        call = partial(work.run, READERS[name], RngChooser(rng))
    (outcome, _what), seconds, peak = measured(call)
    return outcome, seconds, peak


def _row(name: str, row: dict) -> str:
    return (
        f"{name:<20}{row['cases']:>7}{row['errors']:>8}{row['valid']:>7}{row['tracebacks']:>12}"
        f"{row['wrong']:>7}{row['peak'] / 2**20:>10.1f}{row['slowest']:>9.2f}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=200, help="cases per reader")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--readers", nargs="*", default=NAMES, choices=NAMES)
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="fricid-fuzz-"))
    work = Workspace(folder)
    failures: list[str] = []
    totals = {**dict.fromkeys(COUNTS, 0), "peak": 0.0, "slowest": 0.0}
    start = time.perf_counter()
    print(
        f"{'reader':<20}{'cases':>7}{'errors':>8}{'valid':>7}{'tracebacks':>12}{'wrong':>7}"
        f"{'peak MiB':>10}{'max s':>9}"
    )
    try:
        for name in args.readers:
            rng = np.random.default_rng([args.seed, NAMES.index(name)])
            row = {**dict.fromkeys(COUNTS, 0), "peak": 0.0, "slowest": 0.0}
            for i in range(args.cases):
                row["cases"] += 1
                try:
                    outcome, seconds, peak = _case(work, name, rng)
                    row["errors" if outcome == "error" else "valid"] += 1
                    row["peak"], row["slowest"] = (
                        max(row["peak"], peak),
                        max(row["slowest"], seconds),
                    )
                except AssertionError as exc:  # WrongAnswer and the oracle's other checks
                    row["wrong"] += 1
                    failures.append(f"{name} case {i}: wrong answer: {exc}")
                except Exception:
                    row["tracebacks"] += 1
                    failures.append(f"{name} case {i}: traceback:\n{traceback.format_exc()}")
            for key in COUNTS:
                totals[key] += row[key]
            totals["peak"] = max(totals["peak"], row["peak"])
            totals["slowest"] = max(totals["slowest"], row["slowest"])
            print(_row(name, row))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    print(_row("total", totals))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux
    print(
        f"cases tried {totals['cases']}, clean errors {totals['errors']}, valid results "
        f"{totals['valid']}, tracebacks {totals['tracebacks']}, wrong answers {totals['wrong']}; "
        f"peak memory {totals['peak'] / 2**20:.1f} MiB traced in one case, {rss:.0f} MiB "
        f"resident for the process; longest case {totals['slowest']:.2f} s "
        f"({time.perf_counter() - start:.0f} s in all, seed {args.seed})"
    )
    for text in failures[:10]:
        print("\n" + text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
