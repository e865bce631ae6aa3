"""The simulated joint of the compensation studies: one step of its dynamics, static or LuGre.

``J q'' = u - F``: a rigid joint of inertia ``J`` [kg m^2] driven by the torque ``u`` [N m]
against friction ``F``. The step functions advance ``k`` independent runs at once (arrays
of shape ``(k,)``); the caller's loop runs over time only.

Static friction (:func:`static_step`)
    ``F = law(v, load, T)``. At zero velocity the joint sticks while the applied torque stays
    within the break-away friction (the law just off zero, in the direction of the torque),
    and slips once it exceeds it; a step that would carry the velocity through zero stops it
    at zero (the Karnopp scheme, D. Karnopp 1985, adapted to a fixed step). Semi-implicit
    Euler.
LuGre friction (:func:`lugre_step`)
    The bristle model of Canudas de Wit et al. 1995 (eq. 2-4; :mod:`fricid.models.lugre`)::

        dz/dt = v - a z,   a = sigma_0 |v| / g(v),   F = sigma_0 z + sigma_1 dz/dt + sigma_2 v

    The bristles are stiff (``sqrt(sigma_0 / J)`` is hundreds of rad/s), so the step is
    linearly implicit: with ``a`` taken at the velocity at the start of the step, the new
    state and velocity solve the linear pair (implicit Euler)::

        z' = (z + dt v') / (1 + a dt)
        J (v' - v) / dt = u - (sigma_0 z' + sigma_1 (v' - a z') + sigma_2 v')

    implicit Euler for the stiff linear part, so the bristles' fast mode is damped rather
    than amplified at any step (no stick logic is needed: the bristles hold the joint in
    pre-sliding). It converges to the continuous solution at first order in ``dt``
    (``benchmarks/bench_mujoco.py`` shows 1 ms and 0.1 ms against 20 us); the compensation
    study uses 0.2 ms steps.
Open loop (:func:`drive`)
    A torque signal applied to a joint at rest: the Python reference against which a
    simulator (MuJoCo, :mod:`fricid.export.mujoco_check`) is compared.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import ConfigError

__all__ = ["OFF_ZERO", "drive", "lugre_step", "static_step"]

#: Velocity [rad/s] just off zero where the break-away friction is evaluated.
OFF_ZERO = 1e-9

Law = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def static_step(
    law: Law,
    v: np.ndarray,
    u: np.ndarray,
    inertia: float,
    dt: float,
    load: np.ndarray,
    temperature: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """One Karnopp step under a static law: ``(v_new, friction)`` for torques ``u`` (k,)."""
    moving = v != 0.0
    v_eval = np.where(moving, v, np.where(u >= 0.0, OFF_ZERO, -OFF_ZERO))
    f = law(v_eval, load, temperature)
    stuck = ~moving & (np.abs(u) <= np.abs(f))
    f = np.where(stuck, u, f)  # static friction balances the applied torque
    v_new = v + (u - f) / inertia * dt
    v_new = np.where(moving & (np.sign(v_new) != np.sign(v)), 0.0, v_new)
    return np.where(stuck, 0.0, v_new), f


def lugre_step(
    theta: np.ndarray,
    z: np.ndarray,
    v: np.ndarray,
    u: np.ndarray,
    inertia: float,
    dt: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One linearly implicit step of a joint with LuGre friction (module docstring).

    Parameters
    ----------
    theta : array_like
        (7,) LuGre parameters (:data:`fricid.models.lugre.PARAM_NAMES`), or (k, 7): one row
        per run.
    z, v, u : ndarray
        (k,) bristle state [rad], velocity [rad/s] and applied torque [N m].

    Returns
    -------
    z_new, v_new, friction : ndarray
        (k,) arrays; ``friction`` is the LuGre force over the step. The step is compiled
        (:func:`fricid.control._kernels.lugre_plant_step`, also used by the study's loop).
    """
    from ._kernels import lugre_plant_step

    z, v, u = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (z, v, u))
    th = np.broadcast_to(np.atleast_2d(np.asarray(theta, dtype=float)), (z.size, 7))
    out = np.array(
        [lugre_plant_step(th[j], z[j], v[j], u[j], inertia, dt) for j in range(z.size)]
    ).reshape(z.size, 3)
    return out[:, 0], out[:, 1], out[:, 2]


def drive(
    torque,
    dt: float,
    inertia: float,
    *,
    law: Law | None = None,
    lugre_theta=None,
    load: float = 0.0,
    temperature: float = 25.0,
) -> dict[str, np.ndarray]:
    """Apply ``torque`` (n,) [N m] to a joint at rest (q = 0, v = 0, relaxed bristles).

    Give exactly one of ``law`` (static friction, Karnopp) or ``lugre_theta`` (7 LuGre
    parameters). Sample ``i`` holds the state at ``t = i dt``, before ``torque[i]`` acts.

    Returns
    -------
    dict
        ``time``, ``position`` [rad], ``velocity`` [rad/s], ``friction`` [N m], each (n,).
    """
    torque = np.asarray(torque, dtype=float).ravel()
    if (law is None) == (lugre_theta is None):
        raise ConfigError("drive: give exactly one of 'law' and 'lugre_theta'")
    if not (np.isfinite(dt) and dt > 0 and np.isfinite(inertia) and inertia > 0):
        raise ConfigError(f"drive: dt and inertia must be > 0, got {dt!r} and {inertia!r}")
    if not np.all(np.isfinite(torque)):
        raise ConfigError("drive: the torque must be finite")
    n = torque.size
    out = {name: np.empty(n) for name in ("position", "velocity", "friction")}
    out["time"] = np.arange(n) * dt
    if lugre_theta is not None:
        from ._kernels import drive_lugre

        th = np.ascontiguousarray(_checked(lugre_theta))
        drive_lugre(th, torque, float(dt), float(inertia), *(out[k] for k in list(out)[:3]))
        return out
    q, v = np.zeros(1), np.zeros(1)
    lo, te = np.full(1, float(load)), np.full(1, float(temperature))
    for i in range(n):
        out["position"][i], out["velocity"][i] = q[0], v[0]
        v, f = static_step(law, v, torque[i : i + 1], inertia, dt, lo, te)
        out["friction"][i] = f[0]
        q = q + v * dt
    return out


def _checked(theta) -> np.ndarray:
    """7 finite LuGre parameters, as floats (:class:`ConfigError` otherwise)."""
    th = np.asarray(theta, dtype=float)
    if th.shape != (7,) or not np.all(np.isfinite(th)):
        raise ConfigError(f"LuGre takes 7 finite parameters, got {theta!r}")
    return th
