"""Coverage of fricid's 95 % prediction intervals (``FittedModel.predict_interval``) on held-out
noisy samples, per model and per friction law, over seeds.

Each case draws a training design (speeds per direction, loads, temperatures), samples a law
written here (none is one of fricid's families) with Gaussian noise, fits each model, then
draws 400 held-out samples inside the operating range from the same law and noise and counts
how many fall inside the interval. Printed: the mean coverage over seeds and its range.

    python benchmarks/bench_intervals.py --seeds 10
    python benchmarks/bench_intervals.py --seeds 4 --models rbf hybrid --laws tiny
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from fricid.identify import fit
from fricid.samples import FrictionSamples

NOISE = 0.03


def _stribeck_arrhenius(v, load, T):
    a = np.abs(v)
    visc = 0.12 * np.exp(1800.0 * (1.0 / (T + 273.15) - 1.0 / 303.15))
    return np.sign(v) * (0.9 + 0.08 * np.abs(load) + 0.4 * np.exp(-((a / 0.4) ** 1.5)) + visc * a)


def _sigmoid_sqrt(v, load, T):
    a = np.abs(v)
    return np.sign(v) * (0.6 * np.tanh(a / 0.05) + 0.25 * np.sqrt(a)) + 0.05 * (v > 0)


def _cubic_drag(v, load, T):
    return np.sign(v) * (0.5 + 0.3 * np.abs(v) + 0.02 * np.abs(v) ** 3)


LAWS = {
    "stribeck_arrhenius": (_stribeck_arrhenius, 10, True),
    "sigmoid_sqrt": (_sigmoid_sqrt, 10, False),
    "cubic_drag": (_cubic_drag, 10, False),
    "tiny": (_sigmoid_sqrt, 3, False),  # 12 samples: 3 speeds x 2 directions x 2 repeats
}


def _design(n_speeds: int, temp: bool, rng: np.random.Generator, repeats: int) -> np.ndarray:
    speeds = np.geomspace(0.2, 4.0, n_speeds) * rng.uniform(0.97, 1.03, n_speeds)
    rows = []
    temps = (20.0, 35.0, 50.0) if temp else (30.0,)
    for T in temps:
        for s in speeds:
            for d in (-1.0, 1.0):
                for _ in range(repeats):
                    rows.append([d * s, rng.uniform(-1, 1), T + rng.normal(0, 0.2)])
    return np.array(rows)


def _heldout(X: np.ndarray, rng: np.random.Generator, n: int = 400) -> np.ndarray:
    speeds = np.abs(X[:, 0])
    v = rng.choice([-1.0, 1.0], n) * np.exp(
        rng.uniform(np.log(speeds.min()), np.log(speeds.max()), n)
    )
    load = rng.uniform(X[:, 1].min(), X[:, 1].max(), n)
    T = rng.uniform(X[:, 2].min(), X[:, 2].max(), n)
    return np.column_stack([v, load, T])


def coverage(model: str, law: str, seed: int, level: float = 0.95) -> float:
    """Share of held-out noisy samples inside ``model``'s interval at ``level``."""
    f, n_speeds, temp = LAWS[law]
    rng = np.random.default_rng(seed)
    X = _design(n_speeds, temp, rng, 2 if law == "tiny" else 1)
    y = f(*X.T) + NOISE * rng.standard_normal(len(X))
    s = FrictionSamples(velocity=X[:, 0], load=X[:, 1], temperature=X[:, 2], friction=y)
    name = "stribeck_temp" if (model == "analytic" and temp) else model
    name = "stribeck" if name == "analytic" else name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = fit(s, name, seed=seed)
        Xh = _heldout(X, rng)
        yh = f(*Xh.T) + NOISE * rng.standard_normal(len(Xh))
        pi = m.predict_interval(Xh, level, warn=False)
    return float(np.mean((yh >= pi.low) & (yh <= pi.high)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--models", nargs="+", default=["analytic", "rbf", "hybrid", "gp"])
    ap.add_argument("--laws", nargs="+", default=list(LAWS))
    ap.add_argument("--level", type=float, default=0.95)
    args = ap.parse_args()
    print(f"coverage of the {args.level:.0%} prediction interval, {args.seeds} seeds")
    print(f"{'model':10s} {'law':20s} {'mean':>6s} {'min':>6s} {'max':>6s} {'s/fit':>6s}")
    for model in args.models:
        for law in args.laws:
            t0 = time.perf_counter()
            c = [coverage(model, law, seed, args.level) for seed in range(args.seeds)]
            dt = (time.perf_counter() - t0) / args.seeds
            print(
                f"{model:10s} {law:20s} {np.mean(c):6.3f} {np.min(c):6.3f} {np.max(c):6.3f} "
                f"{dt:6.2f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
