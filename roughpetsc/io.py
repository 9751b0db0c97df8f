"""Result files: JSON summaries and HDF5 files that record the options and versions that made them.

Files are written by rank 0 to a temporary name in the same folder and renamed
at the end, so a failed or killed run leaves no half-written file.
"""

import json
import os
import sys
import tempfile

import numpy as np

from .errors import UserError


def versions():
    """Versions of roughpetsc and of the stack it ran on."""
    from petsc4py import PETSc
    import mpi4py
    import petsc4py
    import scipy

    from . import __version__

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
        try:
            found[module] = __import__(module).__version__
        except (ImportError, AttributeError):
            pass
    return found


def provenance():
    """Command line, options database and versions of this run."""
    from petsc4py import PETSc

    return {"command": " ".join(sys.argv), "options": dict(PETSc.Options().getAll()), "versions": versions()}


def check_writable(path, option):
    """Fail early, naming the option, if ``path`` cannot be created."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise UserError(f"-{option}: the folder of {path} does not exist")
    if not os.access(folder, os.W_OK):
        raise UserError(f"-{option}: cannot write into the folder of {path}")


class atomic_path:
    """Context manager giving a temporary path (same folder, same suffix) that replaces ``path`` on success only."""

    def __init__(self, path):
        self.path = path
        folder = os.path.dirname(os.path.abspath(path))
        handle, self.temporary = tempfile.mkstemp(prefix=".tmp-", suffix=os.path.basename(path), dir=folder)
        os.close(handle)

    def __enter__(self):
        return self.temporary

    def __exit__(self, kind, value, traceback):
        if kind is None:
            os.replace(self.temporary, self.path)
        elif os.path.exists(self.temporary):
            os.remove(self.temporary)
        return False


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def write_json(path, data):
    """Write ``data`` as indented JSON, atomically."""
    with atomic_path(path) as temporary:
        with open(temporary, "w") as f:
            json.dump(_jsonable(data), f, indent=2)
            f.write("\n")


def _attribute(value):
    if isinstance(value, (dict, list)):
        return json.dumps(_jsonable(value))
    return "" if value is None else value


def write_h5(path, summary, fields=None, histories=None):
    """Write an HDF5 file: attributes from the summary (nested values as JSON), datasets of fields.

    ``fields`` maps names to whole arrays (e.g. heights, pressure, gap),
    ``histories`` maps step names to residual-history arrays.
    """
    import h5py

    with atomic_path(path) as temporary:
        with h5py.File(temporary, "w") as f:
            for key, value in summary.items():
                if key == "steps":
                    continue
                f.attrs[key] = _attribute(value)
            for index, step in enumerate(summary.get("steps", [])):
                group = f.create_group(f"steps/{index:03d}")
                for key, value in step.items():
                    group.attrs[key] = _attribute(value)
                if histories and index in histories:
                    dataset = group.create_dataset("history", data=histories[index])
                    dataset.attrs["columns"] = "iteration, natural_residual, operator_applications, seconds"
            for name, array in (fields or {}).items():
                f.create_dataset(name, data=array, compression="gzip", compression_opts=1)
