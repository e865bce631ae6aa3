"""The load torque of the load families (:mod:`._friction`): what each joint carries.

The joint-load model (BAS-RBFNN paper eq. 3) raises the Coulomb level with the joint's load
``|tau_l|``, and the paper takes that load as the gravity torque on the joint (its eq. 7). On a
whole arm the gravity torque of each joint depends on every joint's angle and on every link's
mass, so it comes from the rigid-body model:

1. the log's own load channel when it has one for every joint (a torque sensor behind the
   gear, a load cell): it is used as it is;
2. otherwise ``g(q)`` of the arm, first with the URDF's inertial parameters, then again with
   the identified (physically consistent) ones: :func:`fricid.identify.dynamic.arm.fit_arm`
   fits twice, the second time with the load of the first fit's arm, so that approximate
   masses in the URDF do not scale the load coefficient (the provenance's ``load`` says
   which).

``g(q)`` is smooth at a log's rate: it is computed at every :data:`STRIDE`-th sample of the
logged position and interpolated between them (linear; on a Panda multi-sine of 1 rad/s RMS
per joint at 1 kHz, within 2 mN m of the exact 39 N m at most, 6e-5 of it).
"""

from __future__ import annotations

import numpy as np

from ....robot import RigidBodyModel
from ....samples import RobotLog

__all__ = ["STRIDE", "joint_load"]

#: Gravity is computed at every this many samples and interpolated between.
STRIDE = 10

#: Where the load came from (the provenance's ``load``).
FROM_LOG = "the log's load channel"
FROM_URDF = "gravity torque of the URDF's inertial parameters"
FROM_FIT = "gravity torque of the identified inertial parameters"


def log_load(log: RobotLog, joints: tuple[str, ...]) -> np.ndarray | None:
    """The log's load channel for ``joints`` (N, n), or None when it has none (or gaps)."""
    load = log.select(joints).load
    if load is None or not np.isfinite(load).all():
        return None
    return np.asarray(load, dtype=float)


def joint_load(model: RigidBodyModel, position: np.ndarray) -> np.ndarray:
    """The gravity torque ``g(q)`` (N, n) along ``position`` (N, n) (module notes)."""
    N = position.shape[0]
    at = np.unique(np.append(np.arange(0, N, STRIDE), N - 1))
    g = model.gravity_torque(position[at])
    rows = np.arange(N)
    return np.column_stack([np.interp(rows, at, g[:, j]) for j in range(g.shape[1])])
