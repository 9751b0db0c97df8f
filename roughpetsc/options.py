"""Our options in PETSc's options database: help text, typed reads with clear errors, unused-option check."""

import ctypes
import difflib

from petsc4py import PETSc

from .errors import UserError

# Prefixes of options that PETSc objects or PETSc itself read.
PETSC_PREFIXES = ("tao_", "ksp_", "pc_", "mat_", "vec_", "snes_", "log", "options_", "malloc", "info", "help",
                  "version", "fp_trap", "on_error", "viewer", "eps_", "st_", "bv_", "ds_", "rg_", "svd_",
                  "memory_", "objects_", "check_pointer", "no_signal_handler", "python", "skip_petscrc",
                  "history", "use_gpu", "device_", "petsc")


class Reader:
    """Typed reads from the options database that name the option on bad values."""

    def __init__(self, database=None):
        self.database = database or PETSc.Options()

    def _get(self, getter, name, default):
        try:
            return getter(name, default)
        except PETSc.Error:
            raise UserError(f"-{name}: cannot read the value '{self.database.getString(name, '')}'") from None

    def real(self, name, default):
        return self._get(self.database.getReal, name, default)

    def int(self, name, default):
        return self._get(self.database.getInt, name, default)

    def string(self, name, default):
        return self._get(self.database.getString, name, default)

    def bool(self, name, default):
        return self._get(self.database.getBool, name, default)

    def has(self, name):
        return self.database.hasName(name)

    def reals(self, name):
        """A comma-separated list of reals, or None if the option is absent."""
        if not self.database.hasName(name):
            return None
        text = self.database.getString(name, "")
        if not text.strip():
            raise UserError(f"-{name}: the list is empty")
        items = text.split(",")
        if not all(item.strip() for item in items):  # '0.5,,1' or a trailing comma: a value was left out
            raise UserError(f"-{name}: empty item in '{text}' (give comma-separated numbers, e.g. 0.1,0.5,1)")
        try:
            return [float(item) for item in items]
        except ValueError:
            raise UserError(f"-{name}: expected comma-separated numbers, got '{text}'") from None

    # petsc4py.PETSc.Options-like interface for modules that expect it
    getReal = real
    getInt = int
    getString = string
    getBool = bool

    def hasName(self, name):
        return self.has(name)


# TAO options renamed in PETSc 3.21, and their names in older releases: a command written for a current
# PETSc (-tao_monitor_solution draw) works here too.
RENAMED_TAO_OPTIONS = {
    "tao_monitor_solution": "tao_view_solution", "tao_monitor_gradient": "tao_view_gradient",
    "tao_monitor_step": "tao_view_stepdirection", "tao_monitor_residual": "tao_view_residual",
    "tao_monitor_solution_draw": "tao_draw_solution", "tao_monitor_gradient_draw": "tao_draw_gradient",
    "tao_monitor_step_draw": "tao_draw_step", "tao_monitor_short": "tao_smonitor",
    "tao_monitor_constraint_norm": "tao_cmonitor", "tao_monitor_globalization": "tao_gmonitor",
}


# The old -tao_view_* options draw through options of their own ("draw" would name a file).
DRAW_OF_OLD_VIEW = {"tao_view_solution": "tao_draw_solution", "tao_view_gradient": "tao_draw_gradient",
                    "tao_view_stepdirection": "tao_draw_step"}


def _old_form(old, value):
    """The old option name and value for a new-style viewer value (``ascii``, ``ascii:FILE``, ``draw``)."""
    value = value or ""
    if old not in DRAW_OF_OLD_VIEW and not old.startswith("tao_view_"):
        return old, value
    if value.startswith("draw") and old in DRAW_OF_OLD_VIEW:
        return DRAW_OF_OLD_VIEW[old], ""
    # A bare "ascii" would name a file here; "ascii:FILE" works as it is.
    return old, "" if value in ("ascii", "stdout") else value


def translate_renamed_options():
    """On PETSc < 3.21, give each renamed TAO option (any prefix) its old name in the options database."""
    if PETSc.Sys.getVersion() >= (3, 21, 0):
        return
    database = PETSc.Options()
    for name, value in database.getAll().items():
        for new, old in RENAMED_TAO_OPTIONS.items():
            if name == new or name.endswith("_" + new):
                old, value = _old_form(old, value)
                database.delValue(name)
                database.setValue(name[: len(name) - len(new)] + old, value)
                break


def check_names(known_names):
    """Reject options that are neither ours nor PETSc's, with a close-match suggestion."""
    for name in PETSc.Options().getAll():
        if name in known_names or name.startswith(PETSC_PREFIXES):
            continue
        guess = difflib.get_close_matches(name, known_names, n=1)
        hint = f" (did you mean -{guess[0]}?)" if guess else ""
        raise UserError(f"unknown option -{name}{hint}; -help lists the options")


def _petsc_library():
    with open("/proc/self/maps") as maps:
        for line in maps:
            if "libpetsc" in line and ".so" in line:
                return ctypes.CDLL(line.split()[-1])
    return None


def unused_options():
    """Names of options in the database that nothing has read so far (PetscOptionsLeftGet)."""
    library = _petsc_library()
    if library is None:
        return []
    count = ctypes.c_int32() if PETSc.IntType().itemsize == 4 else ctypes.c_int64()
    names = ctypes.POINTER(ctypes.c_char_p)()
    values = ctypes.POINTER(ctypes.c_char_p)()
    if library.PetscOptionsLeftGet(None, ctypes.byref(count), ctypes.byref(names), ctypes.byref(values)):
        return []
    left = [names[i].decode() for i in range(count.value)]
    library.PetscOptionsLeftRestore(None, ctypes.byref(count), ctypes.byref(names), ctypes.byref(values))
    return left


# Read by PetscFinalize, after any check of ours can run.
FINALIZE_OPTIONS = ("options_left", "options_view")


def read_late(name):
    """True for options PETSc reads during or after a solve (viewers, converged reasons): the early check skips them."""
    return "view" in name or "converged_reason" in name


def check_unused(ignore=(), final=True):
    """Raise :class:`UserError` if an option was given that nothing used (a misspelling, say).

    With ``final=False`` (before a solve) options that PETSc reads only during
    or after the solve (:func:`read_late`) are skipped, so a misspelling fails
    before the work and a late option is checked by the final call after it.
    """
    left = [name for name in unused_options()
            if name not in ignore and name not in FINALIZE_OPTIONS and (final or not read_late(name))]
    if left:
        raise UserError("option(s) given but not used by this run: " + ", ".join("-" + n for n in left)
                        + " (misspelled? -help lists the options)")
