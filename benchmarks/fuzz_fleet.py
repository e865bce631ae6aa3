"""The long fuzz run of ``fricid fleet``: hostile manifests and output folders, outcomes counted.

Each case (``tests/_fleet_fuzz.py``) is a fresh folder: a CSV or YAML manifest of one to three
joints with drawn names (short, at and beyond ``NAME_MAX``, unicode, ``..``, separators, NUL,
line breaks), models and logs (missing, FIFO, ``/dev/zero``, folder, junk, a link to a user's
file, or a log the stand-in executor "fits"), YAML alias bombs, self-references and deep
nesting, and an output folder planted with hostile records (absolute paths, ``..``, links,
long and unicode paths, wrong kinds), links in place of the fleet's folders and files, FIFOs
and huge records. The outcome is a clean error (one line), a valid run, a traceback (any
other exception, or a case past its time) or a wrong answer (a file outside ``--out``, or a
user's file inside it, created, changed or removed).

Run::

    PYTHONPATH=src python benchmarks/fuzz_fleet.py --cases 500 --seed 0

It prints one row per manifest kind and the totals, the peak memory of the process and the
slowest case, then the first failures, and exits with status 1 if there was any traceback or
wrong answer.
"""

from __future__ import annotations

import argparse
import resource
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _fleet_fuzz as ff
from fuzzing import RngChooser

KEYS = ("cases", "errors", "valid", "tracebacks", "wrong")


def _peak_mb() -> float:
    """Peak resident memory of this process [MB] (``ru_maxrss``, kB on Linux)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024.0 * 1024.0) if sys.platform == "darwin" else peak / 1024.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--case-seconds",
        type=float,
        default=ff.CASE_SECONDS,
        help="a case that runs longer is stopped and counted as a traceback",
    )
    args = parser.parse_args()
    ff.CASE_SECONDS = args.case_seconds
    folder = Path(tempfile.mkdtemp(prefix="fricid-fuzz-fleet-"))
    rng = np.random.default_rng(args.seed)
    rows: dict[str, dict[str, int]] = {}
    failures: list[str] = []
    slowest = (0.0, "")
    start = time.perf_counter()
    try:
        for i in range(args.cases):
            root = folder / f"case{i}"
            root.mkdir()
            case = ff.draw_case(RngChooser(rng), root)
            kind = f"yaml {case.yaml_kind}" if case.yaml_kind else "csv"
            row = rows.setdefault(kind, dict.fromkeys(KEYS, 0))
            row["cases"] += 1
            t0 = time.perf_counter()
            try:
                outcome, _message = ff.run_case(ff.build_case(case))
                row["errors" if outcome == "error" else "valid"] += 1
            except ff.WrongAnswer as exc:
                row["wrong"] += 1
                failures.append(f"case {i} ({kind}, {case.plants}): wrong answer: {exc}")
            except Exception:
                row["tracebacks"] += 1
                failures.append(f"case {i} ({kind}, {case.plants}):\n{traceback.format_exc()}")
            seconds = time.perf_counter() - t0
            if seconds > slowest[0]:
                slowest = (seconds, f"case {i} ({kind}, logs {[j.log_kind for j in case.joints]})")
            shutil.rmtree(root, ignore_errors=True)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    totals = {k: sum(r[k] for r in rows.values()) for k in KEYS}
    print(f"{'manifest':<18}" + "".join(f"{k:>12}" for k in KEYS))
    for kind in sorted(rows):
        print(f"{kind:<18}" + "".join(f"{rows[kind][k]:>12}" for k in KEYS))
    print(f"{'total':<18}" + "".join(f"{totals[k]:>12}" for k in KEYS))
    print(
        f"cases {totals['cases']}, clean errors {totals['errors']}, valid results "
        f"{totals['valid']}, tracebacks {totals['tracebacks']}, wrong answers (files outside "
        f"--out touched) {totals['wrong']}; peak memory {_peak_mb():.0f} MB; "
        f"{time.perf_counter() - start:.1f} s (seed {args.seed}); slowest case "
        f"{slowest[0]:.2f} s: {slowest[1]}"
    )
    for text in failures[:10]:
        print("\n" + text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
