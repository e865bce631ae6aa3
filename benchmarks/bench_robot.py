"""Whole-arm identification of a simulated 7-joint Panda: the "done when" table.

Usage::

    python benchmarks/bench_robot.py [--seeds 10] [--first 0] [--duration 60] [--rate 1000]
        [--noise 0.05] [--friction stribeck_asym] [--trajectory FILE]
        [--truth own|pd|sim|mujoco] [--window 1.0] [--detect] [--jobs 2] [--cache DIR]
        [--rows FILE]

Per seed: each joint gets its own friction law per direction (``stribeck_asym``: Coulomb,
static, Stribeck velocity and exponent, viscous drawn independently per joint and direction;
``coulomb_viscous_load_asym``: Coulomb friction growing with the joint's load, BAS-RBFNN paper
eq. 3 as ``msk_asym`` without a Stribeck rise, the load the arm's gravity torque, ``--truth
own`` and ``pd`` only; a joint that carries no load, the Panda's vertical first axis, has no
load coefficient to cover),
the arm follows a multi-sine (or the designed trajectory of ``--trajectory``: ``fricid robot
design --csv``'s table, or a CSV with a ``time`` column and one position column per joint,
named as the URDF's joints), its torque is the inverse dynamics plus friction plus Gaussian
noise (``--noise`` N m at the log's rate), the position is quantised to 2^17 counts per
revolution. The held-out log follows a second multi-sine (another seed's phases), so that with
``--trajectory`` the design is identified and a motion it was not designed for is predicted.
:func:`fit_arm` identifies the whole arm; the table gives per joint the friction parameters'
mean relative error and their 95 % intervals' coverage (over seeds, per parameter kind), the
held-out torque error over the estimated noise, and the base inertial parameters' coverage
and the seconds of the identification.

Truth: ``--truth own`` is the tests' generator (``tests/identify/dynamic/_arm_truth.py``: the
arm follows the reference exactly, an open-loop measurement); ``--truth pd`` is its
closed-loop variant (``make_pd_log``: a 10 Hz PD, gains for the least inertia each joint meets
with the others free, on the quantised position with the inverse
dynamics as feed-forward, the arm integrated semi-implicitly at 4 kHz, friction not
compensated, an optional torque ``--disturbance``). ``--truth sim`` is fricid's whole-arm
simulator (:func:`fricid.sim.robot.run_robot`: its own split RK4 integrator of the arm, each
joint's law with the sign smoothed over 1 mrad/s, a ``--bandwidth`` Hz PD on the quantised
position with the inverse dynamics of the reference as feed-forward, the logged velocity the
raw backward difference, the torque the command plus noise), at internal steps of
``--integrator-step`` (default :data:`SIM_STEP`, 0.125 ms: at its default 0.5 ms the
Stribeck slopes of these laws over the wrist's small inertias, about 1000 per second, were not
resolved: noiseless, with the true parameters, the filtered residual of joints 5 to 7 was
0.009-0.037 N m at 0.5 ms, 0.002-0.007 at 0.125 ms and 0.001-0.007 at 0.05 ms, seed 100, 12 s,
measured while the simulator's friction step was first order); it takes ``stribeck_asym`` laws
(``coulomb_viscous_asym`` is given to it as a law without a Stribeck rise); ``--truth
mujoco`` is the same drive with MuJoCo stepping the exported MJCF
(``benchmarks/_robot_truth.py``, ``implicitfast`` at ``--integrator-step``, its
``solreffriction`` at two steps as the export writes it): MuJoCo holds a Coulomb-viscous law
alike in both directions (``frictionloss``, ``damping``: each joint's mean levels of the drawn
law), which is the truth compared against. The closed-loop truths are fitted with
``reversal_window=WINDOW_PERIODS`` (rows near reversals left out; ``--window`` another), the
open-loop one with 0; with ``--detect`` every truth is fitted with ``reversal_window=None``,
fit_arm deciding from the residuals, and the table says on which seeds it found a closed loop.

``--cache DIR`` keeps each simulated log (``.npz``: time, position, velocity, torque, named by
the settings and the seed) and reads it back on a later run with the same settings, so that
fits are compared on the same logs without simulating them again (at its 0.125 ms step,
fricid's simulator takes far longer than the fit; the names do not say which version of the
simulator made a log: empty the folder after changing it); ``--rows FILE`` writes every seed's
parameters (error, coverage, z), held-out ratios and windows as JSON lines.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "identify" / "dynamic"))
import _arm_truth as truth  # noqa: E402

from fricid.identify.dynamic.arm import WINDOW_PERIODS, fit_arm  # noqa: E402
from fricid.robot import RigidBodyModel, base_parameters, example_urdf  # noqa: E402
from fricid.samples import RobotLog  # noqa: E402
from fricid.sim.robot import run_robot  # noqa: E402
from fricid.sim.robot_friction import FRICTION_NAMES, ArmFriction  # noqa: E402

#: ``--truth sim``'s internal step [s]: the simulator's default 0.5 ms is too coarse for these
#: laws on the Panda's wrist (module notes).
SIM_STEP = 1.25e-4

KINDS = ("tau_c", "tau_s", "w_s", "tau_v", "delta", "f_ck", "f_c", "beta")


def _trajectory(path: Path, model: RigidBodyModel):
    """(t, q, dq, ddq) of a trajectory table: fricid's (``fricid robot design --csv``: ``time
    [s]``, ``<joint>.position [rad]``, velocity, acceleration) or a plain one (``time`` and a
    position column per joint, differentiated here)."""
    table = pd.read_csv(path, comment="#")
    cols = {c.split(" [")[0]: c for c in table.columns}
    missing = [c for c in ("time", *model.joints) if c not in cols and f"{c}.position" not in cols]
    if missing:
        raise SystemExit(f"{path}: no column(s) {', '.join(missing)}")

    def column(joint, kind):
        return table[cols[joint if joint in cols else f"{joint}.{kind}"]].to_numpy(float)

    t = table[cols["time"]].to_numpy(float)
    q = np.column_stack([column(j, "position") for j in model.joints])
    dt = float(np.median(np.diff(t)))
    if all(f"{j}.acceleration" in cols for j in model.joints):
        dq = np.column_stack([column(j, "velocity") for j in model.joints])
        ddq = np.column_stack([column(j, "acceleration") for j in model.joints])
    else:
        dq = np.gradient(q, dt, axis=0)
        ddq = np.gradient(dq, dt, axis=0)
    return t, q, dq, ddq


def _laws(model, seed, friction):
    rng = np.random.default_rng(10_000 + seed)
    if friction == "stribeck_asym":
        return [truth.stribeck_law(rng) for _ in model.joints]
    if friction == "coulomb_viscous_load_asym":  # msk_asym of the arm's gravity torque
        return [truth.load_law(rng) for _ in model.joints]
    return [
        (
            "coulomb_viscous_asym",
            {
                "f_c_pos": rng.uniform(0.3, 1.0),
                "beta_pos": rng.uniform(0.1, 0.6),
                "f_c_neg": rng.uniform(0.3, 1.0),
                "beta_neg": rng.uniform(0.1, 0.6),
            },
        )
        for _ in model.joints
    ]


def _mujoco_laws(model, laws):
    """The law MuJoCo simulates for ``laws`` (``frictionloss`` and ``damping``: each joint's
    mean Coulomb and viscous levels, both directions alike) as ``coulomb_viscous_asym``."""
    from _robot_truth import mujoco_friction

    law = mujoco_friction(model, _arm_friction(laws))
    out = []
    for j in range(model.n):
        f_c, beta = float(law.pos["tau_c"][j]), float(law.pos["tau_v"][j])
        values = {f"{k}{d}": v for d in ("_pos", "_neg") for k, v in (("f_c", f_c), ("beta", beta))}
        out.append(("coulomb_viscous_asym", values))
    return out


def _direction(values: dict, d: str) -> dict:
    """One direction's law in the simulator's names (Coulomb-viscous: no Stribeck rise)."""
    if "f_c" + d in values:
        f_c = values["f_c" + d]
        return {"tau_c": f_c, "tau_s": f_c, "w_s": 1.0, "tau_v": values["beta" + d], "delta": 1.0}
    return {k: values[k + d] for k in FRICTION_NAMES}


def _arm_friction(laws) -> ArmFriction:
    """The simulator's law of every joint's ``laws``."""
    sides = []
    for d in ("_pos", "_neg"):
        rows = [_direction(values, d) for _, values in laws]
        sides.append({k: np.array([r[k] for r in rows]) for k in FRICTION_NAMES})
    return ArmFriction(*sides)


def _sim_log(model, laws, seed, args, trajectory):
    t, q, dq, ddq = trajectory
    rate = 1.0 / float(np.median(np.diff(t)))
    simulate = run_robot
    options = {"integrator_step": args.integrator_step}
    if args.truth == "mujoco":  # MuJoCo on the exported MJCF
        from _robot_truth import simulate_robot_mujoco as simulate
    run = simulate(
        model,
        lambda _t: (q, dq, ddq),
        _arm_friction(laws),
        rate=rate,
        duration=len(t) / rate,
        controller="pd",
        feedforward=True,
        bandwidth=args.bandwidth,
        torque_noise=args.noise,
        seed=seed + 20_000,
        **options,
    )
    return run.log


def _logs(model, laws, seed, args, trajectory):
    """The identification log and the held-out one: along a second multi-sine (another seed;
    with ``--trajectory``, the multi-sine of this seed: the design is identified, a motion it
    was not designed for is predicted)."""
    first = trajectory or truth.reference(model, args.duration, args.rate, seed)
    second = truth.reference(model, args.duration, args.rate, seed + 5_000)
    if args.truth in ("sim", "mujoco"):
        return (
            _sim_log(model, laws, seed, args, first),
            _sim_log(model, laws, seed + 5_000, args, second),
        )
    kw = {"duration": args.duration, "rate": args.rate, "noise": args.noise}
    make = truth.make_log
    if args.truth == "pd":
        make = truth.make_pd_log
        kw["disturbance"] = args.disturbance
        kw["inertia"] = "free"  # the Panda's joints 1 and 3 align (make_pd_log's notes)
    one = make(model, laws, seed=seed, trajectory=first, **kw)
    two = make(model, laws, seed=seed + 5_000, trajectory=second, **kw)
    return one, two


def _cached_logs(model, laws, seed, args, trajectory):
    """:func:`_logs`, kept in ``--cache`` (one ``.npz`` per log: time, position, velocity,
    torque) and read from there when a run with the same settings made them."""
    if args.cache is None:
        return _logs(model, laws, seed, args, trajectory)
    key = "-".join(
        str(x)
        for x in (
            args.robot,
            args.truth,
            args.friction,
            args.trajectory.stem if args.trajectory else "multisine",
            args.duration,
            args.rate,
            args.noise,
            args.bandwidth,
            args.integrator_step,
            args.disturbance,
            seed,
        )
    )
    paths = [args.cache / f"{key}-{k}.npz" for k in ("fit", "held")]
    if all(p.exists() for p in paths):
        out = []
        for p in paths:
            with np.load(p) as z:
                out.append(
                    RobotLog(
                        z["time"],
                        model.joints,
                        z["position"],
                        z["velocity"],
                        z["torque"],
                        source=p.name,
                    )
                )
        return tuple(out)
    logs = _logs(model, laws, seed, args, trajectory)
    args.cache.mkdir(parents=True, exist_ok=True)
    for p, log in zip(paths, logs, strict=True):
        sel = log.select(model.joints)
        np.savez(
            p, time=sel.time, position=sel.position, velocity=sel.velocity, torque=sel.motor_torque
        )
    return logs


def _seed(args, seed: int) -> dict:
    """One seed's identification: per joint and parameter the relative error and whether the
    interval covers the truth, the held-out ratio and verdict, the base coverage, the seconds."""
    path, joints = example_urdf(args.robot)
    model = RigidBodyModel.from_urdf(path, joints)
    beta_true = base_parameters(model).project(model.parameters())
    trajectory = _trajectory(args.trajectory, model) if args.trajectory else None
    laws = _laws(model, seed, args.friction)
    if args.truth == "mujoco":
        laws = _mujoco_laws(model, laws)
    log, held = _cached_logs(model, laws, seed, args, trajectory)
    start = time.perf_counter()
    window = args.window if args.truth != "own" else 0.0  # closed loop
    if args.detect:  # fricid decides from the residuals near the reversals
        window = None
    fit = fit_arm(log, model, friction=args.friction, validate=held, reversal_window=window)
    out = {"seconds": time.perf_counter() - start, "params": [], "joints": {}}
    out["closed_loop"] = fit.provenance.get("closed_loop") or "given"
    for joint, (_, values) in zip(fit.joints, laws, strict=True):
        for name, rec in fit.friction[joint]["parameters"].items():
            kind = next(k for k in KINDS if name.startswith(k))
            if "carries no load" in rec["note"]:  # no load, no effect: nothing to cover
                continue
            t = values[name]
            if rec["value"] is None:
                out["params"].append((joint, kind, None, False, float("nan"), name))
                continue
            lo, hi = rec["ci95"]
            z = (rec["value"] - t) / ((hi - lo) / 3.92) if hi > lo else float("nan")
            out["params"].append(
                (joint, kind, abs(rec["value"] - t) / abs(t), lo <= t <= hi, z, name)
            )
        window = fit.provenance.get("windows", {}).get(joint, window)
        out["joints"][joint] = (
            fit.validation[joint]["ratio"],
            fit.validation[joint]["level"],
            window,
        )
    limit = model.effort_limit
    out["overload"] = [
        kind
        for kind, lg in (("fit", log), ("held-out", held))
        if np.any(np.abs(lg.select(model.joints).motor_torque) > limit)
    ]
    ci = fit.base["ci95"]
    out["base"] = float(
        np.mean(
            [lo is not None and lo <= b <= hi for b, (lo, hi) in zip(beta_true, ci, strict=True)]
        )
    )
    print(f"seed {seed}: {out['seconds']:.1f} s", file=sys.stderr, flush=True)
    return out


def run(args) -> None:
    path, joints = example_urdf(args.robot)
    model = RigidBodyModel.from_urdf(path, joints)
    seeds = range(args.first, args.first + args.seeds)
    if args.from_rows:  # saved runs (--rows), printed together: no identification
        saved = [json.loads(line) for path in args.from_rows for line in path.open()]
        saved = list({r["seed"]: r for r in saved}.values())  # one row per seed
        seeds = [r.pop("seed") for r in saved]
        results = saved
        args.seeds, args.first = len(seeds), min(seeds)
    elif args.jobs > 1:  # one process per seed: the seeds are independent
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(args.jobs) as pool:
            results = list(pool.map(_seed, [args] * len(seeds), seeds))
    else:
        results = [_seed(args, seed) for seed in seeds]
    if args.rows and not args.from_rows:  # every seed's rows, for a closer look
        with args.rows.open("w") as f:
            for seed, res in zip(seeds, results, strict=True):
                f.write(json.dumps({"seed": seed, **res}, default=lambda o: o.item()) + "\n")
    rel = defaultdict(list)  # (joint, kind) -> relative errors
    cov = defaultdict(list)  # (joint, kind) -> covered
    ratio, levels, zs, windows = (defaultdict(list) for _ in range(4))
    for res in results:
        for joint, kind, err, covered, z, _ in res["params"]:
            if err is not None:
                rel[joint, kind].append(err)
            cov[joint, kind].append(covered)
            zs[joint].append(z)
        for joint, (r, level, w) in res["joints"].items():
            ratio[joint].append(r)
            levels[joint].append(level)
            windows[joint].append(w)
    base_cov = [res["base"] for res in results]
    seconds = [res["seconds"] for res in results]
    kinds = [k for k in KINDS if any((j, k) in cov for j in model.joints)]
    print(
        f"{args.robot}, {args.seeds} seeds"
        + (f" from {args.first}" if args.first else "")
        + f", {args.duration:g} s at {args.rate:g} Hz, 2^17 "
        f"counts, noise {args.noise:g} N m, friction {args.friction}, truth {args.truth}"
        + (f", trajectory {args.trajectory.name}" if args.trajectory else ", multi-sine")
    )
    head = " ".join(f"{k + ' err/cov':>17}" for k in kinds)
    print(
        f"{'joint':<14}{head} {'joint cov':>10} {'rms z':>6} {'window':>7} "
        f"{'held-out/noise (median)':>24} "
        f"{'verdicts (yes/cav/no)':>22}"
    )
    all_cov = []
    for joint in model.joints:
        cells, joint_cov = [], []
        for k in kinds:
            r, c = rel[joint, k], cov[joint, k]
            joint_cov += c
            if not c:  # nothing to cover (a load coefficient of a joint without load)
                cells.append(f"{'-':>8} {'-':>6}   ")
                continue
            cells.append(f"{100 * np.median(r):7.2f}% {100 * np.mean(c):5.0f}%   ")
        all_cov += joint_cov
        lv = levels[joint]
        counts = f"{lv.count('yes')}/{lv.count('with caveats')}/{lv.count('no')}"
        print(
            f"{joint:<14}{' '.join(cells)} {100 * np.mean(joint_cov):9.1f}% "
            f"{np.sqrt(np.nanmean(np.square(zs[joint]))):6.2f} {np.median(windows[joint]):7.2f} "
            f"{np.mean(ratio[joint]):15.2f} ({np.median(ratio[joint]):5.2f}) {counts:>22}"
        )
    print(
        "friction intervals' coverage over all joints and parameters: "
        f"{100 * np.mean(all_cov):.1f} % (a parameter not determined counts as a miss)"
    )
    params = [p for res in results for p in res["params"]]
    claims = [covered for _, _, err, covered, _, _ in params if err is not None]
    print(
        f"of the intervals given: {sum(claims)} of {len(claims)} cover the truth "
        f"({100 * np.mean(claims):.1f} %); {len(params) - len(claims)} parameters not determined"
    )
    print(f"base inertial parameters' coverage: {100 * np.mean(base_cov):.1f} % (mean over seeds)")
    print(f"seconds per identification: median {np.median(seconds):.1f}, max {np.max(seconds):.1f}")
    if args.detect:
        found = [
            s
            for s, res in zip(seeds, results, strict=True)
            if res["closed_loop"].startswith("detected")
        ]
        print(f"closed loop detected (--detect): {len(found)} of {len(results)} seeds {found}")
    over = [f"{s} {k}" for s, res in zip(seeds, results, strict=True) for k in res["overload"]]
    print(
        "logs whose torque exceeds the URDF's effort limits (a drive cannot give it: the truth's "
        f"controller unstable there): {', '.join(over) or 'none'}"
    )
    print(
        "(err: median relative error over seeds; cov: 95 % intervals covering the truth; "
        "joint cov: all the joint's parameters; rms z: of (estimate - truth) / (half-width / "
        "1.96), 1 where the intervals are calibrated; window: the median over seeds of the joint's "
        "reversal window, periods of the cut-off; held-out/noise: the mean over seeds and the "
        "median)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--first", type=int, default=0, help="the first seed")
    parser.add_argument("--robot", default="panda", help="an example robot (panda, ur5, ...)")
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--noise", type=float, default=0.05)
    parser.add_argument(
        "--friction",
        choices=("stribeck_asym", "coulomb_viscous_asym", "coulomb_viscous_load_asym"),
        default="stribeck_asym",
    )
    parser.add_argument("--trajectory", type=Path, default=None)
    parser.add_argument("--truth", choices=("own", "pd", "sim", "mujoco"), default="own")
    parser.add_argument(
        "--disturbance", type=float, default=0.0, help="--truth pd: torque disturbance [N m]"
    )
    parser.add_argument(
        "--bandwidth", type=float, default=5.0, help="--truth sim: the PD's bandwidth [Hz]"
    )
    parser.add_argument(
        "--integrator-step",
        type=float,
        default=SIM_STEP,
        help="--truth sim: the simulator's largest internal step [s]",
    )
    parser.add_argument(
        "--window",
        type=float,
        default=WINDOW_PERIODS,
        help="closed-loop truths: fit_arm's reversal_window [periods of the cut-off]",
    )
    parser.add_argument(
        "--detect",
        action="store_true",
        help="let fit_arm decide closed loop or not from the residuals (reversal_window=None)",
    )
    parser.add_argument(
        "--jobs", type=int, default=1, help="seeds identified at once (one process each)"
    )
    parser.add_argument(
        "--cache",
        type=Path,
        default=None,
        help="keep the simulated logs here and reuse them (fits compared on the same logs)",
    )
    parser.add_argument("--rows", type=Path, default=None, help="every seed's rows (JSON lines)")
    parser.add_argument(
        "--from-rows",
        type=Path,
        nargs="+",
        default=None,
        help="print the table of saved --rows files (their seeds together) instead of running; "
        "give the settings they ran with",
    )
    args = parser.parse_args()
    if args.friction == "coulomb_viscous_load_asym" and args.truth in ("sim", "mujoco"):
        parser.error("the load law is simulated by --truth own and pd only")
    run(args)


if __name__ == "__main__":
    main()
