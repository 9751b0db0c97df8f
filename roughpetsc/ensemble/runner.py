"""The run of ``-mode ensemble``: groups of ranks solve whole surfaces; world rank 0 keeps the file.

How groups, surfaces and the file fit together: docs/runtime.md, "Ensembles over ranks".
"""

import json
import os
import sys
import time
import traceback

import numpy as np

from ..app.terminal import printer
from ..store import outputs as io
from ..errors import UserError
from ..surface.seeds import RULE as SEED_RULE, surface_seed
from ..store import ensemble_file
from ..surface.moments import surface_moments
from . import settings as ensemble_settings
from .scheduler import IDLE_SLEEP, TAG_NEXT, TAG_RECORD, WorkCounter
from .statistics import compute_models, step_statistics


def probe_solver(s):
    """Build the solver once on a tiny rank-local problem, so that -tao_type and every TAO option are read before
    any work (``check_unused``); the solver's name."""
    from petsc4py import PETSc

    from ..contact.problem import ContactProblem
    from ..solvers import Solver
    from ..surface.grid import Grid
    from ..surface.generators import wave

    grid = Grid(2, 8, 0.25, 1.0)
    problem = ContactProblem(grid, wave(grid, 1.0, 1.0), s.E_star, PETSc.COMM_SELF, 1, "FFTW_ESTIMATE")
    try:
        solver = Solver(problem, "load", s.tao_type, s.rtol)
        name = solver.name
        solver.destroy()
    finally:
        problem.destroy()
    return name


def share_fftw_wisdom(comm, group, s, stored):
    """Make every rank, in this run and in any resumed run, use the same FFTW plans.

    FFTW_MEASURE picks plans by timing, and different plans round differently (1e-13 in g*). Group 0 plans the
    grid once (from the file's wisdom, if any) and every other rank imports world rank 0's wisdom. Returns the
    wisdom (base64 JSON) to store in the file.
    """
    import pyfftw
    from petsc4py import PETSc

    from ..contact.problem import ContactProblem
    from ..fft.plans import decode_wisdom, encode_wisdom
    from ..surface.generators import wave

    stored = comm.bcast(stored, root=0)
    if stored:
        pyfftw.forget_wisdom()
        pyfftw.import_wisdom(decode_wisdom(stored))
    if comm.Get_rank() < group.Get_size():       # group 0
        grid = s.grid
        problem = ContactProblem(grid, wave(grid, 1.0, grid.l1), s.E_star, PETSc.Comm(group), s.threads,
                                 s.effort)
        problem.destroy()
    wisdom = comm.bcast(encode_wisdom(pyfftw.export_wisdom()) if comm.Get_rank() == 0 else None, root=0)
    if comm.Get_rank() != 0:
        pyfftw.forget_wisdom()
        pyfftw.import_wisdom(decode_wisdom(wisdom))
    return wisdom


def solve_surface(reader, s, index, seed, group, run_id, between_steps):
    """Solve one surface along the loads on the group; the record of :mod:`roughpetsc.store.ensemble_file` on the
    leader, None on the other ranks."""
    from petsc4py import PETSc

    from ..app import surface_options
    from ..contact.problem import ContactProblem
    from ..solvers import Solver, drive

    start = time.perf_counter()
    grid, heights = surface_options.from_options(reader, seed=seed)
    problem = ContactProblem(grid, heights, s.E_star, PETSc.Comm(group), s.threads, s.effort)
    solver = None
    try:
        solver = Solver(problem, "load", s.tao_type, s.rtol)
        rows, reasons = [], []

        def keep(index, kind, value, result):
            rows.append(ensemble_file.step_row(result))
            reasons.append(str(result.reason))
            between_steps()

        for _ in drive(solver, [("pstar", float(pstar)) for pstar in s.loads], on_step=keep):
            pass
    finally:
        if solver is not None:
            solver.destroy()
        problem.destroy()
    if group.Get_rank() != 0:
        return None
    steps = ensemble_file.steps_table(rows)
    moments = surface_moments(grid, heights, s.E_star, finite_differences=True)
    surface = {name: float(moments[name]) for name in ensemble_file.SURFACE_FIELDS if name in moments}
    surface.update(index=index, seed=seed, sqrt_m0h=float(problem.sqrt_m0h), sqrt_m0p=float(problem.sqrt_m0p),
                   converged_steps=int(steps["converged"].sum()), run=run_id,
                   time_s=time.perf_counter() - start)
    return {"surface": surface, "steps": steps, "reason": reasons}


def _duration(seconds):
    """A duration for the progress lines: 42s, 3m07s, 2h05m."""
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds}s"
    if seconds < 3600:
        return f"{seconds // 60}m{seconds % 60:02d}s"
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m"


class Ensemble:
    """State of one ensemble run on every rank; the file and the progress on world rank 0."""

    def __init__(self, reader, comm, s, config):
        self.started = time.perf_counter()
        self.reader, self.s, self.config = reader, s, config
        self.comm = comm.Dup()               # our own messages never meet PETSc's or mpi4py-fft's
        self.rank, self.size = self.comm.Get_rank(), self.comm.Get_size()
        self.say = printer(s.quiet, comm)  # print on rank 0 unless -quiet
        self.records, self.runs, self.wisdom, error = [], [], "", None
        if self.rank == 0:
            try:
                if os.path.exists(s.output):
                    self.records, self.runs, self.wisdom = ensemble_file.read_records(s.output, config)
                    io.remove_stale_temporaries(s.output)
                    beyond = [r["surface"]["index"] for r in self.records if r["surface"]["index"] >= s.size]
                    if beyond:
                        raise UserError(f"-ensemble_size {s.size}: the file {s.output} already holds "
                                        f"surface index {max(beyond)}; give at least {max(beyond) + 1}")
            except UserError as exc:
                error = str(exc)
        error = self.comm.bcast(error, root=0)
        if error:
            self.comm.Free()
            raise UserError(error)
        finished = set(self.comm.bcast(sorted(r["surface"]["index"] for r in self.records), root=0))
        self.todo = [i for i in range(s.size) if i not in finished]
        self.run_id = self.comm.bcast(len(self.runs), root=0)
        self.group_ranks = s.group_ranks
        self.groups = self.size // self.group_ranks
        self.group = self.comm.Split(self.rank // self.group_ranks, self.rank)
        self.leader = self.group.Get_rank() == 0
        self.wisdom = share_fftw_wisdom(self.comm, self.group, s, self.wisdom)
        self.counter = WorkCounter(self.comm, self.todo, use_window=os.environ.get(
            "ROUGHPETSC_ENSEMBLE_COUNTER", "window") != "messages")
        self.received = 0              # records of this run that reached rank 0
        self.saved = len(self.records)  # rank 0: surfaces in the file as last written
        self.write_error = None        # rank 0: why the file could not be written (then the run winds down)
        self.expected = len(self.todo)  # rank 0: records to wait for (fewer once the run winds down)
        if self.rank == 0:
            provenance = io.provenance()
            grid = s.grid
            self.runs.append({"run": self.run_id, "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
                              "ranks": self.size, "group_ranks": self.group_ranks, "command": provenance["command"],
                              "counter": self.counter.mode, "solved": []})
            self.attrs = {
                "format": ensemble_file.FORMAT, "ensemble_size": s.size, "ensemble_seed": s.seed,
                "seed_rule": SEED_RULE,
                "loads": s.loads_spec, "solver": config["solver"], "kkt_rtol": s.rtol, "E_star": s.E_star,
                "grid": json.dumps([grid.n0, grid.n1, grid.l0, grid.l1]),
                "conventions": "p* = pbar/sqrt(m0^p), g* = gbar/sqrt(m0^h); A by node count (3.45), A_corrected "
                               "with the perimeter correction; std with ddof = 1",
                "config": json.dumps(config, sort_keys=True), "fftw_wisdom": self.wisdom,
                "command": provenance["command"],
                "options": json.dumps(provenance["options"], sort_keys=True),
                "versions": json.dumps(provenance["versions"], sort_keys=True)}
        io.on_root(self.comm, self.write)  # a file rank 0 cannot write stops every rank, not rank 0 alone

    # --- rank 0: file and progress -------------------------------------------
    def write(self, models=None):
        attrs = dict(self.attrs, complete=len(self.records) == self.s.size, runs=json.dumps(self.runs))
        records = sorted(self.records, key=lambda r: r["surface"]["index"])
        statistics = step_statistics(records, len(self.s.loads))
        ensemble_file.write(self.s.output, attrs, self.s.loads, records, statistics, models)
        self.saved = len(records)

    def accept(self, record, group):
        """Rank 0: a finished surface (from any group) into the file, and one line of progress."""
        surface = record["surface"]
        self.records.append(record)
        self.runs[-1]["solved"].append(surface["index"])
        self.received += 1
        if self.write_error is None:
            try:
                self.write()
            except UserError as error:  # disk full, say: stop handing out work; the file keeps what it had
                self.write_error = str(error)
                self.expected = self.counter.exhaust()
        elapsed = time.perf_counter() - self.started
        left = len(self.todo) - self.received
        eta = _duration(elapsed / self.received * left) if left else "0s"
        m = len(self.s.loads)
        flag = "" if surface["converged_steps"] == m else "  SOME STEPS NOT CONVERGED"
        self.say(f"surface {surface['index']:4d} seed {surface['seed']:10d}  group {group:3d}  "
                 f"{surface['time_s']:8.2f} s  {surface['converged_steps']}/{m} steps converged  "
                 f"alpha_h {surface['alpha_h']:.4g} alpha_p {surface['alpha_p']:.4g}  "
                 f"[{len(self.records)}/{self.s.size} done, ETA {eta}]{flag}")

    def poll(self):
        """Rank 0: take in finished surfaces and work requests from the other groups; True if there were any."""
        from mpi4py import MPI

        status, got = MPI.Status(), False
        while self.comm.Iprobe(MPI.ANY_SOURCE, MPI.ANY_TAG, status):
            source, tag = status.Get_source(), status.Get_tag()
            message = self.comm.recv(source=source, tag=tag)
            if tag == TAG_RECORD:
                self.accept(message, source // self.group_ranks)
            elif tag == TAG_NEXT:
                self.counter.answer(source)
            got = True
        return got

    def _others_pending(self):
        messages = self.counter.mode == "messages" and self.counter.leaders_done < self.groups - 1
        return self.received < self.expected or messages

    # --- every rank ------------------------------------------------------------
    def work(self):
        """Solve surfaces until none is left; rank 0 also collects and writes."""
        between = self.poll if self.rank == 0 else (lambda: None)
        while True:
            k = self.counter.next() if self.leader else None
            k = self.group.bcast(k, root=0)
            if k < 0:
                break
            index = self.todo[k]
            record = solve_surface(self.reader, self.s, index, surface_seed(self.s.seed, index), self.group,
                                   self.run_id, between)
            if self.rank == 0:
                self.accept(record, 0)
            elif self.leader:
                # Stay until rank 0 has taken the record: a large (rendezvous) message only moves while its
                # sender is inside MPI, and a send left pending during the next surface kept rank 0 spinning
                # in its recv for that whole surface. Test + sleep: no busy wait here either.
                request = self.comm.isend(record, dest=0, tag=TAG_RECORD)
                while not request.Test():
                    time.sleep(IDLE_SLEEP)
        if self.rank == 0:
            while self._others_pending():
                if not self.poll():
                    time.sleep(IDLE_SLEEP)
        # Wait for the others without spinning (a blocking MPI call busy-waits and would take a core
        # from a group still at work when the machine is full).
        barrier = self.comm.Ibarrier()
        while not barrier.Test():
            time.sleep(IDLE_SLEEP)

    def finish(self):
        """Rank 0: the final file with statistics and models; returns the exit status on every rank."""
        status = 0
        if self.rank == 0 and self.write_error is not None:
            print(f"roughpetsc: error: {self.write_error}; {self.s.output} keeps the surfaces it had, and a "
                  "rerun resumes from them", file=sys.stderr, flush=True)
            status = 2
        elif self.rank == 0:
            m = len(self.s.loads)
            self.records.sort(key=lambda r: r["surface"]["index"])
            models = None
            if len(self.records) == self.s.size:
                statistics = step_statistics(self.records, m)
                models = compute_models(np.asarray(self.s.loads, dtype=float), statistics["alpha_h_mean"],
                                        statistics["alpha_p_mean"], self.s.surface, self.s.E_star,
                                        self.s.models, statistics)
            self.runs[-1]["seconds"] = round(time.perf_counter() - self.started, 3)
            self.write(models)
            bad = sum(m - r["surface"]["converged_steps"] for r in self.records)
            total = m * len(self.records)
            self.say(f"ensemble: {len(self.records)}/{self.s.size} surfaces, solved {self.received} in this run "
                     f"({_duration(time.perf_counter() - self.started)}); "
                     + (f"all {total} steps converged" if not bad else f"{bad} of {total} steps NOT CONVERGED")
                     + f"; wrote {self.s.output}")
            status = 3 if bad else 0
        return self.comm.bcast(status, root=0)

    def free(self):
        self.counter.free()
        self.group.Free()
        self.comm.Free()


def run(reader, comm):
    """``-mode ensemble``; returns the exit status (0, or 3 if a step failed)."""
    from ..app.options import check_unused

    s = ensemble_settings.read_settings(reader, comm.Get_size())
    solver_name = probe_solver(s)
    check_unused()
    config = ensemble_settings.configuration(s, solver_name)
    ensemble = Ensemble(reader, comm, s, config)
    try:
        ensemble.say(f"ensemble: {s.size} surfaces ({s.size - len(ensemble.todo)} finished in "
                     f"{s.output}, {len(ensemble.todo)} to solve), {len(s.loads)} load steps, "
                     f"{s.grid.n0}x{s.grid.n1} grid, solver {solver_name}, {ensemble.groups} group(s) of "
                     f"{s.group_ranks} rank(s), work counter {ensemble.counter.mode}, run {ensemble.run_id}")
        try:
            ensemble.work()
            return ensemble.finish()
        except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the file keeps every finished surface it was given
            if ensemble.rank == 0:
                print(f"roughpetsc: interrupted; {s.output} keeps {ensemble.saved} of {s.size} surfaces "
                      "(rerun the same command to resume)", file=sys.stderr, flush=True)
            return 130
        except Exception:     # a failure inside one group would leave the others waiting for ever
            traceback.print_exc()
            sys.stderr.flush()
            comm.Abort(1)
    finally:
        ensemble.free()
