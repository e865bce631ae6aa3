"""Calibration of the ``filtered`` route's intervals and of its rate-bias estimate (issue 16).

Usage: ``python benchmarks/calib_trajectory.py [--first 10] [--seeds 40] [--duration 60]
[--noise-free]`` (about 10 s per seed on 2 idle cores). Never run on seeds 0-4, the report's.

For each seed, the virtual joint with the default LuGre truth tracks the multi-sine of
``bench_trajectory.py`` (with the trajectory noise, or none) and
:func:`fricid.identify.dynamic.trajectory.fit_trajectory` identifies it (``lm``). Table 1, per
parameter (sigma_0 and sigma_1 on their log10 search scale): the Monte-Carlo standard
deviation of the estimates over the mean reported standard error and the coverage of the
95 % intervals (CR1, the route's), then the same with the cluster jackknife linearised at the
optimum (CR3: ``bread . sum_g J_g' (I - H_gg)^-1 r_g r_g' (I - H_gg)^-1 J_g . bread .
(G - 1) / G``; Cameron and Miller 2015, MacKinnon, Nielsen and Webb 2023), computed here
from the route's Jacobian and residuals. Table 2: sigma_0 and sigma_1's mean error, RMS error
over the standard error and coverage, as estimated and as corrected by the rate-bias estimate
(``provenance["trajectory"]["rate_bias"]``, shifting the interval on the log scale).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from scipy import stats

import fricid.identify.dynamic._filtered as filtered
from fricid.identify.dynamic._data import cluster_covariance
from fricid.identify.dynamic.trajectory import fit_trajectory
from fricid.identify.static.uncertainty import covariance_svd
from fricid.models import lugre
from fricid.sim import Joint
from fricid.sim import trajectory as tr

TRUTH = tr.LuGreTruth()
JOINT = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=0.01)
NAMES = [*lugre.PARAM_NAMES, "inertia", "p_x", "p_y"]
#: the truth on the search scale (log10 for sigma_0, sigma_1)
TRUE = np.array([4.0, 0.0, *TRUTH.theta[2:], 0.01, 0.3, 0.1])


def cr3_stderr(J: np.ndarray, r: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """Standard errors of the linearised cluster jackknife (module notes)."""
    bread, _ = covariance_svd(J, 1.0)
    Jb = np.nan_to_num(J @ bread)
    uniq = np.unique(labels)
    scores = np.zeros((uniq.size, J.shape[1]))
    for k, lab in enumerate(uniq):
        idx = np.flatnonzero(labels == lab)
        e = np.linalg.solve(np.eye(idx.size) - Jb[idx] @ J[idx].T, r[idx])
        scores[k] = J[idx].T @ e
    cov = (uniq.size - 1) / uniq.size * bread @ (scores.T @ scores) @ bread
    return np.sqrt(np.clip(np.diag(cov), 0, None))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--first", type=int, default=10)
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--noise-free", action="store_true")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    calls: list[tuple] = []

    def spy(J, r, labels):
        calls.append((J, r, labels))
        return cluster_covariance(J, r, labels)

    filtered.cluster_covariance = spy
    noise = {"noise": tr.Noise.none()} if args.noise_free else {}
    est, se1, se3, bias, worst = [], [], [], [], 0.0
    seeds = range(args.first, args.first + args.seeds)
    for seed in seeds:
        log = tr.simulate_trajectory(
            tr.multisine(duration=args.duration, seed=seed), TRUTH, JOINT, seed=seed, **noise
        )
        calls.clear()
        t0 = time.perf_counter()
        f = fit_trajectory(log, "lugre", "lm", seed=seed)
        worst = max(worst, time.perf_counter() - t0)
        J, r, labels = calls[0]  # the estimate's (the second call is the rate bias's)
        _, se, g = cluster_covariance(J, r, labels)
        joint = f.provenance["trajectory"]["joint"]
        x = np.array(
            [f.params[n] for n in lugre.PARAM_NAMES] + [joint[n]["value"] for n in NAMES[7:]]
        )
        x[:2] = np.log10(x[:2])
        est.append(x)
        se1.append(se)
        se3.append(cr3_stderr(J, r, labels))
        rb = f.provenance["trajectory"]["rate_bias"]
        bias.append([rb["sigma_0"]["log10_bias"], rb["sigma_1"]["log10_bias"]])
    err = np.array(est) - TRUE
    se1, se3, bias = np.array(se1), np.array(se3), np.array(bias)
    tq = float(stats.t.ppf(0.975, g - 1))
    print(
        f"filtered route, LuGre truth, multi-sine {args.duration:g} s at 1 kHz, "
        f"{'noise-free' if args.noise_free else 'trajectory noise'}, lm, seeds "
        f"{seeds[0]}-{seeds[-1]}, G = {g} clusters, t = {tq:.3f}\n"
    )
    print(f"{'parameter':<9} {'MC sd/SE':>9} {'cover':>6}  {'CR3 SE/CR1':>10} {'cover':>6}")
    for i, n in enumerate(NAMES):
        sd = err[:, i].std(ddof=1)
        c1 = np.mean(np.abs(err[:, i]) <= tq * se1[:, i])
        c3 = np.mean(np.abs(err[:, i]) <= tq * se3[:, i])
        print(
            f"{n:<9} {sd / se1[:, i].mean():>9.2f} {c1:>6.0%}  "
            f"{np.mean(se3[:, i] / se1[:, i]):>10.3f} {c3:>6.0%}"
        )
    print(
        f"\n{'log10':<9} {'mean err':>9} {'corrected':>10} {'RMS err/SE':>11} {'corr.':>6} "
        f"{'cover':>6} {'corr.':>6}"
    )
    for i, n in enumerate(NAMES[:2]):
        e, c, s = err[:, i], err[:, i] - bias[:, i], se1[:, i]
        print(
            f"{n:<9} {e.mean():>+9.4f} {c.mean():>+10.4f} {np.sqrt(np.mean((e / s) ** 2)):>11.2f} "
            f"{np.sqrt(np.mean((c / s) ** 2)):>6.2f} {np.mean(np.abs(e) <= tq * s):>6.0%} "
            f"{np.mean(np.abs(c) <= tq * s):>6.0%}"
        )
    print(f"\nslowest identification (with the rate bias): {worst:.2f} s (machine may be shared)")


if __name__ == "__main__":
    main()
