"""Fuzz model files longer than the test suite does, and print the counts (issue 12, defect 4).

The mutations and the classification are those of ``tests/fitted/test_fuzz_model.py``
(``tests/_model_fuzz.py``): valid model files of every family (analytic, ``_asym``, ``rbf``,
and files of schema version 1 an earlier fricid wrote, read through the upgrade) are damaged
(byte flips, truncation, inserted bytes, non-UTF-8, random JSON values, NaN, Infinity and
1e400, deleted and added keys, deep nesting, huge arrays, values of another field) and loaded
through the API; every ``--cli-every``-th case also goes through ``fricid
predict`` or ``fricid export`` (C, URDF, MJCF, YAML). Each outcome is a clean error (one line
naming the file), a valid result (finite friction on the model's operating range), a
traceback or a wrong answer; the last two are listed with the case's seed so that

    python benchmarks/fuzz_model.py --cases 1 --seed SEED --keep DIR

writes the file again. Typical use:

    python benchmarks/fuzz_model.py                      # 2000 cases, seed 0
    python benchmarks/fuzz_model.py --cases 20000 --seed 7

Exit status 1 when any case ended in a traceback or a wrong answer.
"""

from __future__ import annotations

import argparse
import collections
import random
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _model_fuzz as mf

CLI_COMMANDS = ("predict", "c", "urdf", "mjcf", "yaml")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=2000, help="number of cases (2000)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first case (0)")
    parser.add_argument(
        "--cli-every", type=int, default=10, help="every n-th case also through the CLI (10)"
    )
    parser.add_argument("--keep", type=Path, help="keep the cases' files in this folder")
    args = parser.parse_args(argv)
    folder = args.keep or Path(tempfile.mkdtemp(prefix="fricid-fuzz-model-"))
    folder.mkdir(parents=True, exist_ok=True)
    valid = mf.write_valid(folder)
    counts: collections.Counter[str] = collections.Counter()
    by_kind: collections.Counter[tuple[str, str]] = collections.Counter()
    findings: list[str] = []
    start = time.perf_counter()
    for i in range(args.cases):
        seed = args.seed + i
        rng = random.Random(seed)
        family, kind = rng.choice(mf.FAMILIES), rng.choice(mf.KINDS)
        path = folder / f"case-{seed}.json"
        path.write_bytes(mf.mutate(valid[family].read_bytes(), rng, kind))
        runs = [("api", mf.classify(path))]
        if args.cli_every and i % args.cli_every == 0:
            command = rng.choice(CLI_COMMANDS)
            out = Path(tempfile.mkdtemp(dir=folder)) / "out"
            runs.append((f"cli {command}", mf.classify_cli(path, command, out)))
        for where, (outcome, detail) in runs:
            counts[outcome] += 1
            counts[f"{where.split()[0]} cases"] += 1
            by_kind[(kind, outcome)] += 1
            if outcome in ("traceback", "wrong"):
                findings.append(f"seed {seed} {family}/{kind} ({where}): {outcome}: {detail}")
        if not args.keep:
            path.unlink()
    elapsed = time.perf_counter() - start
    tried = counts["api cases"] + counts["cli cases"]
    print(f"model-file fuzz: {args.cases} files (seeds {args.seed}..{args.seed + args.cases - 1})")
    print(f"cases tried:    {tried} ({counts['api cases']} API, {counts['cli cases']} CLI)")
    print(f"clean errors:   {counts['error']}")
    print(f"valid results:  {counts['valid']}")
    print(f"tracebacks:     {counts['traceback']}")
    print(f"wrong answers:  {counts['wrong']}")
    print(f"time:           {elapsed:.1f} s")
    print("by mutation (error / valid / traceback / wrong):")
    for kind in mf.KINDS:
        row = " / ".join(str(by_kind[(kind, o)]) for o in ("error", "valid", "traceback", "wrong"))
        print(f"  {kind:<9} {row}")
    for line in findings[:50]:
        print(line)
    return 1 if counts["traceback"] or counts["wrong"] else 0


if __name__ == "__main__":
    sys.exit(main())
