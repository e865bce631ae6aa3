"""The one public ``fit``: samples or a trajectory log, a model, a method -> ``FittedModel``.

Shaped after ``scipy.optimize.minimize``: the arguments every kind of identification shares
are in the signature, ``method`` names the optimiser (one meaning everywhere), ``options`` are
that method's options, and what only one kind uses goes in ``settings``. The kind is decided
by the data and the model, through an explicit table (:data:`KINDS`):

========  =====================================  ==========================================
kind      when                                   done by
========  =====================================  ==========================================
analytic  samples, a law of ``fricid.models``    :func:`.static.least_squares.fit`
learned   samples, ``rbf``, ``hybrid`` or ``gp``  :func:`.learned.train.fit_learned`
dynamic   a trajectory log (``RawLog``)          :func:`.dynamic.trajectory.fit_trajectory`
auto      samples, ``model="auto"``              :func:`.static.select.select`
arm       a whole arm's log (``RobotLog``)       :func:`.dynamic.arm.fit_arm`
========  =====================================  ==========================================

A whole arm returns an :class:`~fricid.fitted.arm.ArmFit` (every joint's friction as a
``FittedModel`` through :meth:`~fricid.fitted.arm.ArmFit.joint_model`); the arm's rigid-body
model goes in ``settings["robot"]``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel
from ..fitted.arm import ArmFit
from ..models import FrictionModel
from ..optim import OptimizeResult, one_blas_thread
from ..samples import FrictionSamples, RawLog, RobotLog
from ._named import KINDS, SETTINGS, _int_seed, _no_weights, _refuse, _settings, fit_named, kind_of

__all__ = ["KINDS", "SETTINGS", "fit", "kind_of"]


def fit(
    data: FrictionSamples | RawLog | RobotLog,
    model: str | FrictionModel,
    method: str | None = None,
    *,
    fixed: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    x0: Mapping[str, float] | None = None,
    seed: int | np.random.Generator | None = 0,
    max_evals: int | None = None,
    options: Mapping[str, Any] | None = None,
    callback: Callable[[OptimizeResult], Any] | None = None,
    intervals: str = "auto",
    loss: str = "l2",
    f_scale: float | None = None,
    weights: str | Any = "none",
    settings: Mapping[str, Any] | None = None,
) -> FittedModel | ArmFit:
    """Identify ``model`` from ``data`` with ``method``.

    Parameters
    ----------
    data : FrictionSamples or RawLog
        Steady-state friction samples (BAS-RBFNN paper, section 2), or a trajectory log for
        dynamic identification (the log's kind decides).
    model : str or FrictionModel
        A law of :data:`fricid.models.MODELS` (eq. 1-4 of the BAS-RBFNN paper, Stribeck with
        exponent of the RWSAVSBAS paper's eq. 7; ``*_asym`` per direction, ``*_temp`` with an
        Arrhenius viscous term), an instance, a learned model (``"rbf"``, ``"hybrid"``,
        ``"gp"``), ``"auto"`` (the family chosen by held-out error), for a trajectory
        ``"lugre"``, ``"dahl"``, ``"stribeck"`` or ``"coulomb_viscous"``, and for a whole
        arm's ``RobotLog`` the friction family of every joint (``"stribeck_asym"``,
        ``"coulomb_viscous_asym"``, ``"coulomb_viscous"``, ``"stribeck"``) or ``"arm"``
        (``settings["friction"]``, default ``stribeck_asym``).
    method : str, optional
        The optimiser. Analytic and dynamic: any of :data:`fricid.optim.METHODS` or
        ``"varpro"`` (analytic only); default ``"lm"``. ``rbf`` and ``hybrid``: ``"lsq"``
        (closed-form least squares, the default), ``"bas"`` (BAS-RBFNN) or ``"ga"``
        (GA-RBFNN). ``gp``: ``"ml"`` (marginal likelihood, the only one). ``auto``: the
        analytic candidates' optimiser.
    fixed, bounds, x0 : mapping, optional
        Named parameters held at a value, their search bounds, their starting values
        (analytic and dynamic models; e.g. ``fixed={"delta": 1.0}`` for the RWSAVSBAS
        paper's Stribeck model).
    seed : int or numpy.random.Generator, optional
        Makes the fit reproducible (default 0).
    max_evals : int, optional
        The method's budget in evaluations (one candidate is one evaluation).
    options : mapping, optional
        The method's options (as ``fricid.optim.minimize`` takes them).
    callback : callable, optional
        Called with the best-so-far ``OptimizeResult`` (analytic fits).
    intervals : {"auto", "profile", "jacobian", "none"}, default "auto"
        Analytic fits: how the 95 % intervals are computed (none for an unconverged fit).
    loss : {"l2", "soft_l1", "huber"}, default "l2"
        Least squares or a robust loss (analytic fits and ``auto``).
    f_scale : float, optional
        N m, the robust loss's scale (default: the measurement scatter).
    weights : {"none", "std"} or array_like, default "none"
        Weighted least squares (analytic fits and ``auto``).
    settings : mapping, optional
        What one kind alone takes (:data:`SETTINGS`): ``rbf`` / ``hybrid``: ``inputs``,
        ``network`` (``RBFNetRegressor`` parameters), ``backbone`` (hybrid); ``gp``:
        ``inputs``, ``max_points``, ``n_restarts``; dynamic: ``route``, ``gravity``, ...
        (:func:`fricid.identify.dynamic.trajectory.fit_trajectory`); ``auto``: ``scheme``
        (validation), ``scatter``, ``learned`` (try the learned families too), ``progress``
        (``progress(i, n, candidate)``, :func:`.static.select.select`); ``arm``: ``robot``
        (the :class:`fricid.robot.RigidBodyModel`, required), ``friction`` (a family or joint
        -> family), ``consistent``, ``encoder_counts``, ``cutoff``, ``validate`` (a second
        ``RobotLog``; :func:`fricid.identify.dynamic.arm.fit_arm`).

    Returns
    -------
    FittedModel or ArmFit
        Parameters with their records (value, bounds, standard error, interval), the
        optimiser's record, metrics, convergence and provenance.

    Raises
    ------
    ConfigError
        Unknown model, method or setting; an argument the kind does not take.
    DataError
        Data that cannot identify the model.
    """
    with one_blas_thread():  # every least-squares path on one BLAS thread
        kind = kind_of(data, model)
        extra = _settings(kind, model, settings)
        if kind == "arm":
            return _fit_arm(
                data,
                model,
                method,
                extra,
                fixed=fixed,
                bounds=bounds,
                x0=x0,
                options=options,
                callback=callback,
                max_evals=max_evals,
                loss=loss != "l2",
                weights=not _no_weights(weights),
                f_scale=f_scale,
                intervals=intervals != "auto",
            )
        if kind == "dynamic":
            from .dynamic.trajectory import fit_trajectory

            _refuse(kind, loss=loss != "l2", weights=not _no_weights(weights), f_scale=f_scale)
            _refuse(kind, fixed=fixed, bounds=bounds, x0=x0, options=options, callback=callback)
            name = model if isinstance(model, str) else model.name
            return fit_trajectory(
                data, name, method or "lm", seed=_int_seed(seed), max_evals=max_evals, **extra
            )
        if kind == "auto":
            from .static.select import select

            _refuse(kind, fixed=fixed, bounds=bounds, x0=x0, callback=callback)
            return select(
                data,
                method or "lm",
                seed=seed,
                max_evals=max_evals,
                options=options,
                intervals=intervals,
                loss=loss,
                f_scale=f_scale,
                weights=weights,
                **extra,
            )
        return fit_named(
            data,
            model,
            method,
            fixed=fixed,
            bounds=bounds,
            x0=x0,
            seed=seed,
            max_evals=max_evals,
            options=options,
            callback=callback,
            intervals=intervals,
            loss=loss,
            f_scale=f_scale,
            weights=weights,
            settings=settings,
        )


def _fit_arm(data: RobotLog, model: Any, method: str | None, extra: dict, **given: Any) -> ArmFit:
    """``fit`` of a whole arm: ``model`` is the friction family or ``"arm"``; nothing but
    ``settings`` configures it."""
    from .dynamic.arm import fit_arm

    _refuse("arm", method=method, **given)
    robot = extra.pop("robot", None)
    if robot is None:
        raise ConfigError("a whole arm needs its rigid-body model: settings={'robot': ...}")
    if not isinstance(model, str):
        raise ConfigError(f"a whole arm's model is a friction family or 'arm'; got {model!r}")
    if model != "arm":
        if "friction" in extra:
            raise ConfigError("give the friction as model= or as settings['friction'], not both")
        extra["friction"] = model
    return fit_arm(data, robot, **extra)
