"""Least-squares Coulomb-viscous projection of any model over its operating range.

Simulators and controller configurations hold friction as ``F = F_c sign(v) + b v`` (URDF
``<dynamics friction= damping=>``, MJCF ``frictionloss``/``damping``), or as that pair per
direction (the ros2_control-style YAML). :func:`project` finds the pair(s) closest to any
fricid model, in the least-squares sense with ``F_c, b >= 0``, over a grid that spans the
model's operating range, and measures what the projection loses.

The grid
    Velocity: 200 points per direction, evenly spaced over the identified range of ``|v|``
    (``FittedModel.operating_range``; a range that does not reach 0, e.g. 0.005-4 rad/s, is
    used as is, one that spans 0 gives ``(0, max]`` per side). A model identified on
    direction-combined samples (positive velocities only) is odd in velocity, so the negative
    side mirrors the positive one. Load and temperature: 7 points each, evenly spaced over
    their identified ranges (one point where the range is a single value). The error
    measures are the RMS and the largest absolute difference over this grid, and the RMS
    difference relative to the RMS friction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import DataError
from ..fitted import FittedModel
from ._common import ExportError, model_name, percent, plain, undetermined_parameters

__all__ = [
    "N_LEVELS",
    "N_VELOCITY",
    "Projection",
    "friction_reads",
    "operating_grid",
    "project",
    "rests_on",
    "rests_on_names",
]

#: Velocity points per direction, and load / temperature levels, of the projection grid.
N_VELOCITY = 200
N_LEVELS = 7


@dataclass(frozen=True)
class Projection:
    """A Coulomb-viscous projection and its error.

    Attributes
    ----------
    coulomb : N m, ``F_c`` (both directions) or ``{"positive": .., "negative": ..}`` magnitudes.
    viscous : N m s/rad, ``b``, likewise.
    rms_error, max_error : N m, over the grid; ``max_at`` is (velocity, load, temperature)
        where the largest error occurs.
    rms_friction : N m, RMS of the model over the grid (the scale of ``relative_error``).
    relative_error : ``rms_error / rms_friction``.
    ranges : the grid's velocity (per side), load and temperature ranges.
    lost : what the projection cannot hold, one phrase each, with numbers.
    rests_on : one line per undetermined parameter that moves the projection
        (:func:`rests_on`); ``rests_on_names`` names them.
    """

    per_direction: bool
    coulomb: dict[str, float]
    viscous: dict[str, float]
    rms_error: float
    max_error: float
    max_at: tuple[float, float, float]
    rms_friction: float
    relative_error: float
    ranges: dict[str, Any] = field(default_factory=dict)
    lost: list[str] = field(default_factory=list)
    rests_on: list[str] = field(default_factory=list)
    rests_on_names: list[str] = field(default_factory=list)

    def summary(self) -> list[str]:
        """Lines for a comment in the exported file."""
        v = self.ranges
        unused = v.get("unused", [])

        def span(name: str, unit: str) -> str:
            if name in unused:
                return f"{name}: not read by the model"
            return f"{name} {v[name][0]:.4g} to {v[name][1]:.4g} {unit}"

        at = [f"velocity {self.max_at[0]:.4g} rad/s"]
        at += [
            f"{name} {x:.4g} {unit}"
            for name, x, unit in (
                ("load", self.max_at[1], "N m"),
                ("temperature", self.max_at[2], "degC"),
            )
            if name not in unused
        ]
        lines = [
            "least-squares Coulomb-viscous projection (F_c, b >= 0) over the operating range: "
            f"|velocity| {v['speed'][0]:.4g} to {v['speed'][1]:.4g} rad/s"
            f"{_mirrored(v)}, "
            f"{span('load', 'N m')}, {span('temperature', 'degC')}",
            f"projection error: RMS {self.rms_error:.4g} N m "
            f"({percent(self.relative_error)} of the RMS friction {self.rms_friction:.4g} N m), "
            f"max {self.max_error:.4g} N m at " + ", ".join(at),
        ]
        if self.lost:
            lines.append("lost in this format: " + "; ".join(self.lost))
        return lines + self.rests_on


def _range(fitted: FittedModel, name: str, override) -> tuple[float, float]:
    if override is not None:
        lo, hi = (float(x) for x in np.broadcast_to(np.asarray(override, dtype=float), (2,)))
    else:
        pair = (fitted.operating_range or {}).get(name)
        if pair is None:
            raise ExportError(
                f"the model file has no operating range for {name}, so the projection has no "
                f"range to work over; give one (e.g. {name}_range=(low, high) in SI units)"
            )
        lo, hi = float(pair[0]), float(pair[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
        raise ExportError(f"the {name} range must be finite with low <= high, got ({lo}, {hi})")
    return lo, hi


def operating_grid(
    fitted: FittedModel,
    velocity_range=None,
    load_range=None,
    temperature_range=None,
) -> tuple[np.ndarray, dict[str, Any]]:
    """The projection grid ``X`` (n, 3) of a model, and its description.

    ``*_range`` override the model's ``operating_range`` ([low, high] in SI units, or one
    value for a fixed operating point).
    """
    v_lo, v_hi = _range(fitted, "velocity", velocity_range)
    if v_lo >= 0 or v_hi <= 0:  # one direction only: |v| range, mirrored
        a, b = sorted((abs(v_lo), abs(v_hi)))
        mirrored = True
        pos = np.linspace(a, b, N_VELOCITY) if b > a else np.full(1, b)
        neg = -pos
    else:  # each side from its slowest measured speed, where the file records it
        mirrored = False
        cover = (fitted.provenance or {}).get("speeds") if velocity_range is None else None
        slow_pos = _slowest(cover, "pos", v_hi)
        slow_neg = _slowest(cover, "neg", -v_lo)
        pos = np.linspace(slow_pos or v_hi / N_VELOCITY, v_hi, N_VELOCITY)
        neg = np.linspace(v_lo, -(slow_neg or -v_lo / N_VELOCITY), N_VELOCITY)
        a, b = min(slow_pos or 0.0, slow_neg or 0.0), max(-v_lo, v_hi)
    if b <= 0:
        raise ExportError("the velocity range is zero; there is no motion to project over")
    levels, unused = {}, []
    used = _inputs(fitted)
    for name, override in (("load", load_range), ("temperature", temperature_range)):
        if override is None and name not in used and name not in (fitted.operating_range or {}):
            # an input the model does not read (a Stribeck model fitted on velocity alone):
            # one placeholder level, never used by the prediction
            levels[name] = np.zeros(1)
            unused.append(name)
            continue
        lo, hi = _range(fitted, name, override)
        levels[name] = np.linspace(lo, hi, N_LEVELS) if hi > lo else np.array([lo])
    v = np.concatenate([neg, pos])
    V, L, T = np.meshgrid(v, levels["load"], levels["temperature"], indexing="ij")
    X = np.column_stack([V.ravel(), L.ravel(), T.ravel()])
    directions = (fitted.provenance or {}).get("directions")
    sides = {1: "positive", -1: "negative"}
    one = directions[0] if isinstance(directions, list) and len(directions) == 1 else 0
    info = {
        "speed": (a, b),
        "mirrored": mirrored,
        "one_side": sides.get(one) if mirrored else None,
        "load": (float(levels["load"][0]), float(levels["load"][-1])),
        "temperature": (float(levels["temperature"][0]), float(levels["temperature"][-1])),
        "unused": unused,
    }
    return X, info


def _slowest(cover: Any, side: str, top: float) -> float | None:
    """The slowest measured speed of ``side`` (``"pos"``, ``"neg"``) [rad/s] of a file's
    ``provenance["speeds"]`` when it is below ``top``, the side's largest; else None."""
    try:
        low = float(cover[side]["range"][0])
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    return low if 0.0 < low < top else None


def _mirrored(info: dict[str, Any]) -> str:
    """The grid's note on a side it mirrors: a direction-combined model is odd in velocity by
    construction; a model of one direction's samples was not measured on the other."""
    if not info["mirrored"]:
        return ""
    side = info.get("one_side")
    if side is None:
        return " (mirrored: direction-combined model)"
    other = "negative" if side == "positive" else "positive"
    return (
        f" (mirrored: identified for {side} velocity only: the {other} side is its mirror "
        "image, not measured)"
    )


def _nnls(A: np.ndarray, y: np.ndarray) -> np.ndarray:
    from scipy.optimize import nnls  # here: `fricid --help` starts without it

    scale = np.maximum(np.abs(A).max(axis=0), 1e-300)
    x, _ = nnls(A / scale, y)
    return x / scale


def _inputs(fitted: FittedModel) -> tuple[str, ...]:
    from .points import model_inputs

    return model_inputs(fitted)


def _lost(
    fitted: FittedModel,
    X: np.ndarray,
    F: np.ndarray,
    info: dict[str, Any],
    per_direction: bool,
    side_fits: dict[str, np.ndarray],
) -> list[str]:
    lost = []
    inputs = _inputs(fitted)
    if fitted.kind == "rbf":
        what = "RBF network" if fitted.model == "rbf" else "Gaussian process"
        lost.append(f"the {what}'s shape (only F_c and b remain)")
    elif model_name(fitted).split("_asym")[0] not in ("coulomb_viscous", "dahl"):
        # (a Dahl model's steady state is Coulomb-viscous: its dynamics are said by the format)
        v = X[:, 0]
        if model_name(fitted).endswith("_asym"):  # each direction's own slowest point
            parts = []
            for word, side in (("forwards", v > 0), ("backwards", v < 0)):
                if side.any():
                    slow = side & (np.abs(v) == np.abs(v[side]).min())
                    parts.append(
                        f"{np.abs(F[slow]).max():.4g} N m {word} at "
                        f"{np.abs(v[slow]).min():.4g} rad/s"
                    )
            at = ", ".join(parts)
        else:
            slow = np.abs(v) == np.abs(v).min()
            at = f"{np.abs(F[slow]).max():.4g} N m at the lowest speed {np.abs(v).min():.4g} rad/s"
        lost.append(
            f"the velocity shape of '{model_name(fitted)}' (e.g. the Stribeck break-away: {at})"
        )
    for name in ("load", "temperature"):
        lo, hi = info[name]
        if name in inputs and hi > lo:
            unit = "N m" if name == "load" else "degC"
            lost.append(f"the {name} dependence ({name} {lo:.4g} to {hi:.4g} {unit})")
    if not per_direction and {"positive", "negative"} <= side_fits.keys():
        p, n = side_fits["positive"], side_fits["negative"]
        if not np.allclose(p, n, rtol=1e-6, atol=1e-12):
            lost.append(
                f"the direction asymmetry (per direction F_c {p[0]:.4g} / {n[0]:.4g} N m, "
                f"b {p[1]:.4g} / {n[1]:.4g} N m s/rad; one value for both here)"
            )
    return lost


def project(
    fitted: FittedModel,
    per_direction: bool = False,
    *,
    velocity_range=None,
    load_range=None,
    temperature_range=None,
) -> Projection:
    """The least-squares Coulomb-viscous projection of ``fitted`` (see the module docstring).

    Parameters
    ----------
    fitted : any model, analytic or RBF.
    per_direction : one ``(F_c, b)`` pair for each direction of motion (else one for both).
    velocity_range, load_range, temperature_range : override the model's operating range.

    Returns
    -------
    Projection
        The parameters, the error over the grid, and what is lost.
    """
    X, info = operating_grid(fitted, velocity_range, load_range, temperature_range)
    F = fitted.predict(X)
    if not np.isfinite(F).all():
        k = int(np.argmin(np.isfinite(F)))
        v, load, temp = (float(x) for x in X[k])
        raise DataError(
            f"model '{model_name(fitted)}' gives a non-finite friction ({float(F[k])!r}) at "
            f"velocity {v!r} rad/s, load {load!r} N m, temperature {temp!r} degC of its "
            "operating range; it cannot be projected"
        )
    v = X[:, 0]
    s = np.sign(v)
    pos = v > 0
    side_fits = _pairs(F, v, True)
    fits = side_fits if per_direction else _pairs(F, v, False)
    resting = _resting(fitted, X, per_direction)
    if per_direction:
        approx = np.where(
            pos,
            fits["positive"][0] * s + fits["positive"][1] * v,
            fits["negative"][0] * s + fits["negative"][1] * v,
        )
    else:
        approx = fits["both"][0] * s + fits["both"][1] * v
    resid = approx - F
    k = int(np.argmax(np.abs(resid)))
    rms_f = float(np.sqrt(np.mean(F**2)))
    rms_e = float(np.sqrt(np.mean(resid**2)))
    return Projection(
        per_direction=per_direction,
        coulomb={key: float(x[0]) for key, x in fits.items()},
        viscous={key: float(x[1]) for key, x in fits.items()},
        rms_error=rms_e,
        max_error=float(np.abs(resid[k])),
        max_at=(float(X[k, 0]), float(X[k, 1]), float(X[k, 2])),
        rms_friction=rms_f,
        relative_error=rms_e / rms_f if rms_f > 0 else 0.0,
        ranges=info,
        lost=_lost(fitted, X, F, info, per_direction, side_fits),
        rests_on=[line for _, line in resting],
        rests_on_names=[name for name, _ in resting],
    )


def _pairs(F: np.ndarray, v: np.ndarray, per_direction: bool) -> dict[str, np.ndarray]:
    """The least-squares ``(F_c, b)``, both >= 0, of friction ``F`` at velocities ``v``: per
    direction (``positive``, ``negative``: magnitudes) or for both (``both``)."""
    s = np.sign(v)
    if not per_direction:
        return {"both": _nnls(np.column_stack([s, v]), F)}
    pos = v > 0
    return {
        "positive": _nnls(np.column_stack([s[pos], v[pos]]), F[pos]),
        "negative": _nnls(np.column_stack([-s[~pos], -v[~pos]]), -F[~pos]),
    }


def rests_on(fitted: FittedModel, X: np.ndarray, per_direction: bool) -> list[str]:
    """One line per parameter the trajectory does not determine
    (:func:`fricid.export.undetermined_parameters`, exported with ``--allow-undetermined``)
    that moves the Coulomb-viscous projection over the grid ``X``: how far ``F_c`` and ``b``
    move as it spans its search range, the others held. A LuGre model's sigma_0 and sigma_1
    shape only its transients and never appear; a parameter whose search range the file does
    not record is named without a span."""
    return [line for _, line in _resting(fitted, X, per_direction)]


def rests_on_names(fitted: FittedModel, X: np.ndarray, per_direction: bool) -> list[str]:
    """The names of the parameters :func:`rests_on` writes a line for: the undetermined
    parameters the projection over ``X`` depends on (a LuGre model's sigma_0 and sigma_1
    never)."""
    return [name for name, _ in _resting(fitted, X, per_direction)]


def _resting(fitted: FittedModel, X: np.ndarray, per_direction: bool) -> list[tuple[str, str]]:
    """``(name, line)`` of :func:`rests_on`."""
    names = undetermined_parameters(fitted)
    if not names or fitted.kind == "rbf":
        return []
    model = fitted.friction_model()
    order = list(model.param_names)
    theta = fitted.theta()
    v = X[:, 0]

    def pairs_at(name: str, value: float) -> np.ndarray:
        th = theta.copy()
        th[order.index(name)] = value
        with np.errstate(all="ignore"):
            F = np.asarray(model.predict(th, X), dtype=float)
        if not np.isfinite(F).all():
            return np.full((2, 2), np.nan)
        return np.array(list(_pairs(F, v, per_direction).values()))

    lines = []
    here = np.array(list(_pairs(fitted.predict(X, warn=False), v, per_direction).values()))
    for name in names:
        p = fitted.parameters[name]
        unit = p.unit or model.units.get(name, "")
        unit = f" {plain(unit)}" if unit and unit != "1" else ""
        ends = [float(b) for b in (p.bounds or ()) if math.isfinite(float(b))]
        if len(ends) < 2:
            moved = pairs_at(name, 1.01 * p.value + 1e-12)
            if np.allclose(moved, here, rtol=1e-9, atol=1e-15):
                continue
            lines.append(
                (
                    name,
                    f"the projection rests on {plain(name)}, which the trajectory does not "
                    "determine (its search range is not recorded): F_c and b are no better "
                    "determined",
                )
            )
            continue
        every = np.stack([here, *(pairs_at(name, x) for x in ends)])
        every = every[np.isfinite(every).all(axis=(1, 2))]
        if np.allclose(every, here, rtol=1e-9, atol=1e-15):
            continue  # the steady state does not read it
        fc, b = every[..., 0], every[..., 1]
        lines.append(
            (
                name,
                f"the projection rests on {plain(name)}, which the trajectory does not "
                f"determine: across its search range {ends[0]:.4g} to {ends[1]:.4g}{unit} (the "
                f"others as identified) F_c spans {fc.min():.4g} to {fc.max():.4g} N m and b "
                f"{b.min():.4g} to {b.max():.4g} N m s/rad",
            )
        )
    return lines


def friction_reads(fitted: FittedModel, X: np.ndarray, names: list[str]) -> list[str]:
    """Those of ``names`` (parameters of an analytic model) that move its predicted friction
    at the points ``X`` (n, 3): set to either end of its recorded search range, or 1 % off
    its value (1 at a value of 0), the others as identified. A LuGre model's friction at a
    speed is its steady state, which sigma_0 and sigma_1 (its transients) do not move."""
    if not names or fitted.kind == "rbf":
        return list(names)
    model = fitted.friction_model()
    order = list(model.param_names)
    theta = fitted.theta()
    X = np.asarray(X, dtype=float)
    here = np.asarray(model.predict(theta, X), dtype=float)
    read = []
    for name in names:
        p = fitted.parameters[name]
        tries = [float(b) for b in (p.bounds or ()) if math.isfinite(float(b))]
        # 1 % off, or 1 in its unit at 0 (where 1 % off is no change: sigma_2 held at 0)
        for value in [*tries, 1.01 * p.value if p.value != 0 else 1.0]:
            th = theta.copy()
            th[order.index(name)] = value
            with np.errstate(all="ignore"):
                F = np.asarray(model.predict(th, X), dtype=float)
            if np.isfinite(F).all() and not np.allclose(F, here, rtol=1e-9, atol=1e-15):
                read.append(name)
                break
    return read
