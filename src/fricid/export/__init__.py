"""Models out: C99 code, URDF / MJCF snippets, ros2_control-style YAML, the model file schema.

>>> from fricid.export import export_c, urdf_text, Smoothing      # doctest: +SKIP
>>> export_c(fitted, "out/", Smoothing("tanh", 0.01))              # out/fricid_friction.[ch]
>>> print(urdf_text(fitted, joint="elbow"))                        # <dynamics .../> + comment

Targets that hold less than the model (URDF, MJCF and YAML hold Coulomb plus viscous
friction) get the least-squares projection over the model's operating range, with its error
and what is lost stated in the file; beyond a tolerance they refuse with an
:class:`ExportError` that says what would be lost. Every file is written atomically.
"""

from __future__ import annotations

from ._common import ExportError
from .c import CCode, c_code, export_c
from .descriptions import (
    DEFAULT_MAX_LOSS,
    DESCRIPTION_TARGETS,
    description_text,
    mjcf_text,
    ros2_yaml_text,
    urdf_text,
    write_text,
)
from .projection import Projection, operating_grid, project
from .schema import model_schema, schema_path, validate_model_dict
from .smoothing import SMOOTHINGS, Smoothing, smooth_predict

__all__ = [
    "DEFAULT_MAX_LOSS",
    "DESCRIPTION_TARGETS",
    "SMOOTHINGS",
    "TARGETS",
    "CCode",
    "ExportError",
    "Projection",
    "Smoothing",
    "c_code",
    "description_text",
    "export_c",
    "mjcf_text",
    "model_schema",
    "operating_grid",
    "project",
    "ros2_yaml_text",
    "schema_path",
    "smooth_predict",
    "urdf_text",
    "validate_model_dict",
    "write_text",
]

#: Every export target, with a line on each (``fricid export --to``).
TARGETS: dict[str, str] = {
    "c": "C99 header and source, double fricid_friction(velocity, load, temperature)",
    "urdf": "URDF <dynamics damping= friction=/> (Coulomb-viscous projection)",
    "mjcf": "MJCF <joint frictionloss= damping=/> (Coulomb-viscous projection)",
    "yaml": "ros2_control-style parameters, Coulomb and viscous per direction (projection)",
}
