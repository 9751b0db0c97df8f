"""The one load-path driver: a solver along a list of loads, each step warm-started, a callback after each.

:func:`drive` runs every path (command line, ensembles, adhesive cycles); :func:`load_path` is its generator
for the Python API.
"""

from petsc4py import PETSc

from ..errors import ParameterError
from .facade import Solver
from .registry import resolve

LOAD_KINDS = ("pstar", "pbar", "gbar")


def drive(solver, steps, on_step=None, first=0, on_start=None):
    """Solve ``steps`` (``(kind, value)`` pairs, kind one of pstar, pbar, gbar) in order; yields each result.

    Each step runs in a PETSc log stage of its own; ``on_start(index, kind, value)`` is called before each,
    ``on_step(index, kind, value, result)`` after each. ``first`` skips the steps before it (a resumed path).
    """
    for index, (kind, value) in enumerate(steps):
        if index < first:
            continue
        if kind not in LOAD_KINDS:
            raise ParameterError("steps", f"a step is ('pstar' | 'pbar' | 'gbar', value), got '{kind}'")
        if on_start is not None:
            on_start(index, kind, value)
        stage = PETSc.Log.Stage(f"RP step {index:03d} {kind}={value:g}")
        stage.push()
        try:
            result = solver.solve(**{kind: value})
        finally:
            stage.pop()
        if on_step is not None:
            on_step(index, kind, value, result)
        yield result


def load_path(problem, pstars=None, pbars=None, gbars=None, tao_type=None, rtol=1e-8, prefix=None, options=None,
              on_step=None):
    """A generator of :class:`~roughpetsc.contact.Result` along the loads, each warm-started, as the load
    history (7.11) is solved. The Solver is made at the first result and destroyed when the generator ends.

    Parameters
    ----------
    problem : ContactProblem or AdhesiveProblem
    pstars, pbars, gbars : sequence of float
        Exactly one: the loads as p* = pbar / sqrt(m0^p), as mean pressures, or as mean gaps
        (displacement control; an adhesive problem takes mean gaps only).
    tao_type, rtol, prefix, options :
        As for :class:`~roughpetsc.solvers.facade.Solver`.
    on_step : callable, optional
        ``on_step(index, kind, value, result)`` after each step (:func:`drive`).
    """
    given = {name: loads for name, loads in (("pstar", pstars), ("pbar", pbars), ("gbar", gbars))
             if loads is not None}
    if len(given) != 1:
        raise ParameterError("pstars", "give exactly one of pstars, pbars, gbars, got "
                                       f"{len(given) or 'none'}")
    (kind, loads), = given.items()
    control = "displacement" if kind == "gbar" else "load"
    resolve(tao_type, control, problem.kind)  # an unknown solver is refused now, not at the first result
    return _results(problem, control, [(kind, load) for load in loads], tao_type, rtol, prefix, options, on_step)


def _results(problem, control, steps, tao_type, rtol, prefix, options, on_step):
    solver = Solver(problem, control, tao_type, rtol, prefix, options)
    try:
        yield from drive(solver, steps, on_step)
    finally:
        solver.destroy()
