"""Raw joint logs to friction samples (BAS-RBFNN paper, section 2; RWSAVSBAS paper, 2.1).

>>> from fricid.extract import extract
>>> result = extract(logs, positions=centres, gravity="fit")     # doctest: +SKIP
>>> result.samples, result.by_direction, result.gravity          # doctest: +SKIP

Modules: :mod:`.segment` (constant-velocity segments, set-point clustering), :mod:`.steady`
(settling, outliers, saturation, rest), :mod:`.accumulate` (per-segment checks and statistics),
:mod:`.bins` (position bins, repetition averaging), :mod:`.gravity` (eq. 7 and 11),
:mod:`.joint_gravity` (eq. 7 with per-set-point friction, no pairing), :mod:`.separation`
(step 4: friction, gravity and the sample tables), :mod:`.torque_constant` (K of eq. 13 from
current and a torque sensor, or from a gravity load known from a URDF),
:mod:`.quality` (the per-set-point quality table and its warnings), :mod:`.gravity_check`
(does eq. 7 explain the position dependence?), :mod:`._gravity_mode` (which gravity mode, and
the note when gravity is not removed), :mod:`.pipeline` (:func:`extract`), :mod:`.result`
(what it returns), :mod:`.arm_gravity` (an arm's base gravity parameters and every joint's
per-set-point friction, jointly) and :mod:`.arm` (:func:`extract_arm`: every joint of a robot
log, gravity from the whole configuration).
"""

from __future__ import annotations

from .arm import ArmExtraction, extract_arm
from .arm_gravity import ArmGravityFit
from .bins import Cells, CellTable, Pooled, PositionBins, pool_cells
from .gravity import GravityFit, fit_gravity, separate
from .joint_gravity import JointGravityFit, fit_gravity_joint, moments
from .pipeline import GRAVITY_MODES, SPIKE_SIGMAS, Diagnostics, ExtractionResult, extract
from .quality import QUALITY_COLUMNS, SCATTER_RATIO, QualityTable, flag_scatter, warn_quality
from .segment import Segment, SegmentCounts, cluster, iter_segments
from .steady import OUTLIER_SIGMAS, SETTLE_SIGMAS, outliers, saturated, settled
from .torque_constant import (
    TorqueConstantFit,
    current_as_torque,
    fit_torque_constant,
    torque_constant_from_gravity,
)

__all__ = [
    "GRAVITY_MODES",
    "OUTLIER_SIGMAS",
    "QUALITY_COLUMNS",
    "SCATTER_RATIO",
    "SETTLE_SIGMAS",
    "SPIKE_SIGMAS",
    "ArmExtraction",
    "ArmGravityFit",
    "CellTable",
    "Cells",
    "Diagnostics",
    "ExtractionResult",
    "GravityFit",
    "JointGravityFit",
    "Pooled",
    "PositionBins",
    "QualityTable",
    "Segment",
    "SegmentCounts",
    "TorqueConstantFit",
    "cluster",
    "current_as_torque",
    "extract",
    "extract_arm",
    "fit_gravity",
    "fit_gravity_joint",
    "fit_torque_constant",
    "flag_scatter",
    "iter_segments",
    "moments",
    "outliers",
    "pool_cells",
    "saturated",
    "separate",
    "settled",
    "torque_constant_from_gravity",
    "warn_quality",
]
