"""Models out: C99 code, URDF / MJCF snippets, ros2_control-style YAML, the model file schema.

>>> from fricid.export import Smoothing, export_c, urdf_text
>>> from fricid.fitted import FittedModel
>>> fitted = FittedModel.from_values(
...     "stribeck",
...     {"tau_c": 0.2, "tau_s": 0.3, "w_s": 0.1, "tau_v": 0.05, "delta": 1.0},
...     operating_range={"velocity": [-1.0, 1.0]},
... )
>>> ", ".join(p.name for p in export_c(fitted, "out/", Smoothing("tanh", 0.01)))
'fricid_friction.h, fricid_friction.c'
>>> paths = export_c(fitted, "out/", clamp=True)  # inputs held in the operating range
>>> "<dynamics" in urdf_text(fitted, joint="elbow")  # <dynamics .../> and a comment
True

All joints of a robot at once (:mod:`fricid.export.robot`): one ros2_control YAML with a
block per joint, one C header and source with a function per joint and a dispatcher.

Targets that hold less than the model (URDF, MJCF and YAML hold Coulomb plus viscous
friction) get the least-squares projection over the model's operating range, with its error
and what is lost stated in the file; beyond a tolerance they refuse with an
:class:`ExportError` that says what would be lost. Every file is written atomically
(:mod:`fricid.io.atomic`).

Model files travel between people and exports go into firmware, so data never becomes code
(:mod:`fricid.export._common`): numbers go through one formatter that refuses NaN and inf,
text from the model file only through a tested escaper, names through strict patterns; XML
is built with :mod:`xml.etree.ElementTree` and YAML with :func:`yaml.safe_dump`; every file
names the model by its SHA-256. Smoothing near zero velocity is a model concern and lives in
:mod:`fricid.models.smoothing` (re-exported here).
"""

from __future__ import annotations

from ..models.smoothing import SMOOTHINGS, Smoothing, smooth_predict
from ._common import (
    ExportError,
    file_sha256,
    model_sha256,
    plain,
    refuse_undetermined,
    refuse_untrusted,
    undetermined_parameters,
)
from .c import CCode, c_code, export_c
from .clamp import clamp_inputs, clamp_limits
from .descriptions import (
    DEFAULT_MAX_LOSS,
    DESCRIPTION_TARGETS,
    description_text,
    mjcf_text,
    ros2_yaml_text,
    undetermined_held,
    urdf_text,
    write_text,
)
from .projection import Projection, operating_grid, project
from .robot import RobotCCode, export_robot_c, robot_c_code, robot_ros2_yaml_text
from .schema import model_schema, schema_path, validate_model_dict

__all__ = [
    "DEFAULT_MAX_LOSS",
    "DESCRIPTION_TARGETS",
    "SMOOTHINGS",
    "TARGETS",
    "CCode",
    "ExportError",
    "Projection",
    "RobotCCode",
    "Smoothing",
    "c_code",
    "clamp_inputs",
    "clamp_limits",
    "description_text",
    "export_c",
    "export_robot_c",
    "file_sha256",
    "mjcf_text",
    "model_schema",
    "model_sha256",
    "operating_grid",
    "plain",
    "project",
    "refuse_undetermined",
    "refuse_untrusted",
    "robot_c_code",
    "robot_ros2_yaml_text",
    "ros2_yaml_text",
    "schema_path",
    "smooth_predict",
    "undetermined_held",
    "undetermined_parameters",
    "urdf_text",
    "validate_model_dict",
    "write_text",
]

#: Every export target, with a line on each (``fricid export --to``).
TARGETS: dict[str, str] = {
    "c": "C99 header and source, double fricid_friction(velocity, load, temperature)",
    "urdf": "URDF <dynamics damping= friction=/> (Coulomb-viscous projection)",
    "mjcf": "MJCF <joint frictionloss= damping=/> (Coulomb-viscous projection; a LuGre model: "
    "MuJoCo 4's dcmotor with lugre friction)",
    "yaml": "ros2_control-style parameters, Coulomb and viscous per direction (projection)",
}
