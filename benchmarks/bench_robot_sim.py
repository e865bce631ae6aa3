"""The whole-arm truth simulator: its cost, its discretisation error, and MuJoCo beside it.

Usage: ``python benchmarks/bench_robot_sim.py [--duration 60] [--convergence 3]`` (needs
``pin`` and ``mujoco``; about a minute on 2 shared cores).

Table 1, cost. The Panda of example-robot-data (7 joints) tracks a random Fourier reference
(:func:`fricid.sim.robot_reference.random_fourier`, seed 0, 5 harmonics of 0.1 Hz within half
its position and speed limits) under the PD drive with feed-forward at 1 kHz, each joint with
the example friction (:func:`fricid.sim.robot_friction.example_friction`), 2^17-count
encoders, 0.05 N m torque noise; ``duration`` seconds of log. Rows: fricid's integrator at its
default 0.5 ms step (and with LuGre friction on joint 7), and MuJoCo stepping the exported MJCF
(``benchmarks/_robot_truth.py``, 0.5 ms, ``implicitfast``). CPU seconds are the process's
own (what the run costs on an idle core); wall seconds depend on the machine's load.

Table 2, discretisation error. The same run for ``convergence`` seconds at internal steps of
1, 0.5 and 0.25 ms against 0.1 ms (encoders of 2^40 counts, so that the quantiser does not
amplify rounding differences): the largest position difference [mrad] and the RMS and largest
command differences [N m] (to compare with the 0.05 N m torque noise).

What it showed (``benchmarks/results/robot_sim.txt``; pin 4.1.0, mujoco 4.0.0, 2 cores shared
with other work): 60 s of the Panda cost 13.9 s of CPU with fricid's integrator, 132.9 s with
LuGre on joint 7 (its bristles need 40 us steps: :func:`fricid.sim.robot_lugre.bristle_step`;
21.1 s at the 0.5 ms it took before), and 2.2 s with MuJoCo; the default 0.5 ms step is within
0.5 mrad and 0.002 N m RMS (0.010 N m at most) of 0.1 ms steps, and 0.25 ms within 0.06 mrad
and 0.0004 N m RMS. Table 3 is why LuGre joints take smaller steps: at 0.5 ms the double
pendulum's LuGre joint slid at 0.02-0.04 rad/s against a fifth of the friction it has at 6.25 us
steps; at 25 us within 3 %.

Table 3, a LuGre joint's friction at low speed against the step (``--bristles`` seconds of
the double pendulum, the step rule switched off).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _robot_truth import simulate_robot_mujoco
from fricid.robot import RigidBodyModel, example_urdf
from fricid.sim.robot import run_robot
from fricid.sim.robot_friction import example_friction
from fricid.sim.robot_lugre import lugre_like
from fricid.sim.robot_reference import FourierTrajectory, random_fourier


def _timed(fn, *args, **kwargs):
    cpu, wall = time.process_time(), time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.process_time() - cpu, time.perf_counter() - wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--convergence", type=float, default=3.0)
    parser.add_argument("--bristles", type=float, default=5.0, help="Table 3's seconds")
    args = parser.parse_args()
    path, joints = example_urdf("panda")
    model = RigidBodyModel.from_urdf(path, joints)
    friction = example_friction(model.effort_limit)
    ref = random_fourier(model, seed=0)
    common = {"duration": args.duration, "seed": 1, "feedforward": True}
    pos7 = {k[:-4]: x for k, x in friction.parameters(6).items() if k.endswith("_pos")}
    print(f"Table 1: {args.duration:g} s of the Panda at 1 kHz")
    print(f"{'plant':<34} {'CPU [s]':>8} {'wall [s]':>9} {'max |q - q_ref| [rad]':>22}")
    rows = (
        ("fricid, 0.5 ms", run_robot, {}),
        ("fricid, LuGre joint 7 (its step)", run_robot, {"lugre": {joints[6]: lugre_like(pos7)}}),
        ("MuJoCo (exported MJCF), 0.5 ms", simulate_robot_mujoco, {}),
    )
    for name, fn, extra in rows:
        run, cpu, wall = _timed(fn, model, ref, friction, **common, **extra)
        err = np.abs(run.truth.position - run.truth.reference[0]).max()
        print(f"{name:<34} {cpu:8.1f} {wall:9.1f} {err:22.4f}  step {1e6 * run.truth.step:.3g} us")
    print(f"\nTable 2: discretisation error over {args.convergence:g} s, against 0.1 ms steps")
    runs = {
        h: run_robot(
            model,
            ref,
            friction,
            duration=args.convergence,
            seed=1,
            feedforward=True,
            integrator_step=h,
            encoder_counts=2**40,
        ).truth
        for h in (1e-3, 5e-4, 2.5e-4, 1e-4)
    }
    fine = runs[1e-4]
    print(f"{'step [ms]':>9} {'max dq [mrad]':>14} {'RMS du [N m]':>13} {'max du [N m]':>13}")
    for h, t in runs.items():
        if h == 1e-4:
            continue
        dq = 1e3 * np.abs(t.position - fine.position).max()
        du = t.torque - fine.torque
        print(f"{1e3 * h:9.2f} {dq:14.3f} {np.sqrt(np.mean(du**2)):13.4f} {np.abs(du).max():13.4f}")
    _bristles(args.bristles)


def _bristles(duration: float) -> None:
    """Table 3: a LuGre joint's friction at low speed against the internal step, the step
    rule (:func:`fricid.sim.robot_lugre.bristle_step`) switched off to show why it exists."""
    import fricid.sim.robot as sim_robot

    path, joints = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, joints)
    joints = model.joints
    friction = example_friction([87.0, 12.0])
    pos = {k[:-4]: x for k, x in friction.parameters(1).items() if k.endswith("_pos")}
    law = lugre_like(pos)
    rng = np.random.default_rng(0)
    lo, hi = np.where(np.isfinite(model.lower), model.lower, -1.0), model.upper
    hi = np.where(np.isfinite(hi), hi, 1.0)
    a, b = rng.uniform(-0.5, 0.5, (2, model.n, 4))
    ref = FourierTrajectory(model.joints, 2 * np.pi * 0.2, 0.5 * (lo + hi), a, b)
    m = 1.0 / np.diagonal(
        np.linalg.inv(model.mass_matrix(ref.evaluate(np.linspace(0, 5, 26))[0])), axis1=1, axis2=2
    ).min(axis=0)
    omega = float(np.sqrt(law["sigma_0"] / m[1]))
    bins = ((0.005, 0.02), (0.02, 0.04), (0.04, 0.08), (0.08, 0.15), (0.3, 0.6))
    print(
        f"\nTable 3: the double pendulum's joint 2 with LuGre (sigma_0 {law['sigma_0']:.4g} "
        "N m/rad, "
        f"least inertia {m[1]:.3g} kg m^2, omega {omega:.0f} rad/s), {duration:g} s at 1 kHz, "
        "PD with feed-forward, 2^20 counts; mean friction [N m] of the samples in each speed band"
    )
    print(f"{'step [us]':>9} {'omega h':>8} " + " ".join(f"{f'{x}-{y}':>11}" for x, y in bins))
    rule = sim_robot.bristle_step
    sim_robot.bristle_step = lambda *_: 1.0  # the rule off (a 1 s step: never the least)
    try:
        for h in (5e-4, 1.25e-4, 5e-5, 2.5e-5, 6.25e-6):
            t = run_robot(
                model,
                ref,
                friction,
                duration=duration,
                feedforward=True,
                seed=0,
                encoder_counts=2**20,
                integrator_step=h,
                lugre={joints[1]: law},
            ).truth
            v, f = t.velocity[:, 1], t.friction_torque[:, 1]
            band = [np.mean(np.sign(v) * f, where=(abs(v) >= x) & (abs(v) < y)) for x, y in bins]
            print(f"{1e6 * h:9.2f} {omega * h:8.3f} " + " ".join(f"{x:11.4f}" for x in band))
    finally:
        sim_robot.bristle_step = rule
    print(f"(the rule's step here: {1e6 * rule(_bristles_of(joints, law), m):.3g} us)")


def _bristles_of(joints, law):
    from fricid.sim.robot_lugre import LuGreBristles

    return LuGreBristles(joints, {joints[1]: law})


if __name__ == "__main__":
    main()
