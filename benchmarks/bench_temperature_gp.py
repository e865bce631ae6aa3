"""Held-out RMSE / noise of the temperature families and the Gaussian process (issue 15).

Three friction laws written for this benchmark (not the simulator presets), one per kind of
issue 15, each sampled on a training design and, with fresh noise, on a held-out design of
other speeds, loads and temperatures inside the training range (never the same draws):

``grid``
    Paper-1-shaped grid (Bittencourt-style load and temperature effects): Coulomb and
    Stribeck levels growing with |load|, an Arrhenius viscous term, the negative direction
    10 % weaker; 10 speeds x 2 directions x 5 loads x 4 temperatures = 400 points.
``arrhenius``
    Asymmetric Stribeck with an Arrhenius viscous term (e_t 3500 K); 15 speeds x 2 directions
    x 5 temperatures = 150 points.
``sigmoid``
    Franka-like sigmoid with a load-dependent Coulomb term; 18 speeds x 2 directions x 5
    loads x 3 temperatures = 540 points.

Noise: Gaussian, ``SIGMA`` = 5 mN m on every sample. Held-out RMSE / noise = 1.0 is the floor
(the model equals the truth). Fits are fricid's defaults (``fit(samples, name)``); the GP's
training time and the share of held-out points whose truth lies in its 95 % band (nominal
0.95) are printed. The machine may be shared: times are indicative.

    python benchmarks/bench_temperature_gp.py
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from fricid.identify import fit
from fricid.models._temperature import arrhenius_factor
from fricid.samples import FrictionSamples

SIGMA = 0.005
FAMILIES = (
    "stribeck_asym",
    "stribeck_temp_asym",
    "msk_asym",
    "msk_temp_asym",
    "vlt_asym",
    "gp",
)


def grid_law(X: np.ndarray) -> np.ndarray:
    v, load, temp = X.T
    av, al = np.abs(v), np.abs(load)
    g = (0.20 + 0.05 * al) * (1.0 + 0.6 * np.exp(-((av / 0.04) ** 1.2)))
    g = g + 0.12 * av * arrhenius_factor(2500.0, temp)
    return np.sign(v) * np.where(v > 0, g, 0.9 * g)


def arrhenius_law(X: np.ndarray) -> np.ndarray:
    v, _, temp = X.T
    av = np.abs(v)
    pos = 0.32 + 0.18 * np.exp(-av / 0.06)
    neg = 0.26 + 0.22 * np.exp(-((av / 0.04) ** 1.5))
    c = np.where(v > 0, 0.22, 0.27) * arrhenius_factor(3500.0, temp)
    return np.sign(v) * np.where(v > 0, pos, neg) + c * v


def sigmoid_law(X: np.ndarray) -> np.ndarray:
    v, load, temp = X.T
    av = np.abs(v)
    coulomb = (0.28 + 0.06 * np.abs(load)) * (2.0 / (1.0 + np.exp(-25.0 * av)) - 1.0)
    return np.sign(v) * (coulomb + 0.1 * av * (1.0 - 0.004 * (temp - 25.0)))


def design(speeds, loads, temps) -> np.ndarray:
    v = np.concatenate([np.asarray(speeds), -np.asarray(speeds)])
    V, L, T = (a.ravel() for a in np.meshgrid(v, loads, temps, indexing="ij"))
    return np.column_stack([V, L, T])


def laws():
    s10, s15, s18 = (np.geomspace(0.01, 2.0, k) for k in (10, 15, 18))
    mid = np.sqrt(s18[:-1] * s18[1:])  # held-out speeds between the training ones
    return {
        "grid": (
            grid_law,
            design(s10, np.linspace(0, 2, 5), [20, 35, 50, 65]),
            design(np.sqrt(s10[:-1] * s10[1:]), [0.25, 0.75, 1.25, 1.75], [27.5, 42.5, 57.5]),
        ),
        "arrhenius": (
            arrhenius_law,
            design(s15, [0.0], np.linspace(20, 60, 5)),
            design(np.sqrt(s15[:-1] * s15[1:]), [0.0], [25.0, 35.0, 45.0, 55.0]),
        ),
        "sigmoid": (
            sigmoid_law,
            design(s18, np.linspace(-2, 2, 5), [25, 40, 55]),
            design(mid, [-1.5, -0.5, 0.5, 1.5], [30.0, 50.0]),
        ),
    }


def samples_of(law, X: np.ndarray, seed: int) -> FrictionSamples:
    y = law(X) + SIGMA * np.random.default_rng(seed).standard_normal(len(X))
    return FrictionSamples(velocity=X[:, 0], load=X[:, 1], temperature=X[:, 2], friction=y)


def main() -> None:
    print(f"held-out RMSE / noise (noise {SIGMA * 1e3:g} mN m; 1.0 is the floor)")
    head = f"{'law':<10} {'n':>4} " + " ".join(f"{f:>18}" for f in FAMILIES)
    print(head + "  gp time [s]  gp 95% band covers truth")
    for name, (law, X_train, X_test) in laws().items():
        train = samples_of(law, X_train, seed=0)
        test = samples_of(law, X_test, seed=1)
        cells, gp_time, cover = [], float("nan"), float("nan")
        for family in FAMILIES:
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fitted = fit(train, family)
                pred = fitted.predict(test.X, warn=False)
            if family == "gp":
                gp_time = time.perf_counter() - start
                mean, std = fitted.predict(test.X, warn=False, return_std=True)
                cover = np.mean(np.abs(mean - law(test.X)) <= 1.96 * std)
            ratio = np.sqrt(np.mean((pred - test.friction) ** 2)) / SIGMA
            cells.append(f"{ratio:>18.3f}")
        row = f"{name:<10} {len(train):>4} " + " ".join(cells)
        print(row + f"  {gp_time:>11.1f}  {cover:>24.3f}")


if __name__ == "__main__":
    main()
