"""Sweeps on arms: each joint's friction from constant-velocity sweeps with coupled gravity.

Two arms, simulated by the sweep generator of the tests (``tests/_arm_sweeps.py``: inverse
dynamics of the example-robot-data URDF plus per-direction Coulomb-viscous friction plus
noise; each speed swept with the other joints in another pose), identified with a model
whose bodies are 10-20 % off:

- the double pendulum (noise 0.01 N m),
- three joints of the Panda (2, 4, 6; the others locked at 0; noise 0.05 N m).

Printed per joint: the RMS error of the per-direction friction samples [N m] by the arm path
(gravity from the whole configuration, base gravity parameters identified), by the URDF's
masses (not identified), by the single-joint path (eq. 7 of the BAS-RBFNN paper, joint fit),
the RMS friction and the RMS standard error of the arm path; then, over ``--seeds`` seeds,
the share of 95 % intervals (+-1.96 standard errors) that hold the truth, for the set-point
frictions and the base gravity parameters; and each joint's per-direction Coulomb-viscous law
fitted to its extracted samples (``coulomb_viscous_asym``): per parameter the median relative
error and the share of 95 % intervals that hold the truth; then that law held out on a second
campaign (another seed, every other joint 0.3 rad from the first campaign's poses: a second
trajectory): the RMS over its set-points of (law - set-point friction) / the set-point's
standard error (the mean torque's noise there; 1 where the law predicts within the noise),
the mean and the largest over seeds; ``z``, the same RMS over the set-point's standard error
and the law's own (its parameters' covariance, the shared gravity error included) in
quadrature, the mean over seeds (1 where the intervals are right: the law fitted on one
campaign carries an error of about the set-point's size, so ``held-out/se`` is above 1 even for
a calibrated fit); ``torque``, the held-out campaign's torque at its set-point speeds
predicted by the first campaign's model (its gravity parameters and the law), RMS error over
the torque noise, the largest over seeds (the issue's "held-out torque error / noise");
``PI95``, the share of the held-out campaign's set-point frictions, measured with the true
gravity (a new sample: the truth plus its noise), inside the law's 95 % prediction interval
(:meth:`fricid.fitted.FittedModel.predict_interval`, the shared gravity error included); and
the seconds of one identification (extraction with the base gravity parameters, then the
law); then, per joint, the trust verdicts (:func:`fricid.identify.trust.assess_trust`) over
the seeds on that law (right) and on a symmetric ``coulomb_viscous`` one (wrong: the truth
differs between the directions).

Run: ``python benchmarks/bench_arm_sweeps.py [--seeds 20] [--per-joint-files]``
(``--per-joint-files``: each joint's sweeps a recording of its own, joined, as ``fricid robot
extract`` reads one file per joint).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.ndimage import minimum_filter1d

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from _arm_sweeps import Law, arm_sweeps, perturbed
from fricid.extract import extract, extract_arm
from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.robot import RigidBodyModel, base_parameters, example_urdf
from fricid.samples import join_robot_logs

PANDA = ("panda_joint2", "panda_joint4", "panda_joint6")


def pendulum():
    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    laws = {"joint1": Law(0.10, 0.08, 0.05, 0.04), "joint2": Law(0.06, 0.07, 0.03, 0.035)}
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    poses = {
        "joint1": [np.array([0.0, q]) for q in (-0.9, 0.0, 0.9)],
        "joint2": [np.array([q, 0.0]) for q in (-0.9, 0.0, 0.9)],
    }
    return "double pendulum", truth, laws, spans, poses, {"noise": 0.01, "rate": 100.0}


def panda():
    path, _ = example_urdf("panda")
    truth = RigidBodyModel.from_urdf(path, PANDA)
    laws = {
        PANDA[0]: Law(1.0, 0.8, 0.5, 0.4),
        PANDA[1]: Law(0.6, 0.7, 0.3, 0.35),
        PANDA[2]: Law(0.3, 0.25, 0.1, 0.12),
    }
    spans = {PANDA[0]: (-1.2, 1.2), PANDA[1]: (-2.8, -0.4), PANDA[2]: (0.3, 3.3)}
    poses = {
        PANDA[0]: [np.array([0.0, a, b]) for a, b in ((-2.2, 1.0), (-1.6, 1.8), (-1.0, 2.6))],
        PANDA[1]: [np.array([a, 0.0, b]) for a, b in ((-0.6, 1.0), (0.0, 1.8), (0.6, 2.6))],
        PANDA[2]: [np.array([a, b, 0.0]) for a, b in ((-0.6, -2.2), (0.0, -1.6), (0.6, -1.0))],
    }
    return "Panda joints 2, 4, 6", truth, laws, spans, poses, {"noise": 0.05, "rate": 100.0}


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


#: ``--per-joint-files``: each joint's sweeps simulated as a recording of its own (its own
#: noise) and the recordings joined (:func:`fricid.samples.join_robot_logs`), as
#: ``fricid robot extract`` reads one file per joint.
PER_JOINT_FILES = False


def _campaign(truth, spans, poses, laws, seed: int, options):
    """The sweeps of ``spans``: one log, or one recording per joint joined
    (:data:`PER_JOINT_FILES`)."""
    if not PER_JOINT_FILES:
        return arm_sweeps(truth, spans, poses, laws, seed=seed, **options)
    files = [
        replace(
            arm_sweeps(truth, {j: span}, poses, laws, seed=10_000 * (k + 1) + seed, **options),
            source=f"{j}.csv",
        )
        for k, (j, span) in enumerate(spans.items())
    ]
    return join_robot_logs(files)


def errors(case, seed: int):
    """One seed: per joint (arm, URDF, eq. 7, friction, se) RMS, and the z-scores."""
    _, truth, laws, spans, poses, options = case
    ident = perturbed(truth, np.random.default_rng(100 + seed))
    log = _campaign(truth, spans, poses, laws, seed, options)
    start = time.perf_counter()
    res = extract_arm(log, ident)  # timed with the laws below: the identification
    seconds = time.perf_counter() - start
    urdf = extract_arm(log, ident, identify=False)
    rows = {}
    for joint, law in laws.items():
        bd = res[joint].by_direction
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            e7 = extract(log.joint(joint), gravity="joint").by_direction
        se = [lv["friction_se"] for lv in res.gravity.joint_levels(joint)]
        rows[joint] = (
            rms(bd.friction - law(bd.velocity)),
            rms(urdf[joint].by_direction.friction - law(bd.velocity)),
            rms(e7.friction - law(e7.velocity)),
            rms(law(bd.velocity)),
            rms(se),
        )
    g = res.gravity
    start = time.perf_counter()
    params, fitted = {}, {}
    for joint, law in laws.items():
        params[joint], fitted[joint] = law_fit(res[joint].by_direction, law)
    params["seconds"] = seconds + time.perf_counter() - start
    for joint in laws:  # the trust verdict on the right law and on a wrong (symmetric) one
        samples = res[joint].by_direction
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            wrong = fit(samples, "coulomb_viscous")
            params[joint]["verdict"] = (
                assess_trust(fitted[joint], samples).level,
                assess_trust(wrong, samples).level,
            )
    shifted = {j: [p + 0.3 for p in ps] for j, ps in poses.items()}
    held_log = _campaign(truth, spans, shifted, laws, seed + 1000, options)
    held = extract_arm(held_log, ident)
    truly = extract_arm(held_log, truth, identify=False)
    base = base_parameters(ident, gravity_only=True)
    for joint in laws:
        params[joint]["held-out torque"] = torque_ratio(
            held_log, ident, base, res.gravity.beta, joint, fitted[joint], options["noise"]
        )
        levels = held.gravity.joint_levels(joint)
        v = np.array([lv["velocity"] for lv in levels])
        err = fitted[joint].predict_point(v) - [lv["friction"] for lv in levels]
        se = np.array([lv["friction_se"] for lv in levels])
        params[joint]["held-out"] = rms(err / se)
        params[joint]["held-out z"] = rms(err / np.hypot(se, prediction_se(fitted[joint], v)))
        # a new measured sample: the held-out campaign's set-points with the true gravity
        new = truly[joint].by_direction
        band = fitted[joint].predict_interval(new.X, warn=False)
        inside = (band.low <= new.friction) & (new.friction <= band.high)
        params[joint]["interval"] = (int(inside.sum()), int(inside.size))
    beta_true = base_parameters(ident, gravity_only=True).project(truth.parameters())
    z_levels = [
        (lv["friction"] - laws[lv["joint"]](lv["velocity"])) / lv["friction_se"] for lv in g.levels
    ]
    return rows, np.abs(z_levels), np.abs((g.beta - beta_true) / g.beta_se), params


#: The per-direction Coulomb-viscous law's parameters and the truth's fields.
LAW_PARAMS = {"f_c_pos": "fc_pos", "beta_pos": "fv_pos", "f_c_neg": "fc_neg", "beta_neg": "fv_neg"}


def law_fit(samples, law):
    """The joint's ``coulomb_viscous_asym`` fit to its extracted samples: each parameter's
    relative error and whether its 95 % interval holds the truth; and the fitted model."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(samples, "coulomb_viscous_asym")
    out = {}
    for name, field in LAW_PARAMS.items():
        p, truth = fitted.parameters[name], getattr(law, field)
        out[name] = (p.value / truth - 1.0, bool(p.ci95[0] <= truth <= p.ci95[1]))
    return out, fitted


def torque_ratio(log, model, base, beta, joint, law, noise: float) -> float:
    """The held-out campaign's torque on ``joint`` at its set-point speeds (measured speed
    within 2 % of one for 0.1 s either side: not on a ramp), predicted by the first
    campaign's model (gravity ``w(q) . beta`` plus the fitted law): RMS error over the torque
    noise."""
    j = model.joints.index(joint)
    v = log.velocity[:, j]
    near = np.zeros(v.size, dtype=bool)
    for speed in (0.2, 0.4, 0.8):
        near |= np.abs(np.abs(v) - speed) <= 0.02 * speed
    half = max(1, round(0.1 / float(np.median(np.diff(log.time)))))
    steady = minimum_filter1d(near.astype(np.uint8), 2 * half + 1).astype(bool)
    q = log.position[steady]
    gravity = base.columns(model.gravity_regressor(q))[:, j, :] @ beta
    error = log.torque[steady, j] - gravity - law.predict_point(v[steady])
    return rms(error) / noise


def prediction_se(fitted, v: np.ndarray) -> np.ndarray:
    """N m, the standard error of the fitted ``coulomb_viscous_asym`` law at speeds ``v``
    (its parameters' covariance, the shared gravity error included, through the law's
    gradient: ``(1, v)`` on the positive side, ``(-1, v)`` on the negative)."""
    names = list(LAW_PARAMS)
    se = np.array([fitted.parameters[n].stderr for n in names])
    free = [n for n, p in fitted.parameters.items() if not p.fixed]
    order = [free.index(n) for n in names]
    cov = np.asarray(fitted.correlation)[np.ix_(order, order)] * np.outer(se, se)
    grad = np.zeros((v.size, 4))
    pos = v > 0
    grad[pos, 0], grad[pos, 1] = 1.0, v[pos]
    grad[~pos, 2], grad[~pos, 3] = -1.0, v[~pos]
    return np.sqrt(np.einsum("ij,jk,ik->i", grad, cov, grad))


def law_table(per_seed: list[dict]) -> None:
    """Per joint and parameter: the median relative error and the intervals' coverage; the
    held-out ratio's mean and largest; the seconds."""
    head = " ".join(f"{n + ' err/cov':>19s}" for n in LAW_PARAMS)
    print(f"{'joint':14s} {head} {'held-out/se (max)':>18s} {'z':>5s} {'torque':>7s} {'PI95':>6s}")
    for joint in (j for j in per_seed[0] if j != "seconds"):
        cells = []
        for name in LAW_PARAMS:
            err = [abs(s[joint][name][0]) for s in per_seed]
            cov = [s[joint][name][1] for s in per_seed]
            cells.append(f"{100 * np.median(err):9.2f}% {100 * np.mean(cov):7.1f}%")
        held = [s[joint]["held-out"] for s in per_seed]
        cells.append(f"{np.mean(held):10.2f} ({np.max(held):5.2f})")
        z = np.mean([s[joint]["held-out z"] for s in per_seed])
        torque = np.max([s[joint]["held-out torque"] for s in per_seed])
        inside = np.sum([s[joint]["interval"] for s in per_seed], axis=0)
        print(
            f"{joint:14s} "
            + " ".join(f"{c:>19s}" for c in cells)
            + f" {z:5.2f} {torque:7.4f} {100 * inside[0] / inside[1]:5.1f}%"
        )
    levels = ("yes", "with caveats", "no")
    for k, which in enumerate(("coulomb_viscous_asym (right)", "coulomb_viscous (wrong)")):
        for joint in (j for j in per_seed[0] if j != "seconds"):
            got = [s[joint]["verdict"][k] for s in per_seed]
            counts = "/".join(str(got.count(lv)) for lv in levels)
            print(f"trust verdict yes/with caveats/no, {which}, {joint}: {counts}")
    sec = [s["seconds"] for s in per_seed]
    print(f"seconds per identification: median {np.median(sec):.2f}, max {np.max(sec):.2f}")


def simulated() -> None:
    """The whole-arm simulator's campaign: per joint the arm path's and eq. 7's RMS error."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "extract"))
    from test_extract_arm_sim import _campaign, _friction

    t0 = time.perf_counter()
    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    log = _campaign(truth)
    pi = truth.parameters().reshape(2, 10)
    ident = truth.with_parameters((pi * np.array([1.15, 0.85])[:, None]).ravel())
    res = extract_arm(log, ident)
    urdf = extract_arm(log, ident, identify=False)
    print("\ndouble pendulum on fricid.sim.robot (N m RMS over the per-direction samples)")
    print(f"{'joint':14s} {'arm':>8s} {'URDF':>8s} {'eq. 7':>8s} {'friction':>9s} {'se':>8s}")
    for j, joint in enumerate(truth.joints):
        bd = res[joint].by_direction
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            e7 = extract(log.joint(joint), gravity="joint").by_direction
        ub = urdf[joint].by_direction
        row = (
            rms(bd.friction - _friction(j, bd.velocity)),
            rms(ub.friction - _friction(j, ub.velocity)),
            rms(e7.friction - _friction(j, e7.velocity)),
            rms(_friction(j, bd.velocity)),
            rms([lv["friction_se"] for lv in res.gravity.joint_levels(joint)]),
        )
        print(f"{joint:14s} " + " ".join(f"{x:8.4f}" for x in row))
    print(f"{time.perf_counter() - t0:.0f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument(
        "--per-joint-files",
        action="store_true",
        help="each joint's sweeps a recording of its own, joined (PER_JOINT_FILES); the "
        "whole-arm simulator's campaign is skipped",
    )
    args = parser.parse_args()
    global PER_JOINT_FILES
    PER_JOINT_FILES = args.per_joint_files
    for make in (pendulum, panda):
        case = make()
        t0 = time.perf_counter()
        rows, _, _, _ = errors(case, 0)
        print(f"\n{case[0]} (seed 0; N m RMS over the per-direction samples)")
        print(f"{'joint':14s} {'arm':>8s} {'URDF':>8s} {'eq. 7':>8s} {'friction':>9s} {'se':>8s}")
        for joint, r in rows.items():
            print(f"{joint:14s} " + " ".join(f"{x:8.4f}" for x in r))
        zl, zb, laws = [], [], []
        for seed in range(args.seeds):
            _, a, b, params = errors(case, seed)
            zl.extend(a)
            zb.extend(b[np.isfinite(b)])
            laws.append(params)
        zl, zb = np.array(zl), np.array(zb)
        print(
            f"95 % interval coverage over {args.seeds} seeds: set-point frictions "
            f"{np.mean(zl < 1.96):.3f} ({zl.size}), base gravity parameters "
            f"{np.mean(zb < 1.96):.3f} ({zb.size}); {time.perf_counter() - t0:.0f} s"
        )
        print(f"each joint's coulomb_viscous_asym fit to its samples, over {args.seeds} seeds:")
        law_table(laws)
    if not PER_JOINT_FILES:
        simulated()


if __name__ == "__main__":
    main()
