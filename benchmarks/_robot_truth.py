"""MuJoCo as a second truth of a whole arm: the exported MJCF run under the same drive.

:func:`simulate_robot_mujoco` writes the arm with :func:`fricid.export.robot_mjcf.robot_mjcf_text`
(each joint's friction as MuJoCo's ``frictionloss`` and ``damping``: the mean Coulomb and
viscous levels of the two directions, the Stribeck rise lost), loads it in MuJoCo and runs
:func:`fricid.sim.robot.run_robot` with MuJoCo as the plant: the same controller at the log's
rate, the same quantised encoders and torque noise, one ``mj_step`` per internal step with
the command on each joint's ``<joint>_motor``, its ``solreffriction`` kept at two of the
plant's steps as the export writes it for its own timestep. The truth record's friction is the
law MuJoCo holds (:func:`mujoco_friction`: Coulomb-viscous, the same level both ways); MuJoCo
applies its ``frictionloss`` as a soft constraint, at its level once a joint slides faster
than a speed set by its inertia and the time constant (:mod:`fricid.export.robot_mjcf`: the
wrist from about 0.03 rad/s at 0.125 ms steps), creeping while it should stick
(:data:`fricid.export.mjcf.FRICTIONLOSS_LINES`).
"""

from __future__ import annotations

import numpy as np

from fricid.export.mujoco_check import require_mujoco
from fricid.export.robot_mjcf import joint_friction, robot_mjcf_text
from fricid.robot import RigidBodyModel
from fricid.sim.robot import DEFAULT_STEP, RobotRun, run_robot
from fricid.sim.robot_friction import ArmFriction

__all__ = ["MujocoPlant", "mujoco_friction", "simulate_robot_mujoco"]


def mujoco_friction(model: RigidBodyModel, friction: ArmFriction) -> ArmFriction:
    """The law MuJoCo simulates for ``friction``: ``frictionloss sign(v) + damping v``."""
    levels = [joint_friction(j, friction.parameters(i))[:2] for i, j in enumerate(model.joints)]
    fl, damping = (np.array(x) for x in zip(*levels, strict=True))
    side = {"tau_c": fl, "tau_s": fl, "w_s": np.ones(model.n), "tau_v": damping}
    side["delta"] = np.ones(model.n)
    return ArmFriction(side, dict(side), friction.smoothing)


class MujocoPlant:
    """An exported MJCF stepped by MuJoCo, ``advance(q, dq, u) -> (q, dq)`` per sample."""

    def __init__(self, xml: str, joints: tuple[str, ...], rate: float, step: float) -> None:
        mujoco = require_mujoco()
        self._mj = mujoco
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.substeps = max(1, int(np.ceil(1.0 / (rate * step) - 1e-9)))
        self.step = 1.0 / (rate * self.substeps)
        self.model.opt.timestep = self.step
        # the export's solreffriction, two timesteps, at this step (fricid.export.robot_mjcf)
        self.model.dof_solref[:, 0] = 2 * self.step
        self.model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        self.data = mujoco.MjData(self.model)
        find = mujoco.mj_name2id
        self._act = [find(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{j}_motor") for j in joints]
        self._started = False

    def start(self, q: np.ndarray, v: np.ndarray) -> None:
        self.data.qpos[:] = q
        self.data.qvel[:] = v
        self._mj.mj_forward(self.model, self.data)
        self._started = True

    def advance(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, ...]:
        if not self._started:
            self.start(q, v)
        self.data.ctrl[self._act] = u
        for _ in range(self.substeps):
            self._mj.mj_step(self.model, self.data)
        return self.data.qpos.copy(), self.data.qvel.copy()


def simulate_robot_mujoco(
    model: RigidBodyModel,
    reference,
    friction: ArmFriction | None,
    *,
    rate: float = 1000.0,
    integrator_step: float = DEFAULT_STEP,
    **options,
) -> RobotRun:
    """``run_robot`` (same options) with MuJoCo stepping the exported MJCF (module notes)."""
    xml, notes = robot_mjcf_text(model, friction)
    plant = MujocoPlant(xml, model.joints, rate, integrator_step)
    law = None if friction is None else mujoco_friction(model, friction)
    run = run_robot(model, reference, law, rate=rate, plant=plant, **options)
    run.log.meta.update({"simulated": "mujoco", "mjcf_notes": notes})
    return run
