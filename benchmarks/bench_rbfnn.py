"""The BAS-RBFNN paper's network study (Tables 1, 3, 4, Fig. 9, 10) on the paper1 preset.

Usage: ``python benchmarks/bench_rbfnn.py [--quick] [--seed 0] [--seeds 5] [--folds 5]
[--epochs 300] [--out DIR]``. Prints every table (errors in mN m, the paper's numbers beside
ours) and the performance targets, and writes CSVs, ``fig9_mse.png``, ``fig10_unseen.png``
and ``summary.md`` to ``--out`` (default ``benchmarks/out/rbfnn``). The study itself is
:func:`fricid.experiments.rbfnn_study.run_study`; ``fricid bench rbfnn`` runs the same.
"""

from __future__ import annotations

import argparse
import sys
import time

from fricid.experiments.rbfnn_study import run_study, study_config, summary_markdown, write_outputs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="reduced design and budgets")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--seeds", type=int, default=None, help="Table 4 runs per method")
    parser.add_argument("--folds", type=int, default=None, help="cross-validation folds")
    parser.add_argument("--epochs", type=int, default=None, help="BAS and GA epoch budget")
    parser.add_argument("--out", default="benchmarks/out/rbfnn")
    args = parser.parse_args(argv)
    changes = {
        key: value
        for key, value in (
            ("seeds", args.seeds),
            ("folds", args.folds),
            ("max_epochs", args.epochs),
        )
        if value is not None
    }
    cfg = study_config(args.quick, seed=args.seed, **changes)
    t0 = time.perf_counter()

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)

    result = run_study(cfg, progress=progress)
    print(summary_markdown(result))
    for path in write_outputs(result, args.out):
        print(f"wrote {path}", file=sys.stderr)
    print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
