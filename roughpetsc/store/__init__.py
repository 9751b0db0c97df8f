"""The one HDF5 store of roughpetsc: one atomic writer, and one schema and one reader per file kind.

File kinds: :mod:`~roughpetsc.store.path_file` (``-mode solve -output``), :mod:`~roughpetsc.store.stats_file`
(``-mode stats -stats_h5``), :mod:`~roughpetsc.store.ensemble_file` (``-mode ensemble -output``). Every file
records the options and versions that made it. Writing is atomic, by :func:`write` (rank 0) or
:func:`write_distributed` (every rank its rows, parallel HDF5); how and why: docs/runtime.md.
"""

from io import BytesIO
import json

import numpy as np

from .outputs import atomic_path, jsonable


def write(path, build, deferred=None):
    """Write an HDF5 file atomically and durably: ``build(h5file)`` fills it in memory first.

    Raises :class:`UserError` naming ``path`` if the file cannot be written.

    Parameters
    ----------
    path : str or os.PathLike
        The file to create or replace.
    build : callable
        Called with an open, empty, writable ``h5py.File``.
    deferred : list, optional
        The temporary joins it instead of replacing ``path`` (:class:`roughpetsc.store.outputs.atomic_path`).
    """
    image = _image(build)
    with atomic_path(path, durable=True, deferred=deferred) as temporary, open(temporary, "wb") as handle:
        handle.write(image.getbuffer())


def _image(build):
    """The HDF5 file that ``build`` writes, in memory."""
    import h5py

    image = BytesIO()
    with h5py.File(image, "w") as f:
        build(f)
    return image


def parallel_hdf5(comm):
    """True when ``comm`` (mpi4py) has several ranks and h5py can write one file from all of them."""
    import h5py

    return comm is not None and comm.Get_size() > 1 and bool(h5py.get_config().mpi)


def write_distributed(path, comm, build, distributed, deferred=None):
    """:func:`write` from every rank of ``comm``, with datasets spread over the ranks.

    Raises :class:`UserError` naming ``path`` on every rank if the file cannot be written.

    Parameters
    ----------
    path, deferred :
        As for :func:`write` (``deferred`` on rank 0).
    comm : mpi4py.MPI.Comm
        Every rank calls this function (:func:`parallel_hdf5` is True).
    build : callable
        Runs on rank 0 and must create each dataset of ``distributed`` empty and uncompressed.
    distributed : dict of name -> (local rows, first row)
        Each rank's block of rows of a dataset, written collectively.
    """
    import h5py

    from ..errors import UserError

    target, temporary, message = None, None, None
    if comm.Get_rank() == 0:
        try:
            image = _image(build)
            target = atomic_path(path, durable=True, deferred=deferred)
            temporary = target.__enter__()
            with open(temporary, "wb") as handle:
                handle.write(image.getbuffer())
        except (UserError, OSError) as error:
            message = str(error) if isinstance(error, UserError) else f"cannot write {path}: {error}"
    temporary, message = comm.bcast((temporary, message), root=0)
    if message is None:
        try:
            with h5py.File(temporary, "r+", driver="mpio", comm=comm) as f:
                for name, (rows, first) in distributed.items():
                    dataset = f[name]
                    with dataset.collective:
                        dataset[first:first + rows.shape[0]] = rows
        except OSError as error:
            message = f"cannot write {path}: {error}"
        messages = comm.allgather(message)
        message = next((m for m in messages if m), None)
    if comm.Get_rank() == 0 and target is not None:
        try:
            failure = (UserError, UserError(message), None) if message else (None, None, None)
            target.__exit__(*failure)
        except UserError as error:
            message = message or str(error)
    message = comm.bcast(message, root=0)
    if message:
        raise UserError(message)


def attribute(value):
    """A value as an HDF5 attribute: dicts and lists as JSON text, None as the empty string."""
    if isinstance(value, (dict, list)):
        return json.dumps(jsonable(value))
    return "" if value is None else value


def from_attribute(value, json_keys=(), key=None):
    """Inverse of :func:`attribute` for one attribute ``key``: numpy scalars as Python, "" as None."""
    if isinstance(value, np.generic):
        value = value.item()
    if key in json_keys:
        return json.loads(value)
    return None if isinstance(value, str) and value == "" else value


def set_attributes(node, mapping):
    """Every ``{name: value}`` of ``mapping`` as an attribute of ``node`` (:func:`attribute` form)."""
    for key, value in mapping.items():
        node.attrs[key] = attribute(value)


def read(path):
    """Any roughpetsc HDF5 file as a flat dict ``{"group/name": value, "@attr": value, "name@attr": value}``."""
    import h5py

    out = {}
    with h5py.File(path, "r") as f:
        for key, value in f.attrs.items():
            out["@" + key] = value

        def visit(name, item):
            if isinstance(item, h5py.Dataset):
                out[name] = item[()]
            for key, value in item.attrs.items():
                out[f"{name}@{key}"] = value

        f.visititems(visit)
    return out
