"""Interactive (Plotly) versions of the friction figures people want to zoom, for the HTML report.

Each function returns a Plotly figure as JSON text (``{"data": [...], "layout": {...}}``),
built from plain dicts, so nothing but the JSON format is needed to make one; the HTML
renderer (:mod:`fricid.report.render`) embeds plotly.js itself inline, so the page stays one
self-contained file that works offline. The static PNG of the same figure
(:mod:`fricid.report.plots`) stays beside it for the Markdown report and without JavaScript.

* :func:`friction_figure`: measured and predicted friction against velocity, one trace per
  direction of motion (and per load and temperature band, as the PNG);
* :func:`residual_figure`: residuals against velocity per direction, with the ±2 RMSE band;
* :func:`stribeck_figure`: the friction magnitude against speed on a log axis, the Stribeck
  region at its left, with the model's Stribeck velocities marked.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping

import numpy as np

from ..samples import FrictionSamples
from .plots import velocity_grid
from .style import COLORS, band_edges, torque_scale, velocity_scale

__all__ = [
    "STRIBECK_VELOCITIES",
    "friction_figure",
    "residual_figure",
    "stribeck_figure",
    "stribeck_range",
    "stribeck_velocities",
]

Predict = Callable[[np.ndarray], np.ndarray]

#: Parameter names (without the ``_pos``/``_neg`` suffix) that are a Stribeck velocity.
STRIBECK_VELOCITIES = ("w_s", "v_s", "v_tl0")

_DIRS = {1: ("positive direction", "circle", "solid"), -1: ("negative direction", "square", "dash")}


def _list(values: np.ndarray) -> list[float | None]:
    """JSON numbers, ``None`` (a gap in a Plotly line) where not finite."""
    return [float(v) if np.isfinite(v) else None for v in np.asarray(values, dtype=float)]


def _groups(samples: FrictionSamples) -> tuple[bool, list[tuple[int, np.ndarray]]]:
    """Whether magnitudes are shown against speed (both directions, or only the negative one),
    and ``(direction, mask)`` of each direction shown."""
    v = samples.velocity
    both = {-1, 1} <= set(samples.directions()) or bool((v < 0).all())
    if not both:
        return False, [(0, np.ones(v.size, dtype=bool))]
    return True, [(d, samples.direction == d) for d in (1, -1) if (samples.direction == d).any()]


def _axis_x(both: bool, unit: str, log: bool) -> dict:
    title = f"speed |velocity| [{unit}]" if both else f"velocity [{unit}]"
    return {
        "title": {"text": title + (", log scale" if log else "")},
        "type": "log" if log else "linear",
    }


def _layout(title: str, xaxis: dict, ytitle: str) -> dict:
    return {
        "title": {"text": title},
        "xaxis": xaxis,
        "yaxis": {"title": {"text": ytitle}, "zeroline": True},
        "hovermode": "closest",
        "legend": {"orientation": "h", "y": -0.2},
        "margin": {"t": 50, "r": 20, "b": 40, "l": 70},
        "template": "plotly_white",
        "height": 480,
    }


def _dump(data: list[dict], layout: dict) -> str:
    return json.dumps({"data": data, "layout": layout}, allow_nan=False)


def _curve(predict: Predict, v: np.ndarray, load: float, temp: float, log: bool):
    grid = velocity_grid(v, log=log)
    ok = np.isfinite(grid)
    X = np.column_stack([grid, np.full_like(grid, load), np.full_like(grid, temp)])
    y = np.full_like(grid, np.nan)
    y[ok] = predict(X[ok])
    return grid, y


def friction_figure(
    samples: FrictionSamples,
    predict: Predict,
    *,
    velocity_unit: str = "rad/s",
    title: str = "Measured and predicted friction",
    log: bool | None = None,
    max_bands: int = 3,
) -> str:
    """Measured friction (markers) and the model (lines) against velocity, per direction.

    With both directions of motion the x axis is the speed and the y axis the friction
    magnitude ``sign(v) F`` (as :func:`fricid.report.plots.friction_curves`); ``log`` (default:
    when the speeds span over 1.5 decades) puts the x axis on a log scale. One trace pair per
    direction, load band and temperature band (at most ``max_bands`` of each).
    """
    vf, vunit = velocity_scale(velocity_unit)
    tf, tunit = torque_scale(samples.friction)
    both, groups = _groups(samples)
    speed = np.abs(samples.velocity[samples.velocity != 0])
    if log is None:
        log = bool(speed.size and speed.max() / speed.min() > 30)
    log = bool(log and (both or (samples.velocity > 0).all()))  # a log axis needs one sign
    data: list[dict] = []
    bands = [
        (lb, tb)
        for lb in band_edges(samples.load, max_bands)
        for tb in band_edges(samples.temperature, max_bands)
    ]
    for k, (lb, tb) in enumerate(bands):
        in_band = (samples.load >= lb[0]) & (samples.load <= lb[1])
        in_band &= (samples.temperature >= tb[0]) & (samples.temperature <= tb[1])
        band = (
            ""
            if len(bands) == 1
            else f", load {lb[0]:.3g}–{lb[1]:.3g} N m, {tb[0]:.3g}–{tb[1]:.3g} °C"
        )
        for g, (d, mask) in enumerate(groups):
            color = COLORS[(k * len(groups) + g) % len(COLORS)]
            sel = mask & in_band
            if not sel.any():
                continue
            word, symbol, dash = _DIRS.get(d, ("", "circle", "solid"))
            name = (word or "friction") + band
            v, f = samples.velocity[sel], samples.friction[sel]
            x, y = (np.abs(v), np.sign(v) * f) if both else (v, f)
            data.append(
                {
                    "type": "scatter",
                    "mode": "markers",
                    "name": f"measured, {name}",
                    "legendgroup": name,
                    "x": _list(x * vf),
                    "y": _list(y * tf),
                    "marker": {"symbol": symbol, "color": color, "size": 7, "opacity": 0.7},
                }
            )
            grid, yp = _curve(
                predict,
                v,
                float(np.median(samples.load[sel])),
                float(np.median(samples.temperature[sel])),
                log,
            )
            xg, yg = (np.abs(grid), np.sign(grid) * yp) if both else (grid, yp)
            data.append(
                {
                    "type": "scatter",
                    "mode": "lines",
                    "name": f"model, {name}",
                    "legendgroup": name,
                    "x": _list(xg * vf),
                    "y": _list(yg * tf),
                    "line": {"color": color, "dash": dash},
                }
            )
    ytitle = f"|friction torque| [{tunit}]" if both else f"friction torque [{tunit}]"
    return _dump(data, _layout(title, _axis_x(both, vunit, log), ytitle))


def residual_figure(
    samples: FrictionSamples,
    residual: np.ndarray,
    *,
    velocity_unit: str = "rad/s",
    title: str = "Residuals (measured − predicted) against velocity",
) -> str:
    """Residuals against velocity (speed when both directions are present), per direction,
    with dashed ±2 RMSE lines; hovering a point shows its load and temperature."""
    residual = np.asarray(residual, dtype=float)
    vf, vunit = velocity_scale(velocity_unit)
    rf, runit = torque_scale(residual)
    both, groups = _groups(samples)
    speed = np.abs(samples.velocity[samples.velocity != 0])
    log = bool(both and speed.size and speed.max() / speed.min() > 30)
    data: list[dict] = []
    for k, (d, sel) in enumerate(groups):
        word, symbol, _ = _DIRS.get(d, ("residual", "circle", "solid"))
        v = samples.velocity[sel]
        data.append(
            {
                "type": "scatter",
                "mode": "markers",
                "name": word,
                "x": _list((np.abs(v) if both else v) * vf),
                "y": _list(residual[sel] * rf),
                # a column not measured is NaN: null in the JSON, which allows no NaN
                "customdata": [
                    list(pair)
                    for pair in zip(
                        _list(samples.load[sel]), _list(samples.temperature[sel]), strict=True
                    )
                ],
                "hovertemplate": "%{x:.4g}, %{y:.4g}<br>load %{customdata[0]:.3g} N m, "
                "%{customdata[1]:.3g} °C<extra></extra>",
                "marker": {"symbol": symbol, "color": COLORS[k % len(COLORS)], "size": 7},
            }
        )
    rmse = float(np.sqrt(np.mean(residual**2))) if residual.size else 0.0
    layout = _layout(title, _axis_x(both, vunit, log), f"residual [{runit}]")
    layout["shapes"] = [
        {
            "type": "line",
            "xref": "paper",
            "x0": 0,
            "x1": 1,
            "y0": s * rmse * rf,
            "y1": s * rmse * rf,
            "line": {"dash": "dash", "color": "#777", "width": 1},
        }
        for s in (-2, 2)
    ]
    return _dump(data, layout)


def stribeck_velocities(params: Mapping[str, float]) -> dict[str, float]:
    """The model's Stribeck velocities [rad/s] by parameter name (positive ones only)."""
    out = {}
    for name, value in params.items():
        base = name.removesuffix("_pos").removesuffix("_neg")
        if base in STRIBECK_VELOCITIES and value is not None and float(value) > 0:
            out[name] = float(value)
    return out


def stribeck_figure(
    samples: FrictionSamples,
    predict: Predict,
    params: Mapping[str, float],
    *,
    velocity_unit: str = "rad/s",
    title: str = "The Stribeck region: |friction| against speed, log axis",
) -> str:
    """The friction magnitude against speed on a log axis, per direction (the low-speed,
    Stribeck region at the left), with dotted vertical lines at the model's Stribeck
    velocities (``w_s``, ``v_s``, ``v_tl0``, per direction where the model has them)."""
    spec = json.loads(
        friction_figure(
            samples.subset(samples.velocity != 0),
            predict,
            velocity_unit=velocity_unit,
            title=title,
            log=True,
        )
    )
    vf, _ = velocity_scale(velocity_unit)
    spec["layout"]["shapes"] = [
        {
            "type": "line",
            "yref": "paper",
            "y0": 0,
            "y1": 1,
            "x0": value * vf,
            "x1": value * vf,
            "line": {"dash": "dot", "color": "#555", "width": 1},
        }
        for value in stribeck_velocities(params).values()
    ]
    marks = stribeck_velocities(params)
    spec["layout"]["annotations"] = [
        {
            "x": float(np.log10(value * vf)),
            "y": 1,
            "yref": "paper",
            "text": name,
            "showarrow": False,
            "yanchor": "bottom",
            "yshift": 14 * k,
        }
        for k, (name, value) in enumerate(marks.items())
    ]
    spec["layout"]["margin"]["t"] = 50 + 14 * len(marks)
    low = stribeck_range(samples.velocity, marks)
    if low is not None:  # opens on the Stribeck region; autoscale (double-click) shows all
        spec["layout"]["xaxis"]["range"] = [float(np.log10(b * vf)) for b in low]
    return json.dumps(spec, allow_nan=False)


def stribeck_range(velocity: np.ndarray, marks: Mapping[str, float]) -> tuple[float, float] | None:
    """The speed range [rad/s] of the Stribeck region: from just below the lowest measured speed
    to 20 times the largest Stribeck velocity (None without one, or when that is the whole
    measured range)."""
    speed = np.abs(np.asarray(velocity, dtype=float))
    speed = speed[speed > 0]
    if not marks or not speed.size:
        return None
    high = 20.0 * max(marks.values())
    if high >= speed.max():
        return None
    return 0.8 * float(speed.min()), high
