"""One joint, from its raw log to fitted models: ``fricid extract`` then ``fricid fit``; or
one whole robot, from its log of all joints and its URDF (:func:`run_robot`).

This module is longer than 500 lines because the single-joint and the whole-robot paths that
the commands and the fleet share belong in the one workflow unit of the layer table.

The single-joint commands and ``fricid fleet`` run these functions, so a joint identified in a
fleet is identified exactly as it would be by hand (DESIGN.md, "The flow of data"):

>>> from fricid.workflow import run_joint
>>> run = run_joint("log.parquet", models=("stribeck", "vlt"), seed=0)  # doctest: +SKIP
>>> run.fits["vlt"].report()                                             # doctest: +SKIP

:func:`load_joint` reads a log with one of the readers of :mod:`fricid.io.registry`
(:data:`~fricid.io.READERS`) and extracts its friction samples;
:func:`select_samples` picks the rows a model is fitted to; :func:`fit_samples` fits one model
as ``fricid fit`` does (the fit, its ``--validate`` validation, then the trust record of
:func:`fricid.identify.trust.assess_trust`, stored in the model); :func:`run_joint` does all
three and fits every model, isolating a model whose fit fails from the others.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import ConfigError, DataError, FricidError
from .extract import GRAVITY_MODES, ExtractionResult, extract
from .fitted import FittedModel
from .io.registry import check_keys, check_reader, gives_samples, open_log
from .samples import FrictionSamples, RawLog

if TYPE_CHECKING:
    from .identify.trust import Trust

__all__ = [
    "DIRECTIONS",
    "EXTRACT_OPTIONS",
    "SAMPLE_SETS",
    "JointData",
    "JointRun",
    "fit_samples",
    "load_joint",
    "run_joint",
    "run_robot",
    "select_direction",
    "select_samples",
]

#: Keyword options of :func:`fricid.extract.extract` a caller may set (SI units).
EXTRACT_OPTIONS: tuple[str, ...] = (
    "positions",
    "bin_halfwidth",
    "median_window",
    "gravity",
    "velocity_tolerance",
    "settle_time",
    "min_samples",
    "velocity_rtol",
    "temperature_atol",
)

#: Which samples a model is fitted to: ``auto`` (the per-direction samples for an ``*_asym``
#: model, else the combined ones), ``combined`` (direction 0, eq. 11) or ``by_direction``.
SAMPLE_SETS: tuple[str, ...] = ("auto", "combined", "by_direction")

#: ``direction`` choices and the sample directions each keeps (None: all of them).
DIRECTIONS: dict[str, list[int] | None] = {
    "all": None,
    "combined": [0],
    "both": [-1, 1],
    "pos": [1],
    "neg": [-1],
}


@dataclass(frozen=True, eq=False)
class JointData:
    """The friction samples of one joint's log.

    Attributes
    ----------
    samples : FrictionSamples
        The combined samples (direction 0, eq. 11 of the BAS-RBFNN paper); for a reader that
        gives samples directly (a folder of steady-state EPOS recordings or one of them, a
        MATLAB table of means), the per-direction operating points as recorded.
    by_direction : FrictionSamples
        The per-direction samples (+1 and -1).
    extraction : ExtractionResult or None
        What :func:`fricid.extract.extract` returned (diagnostics, gravity fit), or None when
        the reader gave samples directly.
    """

    samples: FrictionSamples
    by_direction: FrictionSamples
    extraction: ExtractionResult | None = None


@dataclass(frozen=True, eq=False)
class JointRun:
    """The outcome of :func:`run_joint`.

    Attributes
    ----------
    data : JointData
        The extracted samples.
    fits : dict of str to FittedModel
        Model name -> fitted model, for the models whose fit succeeded.
    errors : dict of str to FricidError
        Model name -> the error of a model whose fit failed.
    used : dict of str to FrictionSamples
        Model name -> the samples that model was fitted to.
    extract_seconds : float
        Wall time of reading and extraction [s].
    fit_seconds : dict of str to float
        Model name -> wall time of its fit (validation and trust included) [s].
    trust : dict of str to Trust
        Model name -> its trust record (:func:`fricid.identify.trust.assess_trust`, also in
        the model's ``trust``).
    """

    data: JointData
    fits: dict[str, FittedModel] = field(default_factory=dict)
    errors: dict[str, FricidError] = field(default_factory=dict)
    used: dict[str, FrictionSamples] = field(default_factory=dict)
    extract_seconds: float = 0.0
    fit_seconds: dict[str, float] = field(default_factory=dict)
    trust: dict[str, Trust] = field(default_factory=dict)


def _design_hints(log: RawLog) -> dict[str, Any]:
    """The extraction hints ``fricid simulate`` records with a log (``meta["design"]``),
    checked: they come from the file, so a bad one is a DataError naming the file and key."""
    meta = log.meta if isinstance(log.meta, Mapping) else {}
    hints = meta.get("design", {})
    if not isinstance(hints, Mapping):
        return {}
    hints = dict(hints)

    def bad(key: str, what: str) -> DataError:
        shown = repr(hints[key])
        shown = shown if len(shown) <= 60 else shown[:57] + "..."
        return DataError(
            f"metadata 'design.{key}' must be {what}, got {shown}",
            file=log.source,
            column=f"meta.design.{key}",
        )

    if "positions_rad" in hints:
        value = hints["positions_rad"]
        if not isinstance(value, list) or not all(
            isinstance(p, int | float) and not isinstance(p, bool) for p in value
        ):
            raise bad("positions_rad", "a list of numbers [rad]")
        positions = np.asarray(value, dtype=float)
        if positions.size == 0 or not np.isfinite(positions).all():
            raise bad("positions_rad", "a non-empty list of finite angles [rad]")
        if np.unique(positions).size != positions.size:
            raise bad("positions_rad", "distinct angles [rad]")
    halfwidth = hints.get("bin_halfwidth_rad")
    if halfwidth is not None and not (
        isinstance(halfwidth, int | float)
        and not isinstance(halfwidth, bool)
        and np.isfinite(halfwidth)
        and halfwidth > 0
    ):
        raise bad("bin_halfwidth_rad", "a positive angle [rad]")
    if "gravity" in hints and hints["gravity"] not in GRAVITY_MODES:
        raise bad("gravity", f"one of {', '.join(GRAVITY_MODES)}")
    return hints


def _extract_stream(
    logs: Iterable[RawLog],
    head: list[RawLog],
    options: Mapping[str, Any],
    on_chunk: Callable[[], None] | None,
) -> JointData:
    """Extract a log stream whose first chunk, read from ``logs``, is ``head.pop()``.

    Unset ``positions``, ``bin_halfwidth`` and ``gravity`` come from the design recorded with
    the log (as ``fricid extract`` does); ``gravity`` then defaults to ``"fit"`` with position
    bins and ``"auto"`` without (gravity removed by the joint fit when the log has a position
    channel; otherwise, or when eq. 7 of the BAS-RBFNN paper is not determined, not removed,
    with a note saying so).
    """
    opts = dict(options)
    hints = _design_hints(head[0])
    if opts.get("positions") is None and "positions_rad" in hints:
        opts["positions"] = np.asarray(hints["positions_rad"], dtype=float)
        if opts.get("bin_halfwidth") is None:
            opts["bin_halfwidth"] = hints.get("bin_halfwidth_rad")
    if opts.get("gravity") is None:
        with_bins = opts.get("positions") is not None
        opts["gravity"] = hints.get("gravity", "fit" if with_bins else "auto")
    if opts.get("positions") is not None:
        opts["positions"] = np.asarray(opts["positions"], dtype=float)

    def tick(chunk: RawLog) -> RawLog:  # holds no chunk while the next one is read
        if on_chunk is not None:
            on_chunk()
        return chunk

    result = extract(map(tick, _chain(head, logs)), **opts)
    return JointData(result.samples, result.by_direction, result)


def _chain(head: list[RawLog], rest: Iterable[RawLog]) -> Iterator[RawLog]:
    while head:
        yield head.pop(0)
    yield from rest


def load_joint(
    path: str | os.PathLike[str],
    reader: str = "table",
    *,
    reader_options: Mapping[str, Any] | None = None,
    extract_options: Mapping[str, Any] | None = None,
    chunk_rows: int = 1_000_000,
    on_chunk: Callable[[], None] | None = None,
    chunk_map: Callable[[RawLog], RawLog] | None = None,
) -> JointData:
    """Read a joint's log and extract its friction samples.

    Parameters
    ----------
    path : str or path-like
        The log: a fricid raw log (``table``), any CSV/Parquet table (``generic``), a ROS 2
        bag or MCAP file (``rosbag``), an EPOS recorder CSV or a folder of steady-state EPOS
        recordings (``epos``), a folder of per-channel files (``channels``), a MATLAB file
        (``mat``); opened by :func:`fricid.io.open_log`.
    reader : str
        One of :data:`fricid.io.READERS`.
    reader_options : Mapping, optional
        The reader's options (:data:`fricid.io.READER_OPTIONS`, SI units), e.g. for
        ``generic`` ``{"columns": {"time": "t", "velocity": "dq", "torque": "tau"},
        "units": {"velocity": "deg/s"}, "temperature": 25.0}``.
    extract_options : Mapping, optional
        Options of :func:`fricid.extract.extract` (:data:`EXTRACT_OPTIONS`). Unset position
        bins and gravity mode come from the design a simulated log records.
    chunk_rows : int
        Rows read at a time from a ``table`` log or a bag (bounded memory).
    on_chunk : callable, optional
        Called once per chunk read (progress).
    chunk_map : callable, optional
        Applied to every chunk read before extraction (e.g.
        :func:`fricid.extract.torque_constant.current_as_torque`, to extract in amperes).

    Returns
    -------
    JointData

    Raises
    ------
    ConfigError
        An unknown reader or option.
    DataError
        Unreadable or unusable data (naming file, row and column where known).
    """
    path = Path(path)
    ropts = dict(reader_options or {})
    eopts = {k: v for k, v in dict(extract_options or {}).items() if v is not None}
    check_reader(reader, ropts)
    check_keys(eopts, EXTRACT_OPTIONS, "extraction option")
    if gives_samples(reader, path, ropts) and eopts:
        what = (
            "steady-state EPOS recordings give one operating point per file"
            if reader == "epos"
            else f"reader '{reader}' gives friction samples directly"
        )
        raise ConfigError(f"{what}; extraction options ({', '.join(eopts)}) do not apply")
    opened = open_log(path, reader, ropts, chunk_rows=chunk_rows)
    if isinstance(opened, FrictionSamples):
        return JointData(opened, opened, None)
    if chunk_map is not None:
        opened = map(chunk_map, opened)
    head = [next(opened, None)]  # the list alone holds it: freed once extracted
    if head[0] is None:  # pragma: no cover - iter_rawlog raises on an empty log
        raise DataError("the log has no rows", file=path)
    return _extract_stream(opened, head, eopts, on_chunk)


def select_direction(samples: FrictionSamples, direction: str = "all") -> FrictionSamples:
    """The rows of ``samples`` for a ``direction`` choice (:data:`DIRECTIONS`)."""
    if direction not in DIRECTIONS:
        raise ConfigError(f"direction must be one of: {', '.join(DIRECTIONS)}; got '{direction}'")
    keep = DIRECTIONS[direction]
    if keep is None:
        return samples
    mask = np.isin(samples.direction, keep)
    if not mask.any():
        raise DataError(
            f"no samples with direction {direction} (the samples have directions "
            f"{samples.directions()})",
            file=samples.source,
        )
    return samples.subset(mask)


def select_samples(
    data: JointData, model: str, *, samples: str = "auto", direction: str = "all"
) -> FrictionSamples:
    """The samples ``model`` is fitted to (:data:`SAMPLE_SETS`, then :data:`DIRECTIONS`)."""
    from .models import get_model

    if samples not in SAMPLE_SETS:
        raise ConfigError(f"samples must be one of: {', '.join(SAMPLE_SETS)}; got '{samples}'")
    if samples == "auto":  # the selection tries the per-direction families too
        by_direction = model.strip().lower() == "auto" or get_model(model).is_asymmetric
        samples = "by_direction" if by_direction else "combined"
    chosen = data.by_direction if samples == "by_direction" else data.samples
    return select_direction(chosen, direction)


def fit_samples(
    samples: FrictionSamples,
    model: str,
    method: str | None = "lm",
    *,
    fixed: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    seed: int = 0,
    max_evals: int | None = None,
    validate: str | None = None,
    loss: str = "l2",
    f_scale: float | None = None,
    weights: str = "none",
    intervals: str = "auto",
    settings: Mapping[str, Any] | None = None,
    callback: Callable[[Any], Any] | None = None,
    on_stage: Callable[[str], None] | None = None,
) -> tuple[FittedModel, Trust]:
    """Fit one model to samples as ``fricid fit`` does: fit, validate, assess trust.

    Parameters
    ----------
    samples : FrictionSamples
    model, method, fixed, bounds, seed, max_evals, loss, f_scale, weights, intervals, settings
        Passed to :func:`fricid.identify.fit` (``model="auto"``: ``validate`` is its scheme).
    validate : str, optional
        Held-out validation of the fitted model (``"lovo"``, ``"kfold:K"``;
        :func:`fricid.identify.validate`), each fold fitted with the same options; stored as
        the model's ``validation``.
    callback : callable, optional
        The optimiser's callback (analytic fits; progress).
    on_stage : callable, optional
        Called with a label when the validation or the trust assessment starts (progress).

    Returns
    -------
    FittedModel
        With ``validation`` (when asked) and ``trust`` (the record's ``to_dict()``).
    Trust
        The record of :func:`fricid.identify.trust.assess_trust` (default options: a
        leave-one-velocity-out run there when the fit brought no validation and the problem
        is small enough).
    """
    from .identify import fit
    from .identify import validate as validate_model
    from .identify.trust import assess_trust

    key = model.strip().lower()
    extra = dict(settings or {})
    if key == "auto" and validate:
        extra["scheme"] = validate
    options: dict[str, Any] = {"loss": loss, "f_scale": f_scale, "weights": weights}
    common = dict(fixed=fixed, bounds=bounds, seed=seed, max_evals=max_evals, **options)
    fitted = fit(
        samples,
        model,
        method,
        settings=extra or None,
        intervals=intervals,
        callback=callback,
        **common,
    )
    if validate and key != "auto":
        if on_stage is not None:
            on_stage(f"validating {fitted.model} ({validate})")
        fitted.validation = validate_model(
            samples,
            fitted.model,
            validate,
            method,
            settings=settings or None,
            intervals=intervals,
            **common,
        ).to_dict()
    if on_stage is not None:
        on_stage(f"assessing trust in {fitted.model}")
    trust = assess_trust(fitted, samples)
    fitted.trust = trust.to_dict()
    return fitted, trust


def run_joint(
    path: str | os.PathLike[str],
    *,
    reader: str = "table",
    reader_options: Mapping[str, Any] | None = None,
    extract_options: Mapping[str, Any] | None = None,
    models: Sequence[str] = ("stribeck",),
    method: str = "lm",
    seed: int = 0,
    samples: str = "auto",
    direction: str = "all",
    fixed: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    max_evals: int | None = None,
    validate: str | None = None,
    loss: str = "l2",
    f_scale: float | None = None,
    weights: str = "none",
    intervals: str = "auto",
    chunk_rows: int = 1_000_000,
) -> JointRun:
    """Identify one joint: :func:`load_joint`, then :func:`fit_samples` per model.

    Parameters
    ----------
    path, reader, reader_options, extract_options, chunk_rows
        See :func:`load_joint`.
    models : sequence of str
        Model names (``fricid.models.MODELS``, ``*_asym`` for per-direction parameters).
    method, seed, max_evals : str, int, int or None
        Passed to :func:`fricid.identify.fit`; every model is fitted with the same ``seed``,
        so the run is reproducible bit for bit.
    samples, direction : str
        Which samples each model is fitted to (:func:`select_samples`).
    fixed, bounds : Mapping, optional
        Parameters held fixed / search ranges (SI), applied to every model that has the
        parameter named.
    validate, loss, f_scale, weights, intervals
        As ``fricid fit`` takes them (``--validate``, ``--loss``, ``--f-scale``,
        ``--weights``, ``--intervals``; :func:`fit_samples`), so a joint identified here and
        by ``fricid fit`` gives the same model, held-out error and trust verdict.

    Returns
    -------
    JointRun
        A model whose fit fails (a :class:`~fricid.errors.FricidError`) is in ``errors``; the
        other models are still fitted, each with its trust record.

    Raises
    ------
    FricidError
        The log cannot be read or extracted (nothing can be fitted then).
    """
    from .models import get_model

    if not models:
        raise ConfigError("run_joint needs at least one model")
    fixed_models = [m for m in models if m.strip().lower() != "auto"]
    names = {n for m in fixed_models for n in get_model(m).param_names}
    for what, given in (("fixed", fixed), ("bounds", bounds)):
        unknown = sorted(set(given or {}) - names)
        if unknown:
            raise ConfigError(
                f"{what} names '{unknown[0]}', a parameter of none of the models "
                f"{', '.join(models)}; their parameters: {', '.join(sorted(names))}"
            )
    t0 = time.perf_counter()
    data = load_joint(
        path,
        reader,
        reader_options=reader_options,
        extract_options=extract_options,
        chunk_rows=chunk_rows,
    )
    run = JointRun(data, extract_seconds=time.perf_counter() - t0)
    for name in models:
        t1 = time.perf_counter()
        try:
            own = (
                {*(fixed or {}), *(bounds or {})}
                if name.strip().lower() == "auto"
                else set(get_model(name).param_names)
            )
            used = select_samples(data, name, samples=samples, direction=direction)
            run.used[name] = used
            run.fits[name], run.trust[name] = fit_samples(
                used,
                name,
                method,
                fixed={k: v for k, v in (fixed or {}).items() if k in own},
                bounds={k: v for k, v in (bounds or {}).items() if k in own},
                seed=seed,
                max_evals=max_evals,
                validate=validate,
                loss=loss,
                f_scale=f_scale,
                weights=weights,
                intervals=intervals,
            )
        except FricidError as exc:
            run.errors[name] = exc
        run.fit_seconds[name] = time.perf_counter() - t1
    return run


def run_robot(
    log: str | os.PathLike[str],
    urdf: str | os.PathLike[str],
    *,
    joints: Sequence[str] | None = None,
    friction: str | Mapping[str, str] = "stribeck_asym",
    validate: str | os.PathLike[str] | None = None,
    consistent: bool = True,
    encoder_counts: int | None = None,
    cutoff: float | None = None,
):
    """Identify a whole robot as ``fricid robot fit`` does: the URDF's rigid-body model
    (:meth:`fricid.robot.RigidBodyModel.from_urdf`), the log of its joints
    (:func:`fricid.io.read_robot_log`), then
    :func:`fricid.identify.dynamic.arm.fit_arm`.

    Parameters
    ----------
    log, urdf : path-like
        The log of all joints (CSV, Parquet, ROS 2 bag, folder) and the robot's URDF.
    joints : sequence of str, optional
        The joints to identify (default: the URDF's movable joints).
    friction, consistent, encoder_counts, cutoff
        As :func:`~fricid.identify.dynamic.arm.fit_arm` takes them.
    validate : path-like, optional
        A second log for held-out validation (default: the last quarter of ``log``).

    Returns
    -------
    fricid.fitted.arm.ArmFit
    """
    from .identify.dynamic.arm import fit_arm
    from .io import read_robot_log
    from .robot import RigidBodyModel

    model = RigidBodyModel.from_urdf(urdf, list(joints) if joints else None)
    data = read_robot_log(log, joints=list(model.joints))
    second = read_robot_log(validate, joints=list(model.joints)) if validate else None
    return fit_arm(
        data,
        model,
        friction=friction,
        consistent=consistent,
        encoder_counts=encoder_counts,
        cutoff=cutoff,
        validate=second,
        urdf=Path(urdf).name,
    )
