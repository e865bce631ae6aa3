"""Robot descriptions and controller configurations: URDF, MJCF and ros2_control-style YAML.

Each holds friction as Coulomb plus viscous (per direction in the YAML), so each gets the
least-squares projection of :mod:`fricid.export.projection`, with the projection error and
what is lost stated in a comment of the file. When the projection misses the model by more
than ``max_loss`` (RMS error relative to the RMS friction, default 50 %), the export is
refused with an :class:`ExportError` that says what would be lost; pass a larger
``max_loss`` (``--max-loss``) to write it anyway, or export to C for the full model.

MJCF is checked in MuJoCo itself (:mod:`fricid.export.mujoco_check`,
``tests/export/test_mujoco.py``),
and a LuGre model goes to MuJoCo 4's ``dcmotor`` LuGre friction (:mod:`fricid.export.mjcf`).
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import yaml

from ..fitted import FittedModel
from ._common import (
    ExportError,
    check_name,
    ensure_out_file,
    fmt_float,
    model_name,
    plain,
    summary_lines,
    undetermined_parameters,
    write_lines_checked,
)
from .mjcf import STIFF_SOLIMP, frictionloss_lines, is_lugre, mjcf_lugre_elements
from .projection import Projection, operating_grid, project, rests_on_names

__all__ = [
    "DEFAULT_MAX_LOSS",
    "DESCRIPTION_TARGETS",
    "description_text",
    "mjcf_text",
    "ros2_yaml_text",
    "undetermined_held",
    "urdf_text",
    "write_text",
]

#: Default tolerance of a projection: RMS error / RMS friction over the operating range.
DEFAULT_MAX_LOSS = 0.5

_JOINT = re.compile(r"[A-Za-z_][A-Za-z0-9_./-]{0,127}")
_NODE = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,127}")


def _check_joint(joint: str) -> str:
    return check_name(
        joint,
        "joint name",
        _JOINT,
        "start with a letter or '_' and hold only letters, digits and _ . / - "
        "(at most 128 characters)",
    )


def _check_node(node: str) -> str:
    return check_name(
        node,
        "ROS 2 node name",
        _NODE,
        "start with a letter or '_' and hold only letters, digits and _ (at most 128 characters)",
    )


def _checked(
    fitted: FittedModel, target: str, per_direction: bool, max_loss: float, ranges: dict
) -> Projection:
    proj = project(fitted, per_direction, **ranges)
    if not proj.relative_error <= max_loss:
        lost = "; ".join(proj.lost) or "the model's shape"
        raise ExportError(
            f"{target} cannot represent model '{model_name(fitted)}' within the tolerance: its "
            f"Coulomb-viscous projection misses it by {100 * proj.relative_error:.3g} % RMS "
            f"(max {proj.max_error:.4g} N m at {proj.max_at[0]:.4g} rad/s; tolerance "
            f"{100 * max_loss:.3g} %). Lost: {lost}. Export to C for the full model, or raise "
            "the tolerance (--max-loss) to write the projection anyway"
        )
    return proj


def _xml(lines: list[str], *elements: ET.Element) -> str:
    """An XML comment of ``lines``, then ``elements``, all serialised by ElementTree.

    ``lines`` hold fixed text, numbers and :func:`~fricid.export._common.plain` text only;
    the check refuses ``--`` (which would end or invalidate the comment) as a last guard.
    """
    write_lines_checked(lines, ("--",))
    comment = ET.Comment("\n" + "".join(f"     {line}\n" for line in lines))
    return "".join(ET.tostring(part, encoding="unicode") + "\n" for part in (comment, *elements))


def urdf_text(
    fitted: FittedModel,
    joint: str = "joint",
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    sha256: str | None = None,
    **ranges,
) -> str:
    """A URDF ``<dynamics damping= friction=/>`` element for the joint, with a comment.

    URDF ``friction`` is the Coulomb friction [N m] and ``damping`` the viscous coefficient
    [N m s/rad]; both from the projection over the operating range. ``source`` and
    ``sha256`` name the model file in the comment
    (:func:`fricid.export._common.summary_lines`); ``ranges`` override the operating range
    (:func:`fricid.export.project`). The text is built with :mod:`xml.etree.ElementTree`.
    """
    name = _check_joint(joint)
    proj = _checked(fitted, "URDF <dynamics>", False, max_loss, ranges)
    lines = [
        *summary_lines(
            fitted, source, sha256, projection_rms=proj.rms_error, held=proj.rests_on_names
        ),
        *proj.summary(),
        f"place inside the joint named {plain(name)}; friction [N m], damping [N m s/rad]",
    ]
    element = ET.Element(
        "dynamics",
        {
            "damping": fmt_float(proj.viscous["both"], "damping"),
            "friction": fmt_float(proj.coulomb["both"], "friction"),
        },
    )
    return _xml(lines, element)


def mjcf_text(
    fitted: FittedModel,
    joint: str = "joint",
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    sha256: str | None = None,
    timestep_check: bool = False,
    inertia: float | None = None,
    timestep=None,
    **ranges,
) -> str:
    """An MJCF ``<joint frictionloss= damping=/>`` element, with a comment.

    MuJoCo's ``frictionloss`` is the Coulomb (dry) friction [N m] and ``damping`` the viscous
    coefficient [N m s/rad]; copy both attributes onto the joint of your model. The comment
    says how MuJoCo applies ``frictionloss`` (a soft constraint:
    :func:`fricid.export.mjcf.frictionloss_lines`). Other arguments as for
    :func:`urdf_text`.

    A LuGre model (``model == "lugre"``) exports instead to a ``<joint damping=/>`` and an
    ``<actuator>`` holding MuJoCo's passive ``dcmotor`` with ``lugre`` friction (MuJoCo >=
    4.0), its comment giving the static projection for older MuJoCo with its error
    (:mod:`fricid.export.mjcf`); ``max_loss`` then bounds the error of mapping the Stribeck
    exponent to MuJoCo's 2. Of ``ranges`` only ``velocity_range`` applies.

    ``timestep_check``: measure in MuJoCo the integrator and the largest timestep that keep
    the break-away within 5 % and a held-out trajectory within 1 % of its span
    (:mod:`fricid.export.mujoco_step`, about a second), write them as an ``<option
    integrator= timestep=/>`` element and the measured errors into the comment; without
    MuJoCo, the conservative default, said to be unmeasured. ``inertia`` [kg m^2] is the
    joint's for that simulation (default: the one a trajectory fit identified, else 0.01).
    ``timestep``: a :class:`fricid.export.mujoco_step.StepAdvice` measured already (on this
    function's text without it), written instead of measuring again.
    """
    name = _check_joint(joint)
    if is_lugre(fitted):
        lines, elements = mjcf_lugre_elements(
            fitted,
            name,
            max_loss=max_loss,
            source=source,
            sha256=sha256,
            velocity_range=ranges.get("velocity_range"),
        )
    else:
        proj = _checked(fitted, "MJCF frictionloss/damping", False, max_loss, ranges)
        lines = [
            *summary_lines(
                fitted, source, sha256, projection_rms=proj.rms_error, held=proj.rests_on_names
            ),
            *proj.summary(),
            *frictionloss_lines(fitted),
            "copy frictionloss [N m], damping [N m s/rad] and solimpfriction onto your <joint>",
        ]
        elements = [
            ET.Element(
                "joint",
                {
                    "name": name,
                    "frictionloss": fmt_float(proj.coulomb["both"], "frictionloss"),
                    "damping": fmt_float(proj.viscous["both"], "damping"),
                    "solimpfriction": STIFF_SOLIMP,
                },
            )
        ]
    advice = timestep
    if advice is None and timestep_check:
        from .mujoco_step import model_inertia, timestep_advice

        advice = timestep_advice(_xml(lines, *elements), *model_inertia(fitted, inertia))
    if advice is not None:
        lines = [*lines, *advice.lines()]
        if advice.timestep is not None:
            option = {"integrator": advice.integrator, "timestep": fmt_float(advice.timestep)}
            elements = [*elements, ET.Element("option", option)]
    return _xml(lines, *elements)


def ros2_yaml_block(
    fitted: FittedModel,
    joint: str,
    *,
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    sha256: str | None = None,
    **ranges,
) -> tuple[str, list[str], dict[str, object]]:
    """One joint of :func:`ros2_yaml_text`: the checked joint name, the comment lines and the
    joint's parameters (per-direction Coulomb and viscous friction of the projection)."""
    name = _check_joint(joint)
    if name == "joints":
        raise ExportError("joint name 'joints' is taken by the list of joints in the YAML")
    proj = _checked(fitted, "the per-direction Coulomb-viscous YAML", True, max_loss, ranges)
    lines = [
        *summary_lines(
            fitted, source, sha256, projection_rms=proj.rms_error, held=proj.rests_on_names
        ),
        *proj.summary(),
    ]
    write_lines_checked(lines, ())
    c, b = proj.coulomb, proj.viscous
    values = {
        "coulomb_positive": c["positive"],
        "coulomb_negative": c["negative"],
        "viscous_positive": b["positive"],
        "viscous_negative": b["negative"],
        "projection_rms_error": proj.rms_error,
    }
    params: dict[str, object] = {key: float(fmt_float(value, key)) for key, value in values.items()}
    params["source_model"] = model_name(fitted)
    return name, lines, params


#: The compensation law and units every ros2_control-style YAML states.
ROS2_LAW_LINES = (
    "tau_ff = coulomb_positive + viscous_positive * v (v > 0); "
    "-coulomb_negative + viscous_negative * v (v < 0)",
    "units: coulomb_* [N m] (magnitudes), viscous_* [N m s/rad], velocity [rad/s]",
)


def ros2_yaml_document(node: str, blocks: list[tuple[str, list[str], dict]]) -> str:
    """The YAML of :func:`ros2_yaml_block` s: ``#`` comment lines (each joint's, then the
    law), then ``<node>: ros__parameters: joints: [...]`` and a mapping per joint."""
    node = _check_node(node)
    names = [name for name, _, _ in blocks]
    if len(set(names)) != len(names):
        raise ExportError(f"a joint is named twice in {names}")
    lines: list[str] = []
    for name, block, _ in blocks:
        lines.extend([f"joint {name}:"] if len(blocks) > 1 else [])
        lines.extend(block)
    lines.extend(ROS2_LAW_LINES)
    params: dict[str, object] = {"joints": names}
    params.update({name: joint_params for name, _, joint_params in blocks})
    doc = {node: {"ros__parameters": params}}
    body = yaml.safe_dump(doc, sort_keys=False, default_flow_style=False, allow_unicode=False)
    return "".join(f"# {line}\n" for line in lines) + body


def ros2_yaml_text(
    fitted: FittedModel,
    joint: str = "joint",
    *,
    node: str = "friction_compensation",
    max_loss: float = DEFAULT_MAX_LOSS,
    source: str | None = None,
    sha256: str | None = None,
    **ranges,
) -> str:
    """A ROS 2 parameter file with per-direction Coulomb and viscous friction of the joint.

    The compensating torque is ``coulomb_positive + viscous_positive v`` for ``v > 0`` and
    ``-coulomb_negative + viscous_negative v`` for ``v < 0`` (``coulomb_*`` are magnitudes
    [N m], ``viscous_*`` in N m s/rad), under ``<node>: ros__parameters: <joint>:``. The
    document is written by :func:`yaml.safe_dump` under ``#`` comment lines; ``node`` must
    be a plain ROS 2 node name. Other arguments as for :func:`urdf_text`. Several joints in
    one file: :func:`fricid.export.robot.robot_ros2_yaml_text`.
    """
    _check_node(node)
    block = ros2_yaml_block(
        fitted, joint, max_loss=max_loss, source=source, sha256=sha256, **ranges
    )
    return ros2_yaml_document(node, [block])


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


def undetermined_held(fitted: FittedModel, target: str, **ranges) -> list[str]:
    """The parameters the trajectory does not determine
    (:func:`~fricid.export._common.undetermined_parameters`) that an export to ``target``
    holds or depends on: every one for C (the full model) and for a LuGre model's MJCF (its
    dcmotor holds sigma_0 and sigma_1); for a Coulomb-viscous projection (yaml, urdf, the
    MJCF of any other model) those that move it over the operating range
    (:func:`~fricid.export.projection.rests_on_names`: never a LuGre model's sigma_0 or
    sigma_1, which its steady state does not read). ``ranges`` as for :func:`urdf_text`."""
    names = undetermined_parameters(fitted)
    if not names or target not in DESCRIPTION_TARGETS or (target == "mjcf" and is_lugre(fitted)):
        return names
    X, _ = operating_grid(fitted, **ranges)
    return rests_on_names(fitted, X, target == "yaml")


def write_text(text: str, path: str | os.PathLike[str]) -> Path:
    """Write ``text`` to ``path`` atomically (nothing half-written on failure)."""
    from ..io.atomic import atomic_write

    path = ensure_out_file(path)
    with atomic_write(path, "w") as fh:
        fh.write(text)
    return path
