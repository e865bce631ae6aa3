"""``fricid reproduce``: every table and figure of a seed paper, regenerated into a folder."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._app import app, console, err_console, handle_errors, plural
from ._progress import QuietOption, tracker
from ._study_options import out_option, quick_option, seed_option


@app.command("reproduce")
@handle_errors
def reproduce_command(
    paper: Annotated[str, typer.Argument(help="Which paper: bas-rbfnn or rwsavsbas.")],
    out: Annotated[
        Path | None, out_option("Folder to write. Default: ./fricid-reproduce/<paper>/.")
    ] = None,
    quick: Annotated[
        bool,
        quick_option(
            "Reduced designs and budgets (RWSAVSBAS: its schedule compressed ten-fold; "
            "BAS-RBFNN: the 330-sample design, smaller networks)."
        ),
    ] = False,
    seed: Annotated[int, seed_option("Random seed (same seed, same report).")] = 0,
    quiet: QuietOption = False,
) -> None:
    """Regenerate every table and figure of a seed paper on the virtual joint (and, for
    rwsavsbas, on the real lead-screw recordings), with the paper's numbers beside ours.

    Writes report.html (self-contained), report.md, one CSV per table and one PNG per figure
    into the folder, all or nothing. Progress is shown on stderr (a bar on a terminal,
    otherwise a line per step and at least every 30 s; no time left: the steps differ too
    much in cost for one to time another; --quiet: none).
    """
    from ..report.reproduce import paper_steps, reproduce

    steps = paper_steps(paper)
    # steps of very unequal cost (a study, then its tables): counted, never timed one by
    # another (a time left from them was off by minutes)
    with tracker(paper, total=len(steps), unit="steps done", quiet=quiet, timed=False) as bar:
        seen: list[str] = []

        def progress(label: str) -> None:
            seen.append(label)
            bar.stage(f"{paper} [{len(seen)}/{len(steps)}] {label}", done=len(seen) - 1, force=True)

        result = reproduce(paper, out, quick=quick, seed=seed, progress=progress)
        bar.update(len(steps))
    console.print(str(result.html), highlight=False, soft_wrap=True)
    err_console.print(
        f"{plural(len(result.document.tables()), 'table')} and "
        f"{plural(len(result.document.figures()), 'figure')} in {result.out}/ "
        f"({result.seconds:.1f} s)"
    )
