"""Our options in PETSc's options database: help text, typed reads with clear errors, unused-option check."""

import ctypes
import difflib

from petsc4py import PETSc

from ..errors import UserError
from ..solvers.options import FINALIZE_OPTIONS, petsc_library, read_late, unused_options
from ..solvers.stopping import read_option
from ..contact.loads import LIST_FILE_PREFIX, parse_reals

# Prefixes of options that PETSc objects or PETSc itself read.
PETSC_PREFIXES = ("tao_", "ksp_", "pc_", "mat_", "vec_", "snes_", "log", "options_", "malloc", "info", "help",
                  "version", "fp_trap", "on_error", "viewer", "eps_", "st_", "bv_", "ds_", "rg_", "svd_",
                  "memory_", "objects_", "check_pointer", "no_signal_handler", "python", "skip_petscrc",
                  "history", "use_gpu", "device_", "petsc")


# petsc4py 3.18 reads a string option into a buffer of this many bytes: longer values come back cut.
PETSC4PY_STRING_BUFFER = 1024


class Reader:
    """``petsc4py.PETSc.Options``'s getters naming the option on bad values; strings whole, lists by :meth:`reals`."""

    def __init__(self, database=None):
        self.database = database or PETSc.Options()

    def getReal(self, name, default):
        return read_option(self.database, "Real", name, default)

    def getInt(self, name, default):
        return read_option(self.database, "Int", name, default)

    def getString(self, name, default):
        """The value of ``-name`` as given (any length), or ``default`` if the option is absent."""
        text = self.database.getString(name, default)
        return whole_string(name, text, self.database.prefix) if self.database.hasName(name) else text

    def getBool(self, name, default):
        return read_option(self.database, "Bool", name, default)

    def hasName(self, name):
        return self.database.hasName(name)

    def reals(self, name):
        """The list of reals of ``-name`` (:func:`parse_reals`), or None if the option is absent."""
        if not self.database.hasName(name):
            return None
        return parse_reals(self.getString(name, ""), name)


def whole_string(name, text, prefix=None):
    """``text``, the value of ``-name`` (options prefix ``prefix``) as petsc4py read it, completed if cut.

    A value of petsc4py's 1023 characters is read again through ``PetscOptionsGetString`` with a buffer long
    enough; where the PETSc library cannot be called, it is refused rather than used cut.
    """
    if text is None or len(text.encode()) < PETSC4PY_STRING_BUFFER - 1:
        return text
    library, why = petsc_library()
    if library is None:
        raise UserError(f"-{name}: a value of {PETSC4PY_STRING_BUFFER - 1} characters or more cannot be read "
                        f"whole here ({why}); give a list in a file, -{name} {LIST_FILE_PREFIX}FILE")
    size = 4 * PETSC4PY_STRING_BUFFER
    while True:
        buffer = ctypes.create_string_buffer(size)
        found = ctypes.c_int(0)  # PetscBool
        if library.PetscOptionsGetString(None, prefix.encode() if prefix else None, ("-" + name).encode(), buffer,
                                         ctypes.c_size_t(size), ctypes.byref(found)):
            raise UserError(f"-{name}: PETSc could not read the value")
        value = buffer.value.decode()
        if len(buffer.value) < size - 1:
            return value
        size *= 4


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


def check_values_given(defaults):
    """Refuse an option of ours given without a value, naming it.

    ``defaults``: our option names and defaults. PETSc's getters would silently return the default for an
    option given without a value (``-gbar`` alone, ``-output -json x``); only a bool option stands alone.
    """
    bare = [name for name, value in PETSc.Options().getAll().items()
            if name in defaults and value is None and not isinstance(defaults[name], bool)]
    if len(bare) == 1:
        name = bare[0]
        example = defaults[name] if defaults[name] != "" else "VALUE"
        raise UserError(f"-{name} was given without a value; give one (-{name} {example}) or leave the option out")
    if bare:
        raise UserError(f"{', '.join('-' + name for name in bare)} were given without a value; give each one "
                        "or leave them out")


def check_unused(ignore=(), final=True, unusable=()):
    """Raise :class:`UserError` if an option was given that nothing used (a misspelling, say).

    With ``final=False`` (before a solve) options PETSc reads only during or after a solve (:func:`read_late`) are
    skipped. ``unusable``: options read but of no use to this run, reported like the unused ones.
    """
    unused = unused_options()
    if unused is None:  # cannot be checked here: unused_options has said so
        return
    unused = list(unused) + [name for name in unusable if name not in unused]
    left = [name for name in unused
            if name not in ignore and name not in FINALIZE_OPTIONS and (final or not read_late(name))]
    if left:
        raise UserError("option(s) given but not used by this run: " + ", ".join("-" + n for n in left)
                        + " (misspelled? -help lists the options)")
