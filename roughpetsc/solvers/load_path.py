"""Results along a list of loads, through one warm-started :class:`~roughpetsc.solvers.solver.Solver`."""

from ..errors import ParameterError
from .registry import resolve
from .solver import Solver


def load_path(problem, pstars=None, pbars=None, gbars=None, tao_type=None, rtol=1e-8, prefix=None):
    """A generator of :class:`~roughpetsc.contact.Result` along the loads, in the order given.

    Each solve starts from the previous solutions (the load-path predictor of
    :class:`~roughpetsc.solvers.continuation.LoadContinuation`), as the load history (7.11) of the
    dissertation is meant to be solved. The Solver is made at the first result and destroyed when the
    generator ends or is closed (``close()``, or garbage collection of an unfinished generator).

    Parameters
    ----------
    problem : ContactProblem
    pstars, pbars, gbars : sequence of float
        Exactly one: the loads as p* = pbar / sqrt(m0^p), as mean pressures, or as mean gaps
        (displacement control).
    tao_type, rtol, prefix :
        As for :class:`~roughpetsc.solvers.solver.Solver`.

    Examples
    --------
    >>> for result in load_path(problem, pstars=[0.1, 0.2, 0.4]):  # doctest: +SKIP
    ...     print(result.pstar, result.A)
    """
    given = {name: loads for name, loads in (("pstar", pstars), ("pbar", pbars), ("gbar", gbars))
             if loads is not None}
    if len(given) != 1:
        raise ParameterError("pstars", "give exactly one of pstars, pbars, gbars, got "
                                       f"{len(given) or 'none'}")
    (name, loads), = given.items()
    control = "displacement" if name == "gbar" else "load"
    resolve(tao_type, control)  # an unknown solver is refused now, not at the first result
    return _results(problem, control, name, list(loads), tao_type, rtol, prefix)


def _results(problem, control, name, loads, tao_type, rtol, prefix):
    solver = Solver(problem, control, tao_type, rtol, prefix)
    try:
        for load in loads:
            yield solver.solve(**{name: load})
    finally:
        solver.destroy()
