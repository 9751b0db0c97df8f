"""The record of a solve-mode run as its load steps finish: what ``-output``, ``-output_fields`` and ``-resume`` keep.

The file (:mod:`roughpetsc.store.path_file`) is rewritten atomically after the steps, so an interrupted run
keeps its finished steps, and ``-resume`` takes those of the same problem and loads from the file and starts
the next load from the last saved pressure (an adhesive path: from the gap of its last step taken).
"""

import json
import time

import numpy as np

from . import attribute
from . import outputs as io
from ..errors import UserError
from . import path_file as load_path

OUTPUT_FIELDS = ("all", "last", "none")

# Summary entries that must agree for -resume to take steps from a file.
RESUME_KEYS = ("grid", "length", "E_star", "solver", "control", "kkt_rtol", "boundary", "hardness")


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
    first_row, local_rows : int or None
        None: the fields given to :meth:`add` are whole (rank 0); else this rank's ``local_rows`` rows from
        ``first_row`` on, which every rank writes (:meth:`write` with ``comm``).
    """

    def __init__(self, summary, heights, keep, first_row=None, local_rows=None):
        self.first_row, self.local_rows = first_row, local_rows
        self.summary = summary
        self.heights = heights
        self.keep = keep
        self.steps = []  # JSON-ready summaries of the finished steps
        self.histories = {}
        self.step_fields = {}  # step index -> {"pressure": ..., "gap": ...} (keep == "all")
        self.last_fields = {}
        self.stresses = []  # roughpetsc.stresses.DepthStresses of the last step (-stress_depths)
        self.write_seconds = 0.0
        self.written_at = -np.inf
        self.written = 0  # steps in the files as last written (those taken from a resumed file included)

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

    def write(self, h5_path, json_path, requests, comm=None):
        """Write the files of the steps so far, each atomically, and replace them together; True if they were.

        On rank 0, or with distributed fields on every rank of ``comm`` (the JSON by rank 0). Once a stop was
        requested (``requests``, :class:`roughpetsc.app.interrupts.StopRequests`) no file is replaced.
        """
        start = time.perf_counter()
        distributed = self.first_row is not None
        written = []
        try:
            if h5_path:
                kept = self.last_fields if self.keep != "none" else {}
                load_path.write(h5_path, self.as_summary(), dict(heights=self.heights, **kept), self.histories,
                                self.step_fields, self.stresses, comm=comm if distributed else None,
                                first_row=self.first_row, deferred=written)
            if json_path and (comm is None or comm.Get_rank() == 0):
                io.write_json(json_path, self.as_summary(), deferred=written)
        except BaseException:
            for temporary in written:
                temporary.discard()
            raise
        count = len(self.steps)

        def bookkeeping():
            self.written = count

        replaced = requests.replace_unless_stopped(written, bookkeeping)
        self.written_at = time.perf_counter()
        self.write_seconds = self.written_at - start
        return replaced

    def due(self):
        """True when a checkpoint now keeps the writing under a fifth of the run time (rewrites grow with the steps)."""
        return time.perf_counter() - self.written_at >= 4.0 * self.write_seconds

    def resume_from(self, path, loads, load_option):
        """Take from ``path`` the steps of ``loads`` it solved for the same problem.

        ``loads``: this run's ``(kind, value)`` of ``-load_option``; the saved loads must begin them. Steps are
        taken up to the first that did not converge. Returns ``(pressure, gap)``, whole fields (pressure and
        length units) or None: the pressure to start the next load from (a warm start: the last saved one), and
        the gap of the last step taken, exactly (an adhesive path continues on its branch from it). Raises
        :class:`UserError` for another problem or other loads.
        """
        try:
            stored = load_path.read(path)
        except OSError as error:
            raise UserError(f"-resume: cannot read {path} ({error})") from None
        if stored is None:
            raise UserError(f"-resume: {path} is not a roughpetsc solve output")
        differ = load_path.differs_from(stored, self.summary, RESUME_KEYS)
        if adhesion_law(stored["attrs"].get("adhesion")) != adhesion_law(attribute(self.summary["adhesion"])):
            differ.append("adhesion")
        if stored["heights"].shape != self.heights.shape or not np.array_equal(stored["heights"], self.heights):
            differ.insert(0, "surface")
        if differ:
            raise UserError(f"-resume: {path} was made for another problem (different {', '.join(differ)}); "
                            "give another -output, or the options that made it")
        saved = [(step["summary"].get("load_option"), step["summary"].get("load_value")) for step in stored["steps"]]
        check_continuation(path, saved, loads, load_option)
        rows = slice(None) if self.first_row is None else slice(self.first_row, self.first_row + self.local_rows)
        for step in stored["steps"]:
            summary = step["summary"]
            if not summary.get("converged"):
                break
            fields = [step["fields"][name][rows] if name in step["fields"] else None for name in ("pressure", "gap")]
            self.add(summary, step["history"], *fields)
        taken = len(self.steps)
        every_step_taken = taken == len(stored["steps"])
        if self.keep != "none" and taken and every_step_taken and "pressure" in stored["last_fields"]:
            # Every step taken: the last fields of the file are those of the last step taken.
            self.last_fields = {name: array[rows] for name, array in stored["last_fields"].items()}
        self.written = taken
        last_taken = stored["steps"][taken - 1]["fields"] if taken else {}
        if not last_taken and taken and every_step_taken:
            last_taken = stored["last_fields"]
        pressure = last_taken.get("pressure", stored["last_fields"].get("pressure"))
        return pressure, last_taken.get("gap")


def adhesion_law(text):
    """The adhesion law of a file's ``adhesion`` attribute (JSON), without what a finished cycle added to it; a
    file from before adhesion was recorded had none."""
    law = json.loads(text) if text else {"law": "none"}
    law.pop("dissipated_energy", None)
    return law


def describe_loads(loads):
    """A few of the loads ``(kind, value)`` of a path, exactly as stored: ``pstar 0.1, 0.2, ..., 4 (95 loads)``."""
    values = [repr(float(value)) for _, value in loads]
    shown = values if len(values) <= 6 else values[:3] + ["..."] + values[-2:]
    kinds = sorted({str(kind) for kind, _ in loads})
    return f"{'/'.join(kinds)} {', '.join(shown)} ({len(values)} load{'s' if len(values) != 1 else ''})"


def check_continuation(path, saved, loads, load_option):
    """Refuse a resumed run whose loads ``(kind, value)`` do not begin with the ``saved`` ones."""
    loads = [(kind, float(value)) for kind, value in loads]
    saved = [(kind, float(value)) for kind, value in saved]
    if loads[:len(saved)] == saved:
        return
    if len(loads) < len(saved) and saved[:len(loads)] == loads:
        why = f"this run's -{load_option} stops after {len(loads)} of them"
    else:
        at = next(i for i, (ours, theirs) in enumerate(zip(loads, saved)) if ours != theirs)
        why = (f"this run's -{load_option} differs at step {at + 1}: {loads[at][0]} {loads[at][1]!r} here, "
               f"{saved[at][0]} {saved[at][1]!r} in the file")
    raise UserError(f"-resume: {path} holds {len(saved)} saved step(s), {describe_loads(saved)}, and {why}; "
                    "resuming would lose saved steps. Give loads that begin with the saved ones (a longer list "
                    "extends the path), or another -output")
