"""Verdict calibration: is "Trust: yes / with caveats / no" right on data fricid did not make?

Usage::

    python benchmarks/bench_verdicts.py [--cases 325] [--quick] [--jobs 2] [--seed-split 4]
        [--models stribeck,coulomb_viscous] [--auto-every 3] [--learned-every 10]
        [--cli-check K] [--json PATH] [--rows PATH] [--report-only] [--tables-from PATH]
        [--classes gravity,regular]

Cases (:mod:`_verdict_cases`, generators written for this benchmark, not ``fricid.sim``):
friction laws outside fricid's families, regular, closely spaced (3-5 %), irregular,
few-level, gapped and lopsided speed designs, tiny sets (12 points), repeated runs, noise
proportional to the friction, gross outliers, unknown noise (no std or count), gravity left
in, and a law with load and temperature. Case ``i`` is of class ``CLASSES[i % 13]`` and is
drawn from seed ``1000 + i``.

Each model (``--models`` on every case; ``--auto-every K`` adds ``auto`` and
``--learned-every K`` adds ``hybrid`` and ``gp`` on every K-th case)
is fitted with ``fricid.identify.fit`` and judged by ``fricid.identify.trust.assess_trust``,
as ``fricid fit`` and the fleet do; its verdict is compared with the TRUE held-out ratio
(:mod:`_verdict_eval`): ``sqrt(mean (F_hat - F)^2 + mean sigma^2) / sqrt(mean sigma^2)`` on
a dense grid over the measured operating range (each direction's slowest to fastest speed,
gaps included; load and temperature over their measured box), ``F`` the noiseless truth and
``sigma`` the true noise std of a sample (for noise proportional to the friction, its root
mean square on the grid): the held-out ratio fricid would measure with unlimited fresh samples
and the true scatter, so a perfect model scores 1.0. Truth classes: ``<1.2`` (within noise,
fricid's ``NOISE_RATIO``), ``1.2-1.5``, ``>1.5``. Goals (on the report cases): "Trust: yes"
for at most 1 % of the fits whose true ratio exceeds 1.5, "Trust: no" for at most 5 % of those
below 1.2; the 95 % prediction intervals of every model covering 90-98 % of fresh noisy samples
on the grid, in every class ("n/a" for a model that exposes no interval). fricid gives no
interval inside a gap between measured speeds (nothing measured backs one there): coverage
is over the grid points with an interval, and a table prints the share of the grid without.

Seed split: a case whose seed is a multiple of ``--seed-split`` is a tuning case (to tune
thresholds on); the tables are printed on the others, the report cases (``--seed-split 0``:
all cases). Both sets go to ``--json``. ``--cli-check K``: K report cases through the API,
``fricid fit`` + ``fricid report`` and the fleet (:mod:`_verdict_cli`; ``auto`` and the
first of ``--models``; cases with repeated runs first), agreement printed. ``--rows PATH``
appends one JSON line per fit as it ends, so an interrupted run keeps what it did;
``--tables-from PATH`` prints the tables of such a file (or of a ``--json`` file) without
running; ``--report-only`` skips the tuning cases; ``--classes`` runs only the cases of the
classes named (their ids and seeds as in the full run).

Runtime is ``auto``'s: CPU seconds per fit and trust assessment (the last table prints
them), measured over 60 cases on a shared machine: ``auto`` 18 (its own leave-one-level-out
over every candidate family), ``stribeck`` 2.4, ``coulomb_viscous`` 0.4, ``hybrid`` 1.3,
``gp`` 1.1. So the default full run (325 cases, ``auto`` on 109 of them, the learned models on
33) is some 3,000 CPU seconds, about 25 minutes on 2 idle cores (``--auto-every 9``: about
14); ``--quick`` is 13 cases, one per class, ``auto`` on 2 (cases 0 and 7), about 75 CPU
seconds: under a minute with ``--jobs 2``. ``--auto-every`` and ``--seed-split`` should not
share a factor, or ``auto`` runs on tuning cases only.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections import defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _verdict_cases import CLASSES, make_case, truth_grid
from _verdict_eval import run_model

LEVELS = ("yes", "with caveats", "no", "error")
TRUTH = ("<1.2", "1.2-1.5", ">1.5")
BASE_SEED = 1000
DEFAULT_MODELS = ("stribeck", "coulomb_viscous")
LEARNED = ("hybrid", "gp")


def truth_class(ratio: float) -> str:
    """The truth class of a true ratio."""
    return "<1.2" if ratio < 1.2 else ("1.2-1.5" if ratio <= 1.5 else ">1.5")


def case_plan(n: int) -> list[tuple[int, str, int]]:
    """``(case id, class, seed)`` of ``n`` cases, the classes in turn."""
    names = list(CLASSES)
    return [(i, names[i % len(names)], BASE_SEED + i) for i in range(n)]


def run_case(item: tuple[int, str, int, tuple[str, ...]]) -> list[dict[str, Any]]:
    """Every model on one case (a process-pool task)."""
    case_id, klass, seed, models = item
    case = make_case(case_id, klass, seed)
    grid = truth_grid(case)
    rows = []
    for model in models:
        row = run_model(case, model, grid)
        row["seed"] = seed
        row["spec"] = {k: v for k, v in case.spec.items() if k != "law"}
        row["law"] = case.law.name
        row["n"] = len(case.samples)
        if "true_ratio" in row:
            row["truth"] = truth_class(row["true_ratio"])
        rows.append(row)
    return rows


def _tasks(args) -> list[tuple[int, str, int, tuple[str, ...]]]:
    models = tuple(args.models.split(","))
    out = []
    for cid, klass, seed in case_plan(args.cases):
        if cid < args.first or (args.classes and klass not in args.classes):
            continue
        if args.report_only and is_tuning(seed, args.seed_split):
            continue
        if args.tuning_only and not is_tuning(seed, args.seed_split):
            continue
        extra: tuple[str, ...] = ()
        if args.auto_every and cid % args.auto_every == 0:
            extra += ("auto",)
        if args.learned_every and cid % args.learned_every == 0:
            extra += LEARNED
        out.append((cid, klass, seed, models + tuple(m for m in extra if m not in models)))
    return out


def run_all(args) -> tuple[list[dict[str, Any]], float]:
    """Every task, on ``args.jobs`` processes, with progress on stderr."""
    tasks = _tasks(args)
    rows: list[dict[str, Any]] = []
    sink = None if args.rows is None else args.rows.open("a", encoding="utf-8")
    t0 = time.perf_counter()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            results = pool.map(run_case, tasks, chunksize=1)
            for k, got in enumerate(results, 1):
                rows.extend(got)
                _progress(k, len(tasks), got, t0, sink)
    else:
        for k, task in enumerate(tasks, 1):
            got = run_case(task)
            rows.extend(got)
            _progress(k, len(tasks), got, t0, sink)
    if sink is not None:
        sink.close()
    return rows, time.perf_counter() - t0


def _progress(k: int, n: int, got: list[dict[str, Any]], t0: float, sink=None) -> None:
    if sink is not None:  # one JSON line per fit, as it finishes (--rows)
        sink.writelines(json.dumps(r, default=str) + "\n" for r in got)
        sink.flush()
    bits = [
        f"{r['model']}={r['level']}"
        + (
            f"({r.get('fricid_ratio') or float('nan'):.2f}/{r['true_ratio']:.2f})"
            if "true_ratio" in r
            else ""
        )
        for r in got
    ]
    print(
        f"[{k}/{n} {time.perf_counter() - t0:.0f}s] case {got[0]['case']} {got[0]['class']}: "
        + " ".join(bits),
        file=sys.stderr,
        flush=True,
    )


# -- tables ---------------------------------------------------------------------------------


def confusion(rows: list[dict[str, Any]]) -> dict[str, dict[str, int]]:
    """Verdict -> truth class -> count (errors have no truth class: column ``-``)."""
    table: dict[str, dict[str, int]] = {lv: dict.fromkeys((*TRUTH, "-"), 0) for lv in LEVELS}
    for r in rows:
        table[r["level"]][r.get("truth", "-")] += 1
    return table


def rates(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The two goals: P(yes | true > 1.5) and P(no | true < 1.2), with their counts."""
    bad = [r for r in rows if r.get("truth") == ">1.5"]
    good = [r for r in rows if r.get("truth") == "<1.2"]
    yes_bad = sum(r["level"] == "yes" for r in bad)
    no_good = sum(r["level"] == "no" for r in good)
    return {
        "yes_given_bad": yes_bad / len(bad) if bad else None,
        "yes_bad": yes_bad,
        "n_bad": len(bad),
        "yes_bad_of_all": yes_bad / len(rows) if rows else None,
        "no_given_good": no_good / len(good) if good else None,
        "no_good": no_good,
        "n_good": len(good),
        "no_good_of_all": no_good / len(rows) if rows else None,
        "errors": sum(r["level"] == "error" for r in rows),
        "n": len(rows),
    }


def coverage(
    rows: list[dict[str, Any]], max_ratio: float | None = None, key: str = "coverage"
) -> dict[str, dict[str, float | None]]:
    """Model -> class -> mean coverage of its 95 % intervals (None: no interval); with
    ``max_ratio``, over the fits whose true ratio is at most that only; ``key="withheld"``:
    the mean share of the grid without an interval (gaps between measured speeds)."""
    acc: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    seen: dict[str, set[str]] = defaultdict(set)
    for r in rows:
        if "true_ratio" not in r:
            continue
        if max_ratio is not None and r["true_ratio"] > max_ratio:
            continue
        seen[r["model"]].add(r["class"])
        if r.get(key) is not None:
            acc[r["model"]][r["class"]].append(r[key])
    out: dict[str, dict[str, float | None]] = {}
    for model, classes in seen.items():
        out[model] = {}
        for c in classes:
            vals = acc[model].get(c)
            out[model][c] = sum(vals) / len(vals) if vals else None
    return out


def _pct(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:.1f} %"


def print_confusion(title: str, rows: list[dict[str, Any]]) -> None:
    tab = confusion(rows)
    print(f"\n{title} ({len(rows)} fits)")
    print(f"{'verdict':>14} | " + " | ".join(f"{t:>8}" for t in (*TRUTH, "-")))
    for lv in LEVELS:
        print(f"{lv:>14} | " + " | ".join(f"{tab[lv][t]:>8}" for t in (*TRUTH, "-")))


def print_classes(rows: list[dict[str, Any]]) -> None:
    """One line per class: yes/caveat/no/error counts in each truth class."""
    print("\nPer class: counts yes/caveat/no in each truth class, then the two goal rates")
    print(
        f"{'class':>10} | {'<1.2':>10} | {'1.2-1.5':>10} | {'>1.5':>10} | err | yes|>1.5 | no|<1.2"
    )
    by = defaultdict(list)
    for r in rows:
        by[r["class"]].append(r)
    for c in CLASSES:
        if c not in by:
            continue
        tab, rt = confusion(by[c]), rates(by[c])
        cells = ["/".join(str(tab[lv][t]) for lv in LEVELS[:3]) for t in TRUTH]
        print(
            f"{c:>10} | "
            + " | ".join(f"{x:>10}" for x in cells)
            + f" | {rt['errors']:>3} | {_pct(rt['yes_given_bad']):>8} | {_pct(rt['no_given_good'])}"
        )


def print_coverage(rows: list[dict[str, Any]]) -> None:
    """The coverage table over every fit, then over the fits within 1.5x of the noise.

    The second table is there because the first mixes two things. Where a model misses the
    law by several times the noise (true ratio > 1.5, the fits "Trust: no" is for), a new
    sample at speed ``v`` is ``b(v) + noise`` with a fixed bias ``b``: an interval centred
    on the model covers it with probability about 0 or about 1 at each speed. Its coverage
    over the grid is then the share of speeds where ``|b|`` stays under the half-width, set
    by how peaked the misfit is rather than by the interval's calibration. On fits within
    1.5x of the noise the bias is at most comparable with the noise, and 90-98 % is a test
    of the interval itself.
    """
    print(
        "\nCoverage of the 95 % prediction intervals"
        " (fresh noisy samples on the grid; goal 90-98 %)"
    )
    _coverage_table(coverage(rows))
    print("\nThe same, over the fits with true ratio <= 1.5 only (n = fits counted)")
    _coverage_table(coverage(rows, 1.5), rows)
    if any(r.get("withheld") for r in rows):
        print("\nShare of the grid with no interval (inside gaps between measured speeds)")
        _coverage_table(coverage(rows, key="withheld"))


def _coverage_table(cov, rows: list[dict[str, Any]] | None = None) -> None:
    classes = [c for c in CLASSES if any(c in v for v in cov.values())]
    print(f"{'model':>16} | " + " | ".join(f"{c[:8]:>8}" for c in classes))
    for model, per in cov.items():
        cells = [_pct(per.get(c)) if c in per else "-" for c in classes]
        if rows is not None:
            counts = [
                sum(
                    r["model"] == model
                    and r["class"] == c
                    and r.get("coverage") is not None
                    and r.get("true_ratio", 9.0) <= 1.5
                    for r in rows
                )
                for c in classes
            ]
            cells = [f"{x} {k}" if x != "-" else x for x, k in zip(cells, counts, strict=True)]
        print(f"{model:>16} | " + " | ".join(f"{x:>8}" for x in cells))


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """JSON-ready summary of ``rows``."""
    models = sorted({r["model"] for r in rows})
    return {
        "confusion": confusion(rows),
        "rates": rates(rows),
        "per_model": {
            m: {"confusion": confusion(sel), "rates": rates(sel)}
            for m in models
            for sel in [[r for r in rows if r["model"] == m]]
        },
        "per_class": {
            c: {"confusion": confusion(sel), "rates": rates(sel)}
            for c in CLASSES
            for sel in [[r for r in rows if r["class"] == c]]
            if sel
        },
        "coverage": coverage(rows),
        "coverage_ratio_le_1_5": coverage(rows, 1.5),
        "withheld": coverage(rows, key="withheld"),
        "seconds_per_model": {
            m: sum(r["seconds"] for r in rows if r["model"] == m)
            / max(1, sum(r["model"] == m for r in rows))
            for m in models
        },
        "cpu_seconds_per_model": {
            m: sum(r["cpu_seconds"] for r in rows if r["model"] == m)
            / max(1, sum(r["model"] == m for r in rows))
            for m in models
        },
    }


def report(rows: list[dict[str, Any]], split: int, tuning: bool = False) -> None:
    """Print every table on the report cases (``tuning``: on the tuning cases)."""
    rep = [r for r in rows if is_tuning(r["seed"], split) == tuning]
    which = "tuning" if tuning else "report"
    print_confusion(f"Verdict against the true held-out ratio, all models, {which} cases", rep)
    for m in sorted({r["model"] for r in rep}):
        print_confusion(f"model {m}", [r for r in rep if r["model"] == m])
    print_classes(rep)
    rt = rates(rep)
    print(
        f'\n"Trust: yes" where true ratio > 1.5: {rt["yes_bad"]}/{rt["n_bad"]} = '
        f"{_pct(rt['yes_given_bad'])} (goal <= 1 %); of all fits {_pct(rt['yes_bad_of_all'])}"
    )
    print(
        f'"Trust: no" where true ratio < 1.2: {rt["no_good"]}/{rt["n_good"]} = '
        f"{_pct(rt['no_given_good'])} (goal <= 5 %); of all fits {_pct(rt['no_good_of_all'])}"
    )
    print(f"fit errors (FricidError, no verdict): {rt['errors']}")
    print_coverage(rep)
    summ = summary(rows)
    wall, cpu = summ["seconds_per_model"], summ["cpu_seconds_per_model"]
    print(
        "\nseconds per fit + trust (wall / CPU): "
        + ", ".join(f"{m} {wall[m]:.1f} / {cpu[m]:.1f}" for m in wall)
    )


def is_tuning(seed: int, split: int) -> bool:
    """A tuning case (module notes, "Seed split")."""
    return split > 0 and seed % split == 0


def print_cli(rows: list[dict[str, Any]]) -> None:
    print("\nSame verdict from the API, `fricid fit`, `fricid report` and the fleet")
    print(f"{'case':>5} {'class':>9} {'model':>16} | api | fit | report | fleet | ratio api/fleet")
    for r in rows:
        print(
            f"{r['case']:>5} {r['class']:>9} {r['model']:>16} | {r['api']} | {r['cli_fit']} | "
            f"{r['cli_report']} | {r['fleet']} | {r['api_ratio']:.4g}/{r['fleet_ratio']:.4g}"
            f"  {'agree' if r['agree'] else 'DISAGREE'}"
        )
    print(f"agreement: {sum(r['agree'] for r in rows)}/{len(rows)}")


def read_rows(path: Path) -> list[dict[str, Any]]:
    """The rows of a ``--json`` file or a ``--rows`` file (one JSON object per line)."""
    text = path.read_text(encoding="utf-8")
    try:
        return list(json.loads(text)["rows"])
    except (json.JSONDecodeError, KeyError, TypeError):
        return [json.loads(line) for line in text.splitlines() if line.strip()]


def parse(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--cases", type=int, default=325, help="number of cases (default 325)")
    p.add_argument("--quick", action="store_true", help="13 cases, one per class; auto on 2")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    p.add_argument("--seed-split", type=int, default=4, help="tuning: seed %% K == 0 (0: none)")
    p.add_argument("--models", default=",".join(DEFAULT_MODELS))
    p.add_argument("--auto-every", type=int, default=3, help="auto every K-th case (1: all)")
    p.add_argument("--learned-every", type=int, default=10, help="hybrid, gp every K-th case")
    p.add_argument("--cli-check", type=int, default=0, metavar="K")
    p.add_argument("--json", type=Path, default=None, metavar="PATH")
    p.add_argument("--rows", type=Path, default=None, metavar="PATH", help="JSON lines as fits end")
    p.add_argument("--report-only", action="store_true", help="skip the tuning cases")
    p.add_argument(
        "--tuning-only", action="store_true", help="only the tuning cases, tables on them"
    )
    p.add_argument("--first", type=int, default=0, help="start at this case (resume a run)")
    p.add_argument(
        "--classes",
        type=lambda text: tuple(c.strip() for c in text.split(",") if c.strip()),
        default=(),
        metavar="A,B",
        help="only the cases of these classes (ids and seeds unchanged)",
    )
    p.add_argument(
        "--tables-from",
        type=Path,
        default=None,
        metavar="PATH",
        help="print the tables of a --rows file or --json file instead of running",
    )
    args = p.parse_args(argv)
    unknown = [c for c in args.classes if c not in CLASSES]
    if unknown:
        p.error(f"unknown class(es) {', '.join(unknown)}; choose from {', '.join(CLASSES)}")
    if args.report_only and args.tuning_only:
        p.error("--report-only and --tuning-only exclude each other")
    if args.quick:
        args.cases, args.auto_every, args.learned_every = 13, 7, 0
    return args


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse(argv)
    tuning = [s for _, _, s in case_plan(args.cases) if is_tuning(s, args.seed_split)]
    print(
        f"{args.cases} cases, models {args.models}"
        + (f" (+ auto every {args.auto_every}th case)" if args.auto_every else "")
        + (
            f" (+ {', '.join(LEARNED)} every {args.learned_every}th case)"
            if args.learned_every
            else ""
        )
        + f"; tuning seeds (not reported): {len(tuning)} with seed % {args.seed_split} == 0"
        + (f" ({tuning[0]}..{tuning[-1]})" if tuning else ""),
        flush=True,
    )
    if args.tables_from is not None:
        rows, seconds = read_rows(args.tables_from), float("nan")
        print(f"{len(rows)} fits read from {args.tables_from.name}")
    else:
        rows, seconds = run_all(args)
        print(f"ran in {seconds:.0f} s on {args.jobs} process(es)")
    report(rows, args.seed_split, args.tuning_only)
    cli_rows: list[dict[str, Any]] = []
    if args.cli_check:
        from _verdict_cli import cli_check

        plan = [
            c
            for c in case_plan(args.cases)
            if not is_tuning(c[2], args.seed_split) and (not args.classes or c[1] in args.classes)
        ]
        # repeated runs first: a table of means carries no std, so only repeats give a scatter
        plan.sort(key=lambda c: c[1] not in ("repeats", "gravity"))
        cases = [make_case(*c) for c in plan[: args.cli_check]]
        cli_rows = cli_check(cases, ("auto", args.models.split(",")[0]))
        print_cli(cli_rows)
    result = {
        "cases": args.cases,
        "models": args.models,
        "seed_split": args.seed_split,
        "tuning_seeds": tuning,
        "seconds": seconds,
        "report": summary([r for r in rows if not is_tuning(r["seed"], args.seed_split)]),
        "tuning": summary([r for r in rows if is_tuning(r["seed"], args.seed_split)]),
        "rows": rows,
        "cli_check": cli_rows,
    }
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=1, default=str), encoding="utf-8")
    return result


if __name__ == "__main__":
    main()
