"""The integrator and timestep of an MJCF export, every cell of the ladder
(:mod:`fricid.export.mujoco_step`).

Usage: ``python benchmarks/bench_mujoco_step.py [MODEL.json ...] [--inertia J]
[--default-solimp]`` (needs ``mujoco``; a few seconds per model). ``--default-solimp``: a
static model's fragment also without the export's ``solimpfriction`` (MuJoCo's default), for
the comparison. Without a model file: the LuGre joint of
``tests/export/test_mujoco.py`` and the virtual joint's LuGre truth (``fricid simulate
--trajectory``), both at J = 0.01 kg m^2.

For each model: the break-away error and the held-out trajectory error (percent; against
MuJoCo's RK4 at 5e-5 s) of every integrator at every timestep, ``*`` where both criteria hold
(5 %, 1 % of the span), and the recommendation ``fricid export --to mjcf`` writes.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from fricid.export import mjcf_text
from fricid.export.mjcf import STIFF_SOLIMP
from fricid.export.mujoco_step import (
    BREAKAWAY_VELOCITY,
    INTEGRATORS,
    TIMESTEPS,
    check_timestep,
    model_inertia,
)
from fricid.fitted import FittedModel

BUILTIN = {
    "test joint (sigma_0 1e3, sigma_1 0.5)": dict(
        sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=2.0
    ),
    "virtual joint truth (sigma_0 1e4, sigma_1 1)": dict(
        sigma_0=1e4, sigma_1=1.0, sigma_2=0.2, tau_c=0.5, tau_s=0.8, w_s=0.1, delta=1.0
    ),
}


def table(name: str, fitted: FittedModel, inertia: float | None, default: bool = False) -> None:
    J, source = model_inertia(fitted, inertia)
    start = time.perf_counter()
    fragment = mjcf_text(fitted, max_loss=1.0)
    if default:  # MuJoCo's own solimpfriction
        fragment = fragment.replace(f' solimpfriction="{STIFF_SOLIMP}"', "")
        name += " (MuJoCo's default solimpfriction)"
    advice = check_timestep(fragment, J, every_step=True)
    advice = replace(advice, inertia_from=source)
    seconds = time.perf_counter() - start
    print(f"\n{name}: J {J:.4g} kg m^2 ({source}); every cell in {seconds:.2f} s")
    level = advice.static_level
    if level > 0:
        print(f"MuJoCo's reference breaks away at {advice.reference_breakaway / level:.3f} x the "
              f"exported static friction {level:.4g} N m (a joint that sticks exactly: "
              f"{1 + 0.5 * BREAKAWAY_VELOCITY**0.5:.3f}, the ramp's own overshoot)")  # fmt: skip
    print("break-away error % / trajectory error % of span; * both criteria hold")
    print(f"{'integrator':13s}" + "".join(f"{t:>17g}" for t in TIMESTEPS))
    for integrator in INTEGRATORS:
        row = sorted(
            (c for c in advice.cells if c.integrator == integrator), key=lambda c: -c.timestep
        )
        cells = "".join(
            f"{100 * c.breakaway_error:8.3g}/{100 * c.trajectory_error:<7.3g}"
            + ("*" if c.passed else " ")
            for c in row
        )
        print(f"{integrator:13s}{cells}")
    for line in advice.lines():
        print("  " + line)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", help="model files (default: two built-in joints)")
    parser.add_argument("--inertia", type=float, default=None)
    parser.add_argument("--default-solimp", action="store_true")
    args = parser.parse_args()
    if args.models:
        for path in args.models:
            if args.default_solimp:
                table(path, FittedModel.load(path), args.inertia, default=True)
            table(path, FittedModel.load(path), args.inertia)
        return
    for name, params in BUILTIN.items():
        fitted = FittedModel.from_values("lugre", params, operating_range={"velocity": [-2, 2]})
        table(name, fitted, args.inertia or 0.01)


if __name__ == "__main__":
    main()
