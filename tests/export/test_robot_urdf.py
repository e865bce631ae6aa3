"""The robot's URDF with identified dynamics: read back, it must give the identified arm."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from fricid.export import ExportError
from fricid.export.robot_urdf import robot_urdf_text, write_robot_urdf
from fricid.fitted import FittedModel
from fricid.robot import (
    RigidBodyModel,
    example_urdf,
    from_log_cholesky,
    to_log_cholesky,
)


@pytest.fixture(scope="module")
def panda() -> RigidBodyModel:
    path, joints = example_urdf("panda")
    return RigidBodyModel.from_urdf(path, joints)


def test_written_inertials_read_back_as_the_identified_arm(panda, tmp_path):
    rng = np.random.default_rng(0)
    pi = from_log_cholesky(to_log_cholesky(panda.parameters()) + 0.1 * rng.normal(size=70))
    friction = FittedModel.from_values(
        "coulomb_viscous", {"f_c": 0.4, "beta": 0.2}, operating_range={"velocity": [-2, 2]}
    )
    out = write_robot_urdf(
        tmp_path / "panda_identified.urdf", panda, pi, {"panda_joint3": friction}
    )
    back = RigidBodyModel.from_urdf(out, panda.joints)
    np.testing.assert_allclose(back.parameters(), pi, rtol=1e-6, atol=1e-9)
    q, dq, ddq = rng.normal(size=(3, 4, 7))
    np.testing.assert_allclose(
        back.inverse_dynamics(q, dq, ddq),
        panda.with_parameters(pi).inverse_dynamics(q, dq, ddq),
        rtol=1e-6,
        atol=1e-8,
    )
    text = out.read_text()
    dynamics = ET.fromstring(text).find("joint[@name='panda_joint3']/dynamics")
    assert float(dynamics.get("friction")) == pytest.approx(0.4)
    assert float(dynamics.get("damping")) == pytest.approx(0.2)
    assert "mass is in link panda_link7" in text  # the hand's mass moved into link 7's body
    assert "SHA-256" in text


def test_inconsistent_parameters_and_the_source_itself_are_refused(panda, tmp_path):
    pi = panda.parameters().copy()
    pi[20] = -1.0  # joint 3's body with a negative mass
    with pytest.raises(ExportError, match="panda_joint3 are not physically consistent"):
        robot_urdf_text(panda, pi)
    with pytest.raises(ExportError, match="is the source URDF"):
        write_robot_urdf(panda.source, panda)
