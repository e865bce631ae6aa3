"""``fricid report``: an HTML and Markdown report of one identified model on one data set."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from ._app import app, console, err_console, handle_errors, plural
from ._paths import check_paths
from ._progress import QuietOption, tracker
from ._study_options import out_option, seed_option


@app.command("report")
@handle_errors
def report_command(
    model: Annotated[
        Path,
        typer.Argument(
            help="Model file (JSON, from `fricid fit`), or a whole-arm fit (from `fricid robot "
            "fit`)."
        ),
    ],
    samples: Annotated[
        Path | None,
        typer.Argument(
            help="Friction samples, CSV or Parquet; for a model from `fricid fit --trajectory`, "
            "the trajectory log (a fricid raw log); none for a whole-arm fit.",
            show_default=False,
        ),
    ] = None,
    heldout: Annotated[
        Path | None,
        typer.Argument(
            help="Trajectory models only: a second log the model was not identified from, "
            "for held-out validation (nothing is refitted).",
            show_default=False,
        ),
    ] = None,
    out: Annotated[
        Path | None,
        out_option(
            "Folder to write (created; files of an earlier report there are replaced). "
            "Default: <model>-report/ in the current directory."
        ),
    ] = None,
    velocity_unit: Annotated[
        str, typer.Option(help="Velocity unit of the figures: rad/s, deg/s, rpm or rev/s.")
    ] = "rad/s",
    bootstrap: Annotated[
        int,
        typer.Option(
            help="Bootstrap resamples for the RBF network's confidence intervals.", min=10
        ),
    ] = 200,
    seed: Annotated[int, seed_option("Seed of the bootstrap.")] = 0,
    validate: Annotated[
        bool,
        typer.Option(
            "--validate/--no-validate",
            help="Run leave-one-velocity-out validation for the trust section when the model "
            "file has none, or only a learned model's own cross-validation (when the problem "
            "is small enough: a few seconds for analytic models, up to about ten for learned "
            "ones, each fold retrained). The trust record `fricid fit` stored in the model "
            "file is read instead when it was computed on the same samples with the same "
            "options (--validate, the default, as fit computes it).",
        ),
    ] = True,
    log_format: Annotated[
        str,
        typer.Option(
            "--format", help="Trajectory models: the logs' format, as in fit --trajectory."
        ),
    ] = "table",
    reader_option: Annotated[
        list[str] | None,
        typer.Option(
            "--reader-option",
            metavar="KEY=VALUE",
            help="Trajectory models: a reader option KEY=VALUE for both logs, as given to "
            "`fricid fit --trajectory` (e.g. temperature=25 for a log without that column).",
        ),
    ] = None,
    quiet: QuietOption = False,
) -> None:
    """Write a report of MODEL on SAMPLES: first "Can I trust this?" (a one-line verdict, data
    quality per set-point, convergence, identifiability, held-out error against the
    measurement scatter, operating range), then parameters with their 95 % intervals, fit
    metrics, measured against predicted friction over velocity, residuals against each input
    and the optimiser's convergence. The verdict line is printed on stderr too.

    The verdict is the fit's trust record: the one the model file carries (from
    `fricid fit` or the fleet) when it was computed on the same samples with the same
    options, else computed now; the report renders it and computes no verdict of its own.

    A whole-arm fit (`fricid robot fit`) needs no data: its report has a row per joint (family,
    held-out error over the noise, verdict and reasons), every joint's friction curve, the
    friction parameters with their intervals, the base inertial parameters, the consistency
    step and each link's mass, centre of mass and inertia.

    A model identified from a trajectory (`fricid fit --trajectory`) takes its log instead of
    samples, and optionally a second log (HELDOUT): the report then shows the measured and
    predicted torque over time, the residuals over time and against velocity, the friction's
    hysteresis at the velocity reversals (against velocity, and against the position since
    the reversal: pre-sliding), the error on the held-out log, and the parameters.

    Outputs in the folder: report.html (self-contained), report.md, one CSV per table and one
    PNG per figure, written all or nothing. Progress goes to stderr (the part being built:
    the trust record and its validation, each figure, the parameters, writing; no time left,
    the parts differ too much in cost to time one by another); --quiet: none.
    """
    from ..errors import ConfigError
    from ..fitted import FittedModel
    from ..identify.trust import assess_trust
    from ..report import model_report, write_document
    from ..units import UNITS

    if velocity_unit not in UNITS["velocity"]:
        raise ConfigError(
            f"--velocity-unit must be one of: {', '.join(UNITS['velocity'])}; got '{velocity_unit}'"
        )
    inputs = {"MODEL": model, "SAMPLES": samples, "HELDOUT": heldout}
    check_paths(inputs={k: v for k, v in inputs.items() if v is not None}, out_dirs={"--out": out})
    out = out or Path(f"{model.stem}-report")
    arm = _arm_fit(model)
    if arm is not None:
        if samples is not None:
            raise ConfigError(
                "a whole-arm fit's report takes no data file: the fit file holds what it shows"
            )
        _arm_report(arm, out, quiet)
        return
    if samples is None:
        raise ConfigError(
            "missing SAMPLES: the friction samples (or, for a model from a trajectory, its log) "
            "the report shows the model on"
        )
    fitted = FittedModel.load(model)
    from ..identify.trajectory_check import is_trajectory_model

    if is_trajectory_model(fitted):
        from .trajectory import parse_reader_options

        reader = (log_format, parse_reader_options(reader_option))
        _trajectory_report(fitted, samples, heldout, out, quiet, reader)
        return
    if reader_option or log_format != "table":
        raise ConfigError(
            "--format and --reader-option read a trajectory log; this model "
            f"('{fitted.model}') was fitted to friction samples"
        )
    if heldout is not None:
        raise ConfigError(
            "a second data file (HELDOUT) is for a model identified from a trajectory; this "
            f"model ('{fitted.model}') was fitted to friction samples"
        )
    data = _read_samples(samples)
    with tracker("report", None, quiet=quiet, timed=False) as track:

        def progress(part: str) -> None:
            track.stage(f"report: {part}")

        progress("the trust record (held-out validation when the model file has none)")
        trust = assess_trust(fitted, data, validate=validate)
        doc = model_report(
            fitted,
            data,
            trust=trust,
            velocity_unit=velocity_unit,
            bootstrap=bootstrap,
            seed=seed,
            samples_label=samples.name,
            progress=progress,
        )
        progress(f"writing {out}/")
        path = write_document(doc, out)
    console.print(str(path), highlight=False, soft_wrap=True)
    err_console.print(str(doc.meta["trust"]), markup=False, highlight=False, soft_wrap=True)
    if "torque unit" in doc.meta:
        err_console.print(
            str(doc.meta["torque unit"]), markup=False, highlight=False, soft_wrap=True
        )
    err_console.print(_wrote(doc, out))


def _arm_fit(path: Path):
    """The whole-arm fit ``path`` holds (its kind ``fricid-arm``), else None."""
    from ..errors import DataError
    from ..fitted.arm import ARM_KIND, ArmFit
    from ..io._jsonfile import read_json

    try:
        doc = read_json(path, what="model file")
    except DataError:
        return None  # the model file's own reader says what is wrong
    if isinstance(doc, dict) and doc.get("kind") == ARM_KIND:
        return ArmFit.from_dict(doc, source=str(path))
    return None


def _arm_report(fit, out: Path, quiet: bool) -> None:
    """The report of a whole-arm fit: a row per joint."""
    from ..report import arm_report, write_document

    with tracker("report", None, quiet=quiet, timed=False) as track:
        track.stage("report: the joints, their friction and the inertial parameters")
        doc = arm_report(fit)
        track.stage(f"report: writing {out}/")
        path = write_document(doc, out)
    console.print(str(path), highlight=False, soft_wrap=True)
    for joint in fit.joints:
        check = fit.validation.get(joint, {})
        reasons = "; ".join(map(str, check.get("reasons", [])))
        err_console.print(
            f"{joint}: {fit.verdict(joint)}" + (f" ({reasons})" if reasons else ""),
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
    err_console.print(_wrote(doc, out))


def _read_samples(path: Path):
    """Friction samples, or a one-line error that says what a raw log is for here."""
    from ..errors import DataError
    from ..io import read_samples

    try:
        return read_samples(path)
    except DataError as exc:
        if "fricid-rawlog" not in exc.message:
            raise
        raise DataError(
            "this is a raw joint log, not friction samples: `fricid extract` turns it into "
            "samples for this model, or `fricid fit --trajectory` identifies a model from it "
            "(whose report takes the log)",
            file=path,
        ) from None


def _trajectory_report(
    fitted, log_path: Path, heldout: Path | None, out: Path, quiet: bool, reader: tuple
):
    """The report of a model from a trajectory on its log (and a held-out one); ``reader``:
    the reader's name and options for both."""
    from ..identify.trajectory_check import predict_trajectory
    from ..report import write_document
    from ..report.trajectory import output_error_note, trajectory_report
    from .trajectory import read_trajectory_log

    with tracker("report", None, quiet=quiet, timed=False) as track:

        def progress(part: str) -> None:
            track.stage(f"report: {part}")

        progress(f"the model along {log_path.name}")
        prediction = predict_trajectory(fitted, read_trajectory_log(log_path, *reader))
        held = None
        if heldout is not None:
            progress(f"the model along the held-out {heldout.name}")
            held = predict_trajectory(fitted, read_trajectory_log(heldout, *reader))
        doc = trajectory_report(
            fitted,
            prediction,
            heldout=held,
            log_label=log_path.name,
            heldout_label=heldout.name if heldout is not None else "",
            progress=progress,
        )
        progress(f"writing {out}/")
        path = write_document(doc, out)
    console.print(str(path), highlight=False, soft_wrap=True)
    for label, pred in ((log_path.name, prediction), (getattr(heldout, "name", ""), held)):
        if pred is None:
            continue
        err_console.print(
            _error_line(label, pred.metrics()),
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
    note = output_error_note(fitted)
    if note:  # the errors above are not the fit's own residual
        err_console.print(f"note: {note}", markup=False, highlight=False, soft_wrap=True)
    if held is not None:  # the verdict graded on the held-out log, or why not
        lines = [f"held-out {doc.meta['held-out grading']}"]
        if "torque scatter of the held-out log [N m]" in doc.meta:
            lines.append(str(doc.meta["trust"]))
        for line in lines:
            err_console.print(line, markup=False, highlight=False, soft_wrap=True)
    err_console.print(_wrote(doc, out))


def _error_line(label: str, m: dict) -> str:
    """A log's torque errors on one line: the raw one, where it slides, low-passed (those
    that exist)."""
    parts = [
        f"{label}: RMS torque error {m['rmse']:.4g} N m ({100 * m['relative']:.3g} % of the RMS "
        f"torque {m['signal_rms']:.4g} N m)"
    ]
    if m["n_sliding"] > 0:
        parts.append(f"where it slides {m['rmse_sliding']:.4g} N m")
    if math.isfinite(m["rmse_filtered"]):
        parts.append(f"low-passed at the fit's cut-off {m['rmse_filtered']:.4g} N m")
    return ", ".join(parts)


def _wrote(doc, out: Path) -> str:
    """What a report wrote: ``wrote 1 table and 3 figures into out/``."""
    return (
        f"wrote {plural(len(doc.tables()), 'table')} and "
        f"{plural(len(doc.figures()), 'figure')} into {out}/"
    )
