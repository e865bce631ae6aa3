"""LuGre from a trajectory against the truth and against sweeps (issue 16, done-when).

Usage: ``python benchmarks/bench_trajectory.py [--seeds 5] [--duration 60] [--method lm]
[--sigma1 1] [--experiment multisine] [--route filtered]`` (about 2 minutes on 2 idle
cores). ``--sigma1``
sets the truth's bristle damping (default 1 N m s/rad: damping ratio
``sigma_1 / (2 sqrt(sigma_0 J))`` = 0.05 with the joint's J; 8 gives 0.4, a well-damped
bristle mode, though not passive by [BO00] with this static part: the table prints the
truth's margin).

For each seed, the virtual joint with a LuGre truth (:class:`fricid.sim.trajectory.
LuGreTruth`: sigma_0 1e4 N m/rad, sigma_1 1 N m s/rad, sigma_2 0.2 N m s/rad, tau_c 0.5 N m,
tau_s 0.8 N m, w_s 0.1 rad/s, delta 1; J 0.01 kg m^2, p_x 0.3 N m, p_y 0.1 N m) tracks a
multi-sine (0.2, 0.5, 1.1, 2.3 Hz, 0.3 rad, random phases from the seed) for ``--duration``
seconds at 1 kHz, logged with :data:`fricid.sim.trajectory.TRAJECTORY_NOISE`, and
:func:`fricid.identify.dynamic.trajectory.fit_trajectory` identifies it (``--route``: ``filtered``,
the default, every parameter at once by the parallel-filtered equation error; or
``two_stage``, ``joint``). The same
joint's steady state (the static Stribeck law LuGre reduces to at constant velocity) is swept
on the ``paper2`` ``reduced`` design (17 speeds 0.005-4 rad/s, 10 passes, horizontal), the
sweeps extracted and fitted with ``stribeck`` by ``lm``.

``--experiment slow_multisine`` runs :func:`fricid.sim.trajectory.slow_multisine` instead
(the same duration: constant-speed plateaus at 0.03-0.3 rad/s both ways for the first half,
the same multi-sine faded in for the second), a designed experiment for the Stribeck region;
the default stays the plain multi-sine (the module notes of
:mod:`fricid.identify.dynamic.trajectory` say why).

Tables: (1) per parameter: truth, sweep estimate with its 95 % interval (seed 0),
trajectory estimate with its interval (seed 0), and the coverage of the trajectory intervals
over the seeds, counted over the closed intervals only: an interval that reaches a bound of
the search box (the parameter record's ``low_open`` or ``high_open``) says the experiment does
not determine the parameter, and is counted apart as "not determined", never as a hit;
the relative half-width of each seed-0 interval is printed beside it;
(2) per seed: identification time (the whole ``fit_trajectory`` call, numba
compiled beforehand; with the filtered route it includes the rate-bias estimate), each route's
time, the rate bias's time and its estimate of sigma_0's and sigma_1's relative bias at the
log's rate (:mod:`fricid.identify.dynamic._rate`, not applied), and whether each static
parameter's trajectory and sweep intervals overlap. The machine may be shared: times are
wall-clock on whatever cores were free.

Measured (the default run, then ``--route two_stage``, both on 2 cores shared with other
jobs, load average 2-4): coverage by the closed 95 % intervals over seeds 0-4, seed 0's
relative half-width, the slowest identification. The filtered column was re-run with the
rate-bias estimate (the same estimates and table; 3.8-5.5 s per identification, 1.7-2.7 s
of it the rate bias; estimated bias sigma_0 +2.9 to +4.2 %, sigma_1 -15 to -39 %, so each
run warns).

=========  ========================  ========================
parameter  filtered (default)        two_stage
=========  ========================  ========================
sigma_0    4/5, 11 %                 5/5, 35 %
sigma_1    5/5, 41 %                 2/2 closed (3/5 open)
sigma_2    4/5, 0.099 %              4/5, 0.58 %
tau_c      4/5, 0.044 %              4/5, 0.4 %
tau_s      3/5, 1.5 %                2/5, 8.1 %
w_s        3/5, 4.2 %                3/5, 19 %
delta      3/5, 2.9 %                4/5, 13 %
total      26/35                     24/32 closed
overlap    23/25 static intervals    19/25
slowest    5.46 s (2.54 s without    5.65 s
           the rate bias)
=========  ========================  ========================

Seeds 0-4 are unlucky for the filtered route: on seeds 10-59 it covered 336/350
(``python benchmarks/calib_trajectory.py --first 10 --seeds 50``), on seeds 10-49 270/280
with the Monte-Carlo spread of the static part within 5 % of the reported standard errors
(``benchmarks/calib_trajectory.py``).
"""

from __future__ import annotations

import argparse
import os
import time
import warnings
from dataclasses import replace

import numpy as np

from fricid.extract import extract
from fricid.identify import fit
from fricid.identify.dynamic.trajectory import fit_trajectory
from fricid.models import Stribeck, lugre
from fricid.sim import Joint, ModelLaw, preset, simulate
from fricid.sim import trajectory as tr

TRUTH = tr.LuGreTruth()
INERTIA = 0.01
JOINT = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=INERTIA)
#: LuGre's static part in the stribeck model's order and names
STATIC_NAMES = {
    "tau_c": "tau_c",
    "tau_s": "tau_s",
    "w_s": "w_s",
    "tau_v": "sigma_2",
    "delta": "delta",
}


def sweeps(seed: int, truth: tr.LuGreTruth):
    """The steady state swept on paper2's reduced design, fitted with stribeck."""
    scenario = preset("paper2", "reduced")
    p = truth.params()
    law = ModelLaw(
        Stribeck(), np.array([p["tau_c"], p["tau_s"], p["w_s"], p["sigma_2"], p["delta"]])
    )
    scenario = replace(scenario, joint=replace(scenario.joint, law=law))
    samples = extract(simulate(scenario, seed=seed), **scenario.extract_options()).samples
    return fit(samples, "stribeck", "lm", seed=seed)


def refine(routes: dict) -> float:
    """Seconds of the refinement regressions (the static part with LuGre's friction along the
    motion); the 'simulation' column is the last pass of the simulation route."""
    return sum(r["seconds"] for k, r in routes.items() if k.startswith("refinement"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--method", default="lm")
    ap.add_argument("--sigma1", type=float, default=float(TRUTH.theta[1]))
    ap.add_argument("--experiment", choices=("multisine", "slow_multisine"), default="multisine")
    ap.add_argument("--route", choices=("filtered", "two_stage", "joint"), default="filtered")
    args = ap.parse_args()
    theta = TRUTH.theta.copy()
    theta[1] = args.sigma1
    truth_model = tr.LuGreTruth(theta=theta)
    warnings.simplefilter("ignore")
    # compile the kernels first so no timing below includes numba's compilation
    fit_trajectory(
        tr.simulate_trajectory(tr.multisine(duration=4.0), TRUTH, JOINT), "lugre", route=args.route
    )
    truth = truth_model.params()
    rows, sweep0, traj0 = [], None, None
    cover = {n: 0 for n in truth}
    undetermined = {n: 0 for n in truth}
    for seed in range(args.seeds):
        log = tr.simulate_trajectory(
            getattr(tr, args.experiment)(duration=args.duration, seed=seed),
            truth_model,
            JOINT,
            seed=seed,
        )
        t0 = time.perf_counter()
        f = fit_trajectory(log, "lugre", args.method, seed=seed, route=args.route)
        seconds = time.perf_counter() - t0
        s = sweeps(seed, truth_model)
        for n, v in truth.items():
            p = f.parameters[n]
            if p.low_open or p.high_open:
                undetermined[n] += 1
            else:
                cover[n] += int(p.ci95[0] <= v <= p.ci95[1])
        overlap = {
            STATIC_NAMES[n]: bool(
                max(f.parameters[STATIC_NAMES[n]].ci95[0], s.parameters[n].ci95[0])
                <= min(f.parameters[STATIC_NAMES[n]].ci95[1], s.parameters[n].ci95[1])
            )
            for n in STATIC_NAMES
        }
        routes = f.provenance["trajectory"]["routes"]
        rb = f.provenance["trajectory"].get("rate_bias")
        rows.append((seed, len(log), seconds, routes, overlap, f.converged, rb))
        if seed == 0:
            sweep0, traj0 = s, f
    print(
        f"LuGre truth; {args.experiment} {args.duration:g} s at 1 kHz; route {args.route}; "
        f"method {args.method}; "
        f"{args.seeds} seeds; truth damping ratio sigma_1 / (2 sqrt(sigma_0 J)) = "
        f"{theta[1] / (2 * np.sqrt(theta[0] * INERTIA)):.2g}\n"
    )
    print(
        f"{'parameter':<9} {'truth':>9}  {'sweeps (seed 0) [95 % CI]':<32} "
        f"{'trajectory (seed 0) [95 % CI] half-width':<44} covered (closed CIs); not determined"
    )
    inverse = {v: k for k, v in STATIC_NAMES.items()}
    for n, v in truth.items():
        if n in inverse:
            k = inverse[n]
            q = sweep0.parameters[k]
            sw = f"{q.value:.4g} [{q.ci95[0]:.4g}, {q.ci95[1]:.4g}]"
        else:
            sw = "- (no effect at constant speed)"
        p = traj0.parameters[n]
        low, high = p.ci95
        width = (high - low) / 2 / abs(p.value)
        tj = f"{p.value:.4g} [{low:.4g}, {high:.4g}] {100 * width:.2g} %"
        if p.low_open or p.high_open:
            tj = f"not determined [{low:.4g}, {high:.4g}] open"
        closed = args.seeds - undetermined[n]
        print(
            f"{n:<9} {v:>9.4g}  {sw:<32} {tj:<44} {cover[n]}/{closed}; "
            f"{undetermined[n]}/{args.seeds}"
        )
    joint = traj0.provenance["trajectory"]["joint"]
    for n, v in (("inertia", 0.01), ("p_x", 0.3), ("p_y", 0.1)):
        r = joint[n]
        tj = f"{r['value']:.4g} [{r['ci95_low']:.4g}, {r['ci95_high']:.4g}]"
        print(f"{n:<9} {v:>9.4g}  {'-':<32} {tj}")
    main_route = "filtered" if args.route == "filtered" else "simulation"
    p = traj0.provenance["trajectory"]["passivity"]
    print(
        f"\npassivity (seed 0): margin {p['margin']:.3g}, passive {p['passive']}, "
        f"across the 95 % box {p['passive_across_ci95']}; truth margin "
        f"{float(lugre.passivity_margin(truth_model.theta)):.3g}"
    )
    print(
        f"\n{'seed':>4} {'samples':>8} {'time [s]':>9} {'regression':>11} {main_route:>11} "
        f"{'refinement':>11} {'rate bias':>10} {'s0, s1 [%]':>12} "
        f"{'converged':>9}  static intervals overlap the sweeps'"
    )
    for seed, n, seconds, routes, overlap, conv, rb in rows:
        ok = ", ".join(f"{k} {'yes' if v else 'NO'}" for k, v in overlap.items())
        bias = (
            f"{rb['seconds']:>10.2f} {100 * rb['sigma_0']['relative']:>+5.1f}, "
            f"{100 * rb['sigma_1']['relative']:>+5.0f}"
            if rb and "skipped" not in rb
            else f"{'-':>10} {'-':>12}"
        )
        print(
            f"{seed:>4} {n:>8} {seconds:>9.2f} {routes['regression']['seconds']:>11.2f} "
            f"{routes[main_route]['seconds']:>11.2f} {refine(routes):>11.2f} {bias} "
            f"{conv!s:>9}  {ok}"
        )
    worst = max(r[2] for r in rows)
    total = sum(cover.values())
    closed_all = args.seeds * len(truth) - sum(undetermined.values())
    print(
        f"\ncovered in all: {total}/{closed_all} closed intervals "
        f"({sum(undetermined.values())} not determined)"
    )
    print(
        f"\nslowest identification: {worst:.2f} s (target < 10 s for 60 s at 1 kHz with lm); "
        f"load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"
    )


if __name__ == "__main__":
    main()
