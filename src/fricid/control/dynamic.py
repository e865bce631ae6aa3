"""Compensation of dynamic (LuGre) friction: static feed-forward against an observer-based one.

The joint of :mod:`fricid.control.tracking` (PD control tracking a slow sinusoid, the same
:class:`~fricid.control.tracking.TrackingConfig`), but its true friction is LuGre
(Canudas de Wit et al. 1995, [CW95] eq. 2-4; :mod:`fricid.models.lugre`), given by the
caller as a :class:`LuGreTruth` and simulated by :func:`fricid.control.plant.lugre_step`.
Three runs advance together, each with the controller
``u = J q_r'' + K_p (q_r - q) + K_d (q_r' - q') + F_ff``:

``PD only``
    ``F_ff = 0``.
``static feed-forward``
    The model's steady-state friction at the reference velocity,
    ``F_ff = sign(v_r) g(v_r) + sigma_2 v_r`` (:func:`fricid.models.lugre.steady_state`: the
    static Stribeck law, what a model identified from constant-velocity sweeps gives).
``LuGre observer``
    The observer-based compensation of [CW95] (there the estimate is also corrected by the
    tracking error through a gain; here that gain is zero): the bristle state
    ``z_hat`` is estimated from the measured joint velocity ``v`` with the model's own update
    (:func:`fricid.models.lugre.simulate`, one sample per control step, exact for a velocity
    held over the step), and ``F_ff = sigma_0 z_hat + sigma_1 dz_hat/dt + sigma_2 v``. It is
    computed from the state measured at the start of the step, so it acts with the
    controller's one-step delay, as on a real drive. The measured velocity is exact unless
    ``velocity_noise`` adds white noise to it (the D term's and the observer's input).

The model's parameters (7, :data:`fricid.models.lugre.PARAM_NAMES`, or 10 per direction,
``ASYM_NAMES``) come from the caller: :func:`lugre_parameters` builds them from a fitted
``lugre`` or ``lugre_asym`` model, or from a static
``stribeck`` or ``coulomb_viscous`` model (its static part, identified from sweeps) plus
``sigma_0`` and ``sigma_1``.

The tracking error is summarised over the whole run and at the zero-velocity crossings of the
reference (within ``crossing_window`` periods of each reversal), where static feed-forward
is weakest: the bristles are in pre-sliding there, and the static law jumps by ``2 tau_s``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import ConfigError, FricidWarning, user_stacklevel
from ..fitted import FittedModel
from ..models import lugre
from .tracking import TrackingConfig

__all__ = [
    "RUNS",
    "DynamicCompensationResult",
    "LuGreTruth",
    "crossing_mask",
    "lugre_compensation_study",
    "lugre_parameters",
]

#: The runs of :func:`lugre_compensation_study`, in order.
RUNS = ("PD only", "static feed-forward", "LuGre observer")


def _names(th: np.ndarray) -> tuple[str, ...]:
    return lugre.ASYM_NAMES if th.size == len(lugre.ASYM_NAMES) else lugre.PARAM_NAMES


def _theta(theta, what: str, widths: tuple[int, ...] = (7, 10)) -> np.ndarray:
    """``theta`` checked: 7 LuGre parameters (or 10 per direction, where ``widths`` has
    10), finite and in the model's domain."""
    th = np.asarray(theta, dtype=float)
    if th.ndim != 1 or th.size not in widths or not np.all(np.isfinite(th)):
        per = " (or 10 per direction)" if 10 in widths else ""
        raise ConfigError(f"{what}: 7 finite LuGre parameters{per} are needed, got {theta!r}")
    if lugre.passivity_margin(th) == -np.inf:
        raise ConfigError(
            f"{what}: sigma_0, tau_c and w_s must be > 0 and sigma_1, sigma_2 >= 0 "
            f"({dict(zip(_names(th), th.tolist(), strict=True))})"
        )
    return th


@dataclass(frozen=True)
class LuGreTruth:
    """The plant's true LuGre friction, given by the caller of
    :func:`lugre_compensation_study`.

    Attributes
    ----------
    theta : the 7 LuGre parameters (:data:`fricid.models.lugre.PARAM_NAMES`).
    name : what the truth is, for reports.
    inertia : the true joint's inertia [kg m^2], replacing the experiment's when given.
    """

    theta: tuple[float, ...]
    name: str = "lugre"
    inertia: float | None = None

    def __post_init__(self) -> None:
        theta = _theta(self.theta, "LuGreTruth", (7,))
        object.__setattr__(self, "theta", tuple(theta.tolist()))
        inertia = self.inertia
        if inertia is not None and not (math.isfinite(inertia) and inertia > 0):
            raise ConfigError(f"LuGreTruth: 'inertia' must be a number > 0, got {inertia!r}")

    @property
    def passive(self) -> bool:
        """Barabanov-Ortega's passivity condition holds (:func:`lugre.passivity_margin`)."""
        return bool(lugre.passivity_margin(np.asarray(self.theta)) >= 0)


def lugre_parameters(
    fitted: FittedModel, sigma_0: float | None = None, sigma_1: float | None = None
) -> np.ndarray:
    """The LuGre parameters of a model, for the observer (7, or 10 for ``lugre_asym``).

    A ``lugre`` or ``lugre_asym`` model gives its own (``sigma_0``, ``sigma_1`` override
    them when given). A ``stribeck`` model gives the static part (``tau_v`` as ``sigma_2``) and a
    ``coulomb_viscous`` one ``tau_c = tau_s = f_c``, ``sigma_2 = beta``; both need
    ``sigma_0`` and ``sigma_1``. Other models have no Stribeck curve ``g(v)`` to build the
    bristle dynamics on (:class:`ConfigError`).
    """
    name = fitted.model.strip().lower()
    p = fitted.params
    try:
        if name in ("lugre", "lugre_asym"):
            names = lugre.PARAM_NAMES if name == "lugre" else lugre.ASYM_NAMES
            th = [float(p[k]) for k in names]
            th[0] = th[0] if sigma_0 is None else sigma_0
            th[1] = th[1] if sigma_1 is None else sigma_1
            return _theta(th, f"model '{name}'")
        if name == "stribeck":
            static = [p["tau_v"], p["tau_c"], p["tau_s"], p["w_s"], p["delta"]]
        elif name == "coulomb_viscous":
            static = [p["beta"], p["f_c"], p["f_c"], 1.0, 1.0]
        else:
            raise ConfigError(
                "the LuGre observer needs a 'lugre', 'lugre_asym', 'stribeck' or "
                f"'coulomb_viscous' model "
                f"(a Stribeck curve g(v) for the bristles), not '{fitted.model}'"
            )
    except KeyError as exc:
        raise ConfigError(f"model '{fitted.model}' lacks parameter {exc.args[0]!r}") from None
    if sigma_0 is None or sigma_1 is None:
        raise ConfigError(
            f"a '{name}' model has no bristle dynamics: give sigma_0 [N m/rad] and sigma_1 "
            "[N m s/rad] (fricid compensate --lugre SIGMA_0,SIGMA_1)"
        )
    return _theta([sigma_0, sigma_1, *map(float, static)], f"model '{name}' with sigma_0, sigma_1")


def crossing_mask(config: TrackingConfig, window: float) -> np.ndarray:
    """Samples within ``window`` periods of a zero crossing of the reference velocity."""
    if not (math.isfinite(window) and 0 < window <= 0.25):
        raise ConfigError(f"the crossing window must be in (0, 0.25] periods, got {window!r}")
    t = config.reference()[0]
    phase = np.mod(t * config.frequency - 0.25, 0.5)  # 0 at each reversal of q_r' = cos
    return np.minimum(phase, 0.5 - phase) <= window


@dataclass(frozen=True)
class DynamicCompensationResult:
    """The runs of :func:`lugre_compensation_study` (:data:`RUNS`) and their errors.

    ``rms``, ``max`` (whole run) and ``rms_crossing``, ``max_crossing`` (at the zero-velocity
    crossings, ``crossing``) map each run to its tracking error [rad]; ``runs`` holds the
    signals (``time``, ``reference``, ``reference_velocity``, and (3, n) ``position``,
    ``velocity``, ``error``, ``torque``, ``friction``, ``feedforward``).
    """

    config: TrackingConfig
    truth: str
    model: str
    theta: tuple[float, ...]
    rms: dict[str, float]
    max: dict[str, float]
    rms_crossing: dict[str, float]
    max_crossing: dict[str, float]
    crossing_window: float
    runs: dict[str, np.ndarray] = field(repr=False)
    crossing: np.ndarray = field(repr=False)
    notes: list[str] = field(default_factory=list)

    def verdict(self) -> str:
        """What the observer did against static feed-forward at the crossings, as measured."""
        obs, stat = self.rms_crossing[RUNS[2]], self.rms_crossing[RUNS[1]]
        if obs < stat:
            ratio = stat / obs if obs > 0 else math.inf
            return (
                f"at the zero-velocity crossings the LuGre observer's RMS error is {ratio:.3g}x "
                f"smaller than static feed-forward's ({1e3 * obs:.4g} against {1e3 * stat:.4g} "
                "mrad)"
            )
        if obs > stat:
            return (
                f"at the zero-velocity crossings the LuGre observer did worse than static "
                f"feed-forward: RMS {1e3 * obs:.4g} against {1e3 * stat:.4g} mrad"
            )
        return "at the zero-velocity crossings the LuGre observer and static feed-forward tie"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (errors in rad)."""
        kp, kd = self.config.gains
        return {
            "model": self.model,
            "truth": self.truth,
            "lugre_parameters": dict(zip(_names(np.asarray(self.theta)), self.theta, strict=True)),
            "rms_error_rad": dict(self.rms),
            "max_error_rad": dict(self.max),
            "crossing_rms_error_rad": dict(self.rms_crossing),
            "crossing_max_error_rad": dict(self.max_crossing),
            "crossing_window_periods": self.crossing_window,
            "verdict": self.verdict(),
            "kp": kp,
            "kd": kd,
            "config": {k: getattr(self.config, k) for k in self.config.__dataclass_fields__},
            "notes": list(self.notes),
        }


def _simulate(
    truth: np.ndarray, model: np.ndarray, config: TrackingConfig, noise: np.ndarray
) -> dict:
    """The three runs, compiled (:func:`fricid.control._kernels.track_lugre`)."""
    from ._kernels import track_lugre

    t, q_r, v_r, a_r = config.reference()
    kp, kd = config.gains
    # the joint starts on the reference, sliding: bristles at their steady deflection
    z0, z0_hat = (
        float(np.sign(v_r[0]) * lugre.stribeck_curve(th, v_r[:1])[0] / th[0])
        for th in (truth, model)
    )
    names = ("position", "velocity", "torque", "friction", "feedforward")
    out = {name: np.empty((len(RUNS), t.size)) for name in names}
    track_lugre(
        np.ascontiguousarray(truth, dtype=float),
        lugre.wide(model),
        q_r,
        v_r,
        a_r,
        lugre.steady_state(model, v_r),
        kp,
        kd,
        float(config.inertia),
        float(config.dt),
        z0,
        z0_hat,
        noise,
        *(out[name] for name in names),
    )
    out["error"] = q_r[None, :] - out["position"]
    out.update(time=t, reference=q_r, reference_velocity=v_r)
    return out


def lugre_compensation_study(
    theta,
    config: TrackingConfig | None = None,
    *,
    truth: LuGreTruth,
    model: str = "lugre",
    crossing_window: float = 0.05,
    velocity_noise: float = 0.0,
    seed=None,
) -> DynamicCompensationResult:
    """Track the reference with PD only, static feed-forward and the LuGre observer.

    Parameters
    ----------
    theta : array_like
        The model's 7 LuGre parameters, or 10 per direction (:func:`lugre_parameters`): the
        observer's, and the static feed-forward's steady state.
    config : TrackingConfig, optional
        The experiment (default :class:`TrackingConfig`); a ``truth`` with an inertia
        replaces ``config.inertia``. Load and temperature do not enter LuGre friction.
    truth : LuGreTruth
        The plant's friction, given by the caller (this module imports no simulation code).
    model : str
        The model's name, for reports.
    crossing_window : float
        Half-width [periods] of the window around each zero-velocity crossing.
    velocity_noise : float
        Standard deviation [rad/s] of white Gaussian noise on the measured velocity, which
        the D term and the observer use (the same draw in every run); 0: measured exactly.
    seed : int or numpy.random.Generator, optional
        Of the noise.

    Returns
    -------
    DynamicCompensationResult

    Warns
    -----
    FricidWarning
        A feed-forward made tracking worse than PD only (whole-run RMS), or the truth or the
        model is not passive ([BO00], :func:`fricid.models.lugre.passivity_margin`).
    """
    th = _theta(theta, "the model's LuGre parameters")
    config = config or TrackingConfig()
    notes = []
    if truth.inertia is not None and truth.inertia != config.inertia:
        config = replace(config, inertia=truth.inertia)
        notes.append(f"inertia {truth.inertia} kg m^2 from the '{truth.name}' joint")
    for what, params in (("the true LuGre friction", truth.theta), ("the model", th)):
        if lugre.passivity_margin(np.asarray(params)) < 0:
            notes.append(
                f"{what} is not passive (sigma_1 above 4 sigma_2 tau_c / (tau_s - tau_c), "
                "Barabanov and Ortega 2000): it can feed energy into the joint"
            )
            warnings.warn(notes[-1], FricidWarning, stacklevel=user_stacklevel())
    mask = crossing_mask(config, crossing_window)
    if not (math.isfinite(velocity_noise) and velocity_noise >= 0):
        raise ConfigError(f"velocity_noise must be >= 0 rad/s, got {velocity_noise!r}")
    noise = np.zeros(mask.size)
    if velocity_noise > 0:
        noise = np.random.default_rng(seed).normal(0.0, velocity_noise, mask.size)
        notes.append(f"measured velocity with {velocity_noise:g} rad/s RMS white noise")
    runs = _simulate(np.asarray(truth.theta), th, config, noise)
    err = np.abs(runs["error"])

    def stat(values: np.ndarray, fn) -> dict[str, float]:
        return {name: float(fn(values[j])) for j, name in enumerate(RUNS)}

    result = DynamicCompensationResult(
        config=config,
        truth=truth.name,
        model=model,
        theta=tuple(th.tolist()),
        rms=stat(err, lambda e: np.sqrt(np.mean(e**2))),
        max=stat(err, np.max),
        rms_crossing=stat(err[:, mask], lambda e: np.sqrt(np.mean(e**2))),
        max_crossing=stat(err[:, mask], np.max),
        crossing_window=crossing_window,
        runs=runs,
        crossing=mask,
        notes=notes,
    )
    for name in RUNS[1:]:
        if result.rms[name] > result.rms[RUNS[0]]:
            warnings.warn(
                f"{name} made tracking worse than PD only: RMS error "
                f"{1e3 * result.rms[name]:.4g} against {1e3 * result.rms[RUNS[0]]:.4g} mrad",
                FricidWarning,
                stacklevel=user_stacklevel(),
            )
    return result
