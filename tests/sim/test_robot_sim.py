"""The whole-arm truth simulator (fricid.sim.robot): integrator, drive, sensors, friction."""

from __future__ import annotations

import math
import warnings
from functools import cache

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from fricid.errors import ConfigError
from fricid.models import get_model
from fricid.robot import RigidBodyModel, example_urdf
from fricid.sim.robot import _pin_calls, default_gains, quantise, run_robot, simulate_robot
from fricid.sim.robot_drive import STABLE_DAMPING
from fricid.sim.robot_friction import ArmFriction, example_friction
from fricid.sim.robot_reference import FourierTrajectory, random_fourier, sweep_reference


@cache
def arm(name: str) -> RigidBodyModel:
    path, joints = example_urdf(name)
    return RigidBodyModel.from_urdf(path, joints)


def fourier(model: RigidBodyModel, seed: int = 0, amplitude: float = 0.25) -> FourierTrajectory:
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(model.lower), model.lower, -1.0)
    hi = np.where(np.isfinite(model.upper), model.upper, 1.0)
    q0 = 0.5 * (lo + hi)
    a, b = rng.uniform(-amplitude, amplitude, (2, model.n, 4))
    return FourierTrajectory(model.joints, 2 * math.pi * 0.2, q0, a, b)


def energy(model: RigidBodyModel, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    import pinocchio as pin

    kinetic = 0.5 * np.einsum("ni,nij,nj->n", v, model.mass_matrix(q), v)
    potential = np.array([pin.computePotentialEnergy(model._model, model._data, x) for x in q])
    return kinetic, kinetic + potential


def test_energy_kept_without_friction_and_control():
    model = arm("double_pendulum")
    ref = FourierTrajectory(model.joints, 1.0, [1.2, -0.7], np.zeros((2, 1)), np.zeros((2, 1)))
    truth = run_robot(model, ref, None, controller="none", duration=2.0, torque_noise=0).truth
    kinetic, total = energy(model, truth.position, truth.velocity)
    assert kinetic.max() > 1.0  # it really swings
    assert np.ptp(total) / kinetic.max() < 1e-4
    assert not np.any(truth.torque)


def test_fast_pinocchio_calls_match_the_model():
    model = arm("panda")
    aba, minv = _pin_calls(model)
    rng = np.random.default_rng(3)
    q, v, u = rng.normal(size=(3, 7))
    assert np.allclose(aba(q, v, u), model.forward_dynamics(q, v, u)[0], rtol=1e-10, atol=1e-9)
    assert np.allclose(minv(q) @ model.mass_matrix(q)[0], np.eye(7), atol=1e-9)


def test_pd_loop_tracks_the_reference():
    model = arm("panda")
    ref = fourier(model)
    fb = run_robot(model, ref, None, duration=1.0, feedforward=True, torque_noise=0).truth
    assert np.abs(fb.position - fb.reference[0]).max() < 1e-3
    friction = example_friction(model.effort_limit)
    pd = run_robot(model, ref, friction, duration=1.0, feedforward=True).truth
    # friction is not fed forward: it stays as an error of about friction / Kp
    assert np.abs(pd.position - pd.reference[0]).max() < 0.05
    ct = run_robot(model, ref, None, duration=1.0, controller="torque").truth
    assert np.abs(ct.position - ct.reference[0]).max() < 1e-3


def test_encoder_quantises_and_velocity_is_a_backward_difference():
    model = arm("double_pendulum")
    counts = 2**12
    log = simulate_robot(model, fourier(model), None, duration=0.5, encoder_counts=counts, seed=1)
    steps = np.diff(log.position, axis=0) / (2 * math.pi / counts)
    assert np.allclose(steps, np.round(steps), atol=1e-6)
    assert (np.abs(np.round(steps)) == 1).any() and (steps == 0).any()
    assert np.allclose(log.position, quantise(log.position, counts), atol=0)
    assert np.allclose(log.velocity[1:], np.diff(log.position, axis=0) * 1000.0)


def test_torque_noise_and_seed():
    model = arm("double_pendulum")
    ref = fourier(model)
    run = run_robot(model, ref, None, duration=1.0, torque_noise=[0.1, 0.02], seed=5)
    again = simulate_robot(model, ref, None, duration=1.0, torque_noise=[0.1, 0.02], seed=5)
    assert np.array_equal(run.log.torque, again.torque)
    noise = run.log.torque - run.truth.torque
    assert np.allclose(noise.std(axis=0), [0.1, 0.02], rtol=0.15)


def test_friction_is_what_torque_minus_inverse_dynamics_shows():
    """Noiseless: the command minus the rigid-body torque of the simulated motion, with the
    acceleration taken from the motion itself (mean over each held-command period), is each
    joint's own law, per direction."""
    model = arm("panda")
    friction = example_friction(model.effort_limit)
    run = run_robot(model, fourier(model, 1, 0.4), friction, duration=1.5, torque_noise=0)
    t = run.truth
    assert np.array_equal(run.log.torque, t.torque)
    q = 0.5 * (t.position[1:] + t.position[:-1])
    v = 0.5 * (t.velocity[1:] + t.velocity[:-1])
    a = np.diff(t.velocity, axis=0) * 1000.0
    shown = t.torque[:-1] - model.inverse_dynamics(q, v, a)
    moving = np.abs(v) > 0.05
    err = np.abs(shown - friction(v))[moving]
    assert moving.mean() > 0.7
    assert err.max() < 0.02 * np.abs(friction(v)).max()
    # the two directions of a joint differ, and so do the joints
    for j in range(7):
        p = friction.parameters(j)
        assert p["tau_c_pos"] != p["tau_c_neg"]
    assert len({round(friction.parameters(j)["tau_c_pos"], 6) for j in range(7)}) == 7


def test_friction_law_is_fricids_stribeck_asym():
    friction = example_friction([87.0, 12.0, 40.0])
    model = get_model("stribeck_asym")
    v = np.concatenate([np.linspace(-2, -0.05, 40), np.linspace(0.05, 2, 40)])
    for j in range(3):
        theta = model.param_vector(friction.parameters(j))
        X = np.column_stack([v, np.zeros_like(v), np.full_like(v, 25.0)])
        expected = model.predict(theta, X)
        vj = np.zeros((v.size, 3))
        vj[:, j] = v
        assert np.allclose(friction(vj)[:, j], expected, rtol=1e-6, atol=1e-9)
    eps = 1e-7
    for x in (np.array([0.3, -0.01, 2e-3]), np.array([-0.7, 0.2, -4e-3])):
        numeric = (friction(x + eps) - friction(x - eps)) / (2 * eps)
        assert np.allclose(friction.slope(x)[1], numeric, rtol=1e-4)
        assert np.allclose(np.array(friction.row_slope(x)), np.array(friction.slope(x)))
    assert np.all(friction(np.zeros(3)) == 0)


def test_friction_law_rejects_bad_values():
    good = example_friction([10.0, 10.0])
    with pytest.raises(ConfigError):
        ArmFriction({**good.pos, "w_s": np.array([0.0, 0.1])}, good.neg)
    with pytest.raises(ConfigError):
        ArmFriction({k: v for k, v in good.pos.items() if k != "delta"}, good.neg)


def test_references_are_consistent():
    model = arm("panda")
    t = np.arange(0, 5, 1e-4)
    for ref in (
        fourier(model),
        sweep_reference(np.zeros(7), 1, [0.2, 0.8], -0.5, 0.6, acceleration=3.0, dwell=0.2),
    ):
        q, dq, ddq = ref.evaluate(t)
        assert np.allclose(np.gradient(q, t, axis=0)[1:-1], dq[1:-1], atol=2e-3)
        assert np.abs(np.gradient(dq, t, axis=0)[1:-1] - ddq[1:-1]).mean() < 1e-2
    sweep = sweep_reference(np.zeros(7), 1, [0.2, 0.8], -0.5, 0.6, acceleration=3.0, dwell=0.2)
    q, dq, _ = sweep.evaluate(np.arange(0, sweep.duration, 1e-3))
    assert np.allclose(q[:, [0, 2, 3, 4, 5, 6]], 0) and q[:, 1].min() == pytest.approx(-0.5)
    assert q[:, 1].max() == pytest.approx(0.6)
    for begin, end, speed in sweep.plateaus:
        _, dq, _ = sweep.evaluate(np.linspace(begin, end, 50))
        assert np.allclose(dq[:, 1], speed)
    assert [p[2] for p in sweep.plateaus] == [0.2, -0.2, 0.8, -0.8]
    with pytest.raises(ConfigError):
        sweep_reference(np.zeros(2), 0, [3.0], 0.0, 1.0)
    drifting = sweep_reference(
        np.zeros(7), 1, [0.5], -0.5, 0.6, drift=np.full(7, 0.3), drift_period=8.0
    )
    t = np.arange(0, drifting.duration, 1e-3)
    q, dq, ddq = drifting.evaluate(t)
    assert np.allclose(q[:, 0], 0.3 * np.sin(2 * np.pi * t / 8.0))
    assert np.allclose(np.gradient(q, t, axis=0)[1:-1, 0], dq[1:-1, 0], atol=1e-5)
    assert np.allclose(np.gradient(dq, t, axis=0)[1:-1, 0], ddq[1:-1, 0], atol=1e-5)
    for begin, end, speed in drifting.plateaus:
        assert np.allclose(drifting.evaluate(np.linspace(begin, end, 20))[1][:, 1], speed)


def test_bad_options_are_config_errors():
    model = arm("double_pendulum")
    ref = fourier(model)
    for options in (
        {"controller": "p"},
        {"encoder_counts": 1},
        {"torque_noise": -1.0},
        {"rate": 0.0},
        {"duration": 0.0},
    ):
        with pytest.raises(ConfigError):
            run_robot(model, ref, None, **{"duration": 0.1, **options})
    with pytest.raises(ConfigError):
        run_robot(model, ref, example_friction([1.0, 1.0, 1.0]), duration=0.1)


def test_default_gains_keep_the_panda_loop_stable():
    """Gains from ``1 / (M^-1)_jj``: the discrete loop's ``M^-1 Kd`` stays well inside 1 kHz."""
    model = arm("panda")
    q0 = fourier(model).q0
    kp, kd = default_gains(model, q0)
    rate = np.linalg.eigvals(np.linalg.solve(model.mass_matrix(q0)[0], np.diag(kd))).real
    assert rate.max() * 1e-3 < 0.5
    assert (kp > 0).all()


def test_the_default_gains_hold_where_the_panda_s_joints_1_and_3_align():
    """Joint 2 swept from -0.9 rad through zero (joints 1 and 3 aligned there), the others
    held: gains for the inertia at the start drive the loop unstable, to torques no drive
    gives; the default gains, lowered where the inertia along the reference falls, track it
    (and stay within the sampled loop's bound there)."""
    model = arm("panda")
    start = np.array([-0.828, -0.907, -0.136, -1.681, 0.878, 1.936, 0.005])
    t = np.arange(2500) / 1000.0
    s = np.clip((t - 0.2) / 2.0, 0.0, 1.0)  # 0 to 1 over 2 s, from rest
    shape, speed = 3 * s**2 - 2 * s**3, 6 * s * (1 - s) / 2.0
    q = np.tile(start, (t.size, 1))
    dq, ddq = np.zeros_like(q), np.zeros_like(q)
    q[:, 1] += 1.2 * shape
    dq[:, 1] = 1.2 * speed
    ddq[:, 1] = np.gradient(dq[:, 1], t)

    def run(gains):
        options = {"duration": 2.5, "controller": "pd", "feedforward": True, "gains": gains}
        log = run_robot(model, lambda _t: (q, dq, ddq), None, torque_noise=0.0, **options).log
        return np.abs(log.select(model.joints).motor_torque).max(axis=0)

    assert (run(default_gains(model, start)) > model.effort_limit).any()
    assert (run(None) < model.effort_limit).all()
    kp, kd = default_gains(model, start, path=q, rate=1000.0)
    reach = np.diagonal(np.linalg.inv(model.mass_matrix(q)), axis1=1, axis2=2).max(axis=0)
    assert (kd * reach / 1000.0 <= STABLE_DAMPING + 1e-9).all()
    assert np.allclose(kp / kd, default_gains(model, start)[0] / default_gains(model, start)[1])


def test_the_default_gains_stay_where_the_inertia_barely_changes():
    """The double pendulum's inertia varies by a quarter along its reference: far from the
    sampled loop's bound, its gains are those of the start (lower ones let its joint 2 stick)."""
    model = arm("double_pendulum")
    t = np.arange(4000) / 1000.0
    q = np.column_stack([0.3 * np.sin(t), 0.5 + 0.4 * np.sin(1.3 * t)])
    along, start = default_gains(model, q[0], path=q, rate=1000.0), default_gains(model, q[0])
    np.testing.assert_array_equal(np.array(along), np.array(start))


def test_sweeps_show_the_coupled_gravity_of_the_whole_arm():
    """Constant-velocity sweeps of the double pendulum's first joint, the second held: on the
    plateaus the noiseless torque of the moving joint minus its friction is the rigid-body
    torque at zero acceleration, and the held joint's load varies with the first joint's
    angle (coupled gravity, ``sin(q1 + q2)``), its residual within its static friction."""
    model = arm("double_pendulum")
    friction = example_friction(model.effort_limit)
    ref = sweep_reference([0.0, 0.6], 0, [1.0], -0.6, 0.6, acceleration=5.0, dwell=0.1)
    run = run_robot(model, ref, friction, controller="torque", bandwidth=10.0, torque_noise=0)
    t = run.truth
    on = np.zeros(t.time.size, bool)
    for begin, end, _ in ref.plateaus:
        on |= (t.time > begin + 0.1) & (t.time < end)
    assert on.sum() > 1500
    rigid = model.inverse_dynamics(t.position[on], t.velocity[on], np.zeros((on.sum(), 2)))
    shown = t.torque[on] - rigid
    moving = shown[:, 0] - friction(t.velocity[on])[:, 0]
    # the drive's small accelerations (quantised velocity) average out on a plateau
    assert abs(moving.mean()) < 0.01 * np.abs(rigid[:, 0]).max()
    # and they are the whole of the rest: with the motion's own acceleration (mean over each
    # held-command period) the law is met sample by sample
    mid = on[:-1] & on[1:]
    q = 0.5 * (t.position[1:] + t.position[:-1])[mid]
    v = 0.5 * (t.velocity[1:] + t.velocity[:-1])[mid]
    a = np.diff(t.velocity, axis=0)[mid] * 1000.0
    exact = t.torque[:-1][mid, 0] - model.inverse_dynamics(q, v, a)[:, 0] - friction(v)[:, 0]
    assert np.sqrt(np.mean(exact**2)) < 0.003 * np.abs(rigid[:, 0]).max()
    static = max(friction.pos["tau_s"][1], friction.neg["tau_s"][1])
    assert np.abs(shown[:, 1]).max() < 1.2 * static
    assert np.ptp(rigid[:, 1]) > 2 * static  # the held joint's load follows q1


def test_random_fourier_stays_inside_the_limits():
    model = arm("panda")
    ref = random_fourier(model, harmonics=4, base_frequency=0.2, fraction=0.8, seed=4)
    q, dq, _ = ref.evaluate(np.linspace(0, ref.duration, 3000))
    assert (q >= model.lower).all() and (q <= model.upper).all()
    assert (np.abs(dq) <= 0.8 * model.velocity_limit * (1 + 1e-3)).all()
    assert (
        np.isclose(np.abs(dq).max(0) / model.velocity_limit, 0.8).any()
        or np.isclose(np.abs(q - ref.q0).max(0) / (0.5 * (model.upper - model.lower)), 0.8).all()
    )
    assert np.array_equal(
        ref.a, random_fourier(model, harmonics=4, base_frequency=0.2, fraction=0.8, seed=4).a
    )


LUGRE = {
    "sigma_0": 1e4,
    "sigma_1": 0.3,
    "sigma_2": 0.05,
    "tau_c": 0.12,
    "tau_s": 0.18,
    "w_s": 0.05,
    "delta": 2.0,
}


@pytest.mark.slow  # 1.5 s of the Panda at the step its wrist's bristles need (10 us): 12 s
def test_a_lugre_joint_slides_on_its_steady_state_and_is_named():
    from fricid.models import lugre

    model = arm("panda")
    friction = example_friction(model.effort_limit)
    ref = random_fourier(model, base_frequency=0.2, seed=3)
    run = run_robot(
        model, ref, friction, duration=1.5, torque_noise=0, lugre={"panda_joint7": LUGRE}
    )
    t = run.truth
    theta = np.array([LUGRE[k] for k in lugre.PARAM_NAMES])
    v = t.velocity[:, 6]
    sliding = np.abs(v) > 0.1
    assert sliding.mean() > 0.5
    off = np.abs(t.friction_torque[sliding, 6] - lugre.steady_state(theta, v[sliding]))
    assert np.median(off) < 1e-3 and (off < 0.01).mean() > 0.99
    # the other joints keep their static law
    assert np.allclose(t.friction_torque[:, :6], friction(t.velocity)[:, :6])
    assert t.friction_models["panda_joint7"] == "lugre"
    assert run.log.meta["friction"]["panda_joint7"] == LUGRE
    assert run.log.meta["friction_models"]["panda_joint1"] == "stribeck_asym"
    # the torque shows the bristles: command minus rigid-body torque is their mean friction
    q = 0.5 * (t.position[1:] + t.position[:-1])
    vm = 0.5 * (t.velocity[1:] + t.velocity[:-1])
    shown = t.torque[:-1] - model.inverse_dynamics(q, vm, np.diff(t.velocity, axis=0) * 1e3)
    mean = 0.5 * (t.friction_torque[1:] + t.friction_torque[:-1])
    moving = np.abs(vm[:, 6]) > 0.05
    assert np.abs(shown - mean)[moving, 6].max() < 0.2 * LUGRE["tau_s"]


def _low_speed_friction(run, j: int) -> float:
    v, f = run.truth.velocity[:, j], run.truth.friction_torque[:, j]
    slow = (np.abs(v) > 0.02) & (np.abs(v) < 0.15)
    return float(np.mean(np.sign(v[slow]) * f[slow]))


@pytest.mark.slow  # 2 s of the double pendulum at 25 us and at 6 us steps: 37 s
def test_a_lugre_joint_s_bristles_are_resolved_by_the_step():
    """The joint rings on its bristles at sqrt(sigma_0 / m); at the arm's default 0.5 ms step
    the low-speed friction of the double pendulum's LuGre joint came out a third of the
    converged value (fricid.sim.robot_lugre's notes); the step is now lowered to resolve it,
    and a four times finer step changes that friction by under 3 %."""
    from fricid.sim.robot_lugre import BRISTLE_RESOLUTION, lugre_like

    model = arm("double_pendulum")
    friction = example_friction([87.0, 12.0])
    law = lugre_like({k[:-4]: x for k, x in friction.parameters(1).items() if k.endswith("_pos")})
    ref = fourier(model, amplitude=0.5)
    runs = [
        run_robot(
            model,
            ref,
            friction,
            duration=2.0,
            feedforward=True,
            encoder_counts=2**20,
            integrator_step=step,
            lugre={model.joints[1]: law},
        )
        for step in (5e-4, 5e-4 / 80)
    ]
    m = np.diagonal(
        np.linalg.inv(model.mass_matrix(ref.evaluate(np.linspace(0, 2, 26))[0])), axis1=1, axis2=2
    ).max(axis=0)
    omega = math.sqrt(law["sigma_0"] * m[1])
    assert runs[0].truth.step <= BRISTLE_RESOLUTION / omega
    coarse, fine = (_low_speed_friction(r, 1) for r in runs)
    assert abs(coarse - fine) < 0.03 * fine


def test_lugre_options_are_checked():
    model = arm("double_pendulum")
    ref = fourier(model)
    with pytest.raises(ConfigError, match="passive"):
        run_robot(model, ref, None, duration=0.1, lugre={"joint1": {**LUGRE, "sigma_1": 5.0}})
    with pytest.raises(ConfigError, match="not in the model"):
        run_robot(model, ref, None, duration=0.1, lugre={"elbow": LUGRE})


def test_lugre_like_keeps_the_steady_state_and_is_passive():
    from fricid.models import lugre
    from fricid.sim.robot_lugre import lugre_like

    friction = example_friction([87.0, 12.0])
    for j in range(2):
        pos = {k[:-4]: x for k, x in friction.parameters(j).items() if k.endswith("_pos")}
        law = lugre_like(pos)
        theta = np.array([law[k] for k in lugre.PARAM_NAMES])
        v = np.linspace(0.01, 2.0, 50)
        vj = np.zeros((50, 2))
        vj[:, j] = v
        assert np.allclose(lugre.steady_state(theta, v), friction(vj)[:, j], rtol=1e-9)
        assert lugre.passivity_margin(theta) > 0
        assert law["sigma_0"] * 1e-4 == pytest.approx(pos["tau_s"])


ROTOR = """<robot name="rotor"><link name="base"/>
  <link name="disc"><inertial><mass value="1"/><origin xyz="0 0 0"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="disc"/>
    <axis xyz="0 0 1"/></joint>
</robot>"""


@pytest.mark.slow  # two 2 s runs until the PD's transient has died out: 1.9 s
def test_steady_sliding_torque_is_the_law_at_the_sampled_velocity(tmp_path):
    """A rotor (no gravity) tracking 2 rad/s: the held command equals the friction law at the
    sampled velocity to second order in the step. The linearly implicit Euler step held it
    low by ``h beta / 2 I`` (0.58 % here at 0.125 ms: ``tau_v / I = 100 /s``), which a whole-arm
    fit read as friction levels that low, several standard errors on the Panda's wrist."""
    path = tmp_path / "rotor.urdf"
    path.write_text(ROTOR)
    model = RigidBodyModel.from_urdf(path)
    law = {"tau_c": [0.5], "tau_s": [0.5], "w_s": [0.1], "tau_v": [1.0], "delta": [2.0]}
    friction = ArmFriction(law, law)

    def ref(t):
        return 2.0 * t[:, None], np.full((t.size, 1), 2.0), np.zeros((t.size, 1))

    errors = []
    for step in (2.5e-4, 1.25e-4):
        truth = run_robot(
            model,
            ref,
            friction,
            duration=2.0,
            torque_noise=0,
            encoder_counts=2**40,
            integrator_step=step,
            feedforward=True,
        ).truth
        tail = slice(1500, None)  # steady: the PD's transient has died out
        errors.append(np.abs(truth.torque[tail] / friction(truth.velocity[tail]) - 1).max())
    assert errors[1] < 1e-4
    assert errors[0] / errors[1] > 3.0  # second order, not first


@pytest.mark.slow  # 7 s under the default run's load
def test_a_light_arm_chattering_at_a_coarse_step_is_warned_of():
    """The double pendulum's light joints overshoot zero velocity at every friction step of
    0.5 ms (the linearised smoothed sign is flat away from zero): their true velocity flips
    sign from sample to sample. The simulator says so, and not at a fine enough step; the
    truth's acceleration is its velocity's differences, not ``M^-1 (u - ... - F(dq))``,
    which read hundreds of rad/s^2 where the joints stick."""
    from fricid.errors import DataQualityWarning

    model = arm("double_pendulum")
    ref = fourier(model, amplitude=0.5)
    friction = example_friction([87.0, 12.0])
    with pytest.warns(
        DataQualityWarning, match=r"joint1 \(\d+ % of the samples\).*step of 0.0005 s"
    ):
        coarse = run_robot(model, ref, friction, duration=2.0, feedforward=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataQualityWarning)
        fine = run_robot(
            model, ref, friction, duration=2.0, feedforward=True, integrator_step=31.25e-6
        )
    for t in (coarse.truth, fine.truth):
        np.testing.assert_allclose(t.acceleration, np.gradient(t.velocity, axis=0) * 1e3)
    v = fine.truth.velocity
    assert np.sqrt(np.mean(np.diff(v, axis=0) ** 2)) < 0.2 * np.sqrt(
        np.mean(np.diff(coarse.truth.velocity, axis=0) ** 2)
    )


def test_the_panda_at_its_default_step_does_not_chatter():
    model = arm("panda")
    ref = random_fourier(model, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run_robot(model, ref, example_friction(model.effort_limit), duration=1.0, feedforward=True)
