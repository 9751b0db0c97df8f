"""Options of the solver objects under their prefix: scoped defaults, ``setFromOptions`` with a clear error."""

import ctypes
import ctypes.util
import functools
import glob
import os
import re
import warnings
from contextlib import contextmanager

from petsc4py import PETSc

from ..errors import UserError
from ..parallel import destroyed_at_exit


@functools.cache
def _petsc_library():
    """The PETSc shared library, through petsc4py's extension module (dlsym searches its dependencies)."""
    return ctypes.CDLL(PETSc.__file__)


def stop_subsolver(tao):
    """Set the reason of ALMM's subsolver to DIVERGED_USER, so that its solve ends at its next convergence test.

    petsc4py 3.18 does not wrap ``TaoALMMGetSubsolver``: ctypes.
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
        raise UserError(f"{_options_holding(lines[-1]) or 'a solver option'} was refused by PETSc: "
                        f"{lines[-1]}") from None


def _options_holding(message):
    """The options (``-name``, comma-separated) whose value is the one PETSc's ``message`` quotes, or ''.

    PETSc's message on an unreadable value quotes the value but not the option that held it.
    """
    quoted = re.search(r"Input string (.*) has no|Unknown logical value: (.*)$", message)
    if quoted is None:
        return ""
    value = quoted.group(1) if quoted.group(1) is not None else quoted.group(2)
    return ", ".join("-" + name for name, given in PETSc.Options().getAll().items() if given == value)


@contextmanager
def default_options(defaults, prefix=None, replace=False):
    """Options that apply inside the block unless the user gave them; removed again afterwards.

    Left in the database they would become the next object's settings (BNLS's CG made a later BNTR refuse
    its KSP). ``replace=True`` sets them over a value the user gave, restored afterwards (counted as read).
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


def _library_candidates():
    """Paths where the PETSc library that petsc4py uses may be: the loaded one first."""
    try:  # Linux: the library this process has loaded
        with open("/proc/self/maps") as maps:
            yield from (line.split()[-1] for line in maps if "libpetsc" in line and ".so" in line)
    except OSError:
        pass
    import petsc4py

    config = petsc4py.get_config()  # the PETSc petsc4py was built against (macOS, BSD, Windows)
    folder = os.path.join(config.get("PETSC_DIR", ""), config.get("PETSC_ARCH", "") or "", "lib")
    yield from sorted(glob.glob(os.path.join(folder, "libpetsc*.*")))
    found = ctypes.util.find_library("petsc")
    if found:
        yield found


PROBE_OPTION = "roughpetsc_options_probe"


def _is_this_database(library):
    """True if ``library`` holds the options database petsc4py writes to (and not another copy of PETSc)."""
    database = PETSc.Options()
    database.setValue(PROBE_OPTION, "1")
    try:
        found = ctypes.c_int(0)  # PetscBool
        if library.PetscOptionsHasName(None, None, ("-" + PROBE_OPTION).encode(), ctypes.byref(found)):
            return False
        return bool(found.value)
    finally:
        database.delValue(PROBE_OPTION)


@functools.lru_cache(maxsize=1)
def petsc_library():
    """``(ctypes handle of the PETSc library in use, None)``, or ``(None, why it was not found)``.

    petsc4py 3.18 does not expose PetscOptionsLeftGet, which the check of unused options needs.
    """
    tried = []
    for path in _library_candidates():
        try:
            library = ctypes.CDLL(path)
        except OSError:
            tried.append(path)
            continue
        if hasattr(library, "PetscOptionsLeftGet") and _is_this_database(library):
            return library, None
        tried.append(path)
    return None, ("the PETSc library petsc4py uses was not found" + (f" (tried {', '.join(tried)})" if tried else "")
                  + "; petsc4py itself cannot list the options nothing read")


def unused_options():
    """Names of options in the database that nothing has read so far (PetscOptionsLeftGet).

    None, with a :class:`RuntimeWarning` saying why, if this platform's PETSc cannot be asked.
    """
    library, why = petsc_library()
    if library is None:
        warnings.warn(f"misspelled options cannot be detected: {why}", RuntimeWarning, stacklevel=2)
        return None
    count = ctypes.c_int32() if PETSc.IntType().itemsize == 4 else ctypes.c_int64()
    names = ctypes.POINTER(ctypes.c_char_p)()
    values = ctypes.POINTER(ctypes.c_char_p)()
    if library.PetscOptionsLeftGet(None, ctypes.byref(count), ctypes.byref(names), ctypes.byref(values)):
        warnings.warn("misspelled options cannot be detected: PetscOptionsLeftGet failed", RuntimeWarning,
                      stacklevel=2)
        return None
    left = [names[i].decode() for i in range(count.value)]
    library.PetscOptionsLeftRestore(None, ctypes.byref(count), ctypes.byref(names), ctypes.byref(values))
    return left


# Read by PetscFinalize, after any check of ours can run.
FINALIZE_OPTIONS = ("options_left", "options_view")


def read_late(name):
    """True for options PETSc reads during or after a solve (viewers, converged reasons): the early check skips them."""
    return "view" in name or "converged_reason" in name


# Options of the parts of a TAO that a solver never runs (its line search, its KSP and PC, another TAO type's):
# PETSc reads them into the objects every TAO creates, so they count as used although nothing uses them.
PARTS_UNUSED_BY_PYTHON_TAO = re.compile(
    r"^(tao_ls_|tao_ksp_|tao_pc_|ksp_|pc_|tao_(bnk|bqnk|bncg|bqnls|blmvm|lmvm|almm|gpcg|tron|bnls|bntr|bntl|nls|ntr|"
    r"ntl|owlqn|bmrm|pounders|brgn|admm|ipm|pdipm|cg|nm|lcl)_|tao_subset_type)")


def given_but_unusable(pattern, prefix=None):
    """The options given (with ``prefix``) whose names match ``pattern`` after the prefix: read, never used."""
    prefix = prefix or ""
    return [name for name in PETSc.Options().getAll()
            if name.startswith(prefix) and pattern.match(name[len(prefix):])]


def _option_text(value):
    """An option value as PETSc's database holds it (booleans as true/false, sequences comma-separated)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ",".join(_option_text(item) for item in value)
    return str(value)


class SolverOptions:
    """The options of one solver: set under its prefix for its lifetime, read by its objects, then removed.

    As the options managers of dolfinx and Firedrake: ``options`` (names without dash or prefix) go into
    PETSc's database under ``prefix``; :meth:`destroy` removes them and restores what was there. Without a
    prefix, options given here get one of their own (``rp<id>_``), so that they never leak.
    """

    def __init__(self, prefix=None, options=None):
        options = dict(options or {})
        if options and prefix is None:
            prefix = f"rp{id(self):x}_"
        self.prefix = prefix
        self.given = {}
        self.replaced = {}
        database = PETSc.Options(prefix)
        for name, value in options.items():
            name = name.lstrip("-")
            if database.hasName(name):
                self.replaced[name] = database.getString(name)
            database.setValue(name, _option_text(value))
            self.given[name] = value

    def get(self, name, default=None):
        """The value of ``name`` under the prefix (given here or in the database), as a string, or ``default``."""
        database = PETSc.Options(self.prefix)
        return database.getString(name) if database.hasName(name) else default

    def unused(self, late=False):
        """The options given here that nothing has read so far (``late``: also those read only during a solve)."""
        left = unused_options()
        if left is None:
            return []
        prefix = self.prefix or ""
        return [name for name in self.given
                if prefix + name in left and (late or not read_late(prefix + name))]

    def destroy(self):
        database = PETSc.Options(self.prefix)
        for name in self.given:
            database.delValue(name)
        for name, value in self.replaced.items():
            database.setValue(name, value)
        self.given, self.replaced = {}, {}


def tao_with_callbacks(comm, prefix=None):
    """A new TAO on ``comm`` under ``prefix``, for Python callbacks: destroyed at exit if the script did not."""
    tao = destroyed_at_exit(PETSc.TAO().create(comm))
    tao.setOptionsPrefix(prefix)
    return tao


def python_tao(comm, context, prefix=None):
    """A TAO of type ``python`` around ``context`` (Polonsky-Keer, the gap CG), set from the options under ``prefix``.

    ``-tao_type`` names the backend, so this TAO reads ``python`` instead. A value the context refused in its
    ``setFromOptions`` (its ``option_error``) is raised here, once PETSc's options block is closed.
    """
    from .stopping import DEFAULT_MAX_IT

    tao = tao_with_callbacks(comm, prefix)
    tao.setType(PETSc.TAO.Type.PYTHON)
    tao.setPythonContext(context)
    tao.setMaximumIterations(DEFAULT_MAX_IT)

    def cleanup():
        tao.destroy()
        context.destroy()

    with default_options({"tao_type": PETSc.TAO.Type.PYTHON}, prefix, replace=True):
        set_from_options(tao, cleanup)
    error = getattr(context, "option_error", None)
    if error is not None:
        cleanup()
        raise error
    return tao
