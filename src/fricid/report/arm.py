"""The report of a whole arm's identification: a row per joint first.

It renders an :class:`~fricid.fitted.arm.ArmFit` (computed and judged by
:func:`fricid.identify.dynamic.arm.fit_arm`; nothing here validates or decides): the verdict
per joint with its held-out ratio and reasons, every joint's friction curve in small
multiples, the friction parameters with their 95 % intervals, the base inertial parameters
(with the least-squares values before the consistency step), how the standard ones were made
physically consistent and each link's mass, centre of mass and rotational inertia from them,
and where the numbers came from.

The fit file holds each joint's held-out error and noise, not the held-out residual series:
the report says so instead of drawing residuals over time (``fricid robot fit`` would have to
store them, or the report re-predict the log, which is the identification's work).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from ..errors import ConfigError
from ..fitted.arm import ArmFit
from .document import Document, Figure, Note, Table
from .style import new_figure, png, styled

__all__ = ["arm_report", "base_table", "friction_table", "link_table", "verdict_table"]

#: The ten standard parameters of a link, in the rigid-body model's order.
_STANDARD = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def _num(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _per_joint(value: Any, joint: str) -> Any:
    """``value[joint]`` for a per-joint mapping, else ``value`` itself."""
    return value.get(joint) if isinstance(value, dict) else value


def verdict_table(fit: ArmFit) -> pd.DataFrame:
    """A row per joint: family, noise, held-out error and ratio and where they came from,
    effective samples, verdict and its reasons."""
    effective = fit.provenance.get("effective_samples", {})
    rows = []
    for joint in fit.joints:
        check = fit.validation.get(joint, {})
        rows.append(
            {
                "joint": joint,
                "friction model": fit.friction.get(joint, {}).get("family", "–"),
                "noise [N m]": _num(fit.noise.get(joint)),
                "held-out RMSE [N m]": _num(check.get("rmse")),
                "held-out / noise": _num(check.get("ratio")),
                "held out on": str(check.get("source", "–")),
                "effective samples": _num(_per_joint(effective, joint)),
                "Trust": fit.verdict(joint),
                "why": "; ".join(map(str, check.get("reasons", []))) or "–",
            }
        )
    return pd.DataFrame(rows)


def friction_table(fit: ArmFit) -> pd.DataFrame:
    """Every joint's friction parameters with their 95 % intervals."""
    rows = []
    for joint in fit.joints:
        for name in fit.friction.get(joint, {}).get("parameters", {}):
            p = fit.parameter(joint, name)
            rows.append(
                {
                    "joint": joint,
                    "parameter": name,
                    "value": math.nan if p.not_determined else p.value,
                    "95 % low": p.ci95[0],
                    "95 % high": p.ci95[1],
                    "unit": p.unit,
                    "determined": "no" if p.not_determined else "yes",
                    "note": p.note or "–",
                }
            )
    return pd.DataFrame(rows)


def base_table(fit: ArmFit) -> pd.DataFrame:
    """The base inertial parameters: the value used, the least-squares value before the
    consistency step (when recorded), the 95 % interval and whether the data fix it."""
    b = fit.base
    names = [str(n) for n in b.get("names", [])]
    n = len(names)
    ci = list(b.get("ci95") or [(None, None)] * n)
    determined = list(b.get("determined") or [True] * n)
    frame = pd.DataFrame(
        {
            "base parameter": names,
            "value": [_num(v) for v in b.get("values") or [None] * n],
            "least squares": [_num(v) for v in b.get("values_ls") or [None] * n],
            "95 % low": [_num(c[0]) for c in ci],
            "95 % high": [_num(c[1]) for c in ci],
            "determined": ["yes" if d else "no" for d in determined],
        }
    )
    if "values_ls" not in b:
        frame = frame.drop(columns="least squares")
    return frame


def link_table(fit: ArmFit) -> pd.DataFrame:
    """Each joint's link from the standard parameters: mass [kg], centre of mass [m] (first
    moments over the mass) and rotational inertia [kg m^2] about the joint frame's origin, as
    the fit file holds them (10 per joint, the rigid-body model's order); empty without them."""
    values = fit.standard.get("values") or []
    names = [str(n) for n in fit.standard.get("names") or []]
    record = dict(zip(names, (_num(v) for v in values), strict=False))
    rows = []
    for joint in fit.joints:
        got = [record.get(f"{joint}:{k}", math.nan) for k in _STANDARD]
        if all(math.isnan(v) for v in got):
            continue
        m = got[0]
        com = [v / m if m > 0 else math.nan for v in got[1:4]]
        row = {"joint": joint, "mass [kg]": m}
        row.update({f"c{a} [m]": c for a, c in zip("xyz", com, strict=True)})
        row.update({f"{k} [kg m^2]": v for k, v in zip(_STANDARD[4:], got[4:], strict=True)})
        rows.append(row)
    return pd.DataFrame(rows)


def consistency_note(fit: ArmFit) -> str:
    """The consistency summary as the fit recorded it (nothing is checked here)."""
    std = fit.standard
    if not std:
        return "The fit holds no standard parameters (the consistency step was not run)."
    text = f"Standard parameters used: {std.get('used', 'not recorded')}."
    if "consistent_ls" in std:
        already = bool(std["consistent_ls"])
        text += (
            " The least-squares base parameters were already physically consistent."
            if already
            else " The least-squares base parameters were not physically consistent (a link's "
            "pseudo-inertia not positive definite); the consistent ones were fitted instead"
        )
        if not already and "d2" in std:
            text += (
                f", at a Mahalanobis distance of {_num(std['d2']):.4g} from the least-squares "
                "ones in their covariance"
            )
        text += "." if not already else ""
    return text


def _curves(fit: ArmFit) -> tuple[bytes | None, list[str]]:
    """Small multiples of each joint's friction over its measured speeds; the joints left
    out (no determined model) with the reason."""
    drawn, skipped = [], []
    for joint in fit.joints:
        try:
            drawn.append((joint, fit.joint_model(joint)))
        except ConfigError as exc:
            skipped.append(str(exc))
    if not drawn:
        return None, skipped
    ncols = min(4, len(drawn))
    nrows = math.ceil(len(drawn) / ncols)
    with styled():
        fig, axes = new_figure(nrows, ncols, width=3.0 * ncols, height=2.4 * nrows)
        flat = np.atleast_1d(axes).ravel()
        for ax in flat[len(drawn) :]:
            ax.set_visible(False)
        for ax, (joint, model) in zip(flat, drawn, strict=False):
            lo, hi = model.operating_range.get("velocity", [-1.0, 1.0])
            v = np.linspace(float(lo), float(hi), 401)
            ax.plot(v, model.predict_point(v), lw=1.4)
            ax.axhline(0.0, lw=0.5, color="0.6")
            ax.axvline(0.0, lw=0.5, color="0.6")
            ax.set_title(f"{joint} ({fit.verdict(joint)})", fontsize=9)
            ax.set_xlabel("velocity [rad/s]")
            ax.set_ylabel("friction [N m]")
        return png(fig), skipped


def _meta(fit: ArmFit) -> dict[str, str]:
    prov = fit.provenance

    def text(key: str, fmt: str = "{}") -> str:
        value = prov.get(key)
        return "–" if value is None else fmt.format(value)

    return {
        "log": text("source"),
        "URDF": text("urdf"),
        "estimator": text("estimator"),
        "equations": text("samples"),
        "filter": text("filter"),
        "filter cut-off [Hz]": text("cutoff", "{:.4g}"),
        "decimation": text("decimation"),
        "rows near reversals left out [periods]": text("reversal_window", "{:g}"),
        "closed loop": text("closed_loop") if "closed_loop" in prov else "not recorded",
        "identification [s]": text("seconds", "{:.3g}"),
    }


def _trust_section(doc: Document, fit: ArmFit) -> None:
    trust = doc.section("Can I trust this? One row per joint")
    trust.add(
        Table(
            "joints",
            "Verdict per joint",
            verdict_table(fit),
            caption=(
                "Held-out torque error over the joint's noise after the filter; the verdict "
                "and its reasons are those the identification computed."
            ),
        )
    )
    trust.add(
        Note(
            "Held-out residuals over time are not drawn: the fit file holds each joint's "
            "held-out error and noise, not the residual series."
        )
    )


def _friction_section(doc: Document, fit: ArmFit) -> None:
    figures = doc.section("Friction per joint")
    image, skipped = _curves(fit)
    if image is not None:
        figures.add(
            Figure(
                "friction_per_joint",
                "Identified friction per joint",
                image,
                caption=(
                    "Each joint's friction over the speeds it was measured at (title: its verdict)."
                ),
            )
        )
    for line in skipped:
        figures.add(Note(f"Not drawn: {line}", kind="warning"))
    figures.add(Table("friction", "Friction parameters", friction_table(fit)))


def _inertial_section(doc: Document, fit: ArmFit) -> None:
    inertial = doc.section("Inertial parameters")
    base = base_table(fit)
    n_det = int((base["determined"] == "yes").sum()) if len(base) else 0
    inertial.add(
        Note(
            f"{len(base)} base inertial parameters (the combinations of the links' standard "
            f"parameters the joint torques can tell apart), {n_det} determined by the data. "
            + consistency_note(fit)
        )
    )
    inertial.add(Table("base_parameters", "Base inertial parameters", base))
    links = link_table(fit)
    if len(links):
        inertial.add(
            Table(
                "links",
                "Each link from the standard parameters used",
                links,
                caption=(
                    "Mass, centre of mass and rotational inertia about the joint frame's origin; "
                    "only their base combinations are identified, the rest comes from the "
                    "consistency step and the URDF."
                ),
            )
        )


def arm_report(fit: ArmFit) -> Document:
    """The report of a whole arm's identification (module notes), to be written with
    :func:`fricid.report.write_document`."""
    prov = fit.provenance
    levels = [fit.verdict(j) for j in fit.joints]
    counts = ", ".join(f"{levels.count(k)} {k}" for k in ("yes", "with caveats", "no"))
    doc = Document(
        title=f"Whole-arm identification: {prov.get('robot') or prov.get('urdf') or 'robot'}",
        summary=(
            f"{len(fit.joints)} joints identified together with the arm's rigid-body dynamics "
            f"({prov.get('estimator') or 'estimator not recorded'}). Trust per joint: {counts}."
        ),
        meta=_meta(fit),
    )
    _trust_section(doc, fit)
    _friction_section(doc, fit)
    _inertial_section(doc, fit)
    return doc
