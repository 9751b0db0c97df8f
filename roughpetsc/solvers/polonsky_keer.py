"""Polonsky-Keer constrained conjugate gradients, the context of a TAO of type ``python``.

Polonsky and Keer, Wear 231 (1999), with Vollebregt's bound-constrained active set (``-pk_active_set bccg``)
and the Fourier preconditioner (``-pk_pc fourier``); the backend that drives it along load paths is
:mod:`roughpetsc.solvers.pk`. The algorithm, its options and its operator applications: docs/solvers.md.
"""

import numpy as np
from petsc4py import PETSc

from ..errors import UserError
from .stopping import ConvergenceTest, History, Verdict, check_convergence, option_name, read_option
from ..contact.certificate import KKTReport
from ..parallel import allmax, allsum
from .preconditioner import FourierPreconditioner
from ..contact import loops
from ..elastic import split as split_compliance

PRECONDITIONERS = ("none", "fourier")
ACTIVE_SETS = ("pk", "bccg")
SPLIT_RADIUS, SPLIT_COARSENING, SPLIT_REFRESH = 0, 4, 1e-2  # off: fewer pairs, no faster (docs/solvers.md)
SPLIT_TRANSFER = "bilinear"  # cubic: fewer iterations at N = 8192 only, and slower (docs/solvers.md)
# The stencil's work, (2 R + 1)^2 per corrected node, is spent only up to this many grid sizes (a few per cent of
# a pair's); beyond (a step from a poor start that clips much of the grid) a fresh K p is cheaper.
SPLIT_WORK = 32


class PolonskyKeer:
    """The context of a TAO of type ``python``.

    Before ``tao.solve`` set either ``target_pbar`` (load control, scaled mean pressure; ``target_separation``
    None) or ``target_separation`` (displacement control, scaled rigid separation d, held fixed).
    """

    def __init__(self, problem, rule):
        self.problem = problem
        self.rule = rule
        self.target_pbar = None
        self.target_separation = None
        self.separation = 0.0
        self.preconditioner = "fourier"
        self.refresh = 50
        self.active_set = "bccg"
        # The projection's corrections by the split compliance (elastic/split.py) instead of a fresh K p.
        self.split_radius, self.split_coarsening, self.split_refresh = SPLIT_RADIUS, SPLIT_COARSENING, SPLIT_REFRESH
        self.split_transfer = SPLIT_TRANSFER
        self.split_given = False
        self.split = None
        self.moved = (np.empty(0, dtype=np.int64), np.empty(0))  # the nodes a step's projection moved, and by how much
        self.option_error = None  # what setFromOptions refused, raised by the caller after it returns
        self.history = None
        # K p of the start, if the caller knows it (then the first fresh K p is skipped); cleared by solve.
        self.initial_displacement = None
        # False: a residual below rtol on the updated (not fresh) gap ends the solve, unconfirmed; the caller
        # must then certify on a fresh gap and resume if that fails (the Solver facade does).
        self.confirm = True
        self.unconfirmed = False
        self.watch = None  # the stopping rule's watch of the last solve (its best residual, what stopped it)
        self.current = None  # (natural, load error, fresh) of the iterate the convergence test judges
        self.vecs = [problem.vec() for _ in range(6)]
        self.fourier = FourierPreconditioner(problem)

    def setFromOptions(self, tao):
        """Read ``-pk_pc``, ``-pk_active_set`` and ``-pk_refresh`` under the TAO's options prefix.

        A refused value is kept in :attr:`option_error` for the caller to raise: an exception raised inside
        this callback would leave PETSc's options block open.
        """
        prefix = tao.getOptionsPrefix()
        options = PETSc.Options(prefix)
        self.preconditioner = options.getString("pk_pc", self.preconditioner)
        self.active_set = options.getString("pk_active_set", self.active_set)
        self.split_transfer = options.getString("pk_split_transfer", self.split_transfer)
        try:
            self.refresh = read_option(options, "Int", "pk_refresh", self.refresh)
            self.split_radius = read_option(options, "Int", "pk_split_radius", self.split_radius)
            self.split_coarsening = read_option(options, "Int", "pk_split_coarsening", self.split_coarsening)
            self.split_refresh = read_option(options, "Real", "pk_split_refresh", self.split_refresh)
        except UserError as error:
            self.option_error = error
            return
        self.split_given = options.hasName("pk_split_radius") and self.split_radius > 0
        self.option_error = self._split_option_error(prefix)
        if self.option_error:
            return
        if self.preconditioner not in PRECONDITIONERS:
            self.option_error = UserError(f"{option_name('pk_pc', prefix)}: unknown preconditioner "
                                          f"'{self.preconditioner}' (one of {', '.join(PRECONDITIONERS)})")
        elif self.active_set not in ACTIVE_SETS:
            self.option_error = UserError(f"{option_name('pk_active_set', prefix)}: unknown strategy "
                                          f"'{self.active_set}' (one of {', '.join(ACTIVE_SETS)})")
        elif self.refresh < 1:
            self.option_error = UserError(f"{option_name('pk_refresh', prefix)} must be a positive number of "
                                          f"iterations, got {self.refresh}")

    def _split_option_error(self, prefix):
        """The split's options refused, or None; where the split cannot apply it is off, or refused if asked for."""
        if self.split_radius < 0 or self.split_coarsening < 1:
            return UserError(f"{option_name('pk_split_radius', prefix)} must be 0 (off) or a radius of at least 2 "
                             f"nodes and {option_name('pk_split_coarsening', prefix)} at least 1, got "
                             f"{self.split_radius} and {self.split_coarsening}")
        if not 0.0 < self.split_refresh < 1.0:
            return UserError(f"{option_name('pk_split_refresh', prefix)} must lie in (0, 1), got {self.split_refresh:g}")
        if self.split_transfer not in split_compliance.TRANSFERS:
            return UserError(f"{option_name('pk_split_transfer', prefix)}: unknown transfer '{self.split_transfer}' "
                             f"(one of {', '.join(split_compliance.TRANSFERS)})")
        off = [option_name(name, prefix) for name in ("pk_split_coarsening", "pk_split_refresh", "pk_split_transfer")
               if PETSc.Options(prefix).hasName(name)] if self.split_radius == 0 else []
        if off:
            return UserError(f"{', '.join(off)} given, but the split is off ({option_name('pk_split_radius', prefix)} "
                             f"0, the default): give a radius, or leave {'it' if len(off) == 1 else 'them'} out")
        reason = self.split_unusable()
        if reason and self.split_given:
            return UserError(f"{option_name('pk_split_radius', prefix)} {self.split_radius}: the split correction "
                             f"cannot apply here: {reason} (give 0 to turn it off)")
        return None

    def split_unusable(self):
        """Why the projection's corrections cannot go through the split compliance here, or None."""
        if self.split_radius == 0:
            return "it is turned off"
        if self.active_set != "bccg":
            return "the pk active set enters nodes off the step (a fresh K p follows)"
        if self.problem.upper_bound is not None:
            return "a hardness cap rescales the load with a fresh K p"
        return split_compliance.applicable(self.problem.operator, self.split_radius, self.split_coarsening)

    @property
    def split_applications(self):
        """The split's coarse FFT pairs so far, in pairs of the grid."""
        return self.split.coarse_applications if self.split is not None else 0.0

    def _split_ready(self):
        """The split compliance (built on first use: one pair), or None where it does not apply."""
        if self.split is None and self.split_unusable() is None:
            problem = self.problem
            self.split = split_compliance.SplitCompliance(
                problem.operator, self.split_radius, self.split_coarsening, self.vecs[2], self.vecs[4], problem.mpi,
                self.split_transfer)
            # Room for as many moved nodes as the stencil's work allows: a step that moves more takes a fresh K p.
            room = min(problem.local(problem.heights, readonly=True).size,
                       SPLIT_WORK * problem.n // (2 * self.split_radius + 1) ** 2)
            self.moved = (np.empty(room, dtype=np.int64), np.empty(room))
        return self.split

    def _add_corrections(self, displacement, moved):
        """``K p += K c`` for the projection's corrections c at the ``moved`` nodes of this rank (listed in
        :attr:`moved`) by the split compliance."""
        problem = self.problem
        nodes, values = (array[:moved] for array in self.moved)
        n1 = problem.grid.n1
        rows = nodes // n1 + problem.operator.local_rows.start
        parts = (rows, nodes % n1, values)
        if problem.mpi.Get_size() > 1:
            parts = [np.concatenate(part) for part in zip(*problem.mpi.allgather(parts))]
        self.split.add(*parts, displacement.reshape(problem.operator.local_shape))

    def view(self, tao, viewer):
        """-tao_view: PK's own settings; the line search and KSP that PETSc then lists are never used."""
        limit = f"{self.rule.max_seconds:g} s" if self.rule.max_seconds > 0 else "none"
        unusable = self.split_unusable()
        split = (f"projection corrections by the split compliance (radius {self.split_radius}, coarsening "
                 f"{self.split_coarsening}, {self.split_transfer} transfers, K p afresh at each "
                 f"{self.split_refresh:g} x fall of the residual)"
                 if unusable is None else f"a fresh K p after each projection ({unusable.split(' (')[0]})")
        for line in (f"Polonsky-Keer CG, active set {self.active_set}, preconditioner {self.preconditioner}, K p "
                     f"refreshed every {self.refresh} iterations", split,
                     f"stops at a natural KKT residual (and load error) of {self.rule.rtol:g}; time limit {limit}",
                     "(PETSc lists below the line search and KSP that every TAO holds: Polonsky-Keer uses neither, "
                     "and their options are reported as unused)"):
            viewer.printfASCII(f"  {line}\n")

    def destroy(self, tao=None):
        for v in self.vecs:
            v.destroy()
        self.vecs = []
        if self.fourier is not None:
            self.fourier.destroy()
            self.fourier = None

    def solve(self, tao):
        problem = self.problem
        operator = problem.operator
        mpi = problem.mpi
        n = problem.n
        load_control = self.target_separation is None
        pbar = self.target_pbar if load_control else None
        pressure = tao.getSolution()
        p = problem.local(pressure).ravel()
        h = problem.local(problem.heights, readonly=True).ravel()
        displacement_vec, direction_vec, response_vec = self.vecs[:3]
        displacement = problem.local(displacement_vec).ravel()  # K p
        t = problem.local(direction_vec).ravel()
        response = problem.local(response_vec).ravel()  # K t, then the residual on the free set
        gap = problem.local(self.vecs[3]).ravel()
        z = problem.local(self.vecs[4]).ravel()  # preconditioned residual
        r_old = problem.local(self.vecs[5]).ravel()
        r_old[...] = 0.0
        cap = problem.upper_bound
        upper = np.inf if cap is None else cap  # the kernels' cap: inf reduces every test to the uncapped one
        bccg = self.active_set == "bccg"
        precondition = self.preconditioner == "fourier"
        contact = np.empty_like(p)  # 1.0 on the contact (then free) set, 0.0 elsewhere
        negative = None if bccg else np.empty(p.shape, dtype=bool)  # PK's entering nodes
        t[...] = 0.0
        if not load_control:
            self.separation = self.target_separation
            self._interference_start(pressure, p, h)
        self.history = History(problem)
        self.watch = self.rule.watch(self.history, tao.getMaximumIterations())
        test = ConvergenceTest(self.watch, lambda tao: self.current, confirm=self.confirm)
        tao.setConvergenceTest(test)
        tao.setConvergedReason(PETSc.TAO.Reason.CONTINUE_ITERATING)  # not the verdict of the last solve
        tao.setIterationNumber(0)
        rz_old, conjugate, fresh_needed = 1.0, False, True
        since_fresh = 0
        split = self._split_ready()
        moved_nodes, moved_by = self.moved
        # K p carries split corrections since it was last computed afresh, when the residual was fresh_natural.
        approximated, fresh_natural = False, np.inf
        if self.initial_displacement is not None:
            self.initial_displacement.copy(displacement_vec)
            # Not fresh: with confirm, convergence at once is still confirmed on a computed K p.
            self.initial_displacement, fresh_needed, since_fresh = None, False, 1
        self.unconfirmed = False
        iteration, reason = 0, PETSc.TAO.Reason.DIVERGED_MAXITS
        while True:
            if fresh_needed or since_fresh >= self.refresh:
                operator.displacement(pressure, displacement_vec)
                since_fresh, fresh_needed, approximated = 0, False, False
            fresh = since_fresh == 0
            # Plastic nodes (their gap may be negative) are not in the contact set that fixes d.
            count, gap_sum, total = allsum(mpi, loops.contact_and_gap(p, displacement, h, gap, contact, upper))
            if load_control and count:  # d makes the mean gap on the contact set zero (a fully plastic
                self.separation = -gap_sum / count  # contact keeps the last d)
            kkt = self._report(p, gap, total, pbar, upper)
            if fresh:
                fresh_natural = kkt.natural
            elif approximated and kkt.natural < self.split_refresh * fresh_natural:
                # The corrections' errors are fixed in size while the residual falls: clear them before they
                # steer the directions.
                fresh_needed = True
                continue
            self.current = (kkt.natural, kkt.load_error, fresh)
            reason = check_convergence(tao)
            if test.verdict is Verdict.CONFIRM:
                fresh_needed = True  # confirm on a freshly computed K p before stopping
                continue
            tao.monitor(its=iteration, f=kkt.complementarity, res=kkt.natural, cnorm=kkt.load_error or 0.0)
            if test.verdict is Verdict.CONVERGED:
                self.unconfirmed = not fresh
            if reason != PETSc.TAO.Reason.CONTINUE_ITERATING:
                break
            # The free set: the contact set, the plastic nodes whose gap opens (they leave the cap), and
            # under BCCG the nodes out of contact that overlap.
            if bccg or not load_control or cap is not None:
                count, gap_sum = allsum(mpi, loops.free_set(p, gap, contact, upper, bccg))
            else:
                gap_sum = 0.0  # the free set is the contact set, where d has made the mean gap zero
            # Directions keep the load: under load control the residual has zero mean on the free set.
            mean = gap_sum / count if load_control and gap_sum else 0.0
            r = response
            loops.shift_on(gap, contact, mean, r)
            if precondition:
                self.fourier.apply(r, z, contact, count, keep_load=load_control)
                direction = z
            else:
                direction = r
            rz, r_old_z, t_free, direction_sum = allsum(
                mpi, loops.conjugacy_sums(r, direction, r_old, t, contact, bccg))
            if bccg:
                # Polak-Ribiere (clipped at 0): conjugacy survives changes of the free set.
                beta = max((rz - r_old_z) / rz_old if iteration else 0.0, 0.0)
            else:
                beta = rz / rz_old if conjugate else 0.0
            rz_old = rz
            # Conjugate direction on the free set: t = z + beta t. Under a cap and load control it is kept
            # at zero sum (it keeps the load, which beside capped nodes only a fresh K p could restore).
            shift = (beta * t_free + direction_sum) / count if load_control and cap is not None and count else 0.0
            loops.new_direction(t, contact, beta, shift, direction)
            operator.displacement(direction_vec, response_vec)
            q_sum, t_sum, numerator, q_dot_t = allsum(mpi, loops.step_sums(response, contact, t, gap))
            # Under load control K t enters less its mean on the contact set (t vanishes off it).
            denominator = q_dot_t - q_sum / count * t_sum if load_control else q_dot_t
            if not denominator > 0:
                reason = PETSc.TAO.Reason.DIVERGED_LS_FAILURE
                break
            step = numerator / denominator
            # p - step t projected onto [0, upper]; K p - step K t, the displacement of the unprojected step.
            clipped, total = loops.take_step(p, t, displacement, response, step, upper, moved_nodes, moved_by)
            if bccg:
                changed, total = allsum(mpi, [clipped, total])
                entering = 0
            else:
                # PK: nodes out of contact that overlap enter with p = -step g, and CG restarts.
                overlap = np.less(gap, 0.0, out=negative)
                overlap &= p == 0
                changed, entering = allsum(mpi, [clipped, np.count_nonzero(overlap)])
                if entering:
                    np.copyto(p, -step * gap, where=overlap)
                total, = allsum(mpi, [p.sum()])
                conjugate = entering == 0
            if changed and split is not None and changed * (2 * self.split_radius + 1) ** 2 <= SPLIT_WORK * n:
                self._add_corrections(displacement, clipped)
                approximated = True
            else:
                fresh_needed = bool(changed or entering)
            if load_control and cap is None:
                loops.rescale(p, displacement, pbar * n / total)
            elif load_control:
                # Directions keep the load on the free set: it drifts where the projection clipped (then
                # K p is computed afresh anyway) and slowly otherwise; a drift well inside the tolerance is
                # left for later, as rescaling beside capped nodes costs a fresh K p.
                if changed or abs(total - pbar * n) > 0.01 * self.rule.rtol * pbar * n:
                    fresh_needed |= self._restore_load_below_cap(p, displacement, pbar * n, cap)
                    if self.watch.stopped_by:
                        reason = PETSc.TAO.Reason.DIVERGED_USER
                        break
            since_fresh += 1
            iteration += 1
            tao.setIterationNumber(iteration)
        tao.setIterationNumber(iteration)
        tao.setConvergedReason(reason)

    def _report(self, p, gap, total, pbar, upper):
        """The KKT report of the iterate (``gap += separation`` on the way), without feasibility minima."""
        problem = self.problem
        mean_p = total / problem.n
        scale = pbar if pbar else (mean_p if mean_p > 0 else 1.0)
        natural, complementarity = loops.natural_residual(p, gap, self.separation, scale, upper)
        natural, = allmax(problem.mpi, [natural])
        complementarity, = allsum(problem.mpi, [complementarity])
        return KKTReport(natural=float(natural), complementarity=float(complementarity / total) if total > 0 else 0.0,
                         min_p=np.nan, min_g=np.nan,
                         load_error=None if pbar is None else float(abs(mean_p - pbar) / pbar))

    def _interference_start(self, pressure, p, h):
        """Under displacement control, an empty start becomes ``c max(h - d, 0)``, c the QP's minimiser along it."""
        problem = self.problem
        total, = allsum(problem.mpi, [p.sum()])
        if total > 0:
            return
        np.subtract(h, self.separation, out=p)
        np.maximum(p, 0.0, out=p)
        problem.operator.displacement(pressure, self.vecs[2])
        response = problem.local(self.vecs[2], readonly=True).ravel()
        interference, energy = allsum(problem.mpi, [np.dot(p, p), np.dot(p, response)])
        if energy > 0:
            p *= interference / energy
        if problem.upper_bound is not None:
            np.minimum(p, problem.upper_bound, out=p)

    def _restore_load_below_cap(self, p, displacement, total_load, upper):
        """Rescale the nodes below the cap ``upper`` so that ``sum(p) = total_load``; True if K p is stale.

        A node lifted above the cap is capped in turn. K p follows exactly only while no node is capped.
        """
        mpi = self.problem.mpi
        stale = False
        for _ in range(8):
            # Capped nodes hold p = upper exactly (the projection sets them so): the free load is the rest.
            n_capped, total = allsum(mpi, loops.capped_load(p, upper))
            wanted = total_load - upper * n_capped
            if wanted <= 0:
                # The capped nodes alone carry more than the load: scale every node down, off the cap.
                p *= total_load / total
                return True
            free_load = total - upper * n_capped
            if not free_load > 0:
                # Every loaded node is capped and the load wants more: only a larger contact can carry
                # it, which rescaling cannot make (the caller stops; see CappedPKLoad).
                self.watch.stopped_by = "the cap carries the whole load"
                return True
            scale = wanted / free_load
            lifted, = allsum(mpi, [loops.scale_below_cap(p, upper, scale)])
            if n_capped or stale:
                stale = True
            else:
                displacement *= scale
            if not lifted:
                break
            stale = True
        return bool(stale)
