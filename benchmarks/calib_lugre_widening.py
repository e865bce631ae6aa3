"""LuGre's calibrated widening from tuning runs of ``bench_lugre.py`` (their ``--json``): per
parameter, the 0.95 quantile over every closed claim of the widening that would have held the
truth about the interval as fricid formed it before widening (the factor the run applied times
the one the claim still needed), pooled over the runs.

Usage: ``python benchmarks/calib_lugre_widening.py RUN.json=FACTORS [RUN.json=FACTORS ...]``,
``FACTORS`` the run's ``CALIBRATED_WIDENING`` as ``name:factor`` joined by commas (a parameter
not named was not widened), e.g.::

    python benchmarks/calib_lugre_widening.py \\
      build/settle_tune.json=sigma_0:3.53,sigma_2:1.58,tau_c:1.69,inertia:1.70,p_x:1.24,p_y:1.52 \\
      build/tune35.json=sigma_0:2.13,sigma_1:1.80,sigma_2:1.42,tau_c:1.61,tau_s:1.99,w_s:4.53,\\
    delta:4.42,inertia:1.47,p_x:1.25,p_y:1.22

The product is exact where the widened interval stayed inside the search box; a claim whose
widened interval reached the box became not determined and is no claim here.
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


def main() -> None:
    runs = [arg.split("=", 1) for arg in sys.argv[1:]]
    if not runs:
        sys.exit(__doc__)
    pooled: dict[str, list[float]] = {n: [] for n in bl.PARAMS}
    for path, spec in runs:
        applied = factors(spec)
        for row in json.loads(Path(path).read_text()):
            for n in bl.PARAMS:
                needed = bl._needed(row, n)
                if needed is not None:
                    pooled[n].append(applied.get(n, 1.0) * needed)
    print(f"# {len(runs)} runs: " + " ".join(path for path, _ in runs))
    print(f"{'parameter':10s} {'claims':>6s} {'q50':>6s} {'q90':>6s} {'q95':>6s}")
    for n, xs in pooled.items():
        if not xs:
            continue
        q = [float(np.quantile(xs, p, method="inverted_cdf")) for p in (0.5, 0.9, 0.95)]
        print(f"{n:10s} {len(xs):6d} " + " ".join(f"{x:6.3g}" for x in q))


if __name__ == "__main__":
    main()
