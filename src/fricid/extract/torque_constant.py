"""The torque constant K of eq. 13 (BAS-RBFNN paper, ``tau = K I``) identified from a log.

A drive logged as motor current needs K to become torque. Two references give it:

- **A joint torque sensor** logged beside the current (:func:`fit_torque_constant`): ``tau =
  K I`` by least squares through the origin over every sample. Behind a gearbox of efficiency
  ``eta`` the sensor sees ``eta K I`` while the motor drives the load (motoring, ``tau v > 0``)
  and ``K I / eta`` while the load drives the motor (generating, ``tau v < 0``); when the log
  has both power flows, the two slopes ``K_m`` and ``K_g`` give ``K = sqrt(K_m K_g)`` and
  ``eta = sqrt(K_m / K_g)``.
- **A known gravity load** (:func:`torque_constant_from_gravity`): the link's mass and centre
  of mass (a URDF) give eq. 7's ``p_x, p_y`` in N m; the same fit on the current (extraction
  with ``torque_constant=1``, so torques are in A) gives them in A; K is their ratio, by least
  squares over the two coefficients.

Intervals: samples of a log are correlated (coloured noise, slow drifts), so the standard
errors are cluster-robust over blocks of consecutive samples (``block_rows``, default 10 000
samples, 40 s at 250 Hz), computed from per-block sums: memory is bounded by the number of
blocks, whatever the log's length. The 95 % interval uses Student's t with (blocks - 1)
degrees of freedom.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from ..samples import RawLog
from .segment import as_log_stream

__all__ = [
    "TorqueConstantFit",
    "current_as_torque",
    "fit_torque_constant",
    "torque_constant_from_gravity",
]

_CLASSES = ("all", "motoring", "generating")


@dataclass(frozen=True)
class TorqueConstantFit:
    """K [N m/A] of eq. 13 with its uncertainty, and the gear efficiency where the data allow.

    Attributes
    ----------
    K, K_se : float
        N m/A, the torque constant (``sqrt(K_m K_g)`` when both power flows were logged,
        else the slope over all samples) and its standard error.
    ci95 : tuple of float
        N m/A, the 95 % confidence interval of K.
    n, blocks : int
        Samples and blocks (the clusters of the standard errors) used.
    residual_rms : float
        N m, RMS of ``tau - K I`` over all samples (with the one-slope K).
    K_motoring, K_motoring_se, K_generating, K_generating_se : float or None
        The slopes of each power flow and their errors (None when that flow was not logged
        in at least two blocks).
    efficiency, efficiency_se : float or None
        ``eta = sqrt(K_m / K_g)`` and its standard error (delta method), or None.
    method : str
        ``"torque sensor"`` or ``"gravity load"``.
    """

    K: float
    K_se: float
    ci95: tuple[float, float]
    n: int
    blocks: int
    residual_rms: float
    K_motoring: float | None = None
    K_motoring_se: float | None = None
    K_generating: float | None = None
    K_generating_se: float | None = None
    efficiency: float | None = None
    efficiency_se: float | None = None
    method: str = "torque sensor"

    def summary(self) -> str:
        """One or two lines for the CLI or a report."""
        lo, hi = self.ci95
        basis = (
            "from eq. 7's p_x, p_y on the current"
            if self.method == "gravity load"
            else f"{self.n} samples in {self.blocks} blocks"
        )
        lines = [
            f"torque constant (eq. 13, from the {self.method}): K = {self.K:.6g} +- "
            f"{self.K_se:.2g} N m/A (95 % CI {lo:.6g} to {hi:.6g}; {basis})"
        ]
        if self.efficiency is not None:
            lines.append(
                f"gear efficiency eta = {self.efficiency:.4g} +- {self.efficiency_se:.2g} "
                f"(motoring slope {self.K_motoring:.6g}, generating {self.K_generating:.6g} "
                "N m/A)"
            )
        return "\n".join(lines)


def _ci(value: float, se: float, dof: int) -> tuple[float, float]:
    from scipy import stats  # heavy: imported where used

    t = float(stats.t.ppf(0.975, max(dof, 1)))
    return (value - t * se, value + t * se)


def _slope(sxy: np.ndarray, sxx: np.ndarray) -> tuple[float, float, int]:
    """Slope through the origin from per-block sums, its cluster-robust error, the blocks."""
    used = sxx > 0
    b = int(used.sum())
    total = float(sxx.sum())
    if b == 0 or total <= 0:
        return math.nan, math.nan, 0
    k = float(sxy.sum()) / total
    r = sxy[used] - k * sxx[used]
    se = math.sqrt(b / (b - 1) * float(r @ r)) / total if b > 1 else math.nan
    return k, se, b


def fit_torque_constant(
    logs: RawLog | Iterable[RawLog],
    *,
    block_rows: int = 10_000,
    min_speed: float | None = None,
) -> TorqueConstantFit:
    """Identify K from a log with both motor current and a joint torque sensor.

    Parameters
    ----------
    logs : RawLog or iterable of RawLog
        One log or its chunks (streamed); each must have ``current`` and ``torque``.
    block_rows : int
        Consecutive samples per block (the clusters of the standard errors).
    min_speed : float, optional
        rad/s; samples slower than this have no power-flow direction (default 1 % of the
        fastest speed seen in the first chunk). They count for the one-slope K only.

    Returns
    -------
    TorqueConstantFit

    Raises
    ------
    DataError
        A chunk without current or torque, no current at all, or fewer than two blocks.
    """
    block_rows = int(block_rows)
    sums = {c: np.zeros((2, 0)) for c in _CLASSES}  # per block: sum(I tau), sum(I^2)
    syy = 0.0
    n = 0
    source = None
    for log in as_log_stream(logs):
        source = source or log.source
        if log.current is None or log.torque is None:
            raise DataError(
                "identifying the torque constant needs both the motor current and a joint "
                "torque sensor (a 'current' and a 'torque' column)",
                file=log.source,
            )
        i, tau, v = log.current, log.torque, log.velocity
        if min_speed is None:
            min_speed = 0.01 * float(np.max(np.abs(v))) if v.size else 0.0
        block = (n + np.arange(i.size)) // block_rows  # global block index
        size = int(block[-1]) + 1 if i.size else 0
        flow = tau * v
        moving = np.abs(v) > min_speed
        for name, mask in (
            ("all", np.ones(i.size, dtype=bool)),
            ("motoring", moving & (flow > 0)),
            ("generating", moving & (flow < 0)),
        ):
            sxy = np.bincount(block[mask], weights=(i * tau)[mask], minlength=size)
            sxx = np.bincount(block[mask], weights=(i * i)[mask], minlength=size)
            grown = np.zeros((2, max(size, sums[name].shape[1])))
            grown[:, : sums[name].shape[1]] = sums[name]
            grown[:, :size] += np.stack([sxy, sxx])
            sums[name] = grown
        syy += float(tau @ tau)
        n += i.size
    if n == 0:
        raise DataError("the log has no rows", file=source)
    merged = {name: (acc[0], acc[1]) for name, acc in sums.items()}
    k_all, se_all, blocks = _slope(*merged["all"])
    if not math.isfinite(k_all) or blocks < 2:
        raise DataError(
            f"identifying the torque constant needs current in at least two blocks of "
            f"{block_rows} samples; the log has {n} samples with {blocks} such block(s)",
            file=source,
        )
    sxy_all, sxx_all = merged["all"]
    rss = max(syy - 2 * k_all * float(sxy_all.sum()) + k_all**2 * float(sxx_all.sum()), 0.0)
    km, km_se, bm = _slope(*merged["motoring"])
    kg, kg_se, bg = _slope(*merged["generating"])
    fit = dict(K=k_all, K_se=se_all, blocks=blocks)
    extra: dict = {}
    if bm >= 2 and bg >= 2 and km > 0 and kg > 0:
        k = math.sqrt(km * kg)
        rel_m, rel_g = km_se / km, kg_se / kg
        k_se = 0.5 * k * math.hypot(rel_m, rel_g)
        eta = math.sqrt(km / kg)
        fit = dict(K=k, K_se=k_se, blocks=blocks)
        extra = dict(
            K_motoring=km,
            K_motoring_se=km_se,
            K_generating=kg,
            K_generating_se=kg_se,
            efficiency=eta,
            efficiency_se=0.5 * eta * math.hypot(rel_m, rel_g),
        )
    return TorqueConstantFit(
        ci95=_ci(fit["K"], fit["K_se"], blocks - 1),
        n=n,
        residual_rms=math.sqrt(rss / n),
        **fit,
        **extra,
    )


def current_as_torque(log: RawLog) -> RawLog:
    """The log with its motor current [A] as its torque (``K = 1``, any torque column dropped).

    Extracting it gives eq. 7's ``p_x, p_y`` in amperes, for
    :func:`torque_constant_from_gravity` (``chunk_map`` of :func:`fricid.workflow.load_joint`).

    Raises
    ------
    DataError
        The log has no current column.
    """
    if log.current is None:
        raise DataError(
            "identifying K from a gravity load needs the motor current; the log has none (a "
            "bag: --effort current; a table: --map current=COLUMN:A)",
            file=log.source,
        )
    return RawLog(
        time=log.time,
        position=log.position,
        velocity=log.velocity,
        temperature=log.temperature,
        current=log.current,
        torque_constant=1.0,
        joint=log.joint,
        source=log.source,
        meta=log.meta,
    )


def torque_constant_from_gravity(
    p_current, p_current_se, p_known, *, source: str | None = None
) -> TorqueConstantFit:
    """K from eq. 7's coefficients fitted on the current [A] and known from the link [N m].

    Parameters
    ----------
    p_current, p_current_se : array_like
        ``(p_x, p_y)`` [A] of the gravity fit on the current (``extract`` with
        ``torque_constant=1``) and their standard errors.
    p_known : array_like
        ``(p_x, p_y)`` [N m] from the link's mass ``m`` and centre of mass (for a link whose
        centre of mass is at distance ``r`` and angle ``phi`` from the joint axis in the
        plane of motion, ``p_x = m g r cos(phi)``, ``p_y = m g r sin(phi)``); from a URDF by
        :func:`fricid.io.urdf.urdf_gravity`.

    Returns
    -------
    TorqueConstantFit
        ``K = (p_known . p_current) / (p_current . p_current)``; its error from the current
        fit's errors (delta method, the known load taken as exact); the interval uses the
        normal quantile (the errors come from a gravity fit over many points); ``n`` and
        ``blocks`` are 2, the coefficients. The gear efficiency is not identified: the
        gravity load alone does not separate the two power flows.
    """
    a = np.asarray(p_current, dtype=float)
    a_se = np.asarray(p_current_se, dtype=float)
    b = np.asarray(p_known, dtype=float)
    norm = float(a @ a)
    if not (norm > 0) or not np.isfinite(a).all() or not np.isfinite(b).all():
        raise DataError("the gravity fit on the current is zero or not finite", file=source)
    k = float(b @ a) / norm
    grad = (b - 2 * k * a) / norm  # dK/da
    k_se = float(np.sqrt(np.sum((grad * a_se) ** 2)))
    from scipy import stats  # heavy: imported where used

    z = float(stats.norm.ppf(0.975))
    return TorqueConstantFit(
        K=k,
        K_se=k_se,
        ci95=(k - z * k_se, k + z * k_se),
        n=2,
        blocks=2,
        residual_rms=float(np.sqrt(np.mean((b - k * a) ** 2))),
        method="gravity load",
    )
