"""Shared pieces of the exporters: the one number formatter, the one text escaper, names.

Data never becomes code (DESIGN.md, "Conventions"). A model file travels between people and
an export goes into firmware, so nothing an exported file says comes from the model file
except through the three gates of this module:

:func:`fmt_float`
    Every number: ``repr`` of the float (the shortest text that reads back bit for bit, a
    valid C, XML attribute and YAML literal); NaN and infinities are refused with a
    :class:`~fricid.errors.DataError` that names the parameter.
:func:`plain`
    Every piece of text from the file (method, data source, the model file's name):
    percent-encoded down to a small alphabet (letters, digits, space and ``_.,:;=+()[]@/``,
    with ``-`` only singly and never first or last). No ``*``, ``#``, ``<``, ``&``, quote,
    ``?``, backslash, control or non-ASCII character survives, and ``--`` cannot form, so
    the result cannot end a C ``/* */`` comment, an XML ``<!-- -->`` comment (or make it
    invalid), a YAML ``#`` line, nor hold a C trigraph. The encoding is reversible
    (``urllib.parse.unquote(text, errors="surrogatepass")``) up to a length limit.
:func:`check_identifier` and :func:`check_name`
    Names that become identifiers (the C prefix, joint and node names) must match a strict
    pattern or the export is refused.

Every export also names the model by its SHA-256 (of the file's bytes when the file is
known, else of the model's canonical JSON), so a reader can tell which file it came from
without trusting anything the file says.
"""

from __future__ import annotations

import hashlib
import json
import math
import numbers
import os
import re
import string
from collections.abc import Collection
from pathlib import Path

from .. import __version__
from ..errors import ConfigError, DataError
from ..fitted import FittedModel
from ..models import STATEFUL
from ._trust import printable_reasons, trust_line, trust_of

__all__ = [
    "ExportError",
    "check_identifier",
    "check_name",
    "file_sha256",
    "fmt_float",
    "model_name",
    "model_sha256",
    "operating_pair",
    "percent",
    "plain",
    "range_lines",
    "summary_lines",
    "write_lines_checked",
]

#: Longest piece of file text written (the rest is counted, not written).
PLAIN_LIMIT = 120

_PLAIN = frozenset(string.ascii_letters + string.digits + " _.,:;=+()[]@/")
_C_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")
_SHA256 = re.compile(r"[0-9a-f]{64}")


class ExportError(ConfigError):
    """The export target cannot represent the model (the message says what would be lost)."""


def fmt_float(value: float, name: str = "value") -> str:
    """A number for an exported file, written so that it reads back bit for bit.

    Parameters
    ----------
    value : float
        A real number (a bool or a non-number is refused).
    name : str
        What the number is (a parameter name), for the error message.

    Returns
    -------
    str
        ``repr(float(value))``: the shortest decimal text that reads back as the same double
        (e.g. ``0.005``, ``-1e-05``, ``2.0``), valid in C99, XML attributes and YAML.

    Raises
    ------
    DataError
        ``value`` is NaN, infinite or not a real number; the message names ``name``.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise DataError(f"{name} must be a number, got {type(value).__name__}", column=name)
    value = float(value)
    if not math.isfinite(value):
        raise DataError(f"{name} is {value!r}: a non-finite value cannot be exported", column=name)
    return repr(value)


def plain(text: object, limit: int = PLAIN_LIMIT) -> str:
    """``text`` escaped so that it is inert in C, XML and YAML comments (module docstring).

    Parameters
    ----------
    text : object
        Text from a model file (anything else is converted with ``str``).
    limit : int
        Characters of ``text`` written; a longer text is cut there and the number of
        characters left out is appended as ``[N more characters]``.

    Returns
    -------
    str
        Only letters, digits, space, ``_.,:;=+()[]@/``, ``%XX`` escapes and single ``-``
        characters that neither start nor end it. Spaces at either end are escaped too
        (``%20``): exports strip trailing blanks from their lines, and "a " must not come out
        as "a".
    """
    text = str(text)
    extra = len(text) - limit
    if extra > 0:
        text = text[:limit]
    out: list[str] = []
    last = len(text) - 1
    for i, ch in enumerate(text):
        inner = 0 < i < last
        if (ch in _PLAIN and (ch != " " or inner)) or (
            ch == "-" and inner and not out[-1].endswith("-")
        ):
            out.append(ch)
        else:
            out.append("".join(f"%{b:02X}" for b in ch.encode("utf-8", "surrogatepass")))
    if extra > 0:
        out.append(f" [{extra} more characters]")
    return "".join(out)


def check_identifier(prefix: str) -> str:
    """``prefix`` if it is a plain C identifier (a letter, then letters, digits or ``_``,
    at most 63 characters), else :class:`ExportError`."""
    if not isinstance(prefix, str) or not _C_IDENT.fullmatch(prefix):
        raise ExportError(
            f"prefix {prefix!r} is not a C identifier of the form [A-Za-z][A-Za-z0-9_]* "
            "(at most 63 characters)"
        )
    return prefix


def check_name(name: str, what: str, pattern: re.Pattern[str], allowed: str) -> str:
    """``name`` if it matches ``pattern`` in full, else :class:`ExportError` naming ``what``
    and the ``allowed`` form."""
    if not isinstance(name, str) or not pattern.fullmatch(name):
        raise ExportError(f"{what} {name!r} must {allowed}")
    return name


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 (hex) of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def model_sha256(fitted: FittedModel) -> str:
    """SHA-256 (hex) of the model's canonical JSON (sorted keys, no spaces)."""
    text = json.dumps(fitted.to_dict(), sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def model_name(fitted: FittedModel) -> str:
    """The model's registry name, taken from the registry (never the file's text)."""
    if fitted.model in STATEFUL:
        return str(fitted.model)
    model = fitted.friction_model()  # ConfigError for a name the registry does not know
    return model.name


def _display(value: object) -> str | None:
    """A finite number for a summary line (6 significant digits), else None."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return None
    value = float(value)
    return f"{value:.6g}" if math.isfinite(value) else None


def summary_lines(
    fitted: FittedModel,
    source: str | None = None,
    sha256: str | None = None,
    *,
    projection_rms: float | None = None,
    projection: str = "projection",
    held: Collection[str] | None = None,
) -> list[str]:
    """The fixed-format provenance lines at the top of every exported file.

    Parameters
    ----------
    fitted : FittedModel
        The model.
    source : str, optional
        The model file's name (escaped with :func:`plain`).
    sha256 : str, optional
        SHA-256 (64 lower-case hex digits) of the model file's bytes; without it, the SHA-256
        of the model's canonical JSON is given and labelled so.
    projection_rms : float, optional
        N m, the RMS error over the operating range of what is exported when that is not the
        model itself (a Coulomb-viscous projection: :attr:`fricid.export.Projection.
        rms_error`). When it exceeds the model's measurement scatter
        (:func:`fricid.export._trust.model_scatter`), the trust line says how many times the
        scatter the ``projection`` (fixed text: what was exported) misses the model by; beyond
        what the trust check passes (3 times: ``NO``, 1.2 times: ``with caveats``) it leads
        with that grade of the file's numbers, the model's own verdict after it
        (:func:`fricid.export._trust.trust_line`).
    held : collection of str, optional
        The undetermined parameters (:func:`undetermined_parameters`) the exported numbers
        depend on (a projection's: :attr:`fricid.export.Projection.rests_on_names`); the others
        are said not to be in the file. Default: every one (the file holds the model).

    Returns
    -------
    list of str
        Lines of fixed text, registry names, numbers and :func:`plain` text only.
    """
    lines = [f"fricid {plain(__version__)} export of the model '{model_name(fitted)}'"]
    if sha256 is not None:
        if not isinstance(sha256, str) or not _SHA256.fullmatch(sha256):
            raise ExportError(f"sha256 must be 64 lower-case hex digits, got {sha256!r}")
        lines.append(
            f"model file sha256 {sha256}" + (f", file name {plain(source)}" if source else "")
        )
    else:
        lines.append(
            f"model content sha256 {model_sha256(fitted)} (canonical JSON)"
            + (f", from {plain(source)}" if source else "")
        )
    prov = fitted.provenance if isinstance(fitted.provenance, dict) else {}
    seed, method = fitted.optimizer.seed, fitted.optimizer.method
    seed_text = str(seed) if isinstance(seed, int) and not isinstance(seed, bool) else "none"
    n = prov.get("n_samples")
    count = f", {n} samples" if isinstance(n, int) and not isinstance(n, bool) and n >= 0 else ""
    data = prov.get("source")
    lines.append(
        f"identified by {plain(method) if method else 'an unrecorded method'} "
        f"(seed {seed_text}) from {plain(data) if data else 'unrecorded data'}{count}"
    )
    metrics = fitted.metrics if isinstance(fitted.metrics, dict) else {}
    parts = []
    for key in ("fitness", "rmse", "max_abs_error"):
        shown = _display(metrics.get(key))
        if shown is not None:
            parts.append(f"{key} {shown}")
    trajectory = prov.get("trajectory") if isinstance(prov.get("trajectory"), dict) else {}
    estimator = trajectory.get("estimator")
    if isinstance(estimator, dict):  # {"name": ..., "bias": ...}
        estimator = estimator.get("name")
    if isinstance(estimator, str) and estimator:  # fricid's own names run to 160 characters
        lines.append(f"estimator: {plain(estimator, limit=2 * PLAIN_LIMIT)}")
    if parts and trajectory:
        lines.append(
            "fit on its data: " + ", ".join(parts) + " (rmse, max error in N m, of the residual "
            "the estimator fitted: low-passed and decimated, or a simulation's; fricid report "
            "gives the torque error on a log)"
        )
    elif parts:
        lines.append("fit on its data: " + ", ".join(parts) + " (rmse, max error in N m)")
    undetermined = undetermined_parameters(fitted)
    inside = [n for n in undetermined if held is None or n in held]
    if inside:
        lines.append(
            "NOT DETERMINED by the trajectory, exported as identified: "
            + ", ".join(plain(n) + _one_bound(fitted.parameters[n]) for n in inside)
        )
    if len(inside) < len(undetermined):
        lines.append(
            "NOT DETERMINED by the trajectory, not in this file (its numbers do not depend on "
            "it): " + ", ".join(plain(n) for n in undetermined if n not in inside)
        )
    verdict = trust_line(fitted, projection_rms, projection)
    return [*lines, verdict]


def refuse_untrusted(fitted: FittedModel, allow: bool, joint: str | None = None) -> None:
    """Refuse to export a model whose recorded verdict is ``no`` unless ``allow`` (then
    :func:`summary_lines` says so in the file's comment); ``joint`` names it in the message.

    Raises
    ------
    ExportError
        Such a model, not allowed.
    """
    level, reasons = trust_of(fitted)
    if level == "no" and not allow:
        # printable characters only (no terminal controls from a file), whole reasons
        why = printable_reasons(reasons, limit=500) or "no reason recorded"
        whose = f"joint {plain(joint)}: the" if joint else "the"
        raise ExportError(
            f"{whose} '{model_name(fitted)}' model's trust verdict is 'no' ({why}): a controller "
            "or simulator would run on a model its own check rejects; record better data or "
            "fit another model, or export anyway with --allow-untrusted (the file's comment "
            "then says so)"
        )


def _one_bound(p) -> str:
    """`` (the data: at most 1.106 N m s/rad)``: the one bound a parameter's interval open at
    one end of its search range sets (:attr:`fricid.fitted.Parameter.one_bound`), else ``""``."""
    if not p.one_bound:
        return ""
    return f" (the data: {p.one_bound}{' ' + plain(p.unit) if p.unit else ''})"


def undetermined_parameters(fitted: FittedModel) -> list[str]:
    """The parameters of a model identified from a trajectory (``provenance["trajectory"]``)
    that its record says the data do not determine (:attr:`fricid.fitted.Parameter.
    not_determined`: an interval open at both ends of the search box, or withheld)."""
    prov = fitted.provenance if isinstance(fitted.provenance, dict) else {}
    if "trajectory" not in prov:
        return []
    return [n for n, p in fitted.parameters.items() if p.not_determined]


def refuse_undetermined(
    fitted: FittedModel, allow: bool, held: Collection[str] | None = None
) -> None:
    """Refuse to export a trajectory model with an undetermined parameter that the exported
    numbers depend on (``held``; default every undetermined one) unless ``allow`` (then
    :func:`summary_lines` names them in the file's comment).

    Raises
    ------
    ExportError
        Such a parameter, not allowed.
    """
    undetermined = [n for n in undetermined_parameters(fitted) if held is None or n in held]
    if undetermined and not allow:
        raise ExportError(
            "the trajectory does not determine "
            + ", ".join(plain(n) for n in undetermined)
            + f" of the '{model_name(fitted)}' model (see its parameter records); a controller "
            "or simulator would run on an arbitrary value: record a richer trajectory, or "
            "export anyway with --allow-undetermined (the file's comment then names them)"
        )


def range_lines(fitted: FittedModel) -> list[str]:
    """The operating range the model was identified on, numbers only (one line per input
    recorded, or one line saying none is recorded).

    Raises
    ------
    DataError
        A recorded range that is not two finite numbers with low <= high.
    """
    ranges = fitted.operating_range if isinstance(fitted.operating_range, dict) else {}
    units = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}
    lines = []
    for name, unit in units.items():
        pair = operating_pair(fitted, name, ranges)
        if pair is not None:
            lo, hi = pair
            lines.append(f"  {name} {fmt_float(lo)} to {fmt_float(hi)} {unit}")
    if not lines:
        return ["Operating range: not recorded in the model file."]
    return ["Operating range of the identification data (SI units):", *lines]


def operating_pair(
    fitted: FittedModel, name: str, ranges: dict | None = None
) -> tuple[float, float] | None:
    """``(low, high)`` of one input's recorded operating range, validated; None if absent."""
    if ranges is None:
        ranges = fitted.operating_range if isinstance(fitted.operating_range, dict) else {}
    pair = ranges.get(name)
    if pair is None:
        return None
    column = f"operating_range.{name}"
    if not isinstance(pair, list | tuple) or len(pair) != 2:
        raise DataError(f"{column} must be [low, high]", column=column)
    lo, hi = (float(fmt_float(x, column)) for x in pair)
    if lo > hi:
        raise DataError(f"{column} has low > high ({lo!r} > {hi!r})", column=column)
    return lo, hi


def write_lines_checked(lines: list[str], forbidden: tuple[str, ...]) -> list[str]:
    """``lines`` unchanged, after checking that each is printable ASCII (so no line break of
    any kind, no control character) without a ``forbidden`` sequence: a last guard, as
    :func:`plain` already makes these impossible.

    Raises
    ------
    ExportError
        A line that fails the check (an internal error: a template is wrong).
    """
    for line in lines:
        bad = [x for x in forbidden if x in line]
        if bad or not (line.isascii() and line.isprintable()):
            what = repr(bad[0]) if bad else "a character that is not printable ASCII"
            raise ExportError(f"internal error: comment line {line!r} holds {what}")
    return lines


def ensure_out_file(path: str | os.PathLike[str]) -> Path:
    """``path`` as a Path, refusing an existing directory (an export writes a file there)."""
    path = Path(path)
    if path.is_dir():
        raise ExportError(f"--out {path} is a directory; give the file to write")
    return path


def percent(share: float) -> str:
    """A relative error as a percentage, ``"1.23 %"``; below 1e-6 % (the rounding of an exact
    projection: a Coulomb-viscous model projects onto itself) ``"0 %"``."""
    return "0 %" if abs(share) < 1e-8 else f"{100 * share:.3g} %"
