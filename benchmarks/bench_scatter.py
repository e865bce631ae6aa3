"""The measurement scatter on closely spaced speeds: 38 speeds per direction 3 % apart,
friction ``sign(v) (1 + 2 |v|)`` plus noise of std 0.05 N m, 20 seeds. Velocity levels that
chained neighbour to neighbour once read the law's rise as scatter between "repeated runs"
(about 0.13); the scatter should read the noise.

Run: ``python benchmarks/bench_scatter.py``.
"""

from __future__ import annotations

import numpy as np

from fricid.identify._scatter import measurement_scatter
from fricid.samples import FrictionSamples

NOISE = 0.05


def main() -> None:
    values, methods = [], set()
    speed = 0.1 * 1.03 ** np.arange(38)
    v = np.r_[-speed, speed]
    for seed in range(20):
        rng = np.random.default_rng(seed)
        y = np.sign(v) * (1 + 2 * np.abs(v)) + rng.normal(0.0, NOISE, v.size)
        sc = measurement_scatter(
            FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)
        )
        values.append(sc.value)
        methods.add(sc.method)
    print(
        f"scatter over 20 seeds (true {NOISE}): median {np.median(values):.4f}, "
        f"range {min(values):.3f}-{max(values):.3f}; method: {', '.join(sorted(methods))}"
    )


if __name__ == "__main__":
    main()
