"""The whole-arm fit's signals (``fricid.identify.dynamic.arm._signals``) on motions a drive
in closed loop makes: broadband torque, joints that stop, a torque held between samples."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from fricid.identify.dynamic.arm import _moving, _torque_delay
from fricid.identify.dynamic.arm._friction import JointFriction, friction_for
from fricid.identify.dynamic.arm._signals import prepare_signals
from fricid.robot import RigidBodyModel, base_parameters, example_urdf

RATE = 1000.0
CUTOFF = 6.0


def _motion(t: np.ndarray, jitter: float = 0.0):
    """(q, dq, ddq) of both joints: slow sines, plus (``jitter`` rad/s^2) an 8 Hz and a 11 Hz
    acceleration, the band just above the cut-off that a PD on a quantised position fills."""
    w = 2 * np.pi * np.array([[0.3, 0.7], [0.45, 0.9]])
    q = np.column_stack([np.sin(w[j, 0] * t) + 0.3 * np.sin(w[j, 1] * t) for j in range(2)])
    dq = np.column_stack(
        [w[j, 0] * np.cos(w[j, 0] * t) + 0.3 * w[j, 1] * np.cos(w[j, 1] * t) for j in range(2)]
    )
    ddq = np.column_stack(
        [
            -(w[j, 0] ** 2) * np.sin(w[j, 0] * t) - 0.3 * w[j, 1] ** 2 * np.sin(w[j, 1] * t)
            for j in range(2)
        ]
    )
    for f in (8.0, 11.0):
        wf = 2 * np.pi * f
        q += jitter / wf**2 * -np.sin(wf * t)[:, None]
        dq += jitter / wf * -np.cos(wf * t)[:, None]
        ddq += jitter * np.sin(wf * t)[:, None]
    return q, dq, ddq


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))


def test_torque_and_states_pass_the_same_low_pass(pendulum):
    """Torque the arm follows in the band just above the cut-off is filtered as its motion
    is: with the true parameters, nothing of that band is left in the residual."""
    t = np.arange(int(8 * RATE)) / RATE
    q, dq, ddq = _motion(t, jitter=20.0)
    tau = pendulum.inverse_dynamics(q, dq, ddq)
    sig = prepare_signals(t, q, tau, counts=2**30, cutoff=CUTOFF)
    bp = base_parameters(pendulum)
    res = sig.tau - sig.regressor(pendulum, bp) @ bp.project(pendulum.parameters())
    q0, dq0, ddq0 = _motion(t)
    band = tau - pendulum.inverse_dynamics(q0, dq0, ddq0)  # the fast part of the torque
    assert _rms(res) < 0.2 * _rms(sig.parallel(band))  # 0.09 here; 0.91 filtered twice


def test_friction_columns_follow_a_joint_that_stops(pendulum):
    """A joint that stops for a while (as one sticks in closed loop): the friction columns,
    through the torque's filter, are the filtered friction of the true motion on the rows the
    fit keeps, to a small share of the Coulomb level."""
    t = np.arange(int(12 * RATE)) / RATE
    v = np.clip(0.6 + 0.8 * np.sin(2 * np.pi * 0.4 * t), 0.0, None)  # dwells at zero
    q = np.column_stack([np.cumsum(v) / RATE, 0.2 * np.sin(2 * np.pi * 0.3 * t)])
    dq = np.column_stack([v, 0.2 * 2 * np.pi * 0.3 * np.cos(2 * np.pi * 0.3 * t)])
    jf = JointFriction("coulomb_viscous")
    theta = np.array([1.0, 0.2])  # f_c, beta
    friction = jf.columns(dq[:, 0]) @ theta
    sig = prepare_signals(
        t, q, np.column_stack([friction, 0 * t]), counts=2**30, cutoff=CUTOFF, stops=True
    )
    moving = _moving(sig, 1.0)[:, 0]
    assert 0.2 < moving.mean() < 0.9
    model = sig.parallel(jf.columns(sig.full_dq[:, 0])) @ theta
    # 2e-4 of the Coulomb level here; 7e-3 with the columns of the low-passed velocity
    assert _rms((sig.tau[:, 0] - model)[moving]) < 2e-3 * theta[0]


@pytest.mark.parametrize("delay", [0.0, 0.5])
def test_a_torque_held_between_samples_is_half_a_period_late(pendulum, delay):
    """A command held from one sample to the next acts half a period after its sample: the
    delay is estimated (and a torque at the sample instants has none)."""
    t = np.arange(int(8 * RATE)) / RATE
    q = _motion(t)[0]
    # the torque of the motion half a period after each sample, logged at the sample
    tau = pendulum.inverse_dynamics(*_motion(t + delay / RATE))
    sig = prepare_signals(t, q, tau, counts=2**30, cutoff=CUTOFF)
    bp = base_parameters(pendulum)
    frictions = friction_for(pendulum.joints, "coulomb_viscous")
    est = _torque_delay(sig, sig.regressor(pendulum, bp), frictions, _moving(sig))
    assert est == pytest.approx(delay, abs=0.02)
    res = sig.delayed(est).tau - sig.regressor(pendulum, bp) @ bp.project(pendulum.parameters())
    assert _rms(res) < 1e-3 * _rms(sig.tau)


def test_a_stribeck_excess_below_zero_gains_nothing_in_the_shape_search():
    """The Stribeck rise is a static level above the Coulomb one (``tau_s >= tau_c``): a shape
    whose best excess is negative (a dip the data's other errors may ask for, which then
    extrapolates wildly where the fit had no rows) explains nothing."""
    from fricid.identify.dynamic.arm._solve import _projector

    rng = np.random.default_rng(1)
    A = rng.normal(size=(200, 4))
    x = np.exp(-np.linspace(0, 5, 200))  # a candidate Stribeck column
    y = A @ np.array([1.0, -2.0, 0.5, 3.0]) - 0.8 * x + 0.01 * rng.normal(size=200)
    gain = _projector(np.column_stack([A, x]), y, 4, np.arange(200))
    dip, rise = gain(np.column_stack([x, -x]))
    assert dip == 0.0
    assert rise > 0.0


def test_a_stribeck_shape_the_data_do_not_see_gets_a_wide_profile_region(pendulum):
    """Joints that never slow below 0.5 rad/s cannot show a Stribeck rise of 0.05 rad/s: the
    profile region of the shape spans the grid's small Stribeck velocities, where the
    linearised interval alone would say nothing of it."""
    from fricid.identify.dynamic.arm._solve import W_S_GRID, shape_profiles, stack, wls

    t = np.arange(int(8 * RATE)) / RATE
    w = 2 * np.pi * 0.5
    q = np.column_stack([0.8 * t + 0.1 * np.sin(w * t), 0.6 * t + 0.1 * np.cos(w * t)])
    dq = np.column_stack([0.8 + 0.1 * w * np.cos(w * t), 0.6 - 0.1 * w * np.sin(w * t)])
    ddq = np.column_stack([-0.1 * w**2 * np.sin(w * t), -0.1 * w**2 * np.cos(w * t)])
    rise = 0.5 * np.exp(-dq / 0.05)  # nil at these speeds
    tau = pendulum.inverse_dynamics(q, dq, ddq) + 0.4 + 0.2 * dq + rise
    tau += np.random.default_rng(2).normal(0.0, 0.05, tau.shape)
    sig = prepare_signals(t, q, tau, counts=2**17, cutoff=CUTOFF)
    bp = base_parameters(pendulum)
    frictions = friction_for(pendulum.joints, "stribeck_asym")
    Yb = sig.regressor(pendulum, bp)
    moving = _moving(sig)
    _, sigma = wls(stack(Yb, sig, frictions, moving), 2)
    profiles = shape_profiles(sig, Yb, frictions, moving, sigma, np.ones(2))
    for j in range(2):
        region = profiles[j, "_pos"]
        assert region["w_s"][0] == W_S_GRID.min()
        assert region["w_s"][1] >= 0.05


@pytest.mark.slow  # 2.1 s, quiet machine (default run kept short)
def test_the_regressor_goes_through_the_torques_filter_on_a_closed_loop_arm():
    """A PD-tracked Panda whose joints stop at their reversals (fricid's simulator, no torque
    noise): with the true parameters and the true friction, the regressor filtered as the
    torque leaves a small share of the filtered noise on the big joints; the regressor at the
    low-passed states left 1.1-2.7 times it (the mass matrix times accelerations that jump
    where a joint stops or breaks away)."""
    from dataclasses import replace

    from _arm_truth import reference

    from fricid.sim.robot import run_robot
    from fricid.sim.robot_friction import ArmFriction

    path, joints = example_urdf("panda")
    panda = RigidBodyModel.from_urdf(path, joints)
    _, q, dq, ddq = reference(panda, 6.0, RATE, 4)
    ones = np.ones(panda.n)
    side = {"tau_c": 0.6 * ones, "tau_s": 0.6 * ones, "w_s": ones, "tau_v": 0.3 * ones}
    side["delta"] = ones
    run = run_robot(
        panda,
        lambda _t: (q, dq, ddq),
        ArmFriction(side, dict(side)),
        rate=RATE,
        duration=6.0,
        feedforward=True,
        torque_noise=0.0,
        integrator_step=2.5e-4,
    )
    log = run.log
    sig = prepare_signals(
        log.time, log.position, log.torque, counts=2**17, cutoff=CUTOFF, stops=True
    )
    sig = sig.delayed(0.5)  # the held command
    keep = _moving(sig, 1.0)
    bp = base_parameters(panda)
    beta = bp.project(panda.parameters())
    friction = sig.parallel(run.truth.friction_torque)
    white = sig.parallel(np.random.default_rng(0).normal(0.0, 0.05, (len(log.time), 1)))
    noise = float(np.std(white))  # 0.05 N m of white torque noise, filtered

    def ratios(s):
        res = s.tau - s.regressor(panda, bp) @ beta - friction
        return np.array([_rms(res[keep[:, j], j]) for j in range(4)]) / noise

    assert np.all(ratios(sig) < 0.6)  # 0.23-0.36 here
    assert np.all(ratios(replace(sig, wide_position=None)) > 1.0)  # the old way: 1.5-2.7


def test_the_covariance_matches_the_spread_of_the_estimates_over_the_noise(pendulum):
    """The same arm, motion and true friction shapes, 16 draws of white torque noise: the
    estimates scatter about the truth as their standard errors say (z-scores of spread 1),
    and their 95 % intervals cover it at the rate they claim."""
    from dataclasses import replace

    from _arm_truth import make_log

    from fricid.identify.dynamic.arm._filter_cov import filter_correlation
    from fricid.identify.dynamic.arm._solve import arm_covariance, stack, wls

    rng = np.random.default_rng(3)
    laws = []
    for _ in pendulum.joints:
        values = {}
        for d in ("_pos", "_neg"):
            values |= {f"f_c{d}": rng.uniform(0.3, 1.0), f"beta{d}": rng.uniform(0.1, 0.6)}
        laws.append(("coulomb_viscous_asym", values))
    log = make_log(pendulum, laws, duration=20.0, seed=7, noise=0.0)
    clean = prepare_signals(log.time, log.position, log.torque, counts=2**17, inertia=np.ones(2))
    bp = base_parameters(pendulum)
    Yb = clean.regressor(pendulum, bp)
    moving = _moving(clean)
    frictions = friction_for(pendulum.joints, "coulomb_viscous_asym")
    truth = np.concatenate(
        [bp.project(pendulum.parameters())]
        + [[v[k + d] for d in ("_pos", "_neg") for k in ("f_c", "beta")] for _, v in laws]
    )
    rho = filter_correlation(clean)
    z, covered = [], []
    for draw in range(16):
        noise = np.random.default_rng(draw).normal(0.0, 0.02, log.torque.shape)
        sig = replace(clean, tau=clean.tau + clean.parallel(noise))
        st = stack(Yb, sig, frictions, moving)
        theta, sigma = wls(st, 2)
        A, y = st.weighted(sigma)
        _, se, t, *_ = arm_covariance(A, y - A @ theta, st, 2, rho)
        z.append((theta - truth) / se)
        covered.append(np.abs(z[-1]) <= t)
    # the spread's median over 14 parameters varies by about 0.06 over 16 draws
    spread = np.nanmedian(np.nanstd(np.array(z), axis=0))
    assert 0.85 < spread < 1.15, spread  # 0.87 here; Newey-West's alone, 1.16
    assert 0.9 <= np.nanmean(covered) <= 0.99  # 0.94; Newey-West's, 0.897
