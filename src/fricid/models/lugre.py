"""The LuGre dynamic friction model: a bristle state z between the surfaces.

References
----------
[CW95] C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, "A new model for control of
    systems with friction", IEEE Trans. Automatic Control 40(3) 419-425, 1995, eq. 2-4.
[BO00] N. Barabanov, R. Ortega, "Necessary and sufficient conditions for passivity of the
    LuGre friction model", IEEE Trans. Automatic Control 45(4) 830-832, 2000.
[B] The BAS-RBFNN paper, eq. 2 (the Stribeck curve g(v) below, with exponent).

The model ([CW95] eq. 2-4), per joint, with ``g(v)`` the Stribeck curve of [B] eq. 2::

    dz/dt = v - sigma_0 |v| / g(v) * z
    F     = sigma_0 z + sigma_1 dz/dt + sigma_2 v
    g(v)  = tau_c + (tau_s - tau_c) exp(-|v / w_s|^delta)

At constant velocity z settles to ``sign(v) g(v) / sigma_0``, so the steady-state friction is
``sign(v) g(v) + sigma_2 v``: exactly the static ``stribeck`` model with ``tau_v = sigma_2``
(:func:`steady_state`). That is why the static part can be identified from constant-velocity
sweeps as today, and only sigma_0 and sigma_1 need motion through zero velocity (pre-sliding,
stick-slip or any trajectory crossing zero).

Integration. Over one sample the velocity is held constant (zero-order hold), and then the z
equation is linear with a constant rate ``a = sigma_0 |v| / g(v)``; it is solved exactly::

    z(t + dt) = z_ss + (z(t) - z_ss) exp(-a dt),   z_ss = sign(v) g(v) / sigma_0

which is unconditionally stable however stiff the bristles are (sigma_0 of 1e5 N m/rad at
1 kHz is routine), unlike an explicit Euler step. The friction of a sample is evaluated at the
state reached at its end, with ``dz/dt`` from the same formula. Candidates (rows of ``theta``)
are simulated together: the loop runs over time only, compiled by numba.

Per direction (``lugre_asym``, :class:`LuGreAsym`): sigma_2, tau_c and tau_s are given once
for each direction of motion (the sign of v), sigma_0, sigma_1, w_s and delta once; the
steady state is then ``stribeck_asym``'s with the shape shared. Real joints differ by
direction (gear backlash preload, seals, cable routing), and a symmetric law fitted with the
gravity lets the gravity coefficients take up half the difference
(:mod:`fricid.identify.dynamic._direction`). Every function here takes either width.

Passivity ([BO00]): the map from velocity to friction is passive if and only if
``sigma_1 <= 4 sigma_2 tau_c / (tau_s - tau_c)`` (always, when ``tau_s <= tau_c``), with every
parameter positive (:func:`passivity_margin`).

A joint driven by torque (:func:`simulate_joint`): ``J qdd = u + p_x cos q - p_y sin q - F``
(fricid's sign convention, :func:`fricid.sim.gravity_torque`: the motor torque is
``u = J qdd + F - tau_g(q)``). Coupled to the inertia, the bristles make a second fast mode,
an oscillation of about ``sqrt(sigma_0 / J)`` rad/s (1000 rad/s for sigma_0 = 1e4, J = 0.01)
damped by sigma_1, which an explicit step at 1 kHz cannot follow. Over each sub-step the
bristle rate ``a`` and the gravity torque are frozen; the remaining system in ``(z, v)`` is
linear and is solved exactly by its 2x2 matrix exponential (eigenvalues from the trace and
determinant, the slow one as ``det / fast`` to avoid cancellation), so the step is stable for
any stiffness and does not damp the bristle oscillation numerically. The only approximation is
the frozen ``a`` (and gravity) over a sub-step; ``n_sub`` sub-steps per sample control it.

:class:`LuGre` is the model's static projection for the model-file machinery: its
``predict(theta, X)`` is the steady-state friction (:func:`steady_state`), what a static
consumer (export, ``fricid predict``) needs; the dynamics come from :func:`simulate` and
:func:`simulate_joint`.
"""

from __future__ import annotations

import itertools
import os

import numpy as np

from ..errors import ConfigError
from ._asymmetric import directed
from ._base import FrictionModel, Parameter, parameter_batch, simulation_inputs

__all__ = [
    "ASYM_NAMES",
    "ASYM_PARAMETERS",
    "PARAMETERS",
    "PARAM_NAMES",
    "PER_DIRECTION",
    "ROW_THREADS",
    "STRIBECK_NAMES",
    "LuGre",
    "LuGreAsym",
    "in_row_threads",
    "mean_friction",
    "passivity_margin",
    "simulate",
    "simulate_joint",
    "steady_state",
    "stribeck_curve",
    "symmetric_name",
    "wide",
]

#: LuGre's parameters, in the order of ``theta`` columns. The Stribeck part is named as the
#: static ``stribeck`` model ([B] eq. 2); sigma_2 plays tau_v's role. Bounds are relative to
#: the data scales of :func:`fricid.models.data_scales` except sigma_0 and sigma_1, whose
#: defaults are absolute (typical of geared robot joints) and whose bounds a caller sets.
PARAMETERS: tuple[Parameter, ...] = (
    Parameter("sigma_0", "N m/rad", "one", 1e4, 1.0, 1e7, "bristle stiffness", "positive"),
    Parameter("sigma_1", "N m s/rad", "one", 1.0, 0.0, 1e5, "bristle damping", "nonnegative"),
    Parameter(
        "sigma_2", "N m s/rad", "viscous", 0.2, 0.0, 2.0, "viscous coefficient", "nonnegative"
    ),
    Parameter("tau_c", "N m", "torque", 0.5, 0.0, 2.0, "Coulomb friction", "nonnegative"),
    Parameter(
        "tau_s", "N m", "torque", 0.8, 0.0, 2.0, "static (break-away) friction", "nonnegative"
    ),
    Parameter("w_s", "rad/s", "velocity", 0.1, 1e-4, 1.0, "Stribeck velocity", "positive"),
    Parameter("delta", "1", "one", 1.0, 0.2, 4.0, "Stribeck exponent", "positive"),
)
PARAM_NAMES: tuple[str, ...] = tuple(p.name for p in PARAMETERS)
#: LuGre's steady state as the static ``stribeck`` model ([CW95]: at constant velocity LuGre
#: is the Stribeck law with ``tau_v = sigma_2``): stribeck name -> LuGre name.
STRIBECK_NAMES: dict[str, str] = {
    "tau_c": "tau_c",
    "tau_s": "tau_s",
    "w_s": "w_s",
    "tau_v": "sigma_2",
    "delta": "delta",
}

#: The parameters a per-direction LuGre (``lugre_asym``) has one of for each direction of
#: motion; the bristles (sigma_0, sigma_1) and the Stribeck curve's shape (w_s, delta) are
#: shared.
PER_DIRECTION: tuple[str, ...] = ("sigma_2", "tau_c", "tau_s")


_BY_NAME = {p.name: p for p in PARAMETERS}
#: Per-direction LuGre's parameters, in the order of the compiled kernels' columns: sigma_0,
#: sigma_1, the forward set (``_pos``, v >= 0), w_s, delta, the backward set (``_neg``, v < 0).
#: Like the static ``_asym`` models, the backward set holds magnitudes.
ASYM_PARAMETERS: tuple[Parameter, ...] = (
    _BY_NAME["sigma_0"],
    _BY_NAME["sigma_1"],
    *(directed(_BY_NAME[n], "_pos") for n in PER_DIRECTION),
    _BY_NAME["w_s"],
    _BY_NAME["delta"],
    *(directed(_BY_NAME[n], "_neg") for n in PER_DIRECTION),
)
ASYM_NAMES: tuple[str, ...] = tuple(p.name for p in ASYM_PARAMETERS)

_TINY = 1e-12


def symmetric_name(name: str) -> str:
    """The symmetric model's name of a per-direction parameter (``tau_c_neg`` -> ``tau_c``);
    any other name unchanged."""
    for suffix in ("_pos", "_neg"):
        if name.endswith(suffix) and name[: -len(suffix)] in PER_DIRECTION:
            return name[: -len(suffix)]
    return name


def _batch(theta) -> tuple[np.ndarray, bool]:
    """``theta`` as a batch of 7 (symmetric) or 10 (per direction, :data:`ASYM_NAMES`)
    columns, and whether it was one vector."""
    width = np.shape(theta)[-1] if np.ndim(theta) else 0
    names = ASYM_NAMES if width == len(ASYM_NAMES) else PARAM_NAMES
    return parameter_batch(theta, names, "LuGre")


def wide(theta) -> np.ndarray:
    """A batch ``(k, 7)`` or ``(k, 10)`` as the kernels' ``(k, 10)``: the symmetric levels
    repeated for the backward direction (:mod:`._lugre_kernel`)."""
    batch = np.atleast_2d(np.asarray(theta, dtype=float))
    if batch.shape[1] == len(ASYM_NAMES):
        return np.ascontiguousarray(batch)
    return np.ascontiguousarray(np.hstack([batch, batch[:, 2:5]]))


def _of_direction(w: np.ndarray, v: np.ndarray, column: int) -> np.ndarray:
    """Column ``column`` of the forward set (2-4) of the wide batch ``w``, or its backward
    counterpart where ``v < 0``, ``(k, n)``."""
    return np.where(v >= 0, w[:, column : column + 1], w[:, column + 5 : column + 6])


def stribeck_curve(theta, v) -> np.ndarray:
    """``g(v)`` of [CW95] eq. 3 with [B] eq. 2's exponent, ``(k, n)`` for a batch (k, 7), or
    (k, 10) with the levels of each velocity's direction."""
    batch, single = _batch(theta)
    w = wide(batch)
    v = np.asarray(v, dtype=float)[None, :]
    tau_c, tau_s = _of_direction(w, v, 3), _of_direction(w, v, 4)
    w_s, delta = w[:, 5:6], w[:, 6:7]
    a = np.abs(v) / np.maximum(np.abs(w_s), _TINY)
    g = tau_c + (tau_s - tau_c) * np.exp(-(a**delta))
    return g[0] if single else g


def steady_state(theta, v) -> np.ndarray:
    """Friction at constant velocity: ``sign(v) g(v) + sigma_2 v`` (the static Stribeck law;
    per direction, ``stribeck_asym``'s)."""
    batch, single = _batch(theta)
    v = np.asarray(v, dtype=float)
    sigma_2 = _of_direction(wide(batch), v[None, :], 2)
    out = np.sign(v)[None, :] * stribeck_curve(batch, v) + sigma_2 * v[None, :]
    return out[0] if single else out


def passivity_margin(theta) -> np.ndarray:
    """``4 sigma_2 tau_c / (tau_s - tau_c) - sigma_1`` ([BO00]): passive where >= 0.

    ``inf`` when ``tau_s <= tau_c`` (passive for any damping); ``-inf`` when a parameter that
    must be positive is not (sigma_0, tau_c, w_s) or sigma_1, sigma_2 are negative. Per
    direction (10 columns) the smaller of the two directions' margins: the condition applies
    to each direction's branch of the velocity-to-friction map.
    """
    batch, single = _batch(theta)
    w = wide(batch)
    s0, s1, w_s = w[:, 0], w[:, 1], w[:, 5]
    margin = np.full(len(w), np.inf)
    for first in (2, 7):
        s2, tau_c, tau_s = (w[:, first + j] for j in range(3))
        gap = tau_s - tau_c
        with np.errstate(divide="ignore", invalid="ignore"):
            side = np.where(gap > 0, 4.0 * s2 * tau_c / np.where(gap > 0, gap, 1.0) - s1, np.inf)
        bad = (s0 <= 0) | (tau_c <= 0) | (w_s <= 0) | (s1 < 0) | (s2 < 0)
        margin = np.minimum(margin, np.where(bad, -np.inf, side))
    return margin[0] if single else margin


def simulate(theta, v, dt, z0=None) -> tuple[np.ndarray, np.ndarray]:
    """Friction and bristle state along a velocity signal, for one or many parameter vectors.

    Parameters
    ----------
    theta : array_like
        ``(7,)`` or ``(k, 7)`` in the order of :data:`PARAM_NAMES`, or 10 columns per
        direction (:data:`ASYM_NAMES`).
    v : array_like
        ``(n,)`` velocity [rad/s], held constant over each sample.
    dt : float or array_like
        Sample period [s], scalar or ``(n,)`` (the step into each sample).
    z0 : float or array_like, optional
        Initial bristle deflection [rad], scalar or ``(k,)``; default 0 (relaxed).

    Returns
    -------
    F, z : ndarray
        Friction [N m] and state [rad], ``(n,)`` or ``(k, n)`` like ``theta``.
    """
    batch, single = _batch(theta)
    k = batch.shape[0]
    v, dt, z0 = simulation_inputs(v, dt, z0, k, "LuGre")
    n = v.size
    F = np.empty((k, n))
    Z = np.empty((k, n))
    from ._lugre_kernel import run  # lazy: importing numba takes a while

    run(wide(batch), v, dt, z0, F, Z)
    return (F[0], Z[0]) if single else (F, Z)


def mean_friction(theta, v_sub, dt: float, up: int, z0=None) -> np.ndarray:
    """Friction averaged over each sample period, along a velocity given ``up`` times per period.

    What an equation of motion integrated over a sample period needs (the mean torque of a
    zero-order-hold drive balances the mean friction, not the friction at the sample): the
    bristle state is updated exactly over each sub-step (module notes), and its mean over the
    sub-step is exact too.

    Parameters
    ----------
    theta : array_like
        ``(7,)`` or ``(k, 7)`` in the order of :data:`PARAM_NAMES`, or 10 columns per
        direction (:data:`ASYM_NAMES`).
    v_sub : array_like
        ``((n - 1) up + 1,)`` velocity [rad/s]: entry 0 at the first sample, then ``up``
        sub-step velocities per period, each held over ``dt / up``.
    dt : float
        Sample period [s].
    up : int
        Sub-steps per period.
    z0 : float or array_like, optional
        Bristle state at the first sample, scalar or ``(k,)``; default 0.

    Returns
    -------
    ndarray
        ``(n,)`` or ``(k, n)``: entry ``i >= 1`` the mean friction [N m] over the period
        ending at sample ``i``; entry 0 ``sigma_0 z0 + sigma_2 v_sub[0]``.
    """
    batch, single = _batch(theta)
    v = np.ascontiguousarray(np.asarray(v_sub, dtype=float).ravel())
    up = int(up)
    if up < 1 or (v.size - 1) % up:
        raise ConfigError(f"LuGre mean friction: {v.size} velocities are not 1 + {up} per period")
    if not (np.isfinite(dt) and dt > 0):
        raise ConfigError("LuGre mean friction: the sample period must be finite and > 0")
    k = batch.shape[0]
    z0 = np.ascontiguousarray(np.broadcast_to(np.asarray(0.0 if z0 is None else z0, float), (k,)))
    F = np.empty((k, (v.size - 1) // up + 1))
    batch = wide(batch)
    from ._lugre_kernel import run_mean  # lazy: importing numba takes a while

    in_row_threads(lambda a, b: run_mean(batch[a:b], v, float(dt) / up, up, z0[a:b], F[a:b]), k)
    return F[0] if single else F


def simulate_joint(
    theta,
    inertia,
    p_x,
    p_y,
    dt,
    tau,
    *,
    q0=0.0,
    v0=0.0,
    z0=0.0,
    reference=None,
    gains=(0.0, 0.0),
    n_sub: int = 4,
    reset=None,
    measured=None,
    carry=None,
) -> dict[str, np.ndarray]:
    """A joint with LuGre friction driven by a torque (or tracking a reference), batched.

    Parameters
    ----------
    theta : array_like
        LuGre parameters ``(7,)`` or ``(k, 7)`` (:data:`PARAM_NAMES`), or 10 columns per
        direction (:data:`ASYM_NAMES`).
    inertia, p_x, p_y : float or array_like
        J [kg m^2] and the gravity coefficients [N m], scalar or ``(k,)``.
    dt : float or array_like
        Sample period [s], scalar or ``(n,)`` (entry ``i`` is the step into sample ``i``).
    tau : array_like
        ``(n,)`` feed-forward motor torque [N m]; sample ``i``'s value is held until sample
        ``i + 1``.
    q0, v0, z0 : float or array_like
        Initial position [rad], velocity [rad/s] and bristle state [rad], scalar or ``(k,)``.
    reference : tuple of array_like, optional
        ``(q_ref, v_ref)``, each ``(n,)``: the motor adds ``kp (q_ref - q) + kd (v_ref - v)``.
    gains : (float, float)
        ``kp`` [N m/rad], ``kd`` [N m s/rad] of that feedback (0: pure torque drive).
    n_sub : int
        Sub-steps per sample (see the module notes).
    reset : array_like of bool, optional
        ``(n,)``: at these samples position and velocity restart from ``measured``.
    measured : tuple of array_like, optional
        ``(q, v)`` or ``(q, v, a)`` measured, each ``(n,)``; needed with ``reset``. At a reset
        the bristle state starts from the force balance with the measured acceleration ``a``
        (default 0), bounded by the steady deflection (see ``_lugre_kernel.run_joint``).
    carry : array_like of bool, optional
        ``(n,)``: at the reset samples flagged here only position and velocity restart (after
        the sample is simulated); the bristle state carries on from the simulation, as in a
        multiple-shooting segment that continues the previous one.

    Returns
    -------
    dict
        ``position``, ``velocity``, ``state`` (z), ``friction``, ``torque`` (the motor torque
        applied from each sample on), each ``(n,)`` or ``(k, n)`` like ``theta``; NaN rows for
        parameter vectors outside the model's domain (sigma_0, J, tau_c or w_s not positive).
    """
    batch, single = _batch(theta)
    k = batch.shape[0]
    tau = np.ascontiguousarray(np.asarray(tau, dtype=float).ravel())
    n = tau.size
    dt = np.ascontiguousarray(np.broadcast_to(np.asarray(dt, dtype=float), (n,)))
    if n and (not np.all(np.isfinite(dt)) or np.any(dt < 0)):
        raise ConfigError("LuGre joint simulation: sample periods must be finite and >= 0")
    if int(n_sub) < 1:
        raise ConfigError(f"LuGre joint simulation: n_sub must be >= 1, got {n_sub!r}")

    def per_row(x) -> np.ndarray:
        return np.broadcast_to(np.asarray(x, dtype=float), (k,))

    phys = np.ascontiguousarray(np.column_stack([per_row(inertia), per_row(p_x), per_row(p_y)]))
    x0 = np.ascontiguousarray(np.column_stack([per_row(q0), per_row(v0), per_row(z0)]))
    zeros = np.zeros(n)
    qref, vref = (zeros, zeros) if reference is None else reference
    qref = np.ascontiguousarray(np.broadcast_to(np.asarray(qref, float), (n,)))
    vref = np.ascontiguousarray(np.broadcast_to(np.asarray(vref, float), (n,)))
    flags = np.zeros(n, dtype=np.int8) if reset is None else np.asarray(reset, dtype=np.bool_)
    if flags.shape != (n,):
        raise ConfigError("LuGre joint simulation: 'reset' must have one flag per sample")
    flags = flags.astype(np.int8)
    if carry is not None:
        keep = np.asarray(carry, dtype=np.bool_)
        if keep.shape != (n,):
            raise ConfigError("LuGre joint simulation: 'carry' must have one flag per sample")
        flags[(flags == 1) & keep] = 2
    if flags.any() and measured is None:
        raise ConfigError("LuGre joint simulation: 'reset' needs the measured (q, v)")
    qm, vm, am = (zeros, zeros, zeros) if measured is None else (*measured, zeros)[:3]
    qm, vm, am = (
        np.ascontiguousarray(np.broadcast_to(np.asarray(x, float), (n,))) for x in (qm, vm, am)
    )
    out = {name: np.empty((k, n)) for name in ("position", "velocity", "state", "friction")}
    out["torque"] = np.empty((k, n))
    from ._lugre_kernel import run_joint  # lazy: importing numba takes a while

    flags = np.ascontiguousarray(flags)
    batch = wide(batch)
    pd = np.array([float(gains[0]), float(gains[1])])
    names = ("position", "velocity", "state", "friction", "torque")

    def rows(a: int, b: int) -> None:  # rows a..b-1; contiguous slices: written in place
        run_joint(
            *(batch[a:b], phys[a:b], tau, qref, vref, pd, dt, int(n_sub), flags, qm, vm, am),
            x0[a:b],
            *(out[name][a:b] for name in names),
        )

    in_row_threads(rows, k)
    return {key: value[0] for key, value in out.items()} if single else out


#: Threads of :func:`in_row_threads`; None: one per core the process may use.
ROW_THREADS: int | None = None


def _cores() -> int:
    if ROW_THREADS is not None:
        return max(int(ROW_THREADS), 1)
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def in_row_threads(rows, k: int) -> None:
    """``rows(a, b)`` over ``0..k`` cut into one contiguous block per core, the blocks in
    threads (the compiled kernel releases the GIL: ``nogil=True``; the rows of a finite-
    difference Jacobian are independent simulations). Plain Python threads, not numba's
    ``parallel=True``: its default threading layer (workqueue) is neither thread- nor
    fork-safe, and fleets run joints in threads and forked processes. The results are the
    same bit for bit. Measured on 2 cores (``python benchmarks/bench_lugre_threads.py``,
    ``benchmarks/results/lugre_threads.txt``): see there."""
    workers = min(k, _cores())
    if workers < 2:
        rows(0, k)
        return
    from concurrent.futures import ThreadPoolExecutor

    cuts = np.linspace(0, k, workers + 1).round().astype(int)
    with ThreadPoolExecutor(workers) as pool:
        for f in [pool.submit(rows, a, b) for a, b in itertools.pairwise(cuts)]:
            f.result()


class LuGre(FrictionModel):
    """LuGre's static projection ([CW95] eq. 2-4 at constant velocity): the model file's face.

    ``predict(theta, X)`` is the steady-state friction ``sign(v) g(v) + sigma_2 v``
    (:func:`steady_state`); sigma_0 and sigma_1 do not change it (they shape the transients
    that :func:`simulate` and :func:`simulate_joint` give).
    """

    name = "lugre"
    title = "LuGre (dynamic; steady state shown)"
    equation = "Canudas de Wit et al. 1995, eq. 2-4"
    inputs = ("velocity",)
    parameters = PARAMETERS

    def _predict(self, theta, X):
        return steady_state(theta, X[:, 0])


class LuGreAsym(FrictionModel):
    """Per-direction LuGre's static projection: the steady state ``stribeck_asym`` with w_s
    and delta shared (module notes); parameters :data:`ASYM_NAMES`."""

    name = "lugre_asym"
    title = "LuGre per direction (dynamic; steady state shown)"
    equation = "Canudas de Wit et al. 1995, eq. 2-4, levels per direction"
    inputs = ("velocity",)
    parameters = ASYM_PARAMETERS

    def _predict(self, theta, X):
        return steady_state(theta, X[:, 0])
