"""Result files: checks of output paths, atomic replacement, JSON, versions and provenance.

Files are written by rank 0 to a temporary name in the same folder and renamed at the end (:class:`atomic_path`),
so a failed or killed run leaves no half-written file. HDF5 files are written by :mod:`roughpetsc.store`.
"""

from contextlib import suppress
import json
import os
import re
import sys
import tempfile

import numpy as np

from ..errors import UserError


def versions():
    """Versions of roughpetsc and of the stack it ran on."""
    from petsc4py import PETSc
    import mpi4py
    import petsc4py
    import scipy

    from .. import __version__

    found = {
        "roughpetsc": __version__,
        "petsc": ".".join(str(v) for v in PETSc.Sys.getVersion()),
        "petsc4py": petsc4py.__version__,
        "mpi4py": mpi4py.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "python": sys.version.split()[0],
    }
    for module in ("pyfftw", "mpi4py_fft", "h5py"):
        with suppress(ImportError, AttributeError):
            found[module] = __import__(module).__version__
    return found


def provenance():
    """Command line, options database and versions of this run."""
    from petsc4py import PETSc

    return {"command": " ".join(sys.argv), "options": dict(PETSc.Options().getAll()), "versions": versions()}


def check_writable(path, option):
    """Fail early, naming the option, if a file cannot be written at ``path``.

    Refused: a folder, a missing folder or one that takes no new file (tried), a file without write permission.
    """
    if os.path.isdir(path):
        raise UserError(f"-{option} {path}: is a folder; give a file name")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise UserError(f"-{option} {path}: the folder {folder} does not exist")
    if os.path.exists(path) and not os.access(path, os.W_OK):
        raise UserError(f"-{option} {path}: the file is not writable")
    try:
        handle, trial = tempfile.mkstemp(prefix=".tmp-", dir=folder)
    except OSError as error:
        raise UserError(f"-{option} {path}: cannot create a file in {folder} ({error.strerror})") from None
    os.close(handle)
    os.remove(trial)


def _same_file(a, b):
    if os.path.exists(a) and os.path.exists(b):
        return os.path.samefile(a, b)
    return os.path.realpath(a) == os.path.realpath(b)


def check_outputs(outputs, overwrite=False, inputs=(), may_exist=()):
    """Refuse, before any work, outputs that would lose a file or cannot be written.

    Parameters
    ----------
    outputs : list of (option, path)
        The files a run will write; empty paths are skipped.
    overwrite : bool
        ``-overwrite``: an existing output file may be replaced.
    inputs : list of (option, path)
        Files the run reads: never an output, even with ``-overwrite``.
    may_exist : iterable of option names
        Outputs that are meant to exist already (a file to resume).
    """
    written = []
    for option, path in outputs:
        if not path:
            continue
        check_writable(path, option)
        for input_option, input_path in inputs:
            if input_path and _same_file(path, input_path):
                raise UserError(f"-{option} {path}: is the input file of -{input_option}; write elsewhere")
        for other_option, other_path in written:
            if _same_file(path, other_path):
                raise UserError(f"-{option} and -{other_option} name the same file {path}")
        written.append((option, path))
        if os.path.exists(path) and not overwrite and option not in may_exist:
            raise UserError(f"-{option} {path}: the file exists; give -overwrite to replace it")


def check_figure_format(path, option):
    """Raise :class:`UserError` naming ``option`` unless matplotlib writes the format of ``path``'s suffix."""
    from matplotlib.backend_bases import FigureCanvasBase

    suffix = os.path.splitext(path)[1].lower().lstrip(".")
    formats = FigureCanvasBase.get_supported_filetypes()
    if suffix not in formats:
        raise UserError(f"-{option} {path}: unknown figure format '{suffix}' (one of {', '.join(sorted(formats))})")


def on_root(comm, action, *args):
    """Run ``action(*args)`` on rank 0 only; its :class:`UserError` is raised on every rank.

    Otherwise the other ranks would wait for ever in their next collective call. Returns the result on rank 0,
    None elsewhere.
    """
    result, message = None, None
    if comm is None or comm.Get_rank() == 0:
        try:
            result = action(*args)
        except UserError as error:
            message = str(error)
    if comm is not None and comm.Get_size() > 1:
        message = comm.bcast(message, root=0)
    if message is not None:
        raise UserError(message)
    return result


def file_mode():
    """The mode of a newly created file, ``0o666`` less the umask (0644 under the usual umask 022)."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


class atomic_path:
    """Context manager giving a temporary path (same folder, same suffix) that replaces ``path`` on success only.

    The file gets the mode of any new file (mkstemp's would be 0600). ``durable``: fsync the file and its folder,
    so a crash leaves the old or the new file, whole. ``deferred``: a list the written temporary joins instead of
    replacing ``path``, for the caller to :meth:`replace` or :meth:`discard`. Failures raise :class:`UserError`.
    """

    def __init__(self, path, durable=False, deferred=None):
        self.path, self.durable, self.deferred = path, durable, deferred
        folder = os.path.dirname(os.path.abspath(path))
        try:
            handle, self.temporary = tempfile.mkstemp(prefix=".tmp-", suffix=os.path.basename(path), dir=folder)
        except OSError as error:
            raise UserError(f"cannot write {path}: {_os_reason(error)}") from None
        os.close(handle)

    def __enter__(self):
        return self.temporary

    def __exit__(self, kind, value, traceback):
        if kind is None:
            try:
                os.chmod(self.temporary, file_mode())
                if self.durable:
                    _fsync(self.temporary)
                if self.deferred is None:
                    self.replace()
                else:
                    self.deferred.append(self)
                return False
            except OSError as error:
                kind, value = type(error), error
        self.discard()
        if issubclass(kind, OSError):  # disk full, permissions changed under the run, ...
            raise UserError(f"cannot write {self.path}: {_os_reason(value)}") from None
        return False

    def replace(self):
        """:meth:`rename`, then :meth:`sync_folder` (done on exit unless ``deferred``, a list it then joins)."""
        self.rename()
        self.sync_folder()

    def rename(self):
        """Rename the written temporary over the file."""
        try:
            os.replace(self.temporary, self.path)
        except OSError as error:
            self.discard()
            raise UserError(f"cannot write {self.path}: {_os_reason(error)}") from None

    def sync_folder(self):
        """If ``durable``, fsync the folder, so that the rename outlives a crash."""
        if self.durable:
            _fsync(os.path.dirname(os.path.abspath(self.path)))

    def discard(self):
        """Remove the temporary, if it is still there."""
        if os.path.exists(self.temporary):
            os.remove(self.temporary)


def _os_reason(error):
    """The system's words for an OSError, also when HDF5 wrapped them in its own long message."""
    found = re.search(r"error message = '([^']+)'", str(error))
    return found.group(1) if found else error.strerror or str(error).splitlines()[0]


def remove_stale_temporaries(path):
    """Delete the temporaries of :class:`atomic_path` for ``path`` a killed run left (no other run may write it)."""
    folder = os.path.dirname(os.path.abspath(path))
    suffix = os.path.basename(path)
    for name in os.listdir(folder):
        if name.startswith(".tmp-") and name.endswith(suffix) and len(name) > len(".tmp-") + len(suffix):
            with suppress(OSError):
                os.remove(os.path.join(folder, name))


def _fsync(path):
    handle = os.open(path, os.O_RDONLY)
    try:
        os.fsync(handle)
    except OSError:  # some file systems cannot fsync a folder
        pass
    finally:
        os.close(handle)


def jsonable(value):
    """``value`` with numpy arrays and scalars as Python lists and numbers, non-finite floats as None (JSON null)."""
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def write_json(path, data, deferred=None):
    """Write ``data`` as indented JSON, atomically; ``deferred``: as for :class:`atomic_path`."""
    with atomic_path(path, deferred=deferred) as temporary:
        with open(temporary, "w") as f:
            json.dump(jsonable(data), f, indent=2)
            f.write("\n")
