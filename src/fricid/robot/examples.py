"""URDFs of real robots shipped by the PyPI package ``example-robot-data`` (the ``dev`` and
``robot`` extras install it): truth models for tests, benchmarks and the docs."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

from ..errors import ConfigError

__all__ = ["EXAMPLE_ROBOTS", "example_urdf"]

#: Name -> the URDF's path inside the package's data, and the joints to identify (None: all).
EXAMPLE_ROBOTS: dict[str, tuple[str, tuple[str, ...] | None]] = {
    "panda": (
        "panda_description/urdf/panda.urdf",
        tuple(f"panda_joint{i}" for i in range(1, 8)),
    ),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", None),
    "double_pendulum": ("double_pendulum_description/urdf/double_pendulum.urdf", None),
}

_PREFIX = "cmeel.prefix/share/example-robot-data/robots/"


def example_urdf(name: str) -> tuple[Path, tuple[str, ...] | None]:
    """The URDF of an example robot (:data:`EXAMPLE_ROBOTS`) and its arm's joints.

    Raises
    ------
    ConfigError
        An unknown name (the known ones listed), or ``example-robot-data`` not installed.
    """
    if name not in EXAMPLE_ROBOTS:
        raise ConfigError(f"no example robot '{name}'; known: {', '.join(EXAMPLE_ROBOTS)}")
    relative, joints = EXAMPLE_ROBOTS[name]
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        raise ConfigError(
            "the example robots come from the package example-robot-data: "
            "pip install 'fricid[robot]'"
        ) from None
    path = Path(str(dist.locate_file(_PREFIX + relative)))
    if not path.is_file():
        raise ConfigError(f"example-robot-data has no {relative} (looked at {path})")
    return path, joints
