"""``fricid fit LOG --trajectory``: identify friction, inertia and gravity from any motion.

A hook in :mod:`fricid.cli.fit` delegates here. The log is opened by any reader that gives
a time series (:func:`fricid.io.open_log`: ``table``, ``generic``, ``rosbag``, ``channels``,
``mat``, ``epos``; reader options as ``--reader-option KEY=VALUE``), its chunks joined, and
identified by :func:`fricid.identify.dynamic.trajectory.fit_trajectory`.
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

from rich.markup import escape

from ..errors import ConfigError, DataError
from ._app import console, err_console
from ._progress import tracker

__all__ = ["parse_reader_options", "read_trajectory_log", "run_trajectory", "trajectory_text"]


def parse_reader_options(items: list[str] | None) -> dict:
    """``["joint=elbow", "torque_constant=0.5"]`` -> a dict; values read as JSON where they
    parse (numbers, booleans, objects), else as text."""
    out: dict = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"--reader-option takes KEY=VALUE, got '{item}'")
        try:
            out[key.strip()] = json.loads(value)
        except json.JSONDecodeError:
            out[key.strip()] = value
    return out


def _derivative_lines(d: dict) -> list[str]:
    """The derivative filter's settings, and the window's predicted biases
    (:mod:`fricid.identify.dynamic._window`)."""
    shown = {k: v for k, v in d.items() if k not in ("method", "source", "bias")}
    if "window" in shown:
        shown["window"] = f"{1e3 * shown['window']:.0f} ms"
    lines = [
        f"    derivatives: {d.get('method')} of the {d.get('source')}, "
        + ", ".join(f"{k} {v}" for k, v in shown.items())
    ]
    b = d.get("bias")
    if b:
        worst = max(b["over_stderr"], key=b["over_stderr"].get)
        wider = (
            f"widened from {1e3 * b['widened_from']:.0f} ms for the encoder's noise; "
            if b.get("widened_from")
            else f"narrowed from {1e3 * b['narrowed_from']:.0f} ms for the motion; "
            if b.get("narrowed_from")
            else ""
        )
        lines.append(
            f"    derivative window: {wider}the encoder's noise biases the inertia by "
            f"{-100 * b['noise_share']:+.2f} %, the filter's bending of the motion by "
            f"{100 * b['distortion']:+.2f} %: predicted inertia bias {100 * b['relative']:+.2f} "
            "%, the largest "
            f"{b['over_stderr'][worst]:.2f} standard errors ({worst})"
            + ("; corrected" if b.get("applied") else "")
        )
    return lines


def trajectory_text(fitted) -> str:
    """The trajectory block of the report: filter, routes, joint parameters, passivity."""
    info = fitted.provenance.get("trajectory", {})
    d = info.get("derivative", {})
    lines = [
        "[[Trajectory]]",
        f"    route: {info.get('route')} (static part from {info.get('static_from')}); "
        f"{info.get('seconds', float('nan')):.2f} s",
    ]
    if info.get("resampled"):
        rate = info.get("sample_rate")
        lines.append(
            "    resampled: the time stamps' steps vary by more than 1 % of their median, so "
            f"every column was interpolated linearly onto a uniform {rate:.6g} Hz grid (the "
            "encoder read from the rows as written)"
        )
    if d:
        lines.extend(_derivative_lines(d))
    lines.extend(_presliding_lines(info.get("presliding")))
    pf = info.get("parallel_filter")
    if pf:
        lines.append(
            f"    parallel filter (both sides): Butterworth {pf['cutoff']:g} Hz, order "
            f"{pf['order']}, zero phase, decimated by {pf['decimate']}"
        )
    conv = fitted.convergence or {}
    why = "the fit did not converge" if conv and not conv.get("converged") else "not determined"
    from ..identify.dynamic._routes import JOINT_UNITS

    for name, row in info.get("joint", {}).items():
        unit = JOINT_UNITS.get(name, "")
        lines.append(
            f"    {name}: {row['value']:.6g} {unit + ' ' if unit else ''}{_interval(row, why)}"
        )
    if info.get("gravity_note"):
        lines.append(f"    gravity: {info['gravity_note']}")
    if info.get("intervals_note"):
        lines.append(f"    intervals: {info['intervals_note']}")
    for name, route in info.get("routes", {}).items():
        rms = ", ".join(f"{k} {v:.3g}" for k, v in route.get("rms", {}).items())
        lines.append(
            f"    route {name}: {route.get('nfev')} evaluations, {route.get('seconds', 0):.2f} s, "
            f"converged {route.get('converged')}, residual RMS {rms}"
        )
    undetermined = {n for n, par in fitted.parameters.items() if par.not_determined}
    rb = info.get("rate_bias")
    if rb and "skipped" in rb:
        lines.append(f"    rate bias: not estimated ({rb['skipped']})")
    elif rb:
        lines.append(
            f"    rate bias at {rb['log_rate']:.6g} Hz (simulated at the estimate, "
            f"{rb['internal_rate']:.6g} Hz inside; not applied): "
            + ", ".join(
                _undetermined_bias(n, rb[n])
                if n in undetermined
                else _rate_bias(n, rb[n], fitted.params.get(n))
                for n in ("sigma_0", "sigma_1")
            )
        )
    lines.extend(_measurement_lines(info))
    cal = info.get("calibration")
    if isinstance(cal, dict) and cal.get("factors"):
        factors = ", ".join(f"{n} x{k:g}" for n, k in cal["factors"].items())
        rest = cal.get("rest_share")
        which = (
            ""
            if rest is None
            else f"; the log rests {100 * rest:.0f} % of its time: the factors of logs that "
            + ("rest" if cal.get("resting") else "do not")
        )
        lines.append(
            f"    intervals: calibrated on an independent simulator's logs, each side widened "
            f"({factors}; sigma_0 on a log scale{which}; before: provenance 'calibration')"
        )
    p = info.get("passivity")
    if p:
        from ..models.lugre import symmetric_name

        condition = {"sigma_0", "sigma_1", "sigma_2", "tau_c", "tau_s"}  # its parameters
        rests = sorted(n for n in undetermined if symmetric_name(n) in condition)
        caveat = f" (it rests on {', '.join(rests)}, not determined)" if rests else ""
        lines.append(f"    passivity: {_passivity(p)}{caveat}")
    return "\n".join(lines)


def _presliding_lines(record: dict | None) -> list[str]:
    """The pre-sliding route's record: what the log determines and why not the rest, the
    encoder's resolution of the deflection, the timing the damping rests on, J's union."""
    if not record:
        return []
    out = [f"    determined: {', '.join(record['determined'])}"]
    out += [f"    not determined: {n}: {why}" for n, why in record["not_determined"].items()]
    counts = record.get("deflection_counts")
    resolved = f" = {counts:.3g} counts" if counts is not None else ""
    out.append(
        f"    largest bristle deflection {record['deflection']:.3g} rad{resolved} "
        f"(resolved from {record['resolved_from_counts']:g} counts); bristles' level at rest "
        f"{record['bristle_level']:.4g} N m"
    )
    out.append(f"    timing: {record['timing']}")
    kept = [r for r in record.get("inertia_profile", []) if r["accepted"]]
    if kept:
        js = ", ".join(f"{r['inertia']:.3g}" for r in kept)
        out.append(f"    intervals: union over J = {js} kg m^2 (the J the log does not reject)")
    return out


def _measurement_lines(info: dict) -> list[str]:
    """The encoder, the output-error decision and the estimator, one line each."""
    out = []
    enc = info.get("encoder")
    if enc and enc.get("counts_per_rev"):
        out.append(
            f"    encoder: {enc['counts_per_rev']:.10g} counts/rev (from the {enc['source']}"
            if enc["source"] == "position steps"
            else f"    encoder: {enc['counts_per_rev']:.10g} counts/rev (given"
        )
        out[-1] += f"), velocity {enc['velocity_form']}"
        if enc.get("velocity_std") is not None:
            out[-1] += f" (quantisation error {enc['velocity_std']:.3g} rad/s RMS)"
    elif enc:
        out.append("    encoder: no quantisation found in the position steps")
    oe = info.get("output_error")
    if oe and "breakaway_counts" in oe:
        done = "applied" if oe["applied"] else "not applied"
        out.append(f"    output error (DIDIM): {done}; {oe['why']}")
        starts = oe.get("starts_sse")
        if starts:
            sse = ", ".join(f"{k} {v:.4g}" for k, v in starts.items())
            out.append(f"    output error's starts (SSE; the lower carried on): {sse}")
    est = info.get("estimator")
    if est:
        out.append(f"    estimator: {est['name']}")
        out.append(f"    closed-loop and quantisation bias: {est['bias']}")
    return out


def _interval(row: dict, why: str) -> str:
    """``+/- se (95 % CI [low, high])``, or ``why`` there is none (the model file stores
    null)."""
    se, low, high = (row.get(k) for k in ("stderr", "ci95_low", "ci95_high"))
    if any(v is None or not math.isfinite(v) for v in (se, low, high)):
        return f"(no interval: {why})"
    return f"+/- {se:.2g} (95 % CI [{low:.5g}, {high:.5g}])"


#: Units of the parameters whose rate bias is estimated.
_BIAS_UNITS = {"sigma_0": "N m/rad", "sigma_1": "N m s/rad"}


def _rate_bias(name: str, row: dict, estimate) -> str:
    """One parameter's rate bias: relative while the bias is smaller than the estimate, else
    absolute (a relative one of 1e29 % says nothing); a corrected value outside the search
    box is said to be so."""
    from ..identify.dynamic._filtered import LOG_BOX

    rel, corrected = row["relative"], row["corrected"]
    if abs(rel) < 1.0 or estimate is None:
        text = f"{name} {100 * rel:+.2g} % (corrected {corrected:.4g}"
    else:
        text = (
            f"{name} {float(estimate) - corrected:+.3g} {_BIAS_UNITS.get(name, '')} (a factor "
            f"{10.0 ** row['log10_bias']:.3g}; corrected {corrected:.4g}"
        )
    lo, hi = (10.0**x for x in LOG_BOX.get(name, (-math.inf, math.inf)))
    if not lo * (1 - 1e-9) <= corrected <= hi * (1 + 1e-9):  # the box's edges are inside
        text += f", outside the search box [{lo:.3g}, {hi:.3g}]: not a usable value"
    return text + ")"


def _undetermined_bias(name: str, row: dict) -> str:
    """A parameter not determined: the move the simulation at the estimate found (the rate-bias
    warning gives it too), without a corrected value (there is no value to correct)."""
    rel = row.get("relative")
    if rel is None or not math.isfinite(rel):
        return f"{name} not determined: no bias or corrected value to give"
    moved = (
        f"{100 * rel:+.2g} %" if abs(rel) < 1.0 else f"by a factor {10.0 ** row['log10_bias']:.3g}"
    )
    return (
        f"{name} not determined (the simulation at the estimate moved it {moved}; no corrected "
        "value to give)"
    )


def _passivity(p: dict) -> str:
    """The passivity line: at the estimate, across the intervals, and the condition; a margin
    the model file stores as null (infinite) said in words."""
    margin, passive = p.get("margin"), p.get("passive")
    if margin is not None:
        at = f"{'passive' if passive else 'NOT passive'} (margin {margin:.3g} N m s/rad"
    elif passive:
        at = (
            "passive for any sigma_1 (tau_s <= tau_c: no Stribeck peak, so the condition "
            "bounds no damping"
        )
    else:
        at = (
            "NOT passive (a parameter outside its valid region: sigma_0, tau_c, w_s > 0 and "
            "sigma_1, sigma_2 >= 0"
        )
    across = p.get("passive_across_ci95")
    ci = {True: "passive", False: "not guaranteed", None: "no intervals"}[across]
    return f"{at}; across the 95 % intervals: {ci}); {p.get('condition', '')}"


def read_trajectory_log(path: Path, reader: str = "table", reader_options: dict | None = None):
    """The whole log at ``path`` as one :class:`~fricid.samples.RawLog` (its chunks joined),
    or a :class:`DataError` when the reader gives friction samples instead of a time series."""
    from ..io import open_log
    from ..samples import RawLog

    try:
        opened = open_log(path, reader, reader_options or {}, steady=False)
    except DataError as exc:  # friction samples where a log goes: the commands that take them
        if "'fricid-samples/" not in exc.message:
            raise
        raise DataError(
            "this is a friction-samples file (fricid extract's output), not a raw log: a "
            "trajectory's identification and its report take a log of time, position, "
            "velocity and torque; samples go to fricid fit SAMPLES (without --trajectory), and "
            "to fricid report with a model fitted on samples",
            file=str(path),
        ) from None
    if not isinstance(opened, RawLog) and not hasattr(opened, "__next__"):
        raise DataError(
            "this reader gives friction samples (steady-state means), not a time series: a "
            "trajectory needs time, position, velocity and torque",
            file=str(path),
        )
    chunks = list(opened)
    log = chunks[0] if len(chunks) == 1 else RawLog.concatenate(chunks)
    from ..samples import check_trajectory_log

    try:  # as the fit checks it, with a CSV's rows and columns as the file writes them
        check_trajectory_log(log)
    except DataError as exc:
        raise _as_in_file(exc, Path(path)) from None
    return log


def _as_in_file(exc: DataError, path: Path) -> DataError:
    """``exc`` (a row as the log's 0-based sample index, a column by its quantity) with the
    CSV file's line and column label, as the reader's own errors give them (a hole in the
    time had been 'row 4000, column time' for line 4002's 'time [s]'); other files as given."""
    if path.suffix.lower() != ".csv" or (exc.row is None and exc.column is None):
        return exc
    from ..io._columns import split_label
    from ..io._csv import read_preamble, record_line

    pre = read_preamble(path)
    row = exc.row if exc.row is None else record_line(pre, exc.row)
    label = next((lab for lab in pre.labels if split_label(lab)[0] == exc.column), exc.column)
    return DataError(exc.message, file=exc.file, row=row, column=label)


def run_trajectory(
    log_path: Path,
    model: str,
    method: str,
    *,
    reader: str,
    reader_options: dict,
    seed: int,
    max_evals: int | None,
    route: str,
    gravity: str,
    out: Path | None,
    quiet: bool = False,
    encoder_counts: float | None = None,
) -> None:
    """Open, identify, save and print (the ``--trajectory`` branch of ``fricid fit``), with
    the stage under way on stderr (:func:`fricid.cli._progress.tracker`; ``quiet``: none)."""
    from ..identify import fit

    log = read_trajectory_log(log_path, reader, reader_options)
    label = f"identifying {model} from the trajectory"
    with (
        warnings.catch_warnings(record=True) as caught,
        tracker(label, None, unit="stages", quiet=quiet, timed=False) as track,
    ):
        warnings.simplefilter("always")

        def progress(i: int, n: int, stage: str) -> None:
            track.total = float(n)
            if i < n:  # a line once past the grace (quick fits stay quiet)
                track.stage(f"{label} [{i + 1}/{n}] {stage}", done=i)
            else:
                track.update(n)

        fitted = fit(
            log,
            model,
            method,
            seed=seed,
            max_evals=max_evals,
            settings={
                "route": route,
                "gravity": gravity,
                "progress": progress,
                **({"encoder_counts": encoder_counts} if encoder_counts is not None else {}),
            },
        )
    lines = [f"{w.category.__name__}: {w.message}" for w in caught]
    if lines:
        fitted.provenance["warnings"] = lines
    from ..identify.trust import assess_trust
    from ._trust_text import trust_lines

    # the one verdict, from the file: convergence, what the log determines, the range (no
    # held-out log here: `fricid report MODEL LOG HELDOUT` validates on a second one)
    trust = assess_trust(fitted, None)
    fitted.trust = trust.to_dict()
    out = out or Path(f"{log_path.stem}.{fitted.model}.json")
    fitted.save(out)
    console.print(fitted.report(), markup=False, highlight=False, soft_wrap=True)
    console.print(trajectory_text(fitted), markup=False, highlight=False, soft_wrap=True)
    console.print(trust_lines(trust), markup=False, highlight=False, soft_wrap=True)
    for w in caught:
        warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    err_console.print(f"wrote {escape(str(out))}")
