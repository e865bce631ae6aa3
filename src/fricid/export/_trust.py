"""The trust line of every exported file, and the model's recorded verdict and reasons.

The line gives the model's recorded trust verdict (:class:`fricid.identify.trust.Trust`, or
a whole-arm joint's validation) in fixed words and numbers only; when what the file holds is a
projection that misses the model beyond its measurement scatter, the line says so, and leads
with the file's own grade when that is worse than the model's.
"""

from __future__ import annotations

import math
import numbers

from ..fitted import FittedModel

__all__ = ["NOT_RECORDED", "model_scatter", "printable_reasons", "trust_line", "trust_of"]


def trust_line(
    fitted: FittedModel, projection_rms: float | None = None, projection: str = "projection"
) -> str:
    """``"trust verdict: ..."`` for the file's comment (arguments as for
    :func:`fricid.export._common.summary_lines`); :data:`NOT_RECORDED` when the model records
    no verdict.

    The verdict is the model's; when ``projection_rms`` misses the model by more than its
    scatter the line says by how many times, and beyond what the trust check passes
    (:func:`_file_level`) it leads with the file's numbers' grade, the model's after it.
    """
    level, _ = trust_of(fitted)
    if level not in _LEVELS:  # fixed words and a number only
        return NOT_RECORDED
    shown, which = None, "held-out"
    for rec, key in ((fitted.trust, "heldout_ratio"), (fitted.validation, "ratio")):
        if isinstance(rec, dict) and isinstance(rec.get(key), int | float):
            ratio = float(rec[key])
            shown = f"{ratio:.3g}" if math.isfinite(ratio) else None
            if str(rec.get("heldout_source", "")).startswith("in-sample"):
                which = "in-sample (no held-out validation)"
            break
    said = [f"{which} error {shown} times the scatter"] if shown is not None else []
    verdict = "NO, exported anyway" if level == "no" else level
    misses, times = _projection_miss(fitted, projection_rms, projection)
    worse = _file_level(times)
    if worse is not None and _LEVELS.index(worse) > _LEVELS.index(level):
        # the file's numbers fail the check the model passed: that leads the line
        return (
            f"trust verdict: {'NO' if worse == 'no' else worse} for this file's numbers "
            f"(they miss the model by {times:.3g} times the scatter, RMS "
            f"{projection_rms:.3g} N m over the operating range; the model itself: "
            f"{verdict}{', ' + said[0] if said else ''}); the model file gives the reasons"
        )
    if misses:  # the verdict above is the model's, not what this file holds
        said = [f"the model's{': ' + said[0] if said else ''}", misses]
    return (
        f"trust verdict: {verdict}"
        + (f" ({'; '.join(said)})" if said else "")
        + "; the model file gives the reasons"
    )


#: The trust line of a model file that records no verdict (an older file, a model fitted in
#: Python): said, not left out, so that a file without the line is never read as trusted.
NOT_RECORDED = (
    "trust verdict: not recorded in the model file (fricid report MODEL SAMPLES grades it)"
)

#: The trust levels, best first.
_LEVELS = ("yes", "with caveats", "no")


def _file_level(ratio: float | None) -> str | None:
    """The trust level of exported numbers that miss the model by ``ratio`` times its
    scatter, as the trust check grades an error: ``no`` beyond
    :data:`fricid.identify.trust.MISS_RATIO`, ``with caveats`` beyond
    :data:`fricid.metrics.NOISE_RATIO`; None within it (or no ratio)."""
    if ratio is None:
        return None
    from ..identify.trust import MISS_RATIO  # here: `fricid --help` starts without scipy
    from ..metrics import NOISE_RATIO

    if ratio > MISS_RATIO:
        return "no"
    return "with caveats" if ratio > NOISE_RATIO else None


def model_scatter(fitted: FittedModel) -> float | None:
    """N m, the measurement scatter the model's trust verdict compared its error with (its
    trust record's ``scatter``, else its validation's); None when not recorded."""
    for rec in (fitted.trust, fitted.validation):
        value = rec.get("scatter") if isinstance(rec, dict) else None
        if not isinstance(value, numbers.Real) or isinstance(value, bool):
            continue
        if math.isfinite(value := float(value)):
            return value if value > 0 else None
    return None


def _projection_miss(
    fitted: FittedModel, rms: float | None, projection: str
) -> tuple[str, float | None]:
    """``("this projection misses the model by 5.91 times the scatter, RMS 0.000377 N m over
    the operating range", 5.91)`` when ``rms`` [N m] exceeds :func:`model_scatter`; else
    ``("", None)`` (a lossless projection, or no scatter recorded)."""
    scatter = model_scatter(fitted)
    if scatter is None or rms is None or not (math.isfinite(rms) and rms > scatter):
        return "", None
    return (
        f"this {projection} misses the model by {rms / scatter:.3g} times the scatter, RMS "
        f"{rms:.3g} N m over the operating range"
    ), rms / scatter


def trust_of(fitted: FittedModel) -> tuple[str | None, list[str]]:
    """The model's trust level (``yes``, ``with caveats``, ``no``) and its reasons as its file
    records them: its trust verdict (:class:`fricid.identify.trust.Trust`) or, for a joint of
    a whole-arm fit, its validation's; ``(None, [])`` when it records none."""
    for rec in (fitted.trust, fitted.validation):
        if isinstance(rec, dict) and isinstance(rec.get("level"), str):
            reasons = rec.get("reasons")
            return rec["level"], [str(r) for r in reasons] if isinstance(reasons, list) else []
    return None, []


def printable_reasons(reasons: list[str], limit: int | None = None) -> str:
    """A record's reasons joined by ``"; "``, each character that is not printable (a
    terminal control from a file) shown as ``?``. With ``limit``, whole reasons only while
    they fit in ``limit`` characters (a first reason longer than that is cut at a space and
    ends in ``...``), then how many more the model file gives: a reason is never cut short
    silently (a parameter's name lost at the end)."""
    shown = ["".join(c if c.isprintable() else "?" for c in r) for r in reasons]
    if limit is None:
        return "; ".join(shown)
    kept: list[str] = []
    for reason in shown:
        if len("; ".join([*kept, reason])) > limit:
            break
        kept.append(reason)
    if not kept and shown:  # the first alone is too long
        kept = [shown[0][:limit].rsplit(" ", 1)[0] + " ..."]
    more = len(shown) - len(kept)
    return "; ".join(kept) + (f"; {more} more in the model file" if more else "")
