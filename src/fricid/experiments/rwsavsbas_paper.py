"""The RWSAVSBAS paper's study on the virtual joint and on real lead-screw recordings: the data.

[R] Kou et al., "A New Parameter Identification Method for Industrial Robots with Friction",
Machines 10(5) 349, 2022. For each data set :func:`run_rwsavsbas` computes what [R]'s tables
and figures show: Table 1 and Fig. 6 (8 runs of VSBAS, IBAS and RWSAVSBAS: final SSE and
convergence histories), Fig. 7 (error per sampling point at each algorithm's best run),
Table 2 (identified parameters with Jacobian confidence intervals, beside the exact optimum)
and the samples for Fig. 3/4 and Fig. 8. The algorithm comparison on the virtual joint is
:func:`fricid.experiments.stribeck_study.run_study`; on the lead screw the paper's three
methods run at the same settings. The document is composed by
:mod:`fricid.report.studies.rwsavsbas`.

The real lead-screw drive of ``shared/data/real/epos-leadscrew/`` (Maxon EPOS, steady state,
one velocity per file) is studied once per direction of motion: a real drive is asymmetric,
and the paper's model (eq. 7) has one parameter set.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..fitted import FittedModel, OptimizerRecord, Parameter
from ..identify import jacobian_uncertainty
from ..io import epos_steady_samples
from ..metrics import metrics
from ..models import get_model
from ..optim import OptimizeResult, minimize_runs
from ..samples import FrictionSamples
from . import stribeck_study as study
from .paper_numbers import RWSAVSBAS as PAPER

__all__ = [
    "FIXED",
    "LEADSCREW_ENV",
    "PAPER_METHODS",
    "PARAMS",
    "STEPS",
    "Comparison",
    "DatasetResult",
    "RwsavsbasResult",
    "find_leadscrew",
    "run_rwsavsbas",
    "scaled_bounds",
]

logger = logging.getLogger(__name__)

#: Labels of the steps reported to the progress callback, in order.
STEPS = (
    "simulating and extracting the virtual joint (paper2 preset)",
    "virtual joint: Table 1, Fig. 6, Fig. 7 (8 runs per algorithm)",
    "virtual joint: Table 2, Fig. 3/4, Fig. 8",
    "lead screw, positive direction",
    "lead screw, negative direction",
)

#: The Stribeck exponent the paper fixes (Tustin's model, section 2.3).
FIXED = {"delta": 1.0}

#: The free parameters of eq. 7, in order.
PARAMS = ("tau_c", "tau_s", "w_s", "tau_v")

#: The algorithms of [R]'s Table 1, Fig. 6 and Fig. 7.
PAPER_METHODS = ("VSBAS", "IBAS", "RWSAVSBAS")

#: Environment variable naming the lead-screw recordings folder.
LEADSCREW_ENV = "FRICID_LEADSCREW_DIR"


def find_leadscrew() -> Path | None:
    """The lead-screw recordings folder.

    Returns
    -------
    pathlib.Path or None
        ``$FRICID_LEADSCREW_DIR``, else ``shared/data/real/epos-leadscrew`` beside the current
        directory or beside the source tree; None if none exists.
    """
    rel = Path("shared") / "data" / "real" / "epos-leadscrew"
    candidates = []
    if os.environ.get(LEADSCREW_ENV):
        candidates.append(Path(os.environ[LEADSCREW_ENV]))
    here = Path.cwd().resolve()
    candidates += [p / rel for p in (here, *here.parents)]
    src = Path(__file__).resolve()
    candidates += [p / rel for p in src.parents]
    for c in candidates:
        if c.is_dir() and any(c.glob("*.csv")):
            return c
    return None


def _as_samples(velocity: np.ndarray, friction: np.ndarray, source: str) -> FrictionSamples:
    return FrictionSamples(
        velocity=velocity,
        load=0.0,
        temperature=25.0,
        friction=friction,
        direction=np.sign(velocity),
        source=source,
    )


def _leadscrew(folder: Path) -> dict[str, FrictionSamples]:
    s = epos_steady_samples(folder)
    pos = s.subset(s.direction == 1)
    neg = s.subset(s.direction == -1)
    return {
        "positive": replace(pos, source=f"{folder.name} (+)"),
        "negative": replace(neg, source=f"{folder.name} (−)"),
    }


def scaled_bounds(samples: FrictionSamples) -> np.ndarray:
    """Search box for data of any scale.

    Parameters
    ----------
    samples : FrictionSamples
        The data.

    Returns
    -------
    numpy.ndarray
        ``(4, 2)`` bounds: tau_c, tau_s in [0, 3 F], w_s in [1e-4 V, V], tau_v in [0, F / V],
        with F the largest |friction| and V the largest |velocity|. For the ``paper2`` preset
        (F = 0.65 N m, V = 4 rad/s) this is close to the study's
        :data:`~fricid.experiments.stribeck_study.BOUNDS`.
    """
    F = float(np.max(np.abs(samples.friction)))
    V = float(np.max(np.abs(samples.velocity)))
    return np.array([[0.0, 3 * F], [0.0, 3 * F], [1e-4 * V, V], [0.0, F / V]])


@dataclass
class Comparison:
    """One data set's algorithm comparison ([R] Table 1, Fig. 6-7).

    Attributes
    ----------
    samples : FrictionSamples
        The data.
    results : dict
        Runs (:class:`~fricid.optim.OptimizeResult`) per method label.
    optimum : tuple
        ``(theta, sse)`` of the exact optimum (variable projection).
    settings : dict
        Each method's setting, as text for the table.
    study : fricid.experiments.stribeck_study.StudyResult or None
        The whole study (virtual joint only): its readings and claims.
    """

    samples: FrictionSamples
    results: dict[str, list[OptimizeResult]]
    optimum: tuple[np.ndarray, float]
    settings: dict[str, str]
    study: study.StudyResult | None = None


@dataclass
class DatasetResult:
    """Everything [R]'s tables and figures show, for one data set.

    Attributes
    ----------
    tag : str
        File-name prefix (``virtual``, ``leadscrew_pos``, ``leadscrew_neg``).
    samples : FrictionSamples
        The data.
    comparison : Comparison
        Table 1, Fig. 6 and Fig. 7's runs.
    best, reference : FittedModel
        RWSAVSBAS's best run and the exact optimum, with Jacobian 95 % intervals (Table 2).
    errors : dict
        Fig. 7: measured minus predicted friction at each sample, best run of each of
        :data:`PAPER_METHODS` [N m].
    truth : dict or None
        The true parameters (the virtual joint: [R]'s Table 2).
    paper_numbers : bool
        Whether [R]'s numbers are comparable (the virtual joint) and shown.
    velocity_unit : str
        Velocity unit of the figures.
    """

    tag: str
    samples: FrictionSamples
    comparison: Comparison
    best: FittedModel
    reference: FittedModel
    errors: dict[str, np.ndarray]
    truth: dict[str, float] | None
    paper_numbers: bool
    velocity_unit: str


@dataclass
class RwsavsbasResult:
    """What :func:`run_rwsavsbas` returns.

    Attributes
    ----------
    virtual : DatasetResult
        The ``paper2`` preset.
    leadscrew : dict
        Per direction (``positive``, ``negative``); empty when the recordings are absent.
    folder : pathlib.Path or None
        The lead-screw recordings folder used.
    quick, seed : bool, int
        The run's settings.
    """

    virtual: DatasetResult
    leadscrew: dict[str, DatasetResult] = field(default_factory=dict)
    folder: Path | None = None
    quick: bool = False
    seed: int = 0


def _virtual_comparison(samples: FrictionSamples, quick: bool, seed: int) -> Comparison:
    res = study.run_study(
        seed=seed,
        quick=quick,
        data_seed=seed,
        time_numpy=False,
        progress=lambda msg: logger.info("stribeck study: %s", msg),
    )
    theta = np.array([res.optimum[n] for n in PARAMS])
    table = res.table
    settings = {label: str(table.loc[label, "setting"]) for label in table.index}
    return Comparison(
        samples,
        {k: res.results[k] for k in table.index},
        (theta, res.optimum["sse"]),
        settings,
        study=res,
    )


def _real_comparison(samples: FrictionSamples, quick: bool, seed: int) -> Comparison:
    """The paper's three methods at the study's settings ([R] 4.1), 8 runs each, on other
    data, in a box scaled to the data (:func:`scaled_bounds`)."""
    problem = study.StribeckProblem(
        samples.velocity, samples.friction, bounds=scaled_bounds(samples)
    )
    fun = study.sse_objective(problem, jit=True)
    specs = [sp for sp in study.method_specs(quick) if sp.label in PAPER_METHODS]
    results, settings = {}, {}
    for spec in specs:
        results[spec.label] = minimize_runs(
            fun,
            problem.bounds,
            spec.method,
            seed=seed,
            runs=PAPER["runs"],
            max_evals=spec.max_evals,
            # the compiled loop: same numbers as the Python one, not timed here
            options={k: v for k, v in spec.options.items() if k != "jit"},
        )
        settings[spec.label] = spec.setting
    return Comparison(samples, results, study.global_optimum(problem), settings)


def _best(runs: list[OptimizeResult]) -> np.ndarray:
    return np.asarray(min(runs, key=lambda r: r.fun).x, dtype=float)


def _fitted_from(theta: np.ndarray, samples: FrictionSamples, method: str) -> FittedModel:
    """A FittedModel of the Stribeck model (delta = 1) at ``theta`` with Jacobian CIs."""
    from scipy import stats

    model = get_model("stribeck")
    X, y = samples.X, samples.friction
    problem = study.StribeckProblem(samples.velocity, y, bounds=scaled_bounds(samples))
    se, _ = jacobian_uncertainty(problem.residuals, theta, len(y))
    t95 = float(stats.t.ppf(0.975, max(len(y) - len(theta), 1)))
    params = {**dict(zip(PARAMS, map(float, theta), strict=True)), **FIXED}
    records = {
        n: Parameter(n, v, unit=model.units.get(n, ""), fixed=n in FIXED) for n, v in params.items()
    }
    for n, v in zip(PARAMS, map(float, se), strict=True):
        records[n] = replace(records[n], stderr=v, ci95_halfwidth=v * t95)
    return FittedModel(
        model="stribeck",
        parameters=records,
        metrics=metrics(y, model.predict(model.param_vector(params), X)),
        optimizer=OptimizerRecord(method=method),
    )


def _dataset(
    tag: str,
    comp: Comparison,
    *,
    truth: dict[str, float] | None,
    paper_numbers: bool,
    velocity_unit: str,
) -> DatasetResult:
    samples = comp.samples
    model = get_model("stribeck")
    errors = {}
    for label in PAPER_METHODS:
        theta = np.append(_best(comp.results[label]), 1.0)
        errors[label] = samples.friction - model.predict(theta, samples.X)
    best = _fitted_from(_best(comp.results["RWSAVSBAS"]), samples, "rwsavsbas")
    reference = _fitted_from(np.asarray(comp.optimum[0], dtype=float), samples, "exact optimum")
    return DatasetResult(
        tag, samples, comp, best, reference, errors, truth, paper_numbers, velocity_unit
    )


def run_rwsavsbas(
    *,
    quick: bool = False,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
    leadscrew: str | os.PathLike[str] | None = None,
) -> RwsavsbasResult:
    """Run [R]'s study on the virtual joint and on the lead-screw recordings.

    Parameters
    ----------
    quick : bool
        Reduced optimiser budgets (RWSAVSBAS's schedule compressed ten-fold, as
        :func:`fricid.experiments.stribeck_study.run_study` does with ``quick``); otherwise
        the paper's 8 runs of 1000 iterations per algorithm.
    seed : int
        Seeds the simulator and every run.
    progress : callable, optional
        Called with the label of each step of :data:`STEPS` as it starts.
    leadscrew : path-like, optional
        Folder of the EPOS recordings (default :func:`find_leadscrew`).

    Returns
    -------
    RwsavsbasResult
    """
    say = progress or (lambda _label: None)
    say(STEPS[0])
    v, y = study.paper2_samples(seed)
    samples = _as_samples(v, y, f"virtual joint paper2/full, seed {seed}")
    folder = Path(leadscrew) if leadscrew is not None else find_leadscrew()
    truth = dict(zip(PARAMS, PAPER["table2"].values(), strict=True))
    say(STEPS[1])
    comp = _virtual_comparison(samples, quick, seed)
    say(STEPS[2])
    virtual = _dataset("virtual", comp, truth=truth, paper_numbers=True, velocity_unit="rad/s")
    out = RwsavsbasResult(virtual, folder=folder, quick=quick, seed=seed)
    if folder is None:
        say(STEPS[3])
        say(STEPS[4])
        return out
    for k, (direction, data) in enumerate(_leadscrew(folder).items()):
        say(STEPS[3 + k])
        out.leadscrew[direction] = _dataset(
            f"leadscrew_{direction[:3]}",
            _real_comparison(data, quick, seed),
            truth=None,
            paper_numbers=False,
            velocity_unit="rpm",
        )
    return out
