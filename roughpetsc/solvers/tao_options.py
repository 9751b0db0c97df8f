"""Options of the solver objects: scoped defaults, ``setFromOptions`` with a clear error, the time limit.

Every TAO object of a solver carries the options prefix its :class:`~roughpetsc.solvers.solver.Solver`
was given (None: the unprefixed command line); everything here reads and writes options under that prefix.
"""

import ctypes
import functools
from contextlib import contextmanager

from petsc4py import PETSc

from ..errors import UserError

# The iteration limit every TAO of the solvers starts with (options may change it): the natural-residual
# test decides, and TAO's own limits (the BNK family stops at 50) would end solves early.
DEFAULT_MAX_IT = 100000


def option_name(name, prefix=None):
    """The option as the user types it: ``-`` + prefix + name."""
    return f"-{prefix or ''}{name}"


def max_seconds(prefix=None):
    """``-solve_max_time``: seconds after which a solve stops with DIVERGED_USER (0: no limit).

    Read once per solver (:func:`~roughpetsc.solvers.registry.make_backend`) and handed to its parts.
    """
    seconds = PETSc.Options(prefix).getReal("solve_max_time", 0.0)
    if not seconds >= 0:
        raise UserError(f"{option_name('solve_max_time', prefix)} must be a non-negative number of seconds, "
                        f"got {seconds}")
    return seconds


@functools.cache
def _petsc_library():
    """The PETSc shared library, through petsc4py's extension module (dlsym searches its dependencies)."""
    return ctypes.CDLL(PETSc.__file__)


def stop_subsolver(tao):
    """Set the reason of ALMM's subsolver to DIVERGED_USER, so that its solve ends at its next convergence test.

    TAO's default test leaves a reason already set. petsc4py 3.18 does not wrap ``TaoALMMGetSubsolver``,
    so it and ``TaoSetConvergedReason`` are called through ctypes.
    """
    library = _petsc_library()
    subsolver = ctypes.c_void_p()
    error = library.TaoALMMGetSubsolver(ctypes.c_void_p(tao.handle), ctypes.byref(subsolver))
    if error == 0:
        error = library.TaoSetConvergedReason(subsolver, ctypes.c_int(int(PETSc.TAO.Reason.DIVERGED_USER)))
    if error != 0:
        raise RuntimeError(f"PETSc error {error} while stopping the ALMM subsolver at the time limit")


def set_from_options(tao, cleanup):
    """``tao.setFromOptions()``; a bad TAO option becomes a :class:`UserError` naming it, after ``cleanup()``."""
    try:
        tao.setFromOptions()
    except PETSc.Error as error:
        cleanup()
        lines = [line.split("]", 1)[-1].strip() for line in str(error).splitlines() if line.strip()]
        raise UserError(f"a solver option was refused by PETSc: {lines[-1]}") from None


@contextmanager
def default_options(defaults, prefix=None, replace=False):
    """Options that apply inside the block unless the user gave them; removed again afterwards.

    The working defaults of one solver object must not stay in the options database, where they
    would become the next object's settings (BNLS's CG made a later BNTR refuse its KSP).

    ``replace=True`` sets them even over a value the user gave, which is restored afterwards (and
    counted as read: the caller has consumed it).
    """
    options = PETSc.Options(prefix)
    given = {name: options.getString(name) for name in defaults if replace and options.hasName(name)}
    inserted = [name for name in defaults if replace or not options.hasName(name)]
    for name in inserted:
        options.setValue(name, defaults[name])
    try:
        yield
    finally:
        for name in inserted:
            options.delValue(name)
        for name, value in given.items():
            options.setValue(name, value)
            options.getString(name)  # a restored value reads as unused otherwise
