"""LuGre's calibrated widening from tuning runs of ``bench_lugre.py`` (their ``--json``): per
parameter, the 0.95 quantile over every closed claim of the widening that would have held the
truth about the interval as fricid formed it before widening (the factor the run applied times
the one the claim still needed), pooled over the runs.

Usage: ``python benchmarks/calib_lugre_widening.py [--by-rest] RUN.json=FACTORS
[RUN.json=FACTORS ...]``,
``FACTORS`` the run's ``CALIBRATED_WIDENING`` as ``name:factor`` joined by commas (a parameter
not named was not widened), e.g.::

    python benchmarks/calib_lugre_widening.py \\
      build/settle_tune.json=sigma_0:3.53,sigma_2:1.58,tau_c:1.69,inertia:1.70,p_x:1.24,p_y:1.52 \\
      build/tune35.json=sigma_0:2.13,sigma_1:1.80,sigma_2:1.42,tau_c:1.61,tau_s:1.99,w_s:4.53,\\
    delta:4.42,inertia:1.47,p_x:1.25,p_y:1.22

The product is exact where the widened interval stayed inside the search box; a claim whose
widened interval reached the box became not determined and is no claim here.

``--by-rest``: the quantiles for the logs that rest at least
:data:`fricid.identify.dynamic._outcome.RESTING` of their time and for the others apart, each
log's rest share the fit's own (:func:`fricid.identify.dynamic._data.rest_share`; a row that
does not record it, ``rest``, is simulated again and read as the fit reads it). A run's
``FACTORS`` may then be ``resting`` (the factors the fit applied were the current
``RESTING_WIDENING`` for the resting logs and ``CALIBRATED_WIDENING`` for the others).

``--hold FACTORS``: also how many of the closed claims a candidate factor set would hold (the
widening each needed at most the candidate's factor; a parameter not named: 1), per group, e.g.
whether the moving logs' own quantiles would still hold another simulator's claims. Claims that
the fit's factors sent to the search box (not determined) are not counted; a narrower factor
could have kept some of them closed.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

import bench_lugre as bl


def factors(spec: str) -> dict[str, float]:
    """``"sigma_0:3.53,p_x:1.24"`` as a dict."""
    out = {}
    for item in filter(None, spec.split(",")):
        name, value = item.split(":")
        out[name.strip()] = float(value)
    return out


def rest(row: dict) -> float:
    """The row's rest share as the fit computes it (simulated again where not recorded)."""
    if row.get("rest") is not None:
        return float(row["rest"])
    import tempfile

    import _lugre_truth as lt
    from fricid.identify.dynamic._data import rest_share, uniform_series
    from fricid.io import read_rawlog

    truth = lt.ALL_TRUTHS[row["truth"]]
    log = lt.simulate(
        truth, row["kind"], row["n"] / row["rate"], row["rate"], row["cpr"], row["seed"]
    )
    with tempfile.TemporaryDirectory() as tmp:
        raw = read_rawlog(lt.write_log(log, Path(tmp) / "log.csv", truth, {}))
    return rest_share(uniform_series(raw))


def table(title: str, pooled: dict[str, list[float]]) -> None:
    print(f"## {title}")
    print(f"{'parameter':10s} {'claims':>6s} {'q50':>6s} {'q90':>6s} {'q95':>6s}")
    for n, xs in pooled.items():
        if not xs:
            continue
        q = [float(np.quantile(xs, p, method="inverted_cdf")) for p in (0.5, 0.9, 0.95)]
        print(f"{n:10s} {len(xs):6d} " + " ".join(f"{x:6.3g}" for x in q))


def held(title: str, pooled: dict[str, list[float]], candidate: dict[str, float]) -> None:
    print(f"## {title}: claims held by the candidate factors (widening needed <= factor)")
    print(f"{'parameter':10s} {'factor':>6s} {'held':>9s}")
    for n, xs in pooled.items():
        if xs:
            f = candidate.get(n, 1.0)
            print(f"{n:10s} {f:6.3g} {sum(x <= f for x in xs):4d}/{len(xs):<4d}")


def main() -> None:
    from fricid.identify.dynamic._outcome import CALIBRATED_WIDENING, RESTING, RESTING_WIDENING

    args = sys.argv[1:]
    by_rest = "--by-rest" in args
    candidate = None
    if "--hold" in args:
        i = args.index("--hold")
        candidate = factors(args[i + 1])
        del args[i : i + 2]
    runs = [arg.split("=", 1) for arg in args if arg != "--by-rest"]
    if not runs:
        sys.exit(__doc__)
    groups = ("all", "resting", "moving") if by_rest else ("all",)
    pooled: dict[str, dict[str, list[float]]] = {g: {n: [] for n in bl.PARAMS} for g in groups}
    for path, spec in runs:
        for row in json.loads(Path(path).read_text()):
            share = rest(row) if by_rest else 0.0
            group = "resting" if share >= RESTING else "moving"
            if spec == "resting":
                applied = dict(RESTING_WIDENING if group == "resting" else CALIBRATED_WIDENING)
            else:
                applied = factors(spec)
            for n in bl.PARAMS:
                needed = bl._needed(row, n)
                if needed is None:
                    continue
                for g in ("all", group) if by_rest else ("all",):
                    pooled[g][n].append(applied.get(n, 1.0) * needed)
    print(f"# {len(runs)} runs: " + " ".join(path for path, _ in runs))
    for g in groups:
        title = {"all": "every log", "resting": f"logs resting >= {RESTING:g} of their time"}
        name = title.get(g, f"logs resting < {RESTING:g} of their time")
        table(name, pooled[g])
        if candidate is not None:
            held(name, pooled[g], candidate)


if __name__ == "__main__":
    main()
