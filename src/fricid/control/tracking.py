"""A joint tracking a slow sinusoid under PD control, without and with friction feed-forward.

The study that shows why friction is identified (the RWSAVSBAS paper, conclusion 3: the model
goes into the controller as torque feed-forward).

The plant
    ``J q'' = u - F(q', load, T)``: a rigid joint of inertia ``J`` [kg m^2] with friction
    ``F`` from a true law, which the caller gives (:class:`Truth`): by default the model
    itself (what the controller would gain if the model were exact), or, for example, the
    virtual joint's law of a simulation preset and its inertia (``fricid compensate --truth
    paper2`` builds it from :func:`fricid.sim.preset`): then the model is judged against
    friction it only approximates. Load and
    temperature are constant; the load enters the friction law only (its own torque is
    taken as compensated, e.g. gravity compensation, in both runs, so the comparison
    isolates friction).
Stiction
    At zero velocity the joint sticks while the applied torque stays within the break-away
    friction (the law just off zero, in the direction of the torque), and slips once it
    exceeds it; a step that would carry the velocity through zero stops it at zero (the
    Karnopp scheme, adapted to a fixed step: :func:`fricid.control.plant.static_step`). So the
    stick-slip at velocity reversals, where PD control without friction compensation lags, is
    simulated rather than smoothed away. A LuGre truth (dynamic friction) is simulated by
    :mod:`fricid.control.dynamic`.
The controller
    ``u = J q_r'' + K_p (q_r - q) + K_d (q_r' - q')`` plus, in the second run, the feed-forward
    ``F_hat(q_r', load, T)``: the model evaluated at the reference velocity (optionally
    smoothed near zero velocity, :mod:`fricid.models.smoothing`). By default ``K_p = J w^2``
    and ``K_d = 2 zeta J w`` with ``w = 2 pi 10 Hz`` and ``zeta = 1``.
The reference
    ``q_r = A sin(2 pi f t)``: it crosses zero velocity twice per period. The joint starts on
    the reference (``q = 0``, ``q' = q_r'(0)``).
Integration
    Semi-implicit Euler with a fixed step (default 0.2 ms); both runs advance together as one
    batch, and the feed-forward is evaluated for the whole time grid at once.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError, ExtrapolationWarning, FricidWarning, user_stacklevel
from ..fitted import FittedModel
from .plant import static_step

__all__ = [
    "CompensationResult",
    "TrackingConfig",
    "Truth",
    "compensation_study",
    "default_config",
    "fitted_law",
    "simulate_tracking",
]

Law = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Truth:
    """The plant's true friction, given by the caller of :func:`compensation_study`.

    Attributes
    ----------
    law : callable
        ``law(velocity, load, temperature)`` [N m] on arrays that broadcast, e.g.
        :func:`fitted_law` of a model, or a virtual joint's law (``fricid.sim``'s
        ``preset(name).joint.law``).
    name : str
        What the law is, for reports (``"model"``, ``"paper2"``, ...).
    inertia : float or None
        The true joint's inertia [kg m^2], replacing the experiment's when given.
    """

    law: Law
    name: str = "custom"
    inertia: float | None = None

    def __post_init__(self) -> None:
        if not callable(self.law):
            raise ConfigError(f"Truth: 'law' must be callable, got {type(self.law).__name__}")
        inertia = self.inertia
        if inertia is not None and not (math.isfinite(inertia) and inertia > 0):
            raise ConfigError(f"Truth: 'inertia' must be a number > 0, got {inertia!r}")


@dataclass(frozen=True)
class TrackingConfig:
    """The experiment: reference, plant, controller and integration.

    Attributes
    ----------
    amplitude : rad, of the reference sinusoid.
    frequency : Hz, of the reference sinusoid.
    periods : number of reference periods simulated.
    inertia : kg m^2, of the joint (the controller knows it exactly).
    kp, kd : PD gains [N m/rad, N m s/rad]; None gives ``J w^2`` and ``2 zeta J w``.
    bandwidth : Hz, the ``w / 2 pi`` of the default gains.
    damping : the ``zeta`` of the default gains.
    load : N m, joint load (friction input only).
    temperature : degC.
    dt : s, integration step.
    """

    amplitude: float = 0.5
    frequency: float = 0.2
    periods: float = 2.0
    inertia: float = 0.01
    kp: float | None = None
    kd: float | None = None
    bandwidth: float = 10.0
    damping: float = 1.0
    load: float = 0.0
    temperature: float = 25.0
    dt: float = 2e-4

    def __post_init__(self) -> None:
        positive = ("amplitude", "frequency", "periods", "inertia", "bandwidth", "damping", "dt")
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ConfigError(f"TrackingConfig: '{name}' must be a number > 0, got {value!r}")
        for name in ("kp", "kd"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"TrackingConfig: '{name}' must be >= 0, got {value!r}")
        for name in ("load", "temperature"):
            if not math.isfinite(getattr(self, name)):
                raise ConfigError(f"TrackingConfig: '{name}' must be finite")
        steps = self.n_steps
        if steps > 20_000_000:
            raise ConfigError(
                f"TrackingConfig: {steps} integration steps is too many; raise dt or shorten "
                "the run (periods, frequency)"
            )
        if self.dt > 0.05 / self.frequency:
            raise ConfigError("TrackingConfig: dt must resolve the reference (dt <= 0.05 / f)")

    @property
    def gains(self) -> tuple[float, float]:
        """``(K_p, K_d)``."""
        w = 2.0 * math.pi * self.bandwidth
        kp = self.inertia * w * w if self.kp is None else self.kp
        kd = 2.0 * self.damping * self.inertia * w if self.kd is None else self.kd
        return float(kp), float(kd)

    @property
    def n_steps(self) -> int:
        return round(self.periods / self.frequency / self.dt)

    def reference(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Time [s], position [rad], velocity [rad/s], acceleration [rad/s^2] of the reference."""
        t = np.arange(self.n_steps + 1) * self.dt
        w = 2.0 * math.pi * self.frequency
        a = self.amplitude
        return t, a * np.sin(w * t), a * w * np.cos(w * t), -a * w * w * np.sin(w * t)


def default_config(fitted: FittedModel, **overrides: Any) -> TrackingConfig:
    """A :class:`TrackingConfig` inside the model's operating range.

    The reference's peak velocity is half the largest identified speed (0.5 rad/s without
    an operating range), at the default frequency; load and temperature are the middle of
    their identified ranges (0 N m and 25 degC without). ``overrides`` set any field;
    ``peak_velocity`` [rad/s] sets the amplitude through the frequency.
    """
    rng = fitted.operating_range or {}

    def middle(name: str, default: float) -> float:
        pair = rng.get(name)
        return default if not pair else 0.5 * (float(pair[0]) + float(pair[1]))

    speed = rng.get("velocity")
    peak = overrides.pop("peak_velocity", None)
    if peak is None:
        peak = 0.5 * max(abs(float(x)) for x in speed) if speed else 0.5
    if not (math.isfinite(peak) and peak > 0):
        raise ConfigError(f"the peak velocity must be > 0 rad/s, got {peak!r}")
    frequency = overrides.get("frequency") or TrackingConfig.frequency
    values: dict[str, Any] = {
        "amplitude": peak / (2.0 * math.pi * frequency),
        "load": middle("load", 0.0),
        "temperature": middle("temperature", 25.0),
    }
    values.update({k: v for k, v in overrides.items() if v is not None})
    return TrackingConfig(**values)


def fitted_law(fitted: FittedModel) -> Law:
    """A fitted model as a friction law ``law(velocity, load, temperature)`` (arrays that
    broadcast), the parameter vector resolved once."""
    if fitted.kind == "rbf":

        def rbf_law(velocity, load, temperature):
            v, lo, t = np.broadcast_arrays(velocity, load, temperature)
            X = np.column_stack([v.ravel(), lo.ravel(), t.ravel()]).astype(float)
            return fitted.predict(X, warn=False).reshape(v.shape)  # range: checked by the study

        return rbf_law
    model = fitted.friction_model()
    theta = fitted.theta()[None, :]

    def law(velocity, load, temperature):
        v, lo, t = np.broadcast_arrays(velocity, load, temperature)
        X = np.empty((v.size, 3))
        X[:, 0], X[:, 1], X[:, 2] = v.ravel(), lo.ravel(), t.ravel()
        return model._predict(theta, X)[0].reshape(v.shape)

    return law


def simulate_tracking(
    law: Law, feedforward: np.ndarray, config: TrackingConfig
) -> dict[str, np.ndarray]:
    """Simulate ``k`` runs of the tracking experiment at once.

    Parameters
    ----------
    law : the plant's true friction law.
    feedforward : (k, n_steps + 1) feed-forward torque [N m] of each run on the time grid
        (zeros for a run without compensation).
    config : the experiment.

    Returns
    -------
    dict
        ``time`` (n,), and (k, n) arrays ``position``, ``velocity``, ``error`` (reference
        minus position) [rad], ``torque`` (controller output) and ``friction`` [N m].
    """
    t, q_r, v_r, a_r = config.reference()
    ff = np.atleast_2d(np.asarray(feedforward, dtype=float))
    k, n = ff.shape[0], t.size
    if ff.shape[1] != n:
        raise ConfigError(f"feedforward must have {n} columns (the time grid), got {ff.shape[1]}")
    kp, kd = config.gains
    J, dt = config.inertia, config.dt
    load = np.full(k, config.load)
    temp = np.full(k, config.temperature)
    q = np.zeros(k)
    v = np.full(k, v_r[0])
    out = {name: np.empty((k, n)) for name in ("position", "velocity", "torque", "friction")}
    # the part of the command known in advance: inertia feed-forward plus friction feed-forward
    base = J * a_r[None, :] + ff
    for i in range(n):
        u = base[:, i] + kp * (q_r[i] - q) + kd * (v_r[i] - v)
        out["position"][:, i] = q
        out["velocity"][:, i] = v
        out["torque"][:, i] = u
        v, out["friction"][:, i] = static_step(law, v, u, J, dt, load, temp)
        q = q + v * dt
    out["error"] = q_r[None, :] - out["position"]
    out["time"] = t
    out["reference"] = q_r
    out["reference_velocity"] = v_r
    return out


@dataclass(frozen=True)
class CompensationResult:
    """The two runs of :func:`compensation_study` and their tracking errors.

    ``rms`` and ``max`` map ``"without"`` / ``"with"`` to the RMS and the largest absolute
    tracking error [rad]; ``runs`` holds the simulated signals (``simulate_tracking``).
    """

    config: TrackingConfig
    truth: str
    model: str
    rms: dict[str, float]
    max: dict[str, float]
    runs: dict[str, np.ndarray] = field(repr=False)
    feedforward: np.ndarray = field(repr=False)
    notes: list[str] = field(default_factory=list)

    @property
    def improvement(self) -> float:
        """RMS error without over RMS error with feed-forward (below 1: worse with it)."""
        return self.rms["without"] / self.rms["with"] if self.rms["with"] > 0 else math.inf

    @property
    def improved(self) -> bool:
        """True only when the feed-forward measurably shrank the RMS tracking error."""
        return self.rms["with"] < self.rms["without"]

    def verdict(self) -> str:
        """One line on what the feed-forward did, as measured: "RMS error N x smaller with
        feed-forward" only when it shrank; else how much worse (or that nothing changed)."""
        with_, without = self.rms["with"], self.rms["without"]
        if self.improved:
            return f"RMS error {self.improvement:.3g}x smaller with feed-forward"
        if with_ > without:
            ratio = with_ / without if without > 0 else math.inf
            return (
                f"the feed-forward made tracking worse: RMS error {ratio:.3g}x larger with it "
                f"({1e3 * with_:.4g} mrad against {1e3 * without:.4g} mrad without)"
            )
        return "the feed-forward did not change the RMS tracking error"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (errors in rad)."""
        kp, kd = self.config.gains
        return {
            "model": self.model,
            "truth": self.truth,
            "rms_error_rad": dict(self.rms),
            "max_error_rad": dict(self.max),
            "rms_improvement": self.improvement,
            "improved": self.improved,
            "verdict": self.verdict(),
            "kp": kp,
            "kd": kd,
            "config": {k: getattr(self.config, k) for k in self.config.__dataclass_fields__},
            "notes": list(self.notes),
        }


def _extrapolation_notes(fitted: FittedModel, X: np.ndarray, ff: np.ndarray, smoothing) -> list:
    """A note when the reference runs below the identified speeds, where the feed-forward is
    extrapolated (a fitted Stribeck peak can grow far beyond the data there), and one per
    gap between measured speeds it crosses; both from
    :meth:`~fricid.fitted.FittedModel.range_check` (per direction where the file records
    the measured speeds)."""
    found = fitted.range_check(X)
    notes = [
        f"the reference crosses a gap of the measured speeds: {b.message}"
        for b in found
        if b.kind == "gap"
    ]
    lows = [b.low for b in found if b.kind == "below"]
    v_min = max(lows, default=0.0)
    zone = 0.0 if smoothing is None else smoothing.zone
    v_r = X[:, 0]
    below = np.abs(v_r) < v_min
    if v_min <= 0 or zone >= v_min or not below.any():
        return notes
    edge = np.abs(ff[~below]).max() if (~below).any() else 0.0
    return [
        f"the reference is below the identified speeds (|v| < {v_min:.4g} rad/s) "
        f"{100 * below.mean():.2g} % of the time, where the feed-forward is extrapolated "
        f"(up to {np.abs(ff[below]).max():.4g} N m, against at most {edge:.4g} N m elsewhere); "
        f"--smooth linear --zone {v_min:.4g} holds it to the line between the identified edges",
        *notes,
    ]


def compensation_study(
    fitted: FittedModel,
    config: TrackingConfig | None = None,
    *,
    truth: Truth | None = None,
    smoothing=None,
) -> CompensationResult:
    """Track the reference without and with ``fitted`` as friction feed-forward.

    Parameters
    ----------
    fitted : FittedModel
        The identified model (the feed-forward).
    config : TrackingConfig, optional
        The experiment (default :class:`TrackingConfig`). A ``truth`` with an inertia
        replaces ``config.inertia``.
    truth : Truth, optional
        The plant's friction, given by the caller (the CLI builds a simulation preset's, a
        test its own law); None: the model itself, named ``"model"``. This module imports
        no simulation code.
    smoothing : Smoothing, optional
        Smoothing of the feed-forward near zero velocity
        (:class:`fricid.models.smoothing.Smoothing`).

    Returns
    -------
    CompensationResult
        RMS and max tracking error of both runs, and the signals; ``notes`` name where the
        reference leaves the model's operating range.

    Warns
    -----
    ExtrapolationWarning
        The reference (velocity above the identified speeds, load, temperature) leaves the
        operating range (:meth:`fricid.fitted.FittedModel.range_check`).
    FricidWarning
        The feed-forward made the tracking worse (:meth:`CompensationResult.verdict`).
    """
    from dataclasses import replace

    from ..models.smoothing import smooth_predict

    config = config or TrackingConfig()
    truth = truth or Truth(fitted_law(fitted), "model")
    notes = []
    if truth.inertia is not None and truth.inertia != config.inertia:
        config = replace(config, inertia=truth.inertia)
        notes.append(f"inertia {truth.inertia} kg m^2 from the '{truth.name}' joint")
    _, _, v_r, _ = config.reference()
    X = np.column_stack(
        [v_r, np.full_like(v_r, config.load), np.full_like(v_r, config.temperature)]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)  # checked once below
        ff = smooth_predict(fitted, X, smoothing)
    notes += _extrapolation_notes(fitted, X, ff, smoothing)
    for bad in fitted.range_check(X):
        if bad.kind in ("below", "gap"):  # reversals always pass through; noted above
            continue
        note = f"the reference goes outside the identified operating range: {bad.message}"
        notes.append(note)
        warnings.warn(note, ExtrapolationWarning, stacklevel=user_stacklevel())
    runs = simulate_tracking(truth.law, np.vstack([np.zeros_like(ff), ff]), config)
    err = np.abs(runs["error"])
    result = CompensationResult(
        config=config,
        truth=truth.name,
        model=fitted.model,
        rms={
            "without": float(np.sqrt(np.mean(err[0] ** 2))),
            "with": float(np.sqrt(np.mean(err[1] ** 2))),
        },
        max={"without": float(err[0].max()), "with": float(err[1].max())},
        runs=runs,
        feedforward=ff,
        notes=notes,
    )
    if result.rms["with"] > result.rms["without"]:
        warnings.warn(result.verdict(), FricidWarning, stacklevel=user_stacklevel())
    return result
