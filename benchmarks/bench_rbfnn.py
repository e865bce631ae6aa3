"""The BAS-RBFNN paper's network study (Tables 1, 3, 4, Fig. 9, 10) on the paper1 preset.

Usage: ``python benchmarks/bench_rbfnn.py [--quick] [--seed 0] [--seeds 5] [--folds 5]
[--epochs 300] [--repeats 3] [--timing-only] [--out DIR]``. Prints every table (errors in
mN m, the paper's numbers beside ours) and the performance targets, and writes CSVs,
``fig9_mse.png``, ``fig10_unseen.png`` and ``summary.md`` to ``--out`` (default
``benchmarks/out/rbfnn``). The study itself is
:func:`fricid.experiments.rbfnn_study.run_study` (rendered by
:mod:`fricid.report.studies.rbfnn`); ``fricid bench rbfnn`` runs the same.

``--timing-only`` makes the data and runs only the training-time comparison on all of it
(:func:`fricid.experiments.rbfnn_study.timing`: RBFNN, hybrid BAS-RBFNN, the MLP and the
larger RBFNN, each the median over ``--seeds`` seeds of the best of ``--repeats`` fits) and
prints its table; nothing is written.
"""

from __future__ import annotations

import argparse
import sys
import time

from fricid.experiments.rbfnn_study import paper1_data, run_study, study_config, timing
from fricid.report.studies.rbfnn import summary_markdown, write_outputs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="reduced design and budgets")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--seeds", type=int, default=None, help="Table 4 runs per method")
    parser.add_argument("--folds", type=int, default=None, help="cross-validation folds")
    parser.add_argument("--epochs", type=int, default=None, help="BAS and GA epoch budget")
    parser.add_argument("--repeats", type=int, default=None, help="timed fits per seed")
    parser.add_argument(
        "--timing-only", action="store_true", help="only the training-time comparison"
    )
    parser.add_argument("--out", default="benchmarks/out/rbfnn")
    args = parser.parse_args(argv)
    changes = {
        key: value
        for key, value in (
            ("seeds", args.seeds),
            ("folds", args.folds),
            ("max_epochs", args.epochs),
            ("timing_repeats", args.repeats),
        )
        if value is not None
    }
    cfg = study_config(args.quick, seed=args.seed, **changes)
    t0 = time.perf_counter()

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)

    if args.timing_only:
        progress(f"data: paper1/{cfg.size} ({cfg.data})")
        samples, _, _ = paper1_data(cfg.size, cfg.seed, cfg.data)
        for threads in (1, None):
            table = timing(samples, cfg, progress, threads=threads)
            print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        return 0
    result = run_study(cfg, progress=progress)
    print(summary_markdown(result))
    for path in write_outputs(result, args.out):
        print(f"wrote {path}", file=sys.stderr)
    print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
