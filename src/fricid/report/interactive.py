"""Interactive (Plotly) versions of the friction figures people want to zoom, for the HTML report.

Each function returns a Plotly figure as JSON text (``{"data": [...], "layout": {...}}``),
built from plain dicts, so nothing but the JSON format is needed to make one; the HTML
renderer (:mod:`fricid.report.render`) embeds plotly.js itself inline, so the page stays one
self-contained file that works offline. The static PNG of the same figure
(:mod:`fricid.report.plots`) stays beside it for the Markdown report and without JavaScript.

* :func:`friction_figure`: measured and predicted friction against velocity, small
  multiples: one panel per load and temperature band, shared axes, a colour per direction;
* :func:`residual_figure`: residuals against each input that varies (velocity on the log
  speed axis the PNG uses, load, temperature), one panel each, with the ±2 RMSE band;
* :func:`stribeck_figure`: the friction magnitude against speed on a log axis, the Stribeck
  region at its left, with the model's Stribeck velocities marked.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping

import numpy as np

from ..samples import FrictionSamples
from .plots import velocity_grid
from .style import COLORS, band_edges, in_band, torque_scale, velocity_scale

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

#: Pixels of one panel's plotting area, and of the gaps that hold a panel's axis titles and
#: the title of the panel below.
PANEL_PX, GAP_PX = 300, 95


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


def _ref_key(ref: str) -> str:
    """A trace's axis reference -> its layout key: ``x`` -> ``xaxis``, ``y3`` -> ``yaxis3``."""
    return f"{ref[0]}axis{ref[1:]}"


def _panels(cells: list[tuple[int, int]], n_rows: int, n_cols: int) -> list[dict]:
    """One panel per ``(row, col)`` cell of an ``n_rows`` x ``n_cols`` grid (row 0 at the top):
    its axis references and domains (fractions of the plotting area)."""
    height = n_rows * PANEL_PX + (n_rows - 1) * GAP_PX
    gap_y = GAP_PX / height
    gap_x = 0.09 if n_cols > 1 else 0.0
    w = (1.0 - gap_x * (n_cols - 1)) / n_cols
    h = (1.0 - gap_y * (n_rows - 1)) / n_rows
    out = []
    for k, (r, c) in enumerate(cells, start=1):
        x0, y1 = c * (w + gap_x), 1.0 - r * (h + gap_y)
        suffix = "" if k == 1 else str(k)
        out.append(
            {"x": f"x{suffix}", "y": f"y{suffix}", "xd": [x0, x0 + w], "yd": [max(0.0, y1 - h), y1]}
        )
    return out


def _grid_layout(
    title: str,
    panels: list[dict],
    xaxes: list[dict],
    ytitle: str,
    *,
    n_rows: int,
    share_x: bool,
    labels: list[str] | None = None,
) -> dict:
    """The layout of small multiples: every panel's axes titled (with their units), the y
    axes shared (and the x axes with ``share_x``), the legend at the right of the panels
    (clear of every axis title), a title above each panel from ``labels``."""
    layout: dict = {
        "title": {"text": title},
        "hovermode": "closest",
        "legend": {"orientation": "v", "x": 1.02, "xanchor": "left", "y": 1, "yanchor": "top"},
        "margin": {"t": 70, "r": 20, "b": 60, "l": 70},
        "template": "plotly_white",
        "height": 130 + n_rows * PANEL_PX + (n_rows - 1) * GAP_PX,
        "annotations": [],
    }
    for k, (panel, xaxis) in enumerate(zip(panels, xaxes, strict=True)):
        layout[_ref_key(panel["x"])] = {
            **xaxis,
            "domain": panel["xd"],
            "anchor": panel["y"],
            **({"matches": "x"} if share_x and k else {}),
        }
        layout[_ref_key(panel["y"])] = {
            "title": {"text": ytitle},
            "zeroline": True,
            "domain": panel["yd"],
            "anchor": panel["x"],
            **({"matches": "y"} if k else {}),
        }
        if labels and labels[k]:
            layout["annotations"].append(
                {
                    "text": labels[k],
                    "xref": "paper",
                    "yref": "paper",
                    "x": sum(panel["xd"]) / 2,
                    "y": panel["yd"][1],
                    "xanchor": "center",
                    "yanchor": "bottom",
                    "showarrow": False,
                    "font": {"size": 13},
                }
            )
    return layout


def _dump(data: list[dict], layout: dict) -> str:
    return json.dumps({"data": data, "layout": layout}, allow_nan=False)


def _curve(predict: Predict, v: np.ndarray, load: float, temp: float, log: bool):
    grid = velocity_grid(v, log=log)
    ok = np.isfinite(grid)
    X = np.column_stack([grid, np.full_like(grid, load), np.full_like(grid, temp)])
    y = np.full_like(grid, np.nan)
    y[ok] = predict(X[ok])
    return grid, y


def _band_cells(samples: FrictionSamples, max_bands: int) -> tuple[list[tuple], int, int]:
    """The panels of the friction figure: ``((row, col), load band, temperature band, label)``
    of each band pair holding samples (rows temperature bands, columns load bands; one row
    when only the temperature varies), and the grid's rows and columns."""
    l_bands = band_edges(samples.load, max_bands)
    t_bands = band_edges(samples.temperature, max_bands)
    by_temp_in_a_row = len(l_bands) == 1 and len(t_bands) > 1
    cells = []
    for i, tb in enumerate(t_bands):
        for j, lb in enumerate(l_bands):
            sel = in_band(samples.load, lb) & in_band(samples.temperature, tb)
            if not sel.any():
                continue
            parts = []
            if len(l_bands) > 1:
                parts.append(_span(*lb, "N m", "load", prefix="load "))
            if len(t_bands) > 1:
                parts.append(_span(*tb, "°C", "temperature"))
            cell = (0, i) if by_temp_in_a_row else (i, j)
            cells.append((cell, lb, tb, ", ".join(parts)))
    n_rows = 1 if by_temp_in_a_row else len(t_bands)
    n_cols = len(t_bands) if by_temp_in_a_row else len(l_bands)
    return cells, n_rows, n_cols


def _span(low: float, high: float, unit: str, name: str, prefix: str = "") -> str:
    """A panel's band of load or temperature: ``prefix`` then ``1–2 N m``, or ``<name> not
    measured`` for the band of samples without it (:func:`fricid.report.style.band_edges`)."""
    if np.isnan(low):
        return f"{name} not measured"
    return prefix + (f"{low:.3g} {unit}" if low == high else f"{low:.3g}–{high:.3g} {unit}")


def friction_figure(
    samples: FrictionSamples,
    predict: Predict,
    *,
    velocity_unit: str = "rad/s",
    title: str = "Measured and predicted friction",
    log: bool | None = None,
    max_bands: int = 3,
) -> str:
    """Measured friction (markers) and the model (lines) against velocity: small multiples,
    one panel per load band and temperature band (at most ``max_bands`` of each; rows are
    temperature bands, columns load bands), with shared axes.

    With both directions of motion the x axis is the speed and the y axis the friction
    magnitude ``sign(v) F`` (as :func:`fricid.report.plots.friction_curves`); ``log`` (default:
    when the speeds span over 1.5 decades) puts the x axis on a log scale. Colours tell the
    directions apart (the same in every panel; the panel tells the band), and each line is
    the model at its panel's median load and temperature.
    """
    vf, vunit = velocity_scale(velocity_unit)
    tf, tunit = torque_scale(samples.friction)
    both, groups = _groups(samples)
    speed = np.abs(samples.velocity[samples.velocity != 0])
    if log is None:
        log = bool(speed.size and speed.max() / speed.min() > 30)
    log = bool(log and (both or (samples.velocity > 0).all()))  # a log axis needs one sign
    cells, n_rows, n_cols = _band_cells(samples, max_bands)
    panels = _panels([c[0] for c in cells], n_rows, n_cols)
    data: list[dict] = []
    shown: set[str] = set()
    for panel, (_, lb, tb, _label) in zip(panels, cells, strict=True):
        band = in_band(samples.load, lb) & in_band(samples.temperature, tb)
        for g, (d, mask) in enumerate(groups):
            sel = mask & band
            if not sel.any():
                continue
            color = COLORS[g % len(COLORS)]
            word, symbol, dash = _DIRS.get(d, ("", "circle", "solid"))
            v, f = samples.velocity[sel], samples.friction[sel]
            x, y = (np.abs(v), np.sign(v) * f) if both else (v, f)
            axes = {"xaxis": panel["x"], "yaxis": panel["y"]}
            for kind in ("measured", "model"):
                name = f"{kind}, {word}" if word else kind
                trace = {"type": "scatter", "name": name, "legendgroup": name, **axes}
                trace["showlegend"] = name not in shown
                shown.add(name)
                if kind == "measured":
                    trace.update(mode="markers", x=_list(x * vf), y=_list(y * tf))
                    trace["marker"] = {"symbol": symbol, "color": color, "size": 7, "opacity": 0.7}
                else:
                    load = float(np.median(samples.load[sel]))
                    temp = float(np.median(samples.temperature[sel]))
                    grid, yp = _curve(predict, v, load, temp, log)
                    xg, yg = (np.abs(grid), np.sign(grid) * yp) if both else (grid, yp)
                    trace.update(mode="lines", x=_list(xg * vf), y=_list(yg * tf))
                    trace["line"] = {"color": color, "dash": dash}
                data.append(trace)
    ytitle = f"|friction torque| [{tunit}]" if both else f"friction torque [{tunit}]"
    layout = _grid_layout(
        title,
        panels,
        [_axis_x(both, vunit, log) for _ in panels],
        ytitle,
        n_rows=n_rows,
        share_x=True,
        labels=[c[3] for c in cells],
    )
    return _dump(data, layout)


def _residual_inputs(samples: FrictionSamples, both: bool, vf: float, vunit: str) -> list:
    """``(name, x values, x axis)`` of each input the residuals are drawn against: the
    velocity (speed with both directions; a log axis when it spans over 1.5 decades of one
    sign, as the PNG), and the load and the temperature where they vary."""
    v = np.abs(samples.velocity) if both else samples.velocity
    moving = v[v != 0]
    log = bool(moving.size and (moving > 0).all() and moving.max() / moving.min() > 30)
    out = [("velocity", v * vf, _axis_x(both, vunit, log))]
    if np.ptp(samples.load) > 0:
        out.append(("load", samples.load, {"title": {"text": "load [N m]"}, "type": "linear"}))
    if np.ptp(samples.temperature) > 0:
        axis = {"title": {"text": "temperature [°C]"}, "type": "linear"}
        out.append(("temperature", samples.temperature, axis))
    return out


def residual_figure(
    samples: FrictionSamples,
    residual: np.ndarray,
    *,
    velocity_unit: str = "rad/s",
    title: str = "Residuals (measured − predicted) against each input",
) -> str:
    """Residuals against each input that varies, one panel each side by side with a shared
    y axis, as ``residuals.png`` beside it: the velocity (the speed when both directions are
    present, on a log axis when it spans over 1.5 decades), the load, the temperature; per
    direction, with dashed ±2 RMSE lines; hovering a point shows its load and temperature."""
    residual = np.asarray(residual, dtype=float)
    vf, vunit = velocity_scale(velocity_unit)
    rf, runit = torque_scale(residual)
    both, groups = _groups(samples)
    inputs = _residual_inputs(samples, both, vf, vunit)
    panels = _panels([(0, j) for j in range(len(inputs))], 1, len(inputs))
    data: list[dict] = []
    for panel, (_name, x, _axis) in zip(panels, inputs, strict=True):
        for k, (d, sel) in enumerate(groups):
            word, symbol, _ = _DIRS.get(d, ("residual", "circle", "solid"))
            data.append(
                {
                    "type": "scatter",
                    "mode": "markers",
                    "name": word,
                    "legendgroup": word,
                    "showlegend": panel is panels[0],
                    "xaxis": panel["x"],
                    "yaxis": panel["y"],
                    "x": _list(x[sel]),
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
    layout = _grid_layout(
        title,
        panels,
        [axis for *_, axis in inputs],
        f"residual [{runit}]",
        n_rows=1,
        share_x=False,
    )
    layout["shapes"] = [
        {
            "type": "line",
            "xref": f"{panel['x']} domain",
            "yref": panel["y"],
            "x0": 0,
            "x1": 1,
            "y0": s * rmse * rf,
            "y1": s * rmse * rf,
            "line": {"dash": "dash", "color": "#777", "width": 1},
        }
        for panel in panels
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
    layout = spec["layout"]
    marks = stribeck_velocities(params)
    refs = sorted((k for k in layout if k.startswith("xaxis")), key=lambda k: int(k[5:] or 1))
    layout["shapes"] = [
        {
            "type": "line",
            "xref": f"x{key[5:]}",
            "yref": f"y{key[5:]} domain",
            "y0": 0,
            "y1": 1,
            "x0": value * vf,
            "x1": value * vf,
            "line": {"dash": "dot", "color": "#555", "width": 1},
        }
        for key in refs
        for value in marks.values()
    ]
    layout["annotations"] = layout.get("annotations", []) + [
        {
            "x": float(np.log10(value * vf)),
            "xref": "x",
            "y": 1,
            "yref": "paper",
            "text": name,
            "showarrow": False,
            "yanchor": "bottom",
            "yshift": 20 + 14 * k,
        }
        for k, (name, value) in enumerate(marks.items())
    ]
    layout["margin"]["t"] = 70 + 14 * len(marks)
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
