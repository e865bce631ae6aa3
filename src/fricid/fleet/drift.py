"""Drift: which joints' friction changed since a previous identification.

Each joint and model identified in both tables is compared parameter by parameter: a
parameter is *flagged* when it moved by more than its combined confidence intervals,
``|p_now - p_before| > ci95_now + ci95_before`` (the two 95 % intervals no longer overlap).
Because parameters of a friction model are correlated, a moved parameter need not change
the friction much; so the predicted friction of both fits is also compared over the
operating range both identifications cover (velocity, load and temperature grid), and its
largest change is reported. A joint has *drifted* when at least one parameter is flagged and
the friction changed by at least ``min_change``.

The joints of a whole robot's row (``model`` ``arm``) are not compared here: their rows hold
no operating range on the grid's terms (load, temperature), so they are left out rather than
compared on made-up ranges.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ConfigError
from ..io import atomic_path, atomic_write
from ..models import get_model
from ._fs import require_real

__all__ = ["Drift", "compare", "plot_drift", "write_drift"]

_KEY = ["robot", "joint", "model"]

#: The unit of each drift column that has one, as written in the CSV headers (the parameter
#: rows' values are in each row's ``unit``; ratios are dimensionless: no unit).
DRIFT_UNITS = {
    "friction_change_max": "N m",
    "friction_change_rms": "N m",
}


@dataclass(frozen=True, eq=False)
class Drift:
    """The comparison of a results table with a baseline.

    Attributes
    ----------
    joints : one row per joint and model in both tables, worst first: ``drifted``,
        ``n_flagged``, ``flagged`` (parameter names), ``worst_parameter``, ``worst_ratio``
        (its move in units of the combined CIs), ``friction_change_max`` and
        ``friction_change_rms`` [N m] over the common operating range,
        ``friction_change_rel`` (the maximum over the largest baseline friction there), and
        both dates.
    params : one row per joint, model and free parameter, worst first: ``baseline``,
        ``current``, ``change``, ``ci95_baseline``, ``ci95_current``, ``ratio``
        (``|change| / (ci95_baseline + ci95_current)``), ``flagged``, ``unit``.
    new : ``robot/joint (model)`` identified now but not in the baseline (or failed there).
    missing : in the baseline but not identified now (or failed now).
    min_change : the friction change [N m] a joint needs to count as drifted.
    """

    joints: pd.DataFrame
    params: pd.DataFrame
    new: list[str]
    missing: list[str]
    min_change: float = 0.0

    @property
    def drifted(self) -> pd.DataFrame:
        """The rows of :attr:`joints` that drifted."""
        return self.joints[self.joints["drifted"]]


def _ok(frame: pd.DataFrame) -> pd.DataFrame:
    if "status" in frame:
        frame = frame[frame["status"] == "ok"]
    frame = frame[frame["model"] != "arm"]  # a whole robot's joints (module notes)
    return frame.drop_duplicates(_KEY, keep="last").set_index(_KEY)


def _label(key: tuple[str, str, str]) -> str:
    return f"{key[0]}/{key[1]} ({key[2]})"


def _span(b: pd.Series, c: pd.Series, lo: str, hi: str) -> tuple[float, float]:
    """The common interval of two rows' ``[lo, hi]``; the current one if they do not meet."""
    low = max(float(b[lo]), float(c[lo]))
    high = min(float(b[hi]), float(c[hi]))
    if not np.isfinite(low) or not np.isfinite(high) or low > high:
        return float(c[lo]), float(c[hi])
    return low, high


def _grid(b: pd.Series, c: pd.Series, asymmetric: bool, n: int) -> np.ndarray:
    """Operating points (velocity, load, temperature) covering both fits' range."""
    s = np.linspace(*_span(b, c, "speed_min", "speed_max"), n)
    if asymmetric:
        s = np.concatenate([-s[::-1], s])
    loads = np.linspace(*_span(b, c, "load_min", "load_max"), 5)
    temps = np.linspace(*_span(b, c, "temperature_min", "temperature_max"), 5)
    v, lo, t = np.meshgrid(s, np.unique(loads), np.unique(temps), indexing="ij")
    return np.column_stack([v.ravel(), lo.ravel(), t.ravel()])


def _theta(row: pd.Series, names: list[str]) -> np.ndarray:
    return np.array([float(row.get(f"param_{n}", np.nan)) for n in names])


def _units(row: pd.Series) -> dict[str, str]:
    text = row.get("units")
    if not isinstance(text, str):
        return {}
    return dict(p.split("=", 1) for p in text.split(";") if "=" in p)


def compare(
    current: pd.DataFrame, baseline: pd.DataFrame, *, min_change: float = 0.0, n_grid: int = 41
) -> Drift:
    """Compare a results table with a baseline (see the module docstring).

    Parameters
    ----------
    current, baseline : results tables (:func:`fricid.fleet.read_results`); only rows with
        status ``ok`` are compared, matched by robot, joint and model (a whole robot's joints
        are left out: module notes).
    min_change : friction change [N m] below which a joint with flagged parameters is not
        counted as drifted (default 0: any flagged parameter).
    n_grid : velocities in the comparison grid (times 5 loads and 5 temperatures).

    Returns
    -------
    Drift
    """
    if min_change < 0:
        raise ConfigError(f"min_change must be >= 0 N m, got {min_change!r}")
    now, before = _ok(current), _ok(baseline)
    common = [k for k in now.index if k in before.index]
    joints, params = [], []
    for key in common:
        c, b = now.loc[key], before.loc[key]
        model = get_model(key[2])
        names = list(model.param_names)
        units = _units(c)
        rows = []
        for name in names:
            pb, pc = float(b.get(f"param_{name}", np.nan)), float(c.get(f"param_{name}", np.nan))
            cb, cc = float(b.get(f"ci95_{name}", np.nan)), float(c.get(f"ci95_{name}", np.nan))
            if not (np.isfinite(cb) and np.isfinite(cc)):
                continue  # fixed, or no uncertainty: nothing to test
            combined = cb + cc
            change = pc - pb
            ratio = abs(change) / combined if combined > 0 else np.inf * (change != 0)
            rows.append(
                {
                    "robot": key[0],
                    "joint": key[1],
                    "model": key[2],
                    "parameter": name,
                    "unit": units.get(name, ""),
                    "baseline": pb,
                    "current": pc,
                    "change": change,
                    "ci95_baseline": cb,
                    "ci95_current": cc,
                    "ratio": float(ratio),
                    "flagged": bool(ratio > 1.0),
                }
            )
        X = _grid(b, c, model.is_asymmetric, n_grid)
        f_before = model.predict(_theta(b, names), X)
        diff = model.predict(_theta(c, names), X) - f_before
        change_max = float(np.max(np.abs(diff)))
        scale = float(np.max(np.abs(f_before)))
        flagged = [r["parameter"] for r in rows if r["flagged"]]
        worst = max(rows, key=lambda r: r["ratio"], default=None)
        joints.append(
            {
                "robot": key[0],
                "joint": key[1],
                "model": key[2],
                "drifted": bool(flagged) and change_max >= min_change,
                "n_flagged": len(flagged),
                "flagged": ";".join(flagged),
                "worst_parameter": None if worst is None else worst["parameter"],
                "worst_ratio": np.nan if worst is None else worst["ratio"],
                "friction_change_max": change_max,
                "friction_change_rms": float(np.sqrt(np.mean(diff**2))),
                "friction_change_rel": change_max / scale if scale > 0 else np.nan,
                "date_baseline": b.get("date"),
                "date_current": c.get("date"),
            }
        )
        params.extend(rows)
    joint_frame = pd.DataFrame(joints, columns=_JOINT_COLUMNS)
    if len(joint_frame):
        joint_frame = joint_frame.sort_values(
            ["drifted", "friction_change_max", "worst_ratio"], ascending=False, kind="stable"
        ).reset_index(drop=True)
    param_frame = pd.DataFrame(params, columns=_PARAM_COLUMNS)
    if len(param_frame):
        param_frame = param_frame.sort_values(
            ["flagged", "ratio"], ascending=False, kind="stable"
        ).reset_index(drop=True)
    return Drift(
        joints=joint_frame,
        params=param_frame,
        new=[_label(k) for k in now.index if k not in before.index],
        missing=[_label(k) for k in before.index if k not in now.index],
        min_change=float(min_change),
    )


_JOINT_COLUMNS = [
    "robot",
    "joint",
    "model",
    "drifted",
    "n_flagged",
    "flagged",
    "worst_parameter",
    "worst_ratio",
    "friction_change_max",
    "friction_change_rms",
    "friction_change_rel",
    "date_baseline",
    "date_current",
]
_PARAM_COLUMNS = [
    "robot",
    "joint",
    "model",
    "parameter",
    "unit",
    "baseline",
    "current",
    "change",
    "ci95_baseline",
    "ci95_current",
    "ratio",
    "flagged",
]


def plot_drift(drift: Drift, path: str | os.PathLike[str], *, top: int = 30) -> Path:
    """Bar charts of the ``top`` worst joints: friction change and parameter shift (PNG).

    Written atomically, with matplotlib's Agg canvas (no display, no global state).
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    rows = drift.joints.head(top).iloc[::-1]
    labels = [f"{r.robot}/{r.joint} ({r.model})" for r in rows.itertuples()]
    colour = ["#c0392b" if d else "#7f8c8d" for d in rows["drifted"]]
    height = max(3.0, 0.28 * len(rows) + 1.6)
    fig = Figure(figsize=(11.0, height), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2, sharey=True)
    y = np.arange(len(rows))
    ax1.barh(y, 1e3 * rows["friction_change_max"].to_numpy(dtype=float), color=colour)
    ax1.set_yticks(y, labels, fontsize=8)
    ax1.set_xlabel("largest change of predicted friction over the operating range [mN m]")
    if drift.min_change > 0:
        ax1.axvline(1e3 * drift.min_change, color="k", ls=":", lw=1, label="min_change")
    ax2.barh(y, rows["worst_ratio"].to_numpy(dtype=float), color=colour)
    ax2.axvline(1.0, color="k", ls="--", lw=1)
    ax2.set_xlabel("largest parameter move / combined 95 % CIs (flagged above 1)")
    n = int(drift.joints["drifted"].sum()) if len(drift.joints) else 0
    fig.suptitle(
        f"Friction drift against the baseline: {n} of {len(drift.joints)} joint fits drifted "
        f"(worst {len(rows)} shown)"
    )
    fig.legend(
        handles=[
            Patch(color="#c0392b", label="drifted"),
            Patch(color="#7f8c8d", label="not drifted"),
        ],
        loc="outside lower center",
        ncols=2,
    )
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return path


def write_drift(drift: Drift, out: str | os.PathLike[str]) -> dict[str, Path]:
    """Write ``drift_joints.csv``, ``drift_params.csv`` and ``drift.png`` into ``out`` (each
    refused if it is a symbolic link or not a regular file: :func:`._fs.require_real`)."""
    out = Path(out)
    paths = {
        "joints": require_real(out, ["drift_joints.csv"]),
        "params": require_real(out, ["drift_params.csv"]),
        "plot": require_real(out, ["drift.png"]),
    }
    for name in ("joints", "params"):
        frame = getattr(drift, name)
        labels = {c: f"{c} [{u}]" for c, u in DRIFT_UNITS.items() if c in frame}
        with atomic_write(paths[name], "w") as fh:
            frame.rename(columns=labels).to_csv(fh, index=False)
    plot_drift(drift, paths["plot"])
    return paths
