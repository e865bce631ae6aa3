"""``fricid fit``: identify a friction model from samples."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ._app import app, console, err_console, handle_errors
from ._options import parse_assignments, parse_ranges
from ._paths import check_paths


def _method_help() -> str:
    from ..optim import METHODS

    return "; ".join(f"{name}: {cls.summary}" for name, cls in METHODS.items())


@app.command("fit")
@handle_errors
def fit_command(
    samples: Annotated[
        Path,
        typer.Argument(
            help="Friction samples, CSV or Parquet (from `fricid extract`).",
        ),
    ],
    model: Annotated[
        str,
        typer.Option(
            "--model",
            "-m",
            help=(
                "Model: coulomb_viscous (eq. 1), stribeck (eq. 2 / RWSAVSBAS eq. 7), msk (eq. 3, "
                "load), vlt (eq. 4, load and temperature); append _asym for parameters per "
                "direction; or rbf, the RBF neural network (eq. 14-15; --method lsq, bas for "
                "BAS-RBFNN or ga for GA-RBFNN)."
            ),
        ),
    ] = "stribeck",
    method: Annotated[
        str,
        typer.Option(
            help="Optimiser (see `fricid methods`): lm, trf, bas, "
            "vsbas, ibas, rwsavsbas, ga, de, cmaes, bas+lm, ..."
        ),
    ] = "lm",
    fix: Annotated[
        list[str] | None,
        typer.Option(
            "--fix",
            help=(
                "Hold a parameter at a value, NAME=VALUE (SI units), e.g. --fix delta=1. "
                "Repeatable."
            ),
        ),
    ] = None,
    bound: Annotated[
        list[str] | None,
        typer.Option(
            "--bound",
            help=(
                "Search range of a parameter, NAME=LOW:HIGH (SI units). Repeatable. Default ranges "
                "scale with the data."
            ),
        ),
    ] = None,
    seed: Annotated[int, typer.Option(help="Random seed (same seed, same result).")] = 0,
    max_evals: Annotated[int | None, typer.Option(help="Budget in model evaluations.")] = None,
    centers: Annotated[
        int, typer.Option(help="rbf: number of Gaussian units (hidden layer).")
    ] = 40,
    inputs: Annotated[
        str, typer.Option(help="rbf: input columns, a comma list of velocity, load, temperature.")
    ] = "velocity,load,temperature",
    direction: Annotated[
        str,
        typer.Option(
            help=("Which samples to use: all, combined (direction 0), both (+1 and -1), pos, neg.")
        ),
    ] = "all",
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            help=(
                "Model file to write (JSON). Default: <samples>.<model>.json in the current "
                "directory."
            ),
        ),
    ] = None,
) -> None:
    """Identify a friction model from samples and write it as a JSON model file.

    Prints the fit report (after lmfit's): method, evaluations and convergence status; data
    points, variables, chi-square (SSE [N m^2]), reduced chi-square, AIC, BIC, R^2; each
    parameter with its standard error, 95 % confidence interval and start, flagged at a
    boundary, at its initial value or not determined; correlations above 0.1. The RBF network
    (--model rbf) goes through the same identification and prints its network instead.
    """
    from ..identify import fit
    from ..io import read_samples
    from ..workflow import select_direction

    check_paths(inputs={"SAMPLES": samples}, out_files={"--out": out})
    data = select_direction(read_samples(samples), direction)
    rbf = model.strip().lower() == "rbf"
    fitted = fit(
        data,
        model,
        _rbf_trainer(method) if rbf else method,
        fixed=parse_assignments(fix, "--fix"),
        bounds=parse_ranges(bound, "--bound"),
        seed=seed,
        max_evals=max_evals,
        **(_rbf_network(centers, inputs) if rbf else {}),
    )
    out = out or Path(f"{samples.stem}.{fitted.model}.json")
    fitted.save(out)
    console.print(fitted.report(), markup=False, highlight=False, soft_wrap=True)
    err_console.print(f"wrote {escape(str(out))}")


def _rbf_trainer(method: str) -> str:
    """The RBF network's trainer: lsq (k-means, widths, ridge weights; the default --method
    lm means it), bas (BAS-RBFNN) or ga (GA-RBFNN)."""
    from ..errors import ConfigError

    trainer = "lsq" if method == "lm" else method
    if trainer not in ("lsq", "bas", "ga"):
        raise ConfigError(f"--model rbf trains with --method lsq, bas or ga; got '{method}'")
    return trainer


def _rbf_network(centers: int, inputs: str) -> dict:
    """``identify.fit``'s network arguments from --centers and --inputs."""
    names = [name.strip() for name in inputs.split(",") if name.strip()]
    network = {"n_centers": centers, "velocity_scale": 0.035 if "velocity" in names else None}
    return {"network": network, "inputs": names}


@app.command("methods")
def methods_command() -> None:
    """List the optimisers and the models, with a line on each."""
    from ..models import MODELS
    from ..optim import METHODS

    console.print("[bold]Models[/] (append _asym for per-direction parameters):")
    for name, cls in MODELS.items():
        m = cls()
        console.print(
            f"  {name:<16} {m.title}; {m.equation}; parameters {', '.join(m.param_names)}",
            highlight=False,
        )
    console.print("[bold]Methods[/]:")
    for name, cls in METHODS.items():
        console.print(f"  {name:<16} {cls.summary}", highlight=False)
