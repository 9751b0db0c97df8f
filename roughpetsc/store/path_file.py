"""The file of a load path (``-mode solve -output``): layout, writer and reader.

Layout::

    /                  attrs: the run's summary (grid, length, E_star, surface, surface_parameters,
                              sqrt_m0h, sqrt_m0p, solver, control, kkt_rtol, boundary, hardness, ranks,
                              command, options, versions; nested values as JSON text) and
                              fields_written_by_every_rank (parallel HDF5, roughpetsc.store)
    /heights           (n0, n1) the whole surface, length units
    /pressure, /gap    (n0, n1) of the last step (unless -output_fields none)
    /steps/NNN         attrs: that step's results (:meth:`roughpetsc.contact.Result.summary` with
                              load_option, load_value; kkt as JSON)
        history        (iterations, 4) iteration, natural KKT residual, operator applications, seconds
        pressure, gap  (n0, n1) with -output_fields all
    /stresses/NN       (-stress_depths) the last step's stresses at the NN-th depth; attrs depth, nu,
                              max_von_mises, max_location (row, column); datasets xx yy zz xy yz xz
                              von_mises (n0, n1), pressure units, tension positive

Every dataset of a name carries the units and description of :data:`DATASET_ATTRIBUTES`.
"""

import numpy as np

from . import attribute, from_attribute, set_attributes, write as write_file, write_distributed

DATASET_ATTRIBUTES = {
    "heights": {"units": "length",
                "description": "surface heights h with zero mean; axis 0 = rows (y), axis 1 = x"},
    "pressure": {"units": "pressure (the units of E_star)",
                 "description": "contact pressure p >= 0 at the nodes of the grid (zero off the contact set)"},
    "gap": {"units": "length",
            "description": "gap g = K p + d - h >= 0 between the deformed surface and the rigid flat (zero in "
                           "contact)"},
    **{name: {"units": "pressure (the units of E_star)",
              "description": f"stress component sigma_{name} (tension positive; z into the body)"}
       for name in ("xx", "yy", "zz", "xy", "yz", "xz")},
    "von_mises": {"units": "pressure (the units of E_star)", "description": "von Mises equivalent stress"},
    "history": {"units": "1, 1, 1, s",
                "description": "per iteration: iteration, natural KKT residual (scale-free), operator applications "
                               "so far, seconds since the start of the solve"},
}
HISTORY_COLUMNS = "iteration, natural_residual, operator_applications, seconds"
FIELD_NAMES = ("pressure", "gap")
STEP_JSON_KEYS = ("kkt",)          # step attributes stored as JSON text


def _field(group, name, array):
    dataset = group.create_dataset(name, data=array, compression="gzip", compression_opts=1)
    dataset.attrs.update(DATASET_ATTRIBUTES.get(name, {}))


def write(path, summary, fields=None, histories=None, step_fields=None, stresses=(), comm=None, first_row=None,
          deferred=None):
    """Write a load path's file (atomically, :func:`roughpetsc.store.write`).

    Parameters
    ----------
    summary : dict
        Root attributes; its ``"steps"`` (a list of step dicts) become ``steps/NNN`` attributes.
    fields : dict of name -> ndarray, optional
        Whole arrays at the root (``heights``, ``pressure``, ``gap``).
    histories : dict of step index -> ndarray (iterations, 4), optional
    step_fields : dict of step index -> {name: ndarray}, optional
        Fields kept per step (``-output_fields all``).
    stresses : sequence of roughpetsc.stresses.DepthStresses
        The last step's subsurface stresses, one per depth.
    comm, first_row :
        With ``first_row``, pressure and gap are this rank's rows from it on, and every rank of ``comm`` calls
        this function (:func:`roughpetsc.store.write_distributed`); ``heights`` is whole.
    deferred : list, optional
        As for :func:`roughpetsc.store.write`.
    """
    distributed = {}
    if first_row is not None:
        shape = fields["heights"].shape
        local = {name: array for name, array in fields.items() if name in FIELD_NAMES}
        distributed.update({name: (array, first_row) for name, array in local.items()})
        for index, arrays in (step_fields or {}).items():
            distributed.update({f"steps/{index:03d}/{name}": (array, first_row) for name, array in arrays.items()})
        fields = {name: array for name, array in fields.items() if name not in FIELD_NAMES}
        step_fields = {}

    def build(f):
        set_attributes(f, {key: value for key, value in summary.items() if key != "steps"})
        f.attrs["fields_written_by_every_rank"] = bool(distributed)
        for index, step in enumerate(summary.get("steps", [])):
            group = f.create_group(f"steps/{index:03d}")
            set_attributes(group, step)
            if histories and index in histories:
                dataset = group.create_dataset("history", data=histories[index])
                dataset.attrs["columns"] = HISTORY_COLUMNS
                dataset.attrs.update(DATASET_ATTRIBUTES["history"])
            for name, array in (step_fields or {}).get(index, {}).items():
                _field(group, name, array)
        for name, array in (fields or {}).items():
            _field(f, name, array)
        for name in distributed:  # created empty; every rank writes its rows
            dataset = f.require_group(name.rpartition("/")[0] or "/").create_dataset(
                name.rpartition("/")[2], shape=shape, dtype="float64")
            dataset.attrs.update(DATASET_ATTRIBUTES.get(name.rpartition("/")[2], {}))
        for index, depth in enumerate(stresses):
            group = f.create_group(f"stresses/{index:02d}")
            group.attrs.update(depth=depth.depth, max_von_mises=depth.max_von_mises,
                               max_location=np.array(depth.max_location))
            for name, array in dict(depth.components, von_mises=depth.von_mises).items():
                _field(group, name, array)

    if distributed:
        write_distributed(path, comm, build, distributed, deferred)
    else:
        write_file(path, build, deferred)


def read(path):
    """A load path's file: ``{"attrs", "heights", "last_fields", "steps"}``, or None if it is not one.

    ``attrs``: the root attributes as stored (JSON as text); ``steps``: ``{"summary", "history", "fields"}`` in
    step order. Raises ``OSError`` if the file cannot be opened as HDF5.
    """
    import h5py

    with h5py.File(path, "r") as f:
        if "heights" not in f or "steps" not in f:
            return None
        steps = []
        for index in range(len(f["steps"])):
            group = f[f"steps/{index:03d}"]
            steps.append({
                "summary": {key: from_attribute(item, STEP_JSON_KEYS, key) for key, item in group.attrs.items()},
                "history": group["history"][()] if "history" in group else np.zeros((0, 4)),
                "fields": {name: group[name][()] for name in FIELD_NAMES if name in group}})
        return {"attrs": dict(f.attrs), "heights": f["heights"][()], "steps": steps,
                "last_fields": {name: f[name][()] for name in FIELD_NAMES if name in f}}


def differs_from(stored, summary, keys):
    """The keys among ``keys`` whose stored root attribute differs from ``summary``'s value (as written)."""
    return [key for key in keys if stored["attrs"].get(key) != attribute(summary[key])]
