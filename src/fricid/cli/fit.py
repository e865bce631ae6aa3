"""``fricid fit``: identify a friction model from samples."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ._app import app, console, err_console, handle_errors
from ._options import (
    BoundOption,
    DirectionOption,
    FixOption,
    LogFormatOption,
    MaxEvalsOption,
    SeedOption,
    out_option,
    parse_assignments,
    parse_ranges,
)
from ._paths import check_paths, read_samples_file
from ._progress import QuietOption, fit_progress
from ._trust_text import heldout_lines, trust_lines


def _method_help() -> str:
    from ..identify.static.varpro import SUMMARY
    from ..optim import METHODS

    items = [f"{name}: {cls.summary}" for name, cls in METHODS.items()]
    return "; ".join([*items, f"varpro: {SUMMARY}"])


def _trajectory_ranges() -> str:
    """Why a trajectory fit takes no --bound or --fix: its search ranges are its own."""
    from ..identify.dynamic._filtered import LOG_BOX

    (a, b), (c, d) = LOG_BOX["sigma_0"], LOG_BOX["sigma_1"]
    return (
        f"a trajectory fit searches its own ranges: LuGre's sigma_0 from 1e{a:g} to 1e{b:g} "
        f"N m/rad and sigma_1 from 1e{c:g} to 1e{d:g} N m s/rad, the levels and J from the "
        "log's torques; a parameter that ends at an edge of its range is marked not determined"
    )


@app.command("fit")
@handle_errors
def fit_command(
    samples: Annotated[
        Path,
        typer.Argument(
            help="Friction samples, CSV or Parquet (from `fricid extract`).",
        ),
    ],
    model: Annotated[
        str,
        typer.Option(
            "--model",
            "-m",
            help=(
                "Model: coulomb_viscous (Coulomb plus viscous), stribeck (with the Stribeck "
                "dip at low speed), msk (Coulomb growing with the joint's load), vlt (load and "
                "temperature dependent), stribeck_temp (stribeck whose levels follow "
                "temperature); append _asym for parameters per direction; rbf, the RBF neural "
                "network (BAS-RBFNN paper eq. 14-15; --method lsq, bas for "
                "BAS-RBFNN or ga for GA-RBFNN); hybrid, an analytic backbone plus an RBF "
                "residual (the learned model to start with: nearest the noise floor on "
                "held-out laws, physics outside the data); gp, a Gaussian process; or "
                "auto: every family the data can support, "
                "chosen by held-out error (leave one velocity level out, or --validate)."
            ),
        ),
    ] = "stribeck",
    method: Annotated[
        str | None,
        typer.Option(
            help="Optimiser (see `fricid methods`): lm, varpro (exact optimum by variable "
            "projection), trf, bas, vsbas, ibas, rwsavsbas, ga, de, cmaes, bas+lm, ... "
            "Default: lm for the analytic models (and --trajectory), lsq for rbf and hybrid "
            "(their trainers: lsq, bas or ga)."
        ),
    ] = None,
    fix: FixOption = None,
    bound: BoundOption = None,
    seed: SeedOption = 0,
    max_evals: MaxEvalsOption = None,
    centers: Annotated[
        int | None,
        typer.Option(
            help="rbf, hybrid: number of Gaussian units (hidden layer); default chosen with "
            "the widths and the ridge penalty by cross-validation (random folds and whole "
            "speed levels held out)."
        ),
    ] = None,
    inputs: Annotated[
        str | None,
        typer.Option(
            help="rbf, hybrid: input columns, a comma list of velocity, load, temperature; "
            "default the measured ones."
        ),
    ] = None,
    learned: Annotated[
        bool,
        typer.Option(
            "--learned",
            help="auto: try the learned families too (rbf, hybrid); slower, each is "
            "retrained for every held-out fold.",
        ),
    ] = False,
    backbone: Annotated[
        str | None,
        typer.Option(
            help="hybrid: the analytic backbone (e.g. stribeck_asym); default the family the "
            "data support with the smallest BIC, temperature variants (*_temp) included."
        ),
    ] = None,
    direction: DirectionOption = "all",
    validate: Annotated[
        str | None,
        typer.Option(
            "--validate",
            help=(
                "Held-out validation: lovo (leave one velocity level out, both directions "
                "together) or kfold[:K] (default K 5). Prints the held-out RMSE beside the "
                "measurement scatter with a verdict, and saves it in the model file."
            ),
        ),
    ] = None,
    loss: Annotated[
        str,
        typer.Option(
            "--loss",
            help=(
                "l2 (least squares), or soft_l1 or huber: robust losses for samples with "
                "spikes, whose scale is the measurement scatter (or --f-scale)."
            ),
        ),
    ] = "l2",
    f_scale: Annotated[
        float | None,
        typer.Option("--f-scale", help="Scale of the robust loss [N m] (default: the scatter)."),
    ] = None,
    weights: Annotated[
        str,
        typer.Option(
            "--weights",
            help=(
                "none, or std: weighted least squares with 1/se^2 from the samples' own "
                "standard errors (std / sqrt(count), or repeated runs)."
            ),
        ),
    ] = "none",
    intervals: Annotated[
        str,
        typer.Option(
            "--intervals",
            help="95 % intervals of the parameters: auto (profile likelihood inside the search "
            "box where it applies), profile, jacobian or none.",
        ),
    ] = "auto",
    out: Annotated[
        Path | None,
        out_option(
            "Model file to write (JSON). Default: <samples>.<model>.json in the current directory."
        ),
    ] = None,
    quiet: QuietOption = False,
    trajectory: Annotated[
        bool,
        typer.Option(
            "--trajectory",
            help="SAMPLES is a raw log of any motion: identify lugre (or lugre_asym, its "
            "levels per direction; dahl, stribeck, coulomb_viscous) with J and gravity from it.",
        ),
    ] = False,
    log_format: LogFormatOption = "table",
    route: Annotated[
        str,
        typer.Option(
            "--route",
            help="--trajectory, lugre: filtered (every parameter by the parallel-filtered "
            "equation error), two_stage or joint (simulation error), presliding (sigma_0 and "
            "sigma_1 from a log that never slides; taken by default for such a log).",
        ),
    ] = "filtered",
    reader_option: Annotated[
        list[str] | None,
        typer.Option(
            "--reader-option", metavar="KEY=VALUE", help="--trajectory: a reader option KEY=VALUE."
        ),
    ] = None,
    encoder_counts: Annotated[
        float | None,
        typer.Option(
            "--encoder-counts",
            help="--trajectory: the encoder's counts per revolution (default: read from the "
            "log's position steps; recorded in the model file).",
        ),
    ] = None,
) -> None:
    """Identify a friction model from samples (or, with --trajectory, a log) and write it as a
    JSON model file.

    One identification for every kind: analytic laws by least squares (--model stribeck, vlt,
    ...), learned models (--model rbf, hybrid, gp), the family chosen by held-out error
    (--model auto), and friction with inertia and gravity from any trajectory
    (--trajectory).

    Prints a least-squares fit report: method, evaluations and convergence status; data
    points, variables, chi-square (SSE [N^2 m^2]), reduced chi-square, AIC, BIC, R^2; each
    parameter with its standard error, 95 % confidence interval and start, flagged at a
    boundary, at its initial value or not determined; correlations above 0.1. The RBF network
    (--model rbf) goes through the same identification and prints its network instead.
    Then the goodness of fit a user can compare: RMSE beside the measurement scatter, R^2 of
    the friction's magnitude per direction (the R-squared above is the BAS-RBFNN paper's
    Table 1 fitness, of the signed friction, which flatters per-direction data); with
    --validate or --model auto, the held-out RMSE and a verdict; with auto, the candidates
    compared. Last, [[Trust]]: the trust verdict (held-out error from
    --validate, else leave one velocity level out run there when small enough, else in-sample,
    labelled), saved in the model file, where `fricid report` on the same samples reads it.
    Warnings print as one line each on stderr and are saved in the model file
    (provenance "warnings"). Progress goes to stderr: a bar on a terminal, otherwise a line
    per tenth of the evaluation budget with the time left (population methods) or every few
    seconds; --quiet: none.
    """
    key = model.strip().lower()
    rbf = key in ("rbf", "hybrid")
    method = method or ("lsq" if rbf else "lm")
    if trajectory:  # delegated (cli/trajectory.py)
        from ..errors import ConfigError
        from .trajectory import parse_reader_options, run_trajectory

        samples_only = {
            "--validate": validate,
            "--loss": None if loss == "l2" else loss,
            "--f-scale": f_scale,
            "--weights": None if weights == "none" else weights,
            "--intervals": None if intervals == "auto" else intervals,
            "--direction": None if direction == "all" else direction,
            "--fix": fix or None,
            "--bound": bound or None,
            "--centers": centers,
            "--inputs": inputs,
            "--learned": learned or None,
            "--backbone": backbone,
        }
        ignored = [flag for flag, value in samples_only.items() if value is not None]
        if ignored:
            reasons = []
            if "--validate" in ignored:
                reasons.append(
                    "a trajectory model is validated on a second log: fricid report MODEL LOG "
                    "HELDOUT"
                )
            if {"--fix", "--bound"} & set(ignored):
                reasons.append(_trajectory_ranges())
            raise ConfigError(
                f"{', '.join(ignored)} {'applies' if len(ignored) == 1 else 'apply'} to friction "
                "samples, not to --trajectory" + (f" ({'; '.join(reasons)})" if reasons else "")
            )

        check_paths(inputs={"LOG": samples}, folders=True, out_files={"--out": out})
        return run_trajectory(
            samples,
            model,
            method,
            reader=log_format,
            reader_options=parse_reader_options(reader_option),
            seed=seed,
            max_evals=max_evals,
            route=route,
            gravity="fit",
            out=out,
            quiet=quiet,
            encoder_counts=encoder_counts,
        )
    from ..workflow import fit_samples, select_direction

    check_paths(inputs={"SAMPLES": samples}, out_files={"--out": out})
    data = select_direction(read_samples_file(samples), direction)
    settings = _rbf_settings(centers, inputs, backbone if key == "hybrid" else None) if rbf else {}
    if key == "auto" and learned:
        settings["learned"] = True
    trainer = _rbf_trainer(method) if rbf else (None if key == "gp" else method)
    fixed = parse_assignments(fix, "--fix")
    with (
        warnings.catch_warnings(record=True) as caught,
        fit_progress(model, method, fixed=fixed, max_evals=max_evals, quiet=quiet) as (
            track,
            callback,
        ),
    ):
        warnings.simplefilter("always")
        if key == "auto":
            settings["progress"] = _auto_progress(track)
        fitted, trust = fit_samples(
            data,
            model,
            trainer,
            fixed=fixed,
            bounds=parse_ranges(bound, "--bound"),
            seed=seed,
            max_evals=max_evals,
            validate=validate,
            loss=loss,
            f_scale=f_scale,
            weights=weights,
            intervals=intervals,
            settings=settings or None,
            callback=callback if key not in ("rbf", "hybrid", "gp") else None,
            on_stage=lambda label: track.stage(label, restart=True),
        )
    lines = [f"{w.category.__name__}: {w.message}" for w in caught]
    if lines:
        fitted.provenance["warnings"] = lines
    out = out or Path(f"{samples.stem}.{fitted.model}.json")
    fitted.save(out)
    console.print(fitted.report(), markup=False, highlight=False, soft_wrap=True)
    console.print(goodness_text(fitted, data), markup=False, highlight=False, soft_wrap=True)
    console.print(trust_lines(trust), markup=False, highlight=False, soft_wrap=True)
    for w in caught:  # shown as the CLI shows every warning (one line on stderr)
        warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    err_console.print(f"wrote {escape(str(out))}")


def _auto_progress(track):
    """``--model auto``'s progress: the candidate under way and its place in the list
    (``auto: 3/9 stribeck_temp``), the count of candidates validated, and the time left once
    the rate of the validated ones is known."""

    def progress(i: int, n: int, label: str) -> None:
        track.total = float(n)
        head = f"auto: {i + 1}/{n} {label}" if i < n else f"auto: {label}"
        track.stage(head, done=i)

    track.unit = "validated"
    return progress


def goodness_text(fitted, samples=None) -> str:
    """The ``[[Goodness of fit]]`` block of ``fricid fit`` (and ``[[Validation]]``,
    ``[[Model selection]]`` when the model file holds them).

    RMSE beside the measurement scatter, with the verdict; RMSE and R^2 of the friction's
    magnitude per direction (issue 11, defect 9); the paper's Table 1 fitness, labelled; with
    ``samples``, a note when a symmetric model misses a direction asymmetry.
    """
    from ..identify.validate import asymmetry_note
    from ..metrics import verdict

    m = fitted.metrics
    scatter = fitted.loss.get("scatter") or {}
    lines = ["[[Goodness of fit]]"]
    rmse = m.get("rmse")
    if rmse is not None:
        lines.append(f"    RMSE               = {rmse:.4g} N m")
    if scatter.get("value") is not None:
        caveat = f"; {scatter['caveat']}" if scatter.get("caveat") else ""
        lines.append(
            f"    scatter            = {scatter['value']:.4g} N m ({scatter['method']}{caveat})"
        )
        if m.get("rmse_over_scatter") is not None:
            lines.append(
                f"    RMSE / scatter     = {m['rmse_over_scatter']:.3g}: "
                f"{verdict(m['rmse_over_scatter'])} (in-sample{_with_outliers(fitted)})"
            )
    for d, label in (("pos", "v > 0"), ("neg", "v < 0"), ("comb", "combined")):
        if m.get(f"r2_magnitude_{d}") is not None:
            lines.append(
                f"    {label:<9} RMSE {m[f'rmse_{d}']:.4g} N m, R^2 of |F| "
                f"{m[f'r2_magnitude_{d}']:.4f}"
            )
    note = asymmetry_note(samples, fitted.model) if samples is not None else ""
    if note:
        lines.append(f"    note: {note}")
    if m.get("fitness") is not None:
        lines.append(
            f"    paper fitness      = {m['fitness']:.4f} (BAS-RBFNN paper Table 1: R^2 of the "
            "signed friction; compare only with the paper)"
        )
    if fitted.loss.get("loss") not in (None, "l2") or fitted.loss.get("weights") not in (
        None,
        "none",
    ):
        scale = fitted.loss.get("f_scale")
        lines.append(
            f"    loss               = {fitted.loss.get('loss')}"
            + (f" (scale {scale:.3g} N m)" if scale else "")
            + f", weights {fitted.loss.get('weights')}"
        )
    lines += heldout_lines(fitted)
    return "\n".join(lines)


def _rbf_trainer(method: str) -> str:
    """The RBF network's trainer: lsq (k-means, widths, ridge weights; the default for these
    models; ``lm``, the analytic models' default, is read as lsq), bas (BAS-RBFNN) or ga
    (GA-RBFNN)."""
    from ..errors import ConfigError

    trainer = "lsq" if method == "lm" else method
    if trainer not in ("lsq", "bas", "ga"):
        raise ConfigError(
            f"--model rbf and hybrid train with --method lsq, bas or ga; got '{method}'"
        )
    return trainer


def _rbf_settings(centers: int | None, inputs: str | None, backbone: str | None = None) -> dict:
    """``identify.fit``'s settings from --centers, --inputs and --backbone (the velocity warp,
    the widths and the penalty are fit's structured defaults)."""
    out: dict = {"network": {"n_centers": centers}}
    if backbone:
        out["backbone"] = backbone
    if inputs:
        out["inputs"] = [name.strip() for name in inputs.split(",") if name.strip()]
    return out


@app.command("methods")
def methods_command() -> None:
    """List every model (analytic with its _temp variants, dynamic, learned) and every
    optimiser, one line each."""
    from rich.markup import escape as esc

    for line in methods_lines():
        bold = not line.startswith(" ")
        console.print(f"[bold]{esc(line)}[/]" if bold else esc(line), highlight=False)


def methods_lines() -> list[str]:
    """The lines of ``fricid methods``: a heading, then one line per model or optimiser,
    every name taken from the registries (:data:`fricid.models.MODELS`, ``DYNAMIC``,
    ``STATEFUL``; :data:`fricid.optim.METHODS`) so that a family registered there is listed."""
    from ..errors import ConfigError
    from ..identify.static.varpro import SUMMARY
    from ..models import DYNAMIC, MODELS, STATEFUL, get_model
    from ..optim import METHODS

    lines = ["Analytic models (append _asym for parameters per direction):"]
    for name, cls in MODELS.items():
        m = cls()
        lines.append(f"  {name:<22} {m.title}; {m.equation}; parameters {', '.join(m.param_names)}")
    for name in MODELS:
        try:
            m = get_model(f"{name}_temp")
        except ConfigError:  # a family with no viscous term (vlt has its own temperature terms)
            continue
        extra = [p for p in m.param_names if p not in get_model(name).param_names]
        lines.append(f"  {m.name:<22} {m.title}; extra parameter {', '.join(extra)}")
    lines.append("Dynamic models (fit --trajectory: identified from a log of any motion):")
    for name, cls in DYNAMIC.items():
        m = cls()
        lines.append(f"  {name:<22} {m.title}; {m.equation}; parameters {', '.join(m.param_names)}")
    lines.append("Learned models (a stored state, no named parameters):")
    lines += stateful_model_lines(STATEFUL)
    lines.append(f"  {'auto':<22} the family chosen by held-out error (--learned: rbf, hybrid too)")
    lines.append("Optimisers (--method):")
    lines += [f"  {name:<22} {cls.summary}" for name, cls in METHODS.items()]
    lines.append(f"  {'varpro':<22} {SUMMARY}")
    return lines


def stateful_model_lines(stateful: dict) -> list[str]:
    """One line per model of ``fricid.models.STATEFUL`` (the RBF network, the hybrid, the
    Gaussian process, and any model a later registration adds): name, title, inputs."""
    lines = []
    for name, m in stateful.items():
        title = getattr(m, "title", "") or type(m).__name__
        equation = getattr(m, "equation", "")
        inputs = getattr(m, "inputs", None)
        bits = [title] + ([equation] if equation else [])
        if inputs:
            bits.append("inputs " + ", ".join(inputs))
        if name in ("rbf", "hybrid"):
            bits.append("trained with --method lsq (default), bas (BAS-RBFNN) or ga (GA-RBFNN)")
        lines.append(f"  {name:<22} " + "; ".join(bits))
    return lines


def _with_outliers(fitted) -> str:
    """``", the 2 samples left out as outliers included"`` for a GP whose training left
    samples out (``state["left_out"]``), or a robust loss's note: the in-sample numbers
    count every sample, the trust verdict the inliers."""
    from ..models.gp import left_out

    records = left_out(fitted.state) if fitted.model == "gp" else []
    count = sum(int(r.get("count", 0)) for r in records)
    if count:
        return f", the {count} sample(s) its training left out as outliers included"
    loss = (fitted.loss or {}).get("loss")
    if loss in ("soft_l1", "huber"):
        return f", the samples the {loss} loss down-weights included"
    return ""
