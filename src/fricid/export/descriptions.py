"""Robot descriptions and controller configurations: URDF, MJCF and ros2_control-style YAML.

Each holds friction as Coulomb plus viscous (per direction in the YAML), so each gets the
least-squares projection of :mod:`fricid.export.projection`, with the projection error and
what is lost stated in a comment of the file. When the projection misses the model by more
than ``max_loss`` (RMS error relative to the RMS friction, default 50 %), the export is
refused with an :class:`ExportError` that says what would be lost; pass a larger
``max_loss`` (``--max-loss``) to write it anyway, or export to C for the full model.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from ..fitted import FittedModel
from ._common import ExportError, describe_model, fmt_float
from .projection import Projection, project

__all__ = [
    "DEFAULT_MAX_LOSS",
    "DESCRIPTION_TARGETS",
    "description_text",
    "mjcf_text",
    "ros2_yaml_text",
    "urdf_text",
    "write_text",
]

#: Default tolerance of a projection: RMS error / RMS friction over the operating range.
DEFAULT_MAX_LOSS = 0.5

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_./-]*$")


def _check_name(joint: str) -> str:
    if not _NAME.match(joint):
        raise ExportError(
            f"joint name {joint!r} must start with a letter or '_' and hold only letters, "
            "digits and _ . / -"
        )
    return joint


def _checked(
    fitted: FittedModel, target: str, per_direction: bool, max_loss: float, ranges: dict
) -> Projection:
    proj = project(fitted, per_direction, **ranges)
    if not proj.relative_error <= max_loss:
        lost = "; ".join(proj.lost) or "the model's shape"
        raise ExportError(
            f"{target} cannot represent model '{fitted.model}' within the tolerance: its "
            f"Coulomb-viscous projection misses it by {100 * proj.relative_error:.3g} % RMS "
            f"(max {proj.max_error:.4g} N m at {proj.max_at[0]:.4g} rad/s; tolerance "
            f"{100 * max_loss:.3g} %). Lost: {lost}. Export to C for the full model, or raise "
            "the tolerance (--max-loss) to write the projection anyway"
        )
    return proj


def _xml_comment(lines: list[str]) -> str:
    body = "\n".join("     " + line.replace("--", "- -") for line in lines)
    return "<!--\n" + body + "\n-->\n"


def urdf_text(
    fitted: FittedModel,
    joint: str = "joint",
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    **ranges,
) -> str:
    """A URDF ``<dynamics damping= friction=/>`` element for the joint, with a comment.

    URDF ``friction`` is the Coulomb friction [N m] and ``damping`` the viscous coefficient
    [N m s/rad]; both from the projection over the operating range.
    """
    proj = _checked(fitted, "URDF <dynamics>", False, max_loss, ranges)
    lines = [
        *describe_model(fitted, source),
        *proj.summary(),
        f'place inside <joint name="{_check_name(joint)}">; friction [N m], damping [N m s/rad]',
    ]
    return (
        _xml_comment(lines) + f'<dynamics damping="{fmt_float(proj.viscous["both"])}" '
        f'friction="{fmt_float(proj.coulomb["both"])}"/>\n'
    )


def mjcf_text(
    fitted: FittedModel,
    joint: str = "joint",
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    **ranges,
) -> str:
    """An MJCF ``<joint frictionloss= damping=/>`` element, with a comment.

    MuJoCo's ``frictionloss`` is the Coulomb (dry) friction [N m] and ``damping`` the viscous
    coefficient [N m s/rad]; copy both attributes onto the joint of your model.
    """
    proj = _checked(fitted, "MJCF frictionloss/damping", False, max_loss, ranges)
    lines = [
        *describe_model(fitted, source),
        *proj.summary(),
        "copy frictionloss [N m] and damping [N m s/rad] onto your <joint>",
    ]
    return (
        _xml_comment(lines) + f'<joint name="{_check_name(joint)}" '
        f'frictionloss="{fmt_float(proj.coulomb["both"])}" '
        f'damping="{fmt_float(proj.viscous["both"])}"/>\n'
    )


def ros2_yaml_text(
    fitted: FittedModel,
    joint: str = "joint",
    *,
    node: str = "friction_compensation",
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    **ranges,
) -> str:
    """A ROS 2 parameter file with per-direction Coulomb and viscous friction of the joint.

    The compensating torque is ``coulomb_positive + viscous_positive v`` for ``v > 0`` and
    ``-coulomb_negative + viscous_negative v`` for ``v < 0`` (``coulomb_*`` are magnitudes
    [N m], ``viscous_*`` in N m s/rad), under ``<node>: ros__parameters: <joint>:``.
    """
    proj = _checked(fitted, "the per-direction Coulomb-viscous YAML", True, max_loss, ranges)
    name = _check_name(joint)
    lines = [
        *describe_model(fitted, source),
        *proj.summary(),
        "tau_ff = coulomb_positive + viscous_positive * v (v > 0); "
        "-coulomb_negative + viscous_negative * v (v < 0)",
        "units: coulomb_* [N m] (magnitudes), viscous_* [N m s/rad], velocity [rad/s]",
    ]
    head = "".join(f"# {line}\n" for line in lines)
    c, b = proj.coulomb, proj.viscous
    return head + (
        f"{node}:\n"
        "  ros__parameters:\n"
        f"    joints: [{name}]\n"
        f"    {name}:\n"
        f"      coulomb_positive: {fmt_float(c['positive'])}\n"
        f"      coulomb_negative: {fmt_float(c['negative'])}\n"
        f"      viscous_positive: {fmt_float(b['positive'])}\n"
        f"      viscous_negative: {fmt_float(b['negative'])}\n"
        f"      projection_rms_error: {fmt_float(proj.rms_error)}\n"
        f"      source_model: {fitted.model}\n"
    )


#: The description targets, by name, with their text builder.
DESCRIPTION_TARGETS = {"urdf": urdf_text, "mjcf": mjcf_text, "yaml": ros2_yaml_text}


def description_text(target: str, fitted: FittedModel, **options) -> str:
    """The text of one of :data:`DESCRIPTION_TARGETS` (``options`` as for that builder)."""
    try:
        builder = DESCRIPTION_TARGETS[target]
    except KeyError:
        raise ExportError(
            f"unknown description target '{target}'; choose one of: "
            + ", ".join(DESCRIPTION_TARGETS)
        ) from None
    return builder(fitted, **options)


def write_text(text: str, path: str | os.PathLike[str]) -> Path:
    """Write ``text`` to ``path`` atomically (nothing half-written on failure)."""
    from ..io.atomic import atomic_write

    path = Path(path)
    with atomic_write(path, "w") as fh:
        fh.write(text)
    return path
