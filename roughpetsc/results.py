"""The record of a solve-mode run as its load steps finish: what ``-output``, ``-output_fields`` and ``-resume`` keep.

A load path is written to its HDF5 file after its steps (atomically, see
:func:`roughpetsc.io.write_h5`), so a run interrupted by Ctrl-C, a batch time
limit or a step that ran out of ``-solve_max_time`` keeps its finished steps,
and ``-resume`` continues it: the steps recorded for the same problem and the
same loads are taken from the file, the next load starts from the last saved
pressure field.

Layout: root attributes from the summary (grid, length, E_star, solver,
surface_parameters, options, versions, ...); datasets ``heights`` and, unless
``-output_fields none``, ``pressure`` and ``gap`` of the last step; group
``steps/NNN`` per step with its results as attributes, its residual
``history`` and, with ``-output_fields all``, its ``pressure`` and ``gap``.
"""

import json
import time

import numpy as np

from . import io
from .errors import UserError

OUTPUT_FIELDS = ("all", "last", "none")

# Attributes of every dataset of that name.
DATASET_ATTRIBUTES = {
    "heights": {"units": "length",
                "description": "surface heights h with zero mean; axis 0 = rows (y), axis 1 = x"},
    "pressure": {"units": "pressure (the units of E_star)",
                 "description": "contact pressure p >= 0 at the nodes of the grid (zero off the contact set)"},
    "gap": {"units": "length",
            "description": "gap g = K p + d - h >= 0 between the deformed surface and the rigid flat (zero in "
                           "contact)"},
    "history": {"units": "1, 1, 1, s",
                "description": "per iteration: iteration, natural KKT residual (scale-free), operator applications "
                               "so far, seconds since the start of the solve"},
}

# Summary entries that must agree for -resume to take steps from a file.
RESUME_KEYS = ("grid", "length", "E_star", "solver", "control", "kkt_rtol")


def _from_attribute(key, value):
    """Inverse of :func:`roughpetsc.io._attribute` for a step's attributes."""
    if isinstance(value, np.generic):
        value = value.item()
    if key == "kkt":
        return json.loads(value)
    return None if isinstance(value, str) and value == "" else value


class PathRecord:
    """The steps of a load path as they finish, kept on rank 0 for the output files.

    Parameters
    ----------
    summary : dict
        Everything but ``steps`` of the JSON summary (JSON-ready).
    heights : ndarray (n0, n1)
        The whole surface, length units.
    keep : one of OUTPUT_FIELDS
        ``-output_fields``: pressure and gap of every step, of the last step, or none.
    """

    def __init__(self, summary, heights, keep):
        self.summary = summary
        self.heights = heights
        self.keep = keep
        self.steps = []  # JSON-ready summaries of the finished steps
        self.histories = {}
        self.step_fields = {}  # step index -> {"pressure": ..., "gap": ...} (keep == "all")
        self.last_fields = {}
        self.write_seconds = 0.0
        self.written_at = -np.inf

    def add(self, step, history, pressure=None, gap=None):
        """Record a finished step: its summary, residual history and (whole) fields, pressure and length units."""
        index = len(self.steps)
        self.steps.append(step)
        self.histories[index] = history
        if pressure is not None:  # the last fields are kept for -plot even with -output_fields none
            self.last_fields = {"pressure": pressure, "gap": gap}
            if self.keep == "all":
                self.step_fields[index] = self.last_fields

    def as_summary(self):
        return dict(self.summary, steps=self.steps)

    def write(self, h5_path, json_path=None):
        """Write the files of the steps so far (rank 0), each atomically."""
        start = time.perf_counter()
        if h5_path:
            fields = dict(heights=self.heights, **(self.last_fields if self.keep != "none" else {}))
            io.write_h5(h5_path, self.as_summary(), fields, self.histories, self.step_fields, DATASET_ATTRIBUTES)
        if json_path:
            io.write_json(json_path, self.as_summary())
        self.written_at = time.perf_counter()
        self.write_seconds = self.written_at - start

    def due(self):
        """True when a checkpoint after this step keeps the writing under a fifth of the run time.

        A rewrite costs more as the steps accumulate (``-output_fields all``);
        between two writes at least four times the last write's duration passes.
        """
        return time.perf_counter() - self.written_at >= 4.0 * self.write_seconds

    def resume_from(self, path, loads):
        """Take from ``path`` the leading steps of ``loads`` it solved for the same problem.

        ``loads`` is the list of ``(option, value)`` of this run. A step is
        taken if it converged and its load equals the load of this run at the
        same position; the first other step and all after it are solved again.
        Returns the whole pressure field (pressure units) to start the next
        load from (that of the last step taken, else the last one saved), or
        None.

        Raises :class:`UserError` if the file records another problem
        (surface, grid, E*, solver, control or tolerance).
        """
        import h5py

        try:
            f = h5py.File(path, "r")
        except OSError as error:
            raise UserError(f"-resume: cannot read {path} ({error})") from None
        with f:
            if "heights" not in f or "steps" not in f:
                raise UserError(f"-resume: {path} is not a roughpetsc solve output")
            # Compared as written: lists as their JSON text, numbers and strings as they are.
            differ = [key for key in RESUME_KEYS if f.attrs.get(key) != io._attribute(self.summary[key])]
            if f["heights"].shape != self.heights.shape or not np.array_equal(f["heights"][()], self.heights):
                differ.insert(0, "surface")
            if differ:
                raise UserError(f"-resume: {path} was made for another problem (different {', '.join(differ)}); "
                                "give another -output, or the options that made it")
            start = f["pressure"][()] if "pressure" in f else None
            for index, (option, value) in enumerate(loads):
                group = f.get(f"steps/{index:03d}")
                if group is None:
                    break
                step = {key: _from_attribute(key, item) for key, item in group.attrs.items()}
                if not (step.get("converged") and step.get("load_option") == option
                        and step.get("load_value") == value):
                    break
                fields = {name: group[name][()] for name in ("pressure", "gap") if name in group}
                self.add(step, group["history"][()] if "history" in group else np.zeros((0, 4)),
                         fields.get("pressure"), fields.get("gap"))
                if "pressure" in fields:
                    start = fields["pressure"]
            if self.keep != "none" and self.steps and len(self.steps) == len(f["steps"]) and "pressure" in f:
                # Every step taken: the last fields of the file are those of the last step taken.
                self.last_fields = {name: f[name][()] for name in ("pressure", "gap")}
        return start
