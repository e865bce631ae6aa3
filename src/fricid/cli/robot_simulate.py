"""``fricid robot simulate``: a whole arm's log from the truth simulator (fricid.sim.robot)."""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ._app import err_console, handle_errors, robot_app

#: Where the robot comes from, for --help.
_ROBOTS = "panda, ur5 or double_pendulum (the example-robot-data URDFs)"


def _model(robot: str | None, urdf: Path | None, joints: str | None):
    from ..errors import ConfigError
    from ..robot import RigidBodyModel, example_urdf

    if urdf is not None and robot is not None:
        raise ConfigError("give --robot or --urdf, not both")
    names = None if joints is None else [j.strip() for j in joints.split(",") if j.strip()]
    if urdf is None:
        path, default = example_urdf(robot or "panda")
        return RigidBodyModel.from_urdf(path, names or default)
    return RigidBodyModel.from_urdf(urdf, names)


def _reference(model, sweep: str | None, velocities: str, harmonics: int, base: float, seed: int):
    import numpy as np

    from ..errors import ConfigError
    from ..sim.robot_reference import random_fourier, sweep_reference

    if sweep is None:
        return random_fourier(model, harmonics=harmonics, base_frequency=base, seed=seed)
    if sweep not in model.joints:
        raise ConfigError(f"--sweep: no joint '{sweep}'; the model's: {', '.join(model.joints)}")
    try:
        speeds = [float(v) for v in velocities.split(",")]
    except ValueError:
        raise ConfigError(
            f"--velocities must be numbers separated by commas; got {velocities!r}"
        ) from None
    j = model.joints.index(sweep)
    bounded = np.isfinite(model.lower) & np.isfinite(model.upper)
    lo = np.where(bounded, model.lower, -1.0)
    hi = np.where(bounded, model.upper, 1.0)
    mid, half = 0.5 * (lo[j] + hi[j]), 0.4 * (hi[j] - lo[j])
    return sweep_reference(0.5 * (lo + hi), j, speeds, mid - half, mid + half)


def _duration(reference, duration: float | None) -> float:
    """The simulated time [s]: as given, else 60 s, or a sweep's whole length; a sweep cut
    short is warned of with the speeds it covers (the double pendulum's first joint's five
    default speeds take 129 s; 60 s held none of them both ways)."""
    from ..errors import ConfigError, DataQualityWarning
    from ..sim.robot_reference import SweepReference

    if not isinstance(reference, SweepReference):
        return 60.0 if duration is None else duration
    plan = reference.duration
    if duration is None:
        if plan > 3600:
            raise ConfigError(
                f"the sweeps take {plan:.0f} s, over the 3600 s a run may take; give fewer or "
                "faster --velocities"
            )
        return float(plan)
    if duration < plan:
        ended = {(round(abs(v), 9), v > 0) for _, t1, v in reference.plateaus if t1 <= duration}
        done = sorted(v for v, up in ended if up and (v, False) in ended)
        covered = (
            f"holds both directions of {', '.join(f'{v:g}' for v in done)} rad/s only"
            if done
            else "holds both directions of none of the speeds"
        )
        warnings.warn(
            f"--duration {duration:g} s cuts the sweeps short: they take {plan:.0f} s; the log "
            f"{covered} (leave --duration out to run them all)",
            DataQualityWarning,
            stacklevel=2,
        )
    return duration


def _truth_json(run, model) -> dict:
    from ..sim.robot import shared_model

    t = run.truth
    return {
        "joints": list(model.joints),
        "friction_model": shared_model(t.friction_models),
        "friction": t.friction_parameters,
        "friction_models": t.friction_models,
        "friction_smoothing_rad_s": None if t.friction is None else t.friction.smoothing,
        "inertial_parameter_names": list(model.parameter_names),
        "inertial_parameters": [float(x) for x in t.parameters],
        "torque_noise_std": run.log.meta["torque_noise"],
        "encoder_counts": run.log.meta["encoder_counts"],
        "integrator_step_s": t.step,
        "source": model.source,
    }


@robot_app.command("simulate")
@handle_errors
def robot_simulate_command(
    out: Annotated[
        Path, typer.Option("--out", "-o", help="The robot log: .parquet or .csv (all joints).")
    ] = Path("robot_log.parquet"),
    robot: Annotated[str | None, typer.Option(help=f"An example robot: {_ROBOTS}.")] = None,
    urdf: Annotated[Path | None, typer.Option(help="Your robot's URDF instead.")] = None,
    joints: Annotated[
        str | None, typer.Option(help="The joints to simulate, comma-separated (default all).")
    ] = None,
    duration: Annotated[
        float | None,
        typer.Option(
            help="[s]; default 60, or with --sweep the sweeps' own length (every speed, both "
            "directions)."
        ),
    ] = None,
    rate: Annotated[float, typer.Option(help="Samples and controller updates per second.")] = (
        1000.0
    ),
    seed: Annotated[int, typer.Option(help="Seed of the trajectory and the noise.")] = 0,
    encoder_counts: Annotated[int, typer.Option(help="Encoder counts per revolution.")] = 2**17,
    torque_noise: Annotated[
        float, typer.Option(help="Std of the logged torque's Gaussian noise [N m].")
    ] = 0.05,
    integrator_step: Annotated[
        float,
        typer.Option(
            help="Largest internal step of the simulation [s]; a light arm whose joints "
            "chatter at the default (a warning says so) needs a smaller one."
        ),
    ] = 5e-4,
    friction: Annotated[
        str,
        typer.Option(
            help="example: per-joint, per-direction Stribeck friction scaled to each joint's "
            "effort limit; none."
        ),
    ] = "example",
    controller: Annotated[str, typer.Option(help="pd or torque (computed torque).")] = "pd",
    feedforward: Annotated[
        bool, typer.Option(help="pd: add the model's inverse dynamics of the reference.")
    ] = True,
    harmonics: Annotated[int, typer.Option(help="Harmonics of the random Fourier reference.")] = 5,
    base_frequency: Annotated[float, typer.Option(help="Its base frequency [Hz].")] = 0.1,
    sweep: Annotated[
        str | None,
        typer.Option(
            help="Instead, constant-velocity sweeps of this joint over 80 % of its range, "
            "the others held at mid-range."
        ),
    ] = None,
    velocities: Annotated[str, typer.Option(help="--sweep: speeds [rad/s], comma-separated.")] = (
        "0.05,0.1,0.2,0.5,1.0"
    ),
    truth: Annotated[
        Path | None, typer.Option(help="Also write the truth (friction, inertia) as JSON.")
    ] = None,
    mjcf: Annotated[
        Path | None, typer.Option(help="Also write the simulated arm as MJCF (for MuJoCo).")
    ] = None,
    lugre: Annotated[
        str | None,
        typer.Option(
            help="Give this joint LuGre friction instead (the example law's positive "
            "direction as its steady state; bristles 0.1 mrad to break-away). The run takes "
            "steps small enough for the bristles' ringing: several times longer."
        ),
    ] = None,
) -> None:
    """Simulate a whole arm tracking a random Fourier reference (or one joint's constant-
    velocity sweeps) with each joint's friction, 2^17-count encoders and torque noise, and
    write the log of every joint: time, quantised position, velocity by backward differences,
    torque. The simulator integrates the rigid-body dynamics of the URDF (Pinocchio) itself
    (RK4 with the friction implicit, 0.5 ms steps; a --lugre joint takes steps small enough
    for its bristles' ringing, about ten times as many on the Panda's wrist) under a PD drive
    at --rate. The truth's
    friction parameters are in the log's metadata (fricid's stribeck_asym names)."""
    from ..errors import ConfigError
    from ..io import write_robot_log
    from ..io.atomic import atomic_write
    from ..sim.robot import run_robot
    from ..sim.robot_friction import example_friction
    from ..sim.robot_lugre import lugre_like

    if friction not in ("example", "none"):
        raise ConfigError(f"--friction must be example or none; got {friction!r}")
    if not (1e-7 <= integrator_step <= 0.01):
        raise ConfigError(f"--integrator-step must lie in [1e-7, 0.01] s; got {integrator_step!r}")
    if duration is not None and not (0 < duration <= 3600):
        raise ConfigError(f"--duration must lie in (0, 3600] s; got {duration!r}")
    if out.suffix.lower() not in (".csv", ".parquet", ".pq"):
        raise ConfigError(f"--out must end in .csv, .parquet or .pq; got '{out.name}'")
    model = _model(robot, urdf, joints)
    reference = _reference(model, sweep, velocities, harmonics, base_frequency, seed)
    duration = _duration(reference, duration)
    law = example_friction(model.effort_limit) if friction == "example" else None
    dynamic = None
    if lugre is not None:
        if lugre not in model.joints or law is None:
            raise ConfigError(
                f"--lugre: a joint of the model ({', '.join(model.joints)}) with --friction example"
            )
        j = model.joints.index(lugre)
        dynamic = {
            lugre: lugre_like(
                {k[:-4]: x for k, x in law.parameters(j).items() if k.endswith("_pos")}
            )
        }
    start, cpu = time.perf_counter(), time.process_time()
    run = run_robot(
        model,
        reference,
        law,
        rate=rate,
        duration=duration,
        controller=controller,
        feedforward=feedforward,
        encoder_counts=encoder_counts,
        torque_noise=torque_noise,
        seed=seed,
        integrator_step=integrator_step,
        lugre=dynamic,
    )
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    path = write_robot_log(run.log, out)
    written = [str(path)]
    if truth is not None:
        with atomic_write(truth, "w") as fh:
            json.dump(_truth_json(run, model), fh, indent=1)
        written.append(str(truth))
    if mjcf is not None:
        from ..export.robot_mjcf import write_robot_mjcf

        written.append(str(write_robot_mjcf(model, mjcf, run.truth.friction_parameters)[0]))
    err_console.print(
        f"simulated {model.n} joints, {len(run.log)} samples ({duration:g} s at {rate:g} Hz) "
        f"in {wall:.1f} s ({cpu:.1f} s CPU); wrote {escape(', '.join(written))}",
        highlight=False,
    )
