"""lcsim for Python: linear complementarity systems and mechanical models with
unilateral constraints, simulated exactly (event-driven, thesis Algorithm 3.7.1) or
by time-stepping, with Moreau's impact law and its variants.

    import lcsim
    model = lcsim.load("robots/two_carts.yaml")
    run = lcsim.simulate(model, dt_out=0.01)
    run.t, run.q, run.v, run.events, run.status
    run.to_csv("two_carts.csv")          # what `lcsim simulate --out` writes

Everything is computed by the C++ library (lcsim._lcsim); invalid input raises
lcsim.InputError with the library's message, numerical trouble is a status.
"""

import csv as _csv
import json as _json
import os as _os
import tempfile as _tempfile
from dataclasses import dataclass as _dataclass

from . import _lcsim
from ._lcsim import (
    Event,
    ImpactResult,
    InputError,
    LcpResult,
    Model,
    Trajectory,
    analyze,
    impact_law_names,
    impacts,
    integrator_names,
    load,
    simulate,
    solve_lcp,
    solver_names,
)

# Trajectory.friction_modes holds indices into this tuple (-1: not determined).
FRICTION_MODES = ("open", "stick", "slip+", "slip-", "slip")  # "slip": a 3-D contact sliding

__all__ = [
    "FRICTION_MODES", "Event", "ImpactResult", "InputError", "LcpResult", "Model", "Trajectory", "analyze",
    "impact_law_names", "impact_map", "impacts", "integrator_names", "load", "simulate",
    "solve_lcp", "solver_names", "study", "StudyTable", "sweep",
]


def _mechanical_views(run):
    """q and v: views (no copy) of the state columns of a mechanical run."""
    n = run.model.dofs
    return run.x[:, :n], run.x[:, n:]


Trajectory.q = property(lambda self: _mechanical_views(self)[0],
                        doc="Coordinates, shape (n, N): a view of x (mechanical models).")
Trajectory.v = property(lambda self: _mechanical_views(self)[1],
                        doc="Velocities, shape (n, N): a view of x (mechanical models).")


def sweep(model, methods, hs, x0=None, t_end=None, impact=None, theta=None, repeat=3,
          sensitivity=()):
    """The work-precision sweep of `lcsim sweep`: each method of `methods` at each
    step of `hs`, against an exact event-driven run. Returns the dict that
    `lcsim sweep --json` prints (rows, references); lcsim.plot.work_precision draws it.
    `sensitivity` (columns as `simulate`'s, e.g. ["x0", "f[1]"]) adds each row's
    error_gradient: its dx(T)/dtheta against the exact derivative."""
    return _json.loads(_lcsim._sweep_json(model, list(methods), [float(h) for h in hs], x0,
                                          t_end, impact, theta, repeat, list(sensitivity)))


def impact_map(model, v1=(-1.0, 1.0), v2=(-1.0, 1.0), n=41, x0=None, law="newton"):
    """The impact map of thesis Figure 3.5 (`lcsim impacts --map`) over pre-impact
    velocities v1 x v2 (n points each) at q = x0's q (default 0). Returns the CSV text
    the CLI prints; lcsim.plot.impact_map draws it."""
    return _lcsim._impact_map_csv(model, tuple(v1), tuple(v2), n, x0, law)


@_dataclass
class StudyTable:
    """The table of a study: `text` is the file `lcsim study --out` writes (CSV, or
    JSON lines), `rows` the same rows parsed (dicts of strings for CSV, of values for
    JSON lines), and the summary: runs in total, resumed from the journal, computed,
    failed (rows whose status is not "completed") and the wall time."""
    text: str
    rows: list
    total: int
    resumed: int
    computed: int
    failed: int
    wall_time_s: float


def study(path, out=None, resume=False, jobs=0, progress=None):
    """Runs the study file `path` (docs/study.md) as `lcsim study` does, on `jobs`
    threads (0: one per core), and returns its StudyTable, the same table whatever
    the number of threads. With `out` the table is also kept there (CSV, or JSON
    lines for a name ending in .jsonl) with its journal <out>.journal, and `resume`
    continues that journal; without it, both live in a temporary folder that is
    removed. `progress` is called with each progress line. A bad study file raises
    InputError; failed runs are rows, not exceptions."""
    def run(target):
        summary = _lcsim._run_study(_os.fspath(path), _os.fspath(target), resume, jobs, progress)
        with open(target, encoding="utf-8") as f:
            text = f.read()
        if _os.fspath(target).endswith(".jsonl"):
            rows = [_json.loads(line) for line in text.splitlines() if line]
        else:
            rows = list(_csv.DictReader(text.splitlines()))
        return StudyTable(text=text, rows=rows, **summary)

    if out is not None:
        return run(out)
    with _tempfile.TemporaryDirectory(prefix="lcsim_study_") as tmp:
        return run(_os.path.join(tmp, "table.csv"))
