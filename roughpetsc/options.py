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
        try:
            values = [float(item) for item in text.split(",") if item.strip()]
        except ValueError:
            raise UserError(f"-{name}: expected comma-separated numbers, got '{text}'") from None
        if not values:
            raise UserError(f"-{name}: the list is empty")
        return values

    # petsc4py.PETSc.Options-like interface for modules that expect it
    getReal = real
    getInt = int
    getString = string
    getBool = bool

    def hasName(self, name):
        return self.has(name)


def format_help(title, option_table):
    """Lines of -help for a table of ``(name, default, help)``."""
    lines = [title]
    for name, default, text in option_table:
        lines.append(f"  -{name} <{default}>: {text}")
    return "\n".join(lines)


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


def check_unused(ignore=()):
    """Raise :class:`UserError` if an option was given that nothing used (a misspelling, say)."""
    left = [name for name in unused_options() if name not in ignore]
    if left:
        raise UserError("option(s) given but not used by this run: " + ", ".join("-" + n for n in left)
                        + " (misspelled? -help lists the options)")
