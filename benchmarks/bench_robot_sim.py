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
with a whole-arm benchmark): 60 s of the Panda cost 16.9 s of CPU (24.2 s wall) with fricid's
integrator, 21.1 s with LuGre on joint 7, and 4.1 s with MuJoCo (4.1 times MuJoCo's cost, as
the 10.0 against 2.4 s of an earlier run on a quieter machine with the first-order friction
step: the theta-method costs the same); the default 0.5 ms step is within 0.5 mrad and
0.002 N m RMS (0.010 N m at most) of 0.1 ms steps, and 0.25 ms within 0.06 mrad and
0.0004 N m RMS (with the first-order friction step: 0.16 mrad and 0.0007 N m).
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
from fricid.sim.robot_reference import random_fourier


def _timed(fn, *args, **kwargs):
    cpu, wall = time.process_time(), time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.process_time() - cpu, time.perf_counter() - wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--convergence", type=float, default=3.0)
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
        ("fricid, 0.5 ms, LuGre joint 7", run_robot, {"lugre": {joints[6]: lugre_like(pos7)}}),
        ("MuJoCo (exported MJCF), 0.5 ms", simulate_robot_mujoco, {}),
    )
    for name, fn, extra in rows:
        run, cpu, wall = _timed(fn, model, ref, friction, **common, **extra)
        err = np.abs(run.truth.position - run.truth.reference[0]).max()
        print(f"{name:<34} {cpu:8.1f} {wall:9.1f} {err:22.4f}")
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


if __name__ == "__main__":
    main()
