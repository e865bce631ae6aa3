"""The MJCF export in MuJoCo, and LuGre compensation (issue 16, "In a real simulator").

Usage: ``python benchmarks/bench_mujoco.py`` (needs ``mujoco``; about 30 s on 2 shared cores).

Table 1, MuJoCo trajectory error. One joint (J = 0.01 kg m^2, no gravity) at rest is driven
open loop by ``u = A sin(2 pi t)`` for 2 s, A above the break-away friction so it sticks and
slips at every reversal. The reference trajectory is the Python joint under the TRUE friction
(:func:`fricid.control.plant.drive`: Karnopp stick-slip for a static law, linearly implicit
LuGre) at a fine step (20 us). Each row is a MuJoCo model (:mod:`fricid.export.mujoco_check`)
stepped at 1 ms and 0.1 ms with the same torque, and its position error against the
reference: RMS and max [mrad], and RMS as a percentage of the reference's position span.
"Python joint" rows give the Python joint itself at that step (its own discretisation error:
the floor of the comparison). MuJoCo models:

* ``exported``: what ``fricid export --to mjcf`` writes for the true model (a static model:
  the ``frictionloss``/``damping`` projection; LuGre: the passive ``dcmotor`` with ``lugre``);
  ``+ solreffriction 2dt``: the same with the frictionloss constraint's time constant at two
  steps instead of MuJoCo's default 0.02 s;
* ``static fallback``: the LuGre export's ``frictionloss``/``damping`` for MuJoCo < 4.0;
* ``stiff LuGre``: a Stribeck law held as a dcmotor LuGre with stiff bristles (sigma_0
  1e4 N m/rad, sigma_1 at the passivity bound): a static law is LuGre's steady state, so this
  is the "true model" in MuJoCo for a Stribeck truth with exponent 2.

When the true model is what fricid exports exactly (Coulomb-viscous; LuGre with exponent 2),
the ``exported`` row is also the "true model" row.

Table 2, compensation at zero-velocity crossings (:mod:`fricid.control.dynamic`): the joint
of ``fricid compensate --truth lugre`` (LuGre truth) tracks 0.2 Hz for 2 periods under PD
control at 10 Hz bandwidth; PD only, static feed-forward (the model's steady state) and the
LuGre observer, with the model's bristle parameters right and off by 2x and 10x, and with
white noise on the measured velocity (D term and observer input; seed 0).

What it showed (mujoco 4.0.0, run on 2 shared cores):

* Coulomb-viscous, exported exactly: MuJoCo's default ``frictionloss`` softness costs 0.45 %
  of the position span (RMS) at 1 ms steps and 0.52 % at 0.1 ms (the joint creeps under
  torques below ``frictionloss``); with ``solreffriction`` at two steps MuJoCo is at the
  Python joint's own discretisation error (0.05 % against 0.09 % at 1 ms, 0.007 % at
  0.1 ms).
* Stribeck truth: the exported projection (``frictionloss``/``damping``) loses the break-away
  peak, 7.1 % of the span; the same law as a stiff-bristle dcmotor LuGre gives 3.3 % at 1 ms
  and 0.33 % at 0.1 ms.
* LuGre truth, exponent 2: the exported dcmotor is the true model: 1.1 % at 1 ms (the Python
  joint 1.3 %), 0.18 % at 0.1 ms (0.12 %); the static fallback for MuJoCo < 4.0, 4.9 %.
  Exponent 1 (w_s refit): 1.8 % and 0.73 %.
* Compensation: with the right bristles the LuGre observer's RMS error at the crossings is
  36x smaller than static feed-forward's (0.040 against 1.44 mrad); sigma_0 2x or 10x too
  high 5.3x and 4.1x, sigma_1 10x too low 18x; sigma_0 2x too LOW makes it slightly worse
  than static (1.51 against 1.44 mrad). Velocity noise of 0.01 rad/s leaves 5.5x; at
  0.05 rad/s the observer ties static feed-forward (1.37 against 1.36 mrad).
"""

from __future__ import annotations

import time

import numpy as np

from fricid.control import TrackingConfig, fitted_law
from fricid.control.dynamic import RUNS, LuGreTruth, lugre_compensation_study
from fricid.control.plant import drive
from fricid.export import mjcf_text
from fricid.export.mujoco_check import one_joint_xml, require_mujoco, run_torque
from fricid.fitted import FittedModel
from fricid.models import lugre

J = 0.01
SECONDS = 2.0
DT_REF = 2e-5
STEPS = (1e-3, 1e-4)
STATIC_RANGE = {"velocity": [0.01, 2.0], "load": [0, 0], "temperature": [25, 25]}
LUGRE = dict(sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=2.0)


def lugre_fit(**changes) -> FittedModel:
    return FittedModel.from_values(
        "lugre", {**LUGRE, **changes}, operating_range={"velocity": [-2.0, 2.0]}
    )


def theta_of(params: dict) -> np.ndarray:
    return np.array([params[k] for k in lugre.PARAM_NAMES])


def truths() -> list[tuple[str, float, dict, list[tuple[str, str, dict | None]]]]:
    """(name, torque amplitude, truth for ``drive``, [(row, fragment, joint overrides)])."""
    cv = FittedModel.from_values(
        "coulomb_viscous", {"f_c": 0.3, "beta": 0.1}, operating_range=STATIC_RANGE
    )
    st_params = {"tau_c": 0.3, "tau_s": 0.5, "w_s": 0.05, "tau_v": 0.1, "delta": 2.0}
    st = FittedModel.from_values("stribeck", st_params, operating_range=STATIC_RANGE)
    bound = 4 * 0.1 * 0.3 / (0.5 - 0.3)  # sigma_1 at the passivity bound
    stiff = lugre_fit(sigma_0=1e4, sigma_1=bound)
    out = []
    for name, amp, fitted, kwargs in (
        ("coulomb_viscous", 0.6, cv, {"law": fitted_law(cv)}),
        ("stribeck (delta 2)", 0.8, st, {"law": fitted_law(st)}),
    ):
        frag = mjcf_text(fitted, joint="j")
        rows = [("exported", frag, None), ("exported + solreffriction 2dt", frag, "2dt")]
        if name.startswith("stribeck"):
            rows.append(("stiff LuGre (dcmotor)", mjcf_text(stiff, joint="j"), None))
        out.append((name, amp, kwargs, rows))
    for delta in (2.0, 1.0):
        fitted = lugre_fit(delta=delta)
        frag = mjcf_text(fitted, joint="j", max_loss=1.0)
        fl, damping = _static_fallback(frag)
        fallback = f'<joint name="j" frictionloss="{fl}" damping="{damping}"/>'
        rows = [
            ("exported (dcmotor LuGre)", frag, None),
            ("static fallback", fallback, None),
            ("static fallback + solreffriction 2dt", fallback, "2dt"),
        ]
        theta = theta_of({**LUGRE, "delta": delta})
        out.append((f"LuGre (delta {delta:g})", 0.8, {"lugre_theta": theta}, rows))
    return out


def _static_fallback(fragment: str) -> tuple[str, str]:
    """The frictionloss and damping the LuGre export's comment gives for MuJoCo < 4.0."""
    line = next(x for x in fragment.splitlines() if "without dcmotor" in x)
    fl = line.split('frictionloss="')[1].split('"')[0]
    damping = line.split('damping="')[1].split('"')[0]
    return fl, damping


def table_mujoco() -> None:
    print("Table 1: MuJoCo trajectory error against the Python joint under the true friction")
    print(f"(open-loop torque A sin(2 pi t), {SECONDS:g} s, J {J} kg m^2; reference step 20 us)")
    head = (
        f"{'truth':20s} {'model':38s} {'dt':>7s} {'RMS mrad':>9s} {'max mrad':>9s} {'% span':>7s}"
    )
    print(head)
    print("-" * len(head))
    for name, amp, kwargs, rows in truths():
        n_ref = round(SECONDS / DT_REF)
        ref = drive(amp * np.sin(2 * np.pi * np.arange(n_ref) * DT_REF), DT_REF, J, **kwargs)
        span = np.ptp(ref["position"])
        for dt in STEPS:
            n = round(SECONDS / dt)
            t = np.arange(n) * dt
            u = amp * np.sin(2 * np.pi * t)
            q_ref = ref["position"][:: round(dt / DT_REF)][:n]
            runs = [("Python joint (same dt)", drive(u, dt, J, **kwargs)["position"])]
            for row, frag, override in rows:
                over = None if override is None else {"solreffriction": f"{2 * dt!r} 1"}
                xml = one_joint_xml(frag, J, dt, joint_overrides=over)
                runs.append((row, run_torque(xml, u)["position"]))
            for row, q in runs:
                err = q - q_ref
                rms = float(np.sqrt(np.mean(err**2)))
                print(
                    f"{name:20s} {row:38s} {dt:7.0e} {1e3 * rms:9.4g} "
                    f"{1e3 * np.abs(err).max():9.4g} {100 * rms / span:7.3g}"
                )
        print(f"{'':20s} (position span of the reference: {span:.4g} rad)")


def table_compensation() -> None:
    print()
    print("Table 2: tracking error [mrad] with a LuGre truth, PD only / static feed-forward /")
    print("LuGre observer (fricid compensate --truth lugre; 0.2 Hz, 2 periods, dt 0.2 ms;")
    print("crossings: within 0.05 periods of each velocity reversal)")
    truth = LuGreTruth(tuple(theta_of(LUGRE)), "lugre", J)
    config = TrackingConfig(amplitude=0.5 / (2 * np.pi * 0.2), frequency=0.2, periods=2.0)
    head = f"{'model bristles':28s} {'run':22s} {'RMS':>8s} {'max':>8s} {'RMS x':>8s} {'max x':>8s}"
    print(head)
    print("-" * len(head))
    for label, s0, s1, noise in (
        ("right (1e3, 0.5)", 1e3, 0.5, 0.0),
        ("sigma_0 x2 (2e3, 0.5)", 2e3, 0.5, 0.0),
        ("sigma_0 /2 (5e2, 0.5)", 5e2, 0.5, 0.0),
        ("sigma_0 x10 (1e4, 0.5)", 1e4, 0.5, 0.0),
        ("sigma_1 /10 (1e3, 0.05)", 1e3, 0.05, 0.0),
        ("right, v noise 0.01 rad/s", 1e3, 0.5, 0.01),
        ("right, v noise 0.05 rad/s", 1e3, 0.5, 0.05),
    ):
        theta = theta_of({**LUGRE, "sigma_0": s0, "sigma_1": s1})
        start = time.perf_counter()
        r = lugre_compensation_study(theta, config, truth=truth, velocity_noise=noise, seed=0)
        took = time.perf_counter() - start
        for name in RUNS:
            print(
                f"{label:28s} {name:22s} {1e3 * r.rms[name]:8.4g} {1e3 * r.max[name]:8.4g} "
                f"{1e3 * r.rms_crossing[name]:8.4g} {1e3 * r.max_crossing[name]:8.4g}"
            )
        print(f"{'':28s} {r.verdict()} [{took:.1f} s]")


if __name__ == "__main__":
    mujoco = require_mujoco()
    print(f"mujoco {mujoco.__version__}; the machine is shared (timings are noisy)")
    table_mujoco()
    table_compensation()
