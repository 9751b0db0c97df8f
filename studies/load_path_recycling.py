"""Warm starts along the 95-step load history (7.11): reduced-basis predictors, recycled products, coarse spaces.

    .venv/bin/python studies/load_path_recycling.py [--n 256] [--variants linear galerkin3 linear+coarse8 ...]

Prototype for issue 12 item 6 (a warm step at most 0.35 of a cold solve at N = 1024). Every variant is a
:class:`roughpetsc.Solver` whose predictor (:meth:`load_start`) or PK preconditioner (the context's
``fourier``) is replaced; the solve and its certificate on a fresh gap are the Solver's. Cost: FFT pairs
(``operator.applications``) per warm step against one cold PK solve at p* = 0.5 (uniform start), group #1,
natural KKT residual 1e-8, one process. Variants:

- ``linear``: the kept predictor (linear extrapolation in the load, K p of the start from the kept K p).
- ``galerkin<k>``: the minimiser of the QP energy 1/2 p'Kp - p'h over the span of the last k solutions
  under the mean-pressure constraint (their kept K p: no FFT), projected onto p >= 0 and rescaled.
- ``galerkin<k>+rec<m>``: the same span plus the last m products (x, K x) of the previous solve (PK's
  search directions with their K t, recorded by :class:`ProductLog`, no FFT).
- ``linear+recycle<m>``: those m recorded products as the coarse space of a balancing preconditioner
  (:class:`CoarseCorrection`) in the next solve (Krylov recycling, no FFT).
- ``linear+coarse<b>[/<s>]``: a b x b block coarse space on the contact set (Vollebregt's subdomain
  deflation vectors), its K products computed (b^2 FFT pairs) every s steps (default every step).

Measured (N = 256 cold 34 iterations / 88 pairs; N = 1024 cold 44 / 119), pairs per warm step and ratio:
linear 42.1 (0.478), at 1024 62.5 (0.525, time ratio 0.50-0.61 against the median of three cold solves);
galerkin2/3/4/6/10 42.1-42.3 (0.478-0.480), galerkin3 at 1024 61.4 (0.516, time ratio 0.57); galerkin3+rec10/40,
galerkin6+rec20 42.3/42.8/42.6; recycle5/10/20/40 47.7/47.7/48.2/68.2 (0.54-0.78);
coarse4 / coarse8 per step 51.2 / 95.8 (14.5 / 13.2 iterations instead of 17.4: 35.2 / 31.8 pairs, 0.40 /
0.36, if the coarse products were free); coarse4/10, coarse8/10, coarse8/95 43.1 / 48.9 / 53.3. The same
coarse8 space shortens the cold solve too (34 -> 27 iterations, 68 pairs without its 64 products), so it is
a better preconditioner, not a warm-start gain. No variant reaches 0.35. Why: at N = 1024 a warm step
spends 18.5 pairs reaching a natural residual of 1e-3 and 43.0 pairs in the tail below it (0.21-0.34
decades per iteration), so the tail alone is 0.36 of the cold solve; and the predictor's error is local
(new contact spots and rims, 10 % of the nodes off by more than 1e-2 pbar, rms 2.7e-2 on the contact set at
step 45) and changes place from step to step (cosine 0.22-0.24 between consecutive steps' start errors; the
best multiple of the previous error removes 2.5 % of the next), so no span of past solutions or past Krylov
vectors represents it: the Galerkin start is within 3 % of the linear one (rms error 1.86e-2 -> 1.81e-2).
"""

import argparse
import os
import time

import numpy as np

import common


class ProductLog:
    """Records the pairs (x, K x) of every compliance application of an operator while ``recording``.

    Wraps ``operator.displacement`` (an instance attribute shadows the method): PK's search directions
    t with K t, and its fresh K p, are kept without any extra FFT.
    """

    def __init__(self, operator, keep):
        self.operator = operator
        self.keep = keep
        self.pairs = []
        self.previous = []  # the pairs of the last finished solve
        self.recording = False
        self.original = operator.displacement

        def displacement(pressure, out):
            self.original(pressure, out)
            if self.recording and self.keep:
                self.pairs.append((pressure.getArray(readonly=True).copy(), out.getArray(readonly=True).copy()))
                del self.pairs[:-self.keep]

        operator.displacement = displacement

    def restore(self):
        del self.operator.displacement


def galerkin_combination(basis, products, heights, count, total_load, cutoff=1e-12):
    """Coefficients c minimising 1/2 p'Kp - p'h over p = W c with sum(p) = total_load.

    The energy of the load-controlled QP (p >= 0 left out); K W is known. Columns are normalised and
    the KKT system solved in the least-squares sense (the basis is nearly dependent).
    """
    W = np.array(basis)
    KW = np.array(products)
    norms = np.sqrt(np.einsum("ij,ij->i", W, W))
    norms[norms == 0] = 1.0
    W = W / norms[:, None]
    KW = KW / norms[:, None]
    G = W @ KW.T
    G = 0.5 * (G + G.T)
    b = W @ heights
    s = W.sum(axis=1)
    k = len(basis)
    system = np.zeros((k + 1, k + 1))
    system[:k, :k] = G
    system[:k, k] = s
    system[k, :k] = s
    rhs = np.concatenate([b, [total_load]])
    solution = np.linalg.lstsq(system, rhs, rcond=cutoff)[0]
    return solution[:k] / norms


def block_basis(problem, blocks):
    """A callable ``(contact, count) -> (W, K W)``: indicators of ``blocks x blocks`` squares on C, mean removed.

    Costs ``blocks**2`` FFT pairs per call (Vollebregt's subdomain deflation vectors).
    """
    rows, cols = problem.operator.local_shape
    i, j = np.meshgrid(np.arange(rows) * blocks // rows, np.arange(cols) * blocks // cols, indexing="ij")
    labels = (i * blocks + j).ravel()
    x, kx = problem.vec(), problem.vec()

    def basis(contact, count):
        W = np.zeros((blocks * blocks, contact.size))
        W[labels, np.arange(contact.size)] = 1.0
        W *= contact
        W -= np.outer(W.sum(axis=1) / count, contact)
        KW = np.empty_like(W)
        for k, w in enumerate(W):
            x.getArray()[...] = w
            problem.operator.displacement(x, kx)
            KW[k] = kx.getArray(readonly=True)
        return W, KW

    basis.destroy = lambda: (x.destroy(), kx.destroy())
    return basis


def recycled_basis(log, keep):
    """A callable ``(contact, count) -> (W, K W)``: the last ``keep`` products (x, K x) of the previous solve."""

    def basis(contact, count):
        pairs = log.previous[-keep:]
        if not pairs:
            return None, None
        return np.array([x for x, _ in pairs]), np.array([kx for _, kx in pairs])

    basis.destroy = lambda: None
    return basis


class CoarseCorrection:
    """The Fourier preconditioner B of PK with a balancing coarse correction.

    Stands in for ``PolonskyKeer.fourier`` (same ``apply``). With ``W`` a few vectors and ``AW`` their K
    products, fetched from ``basis`` at the start of a solve, both restricted to the current free set C
    (mean on C removed: load control), and ``E = W' AW``, the preconditioner is the balancing (BNN) form
    ``(I - Q A) B (I - A Q) + Q``, ``Q = W E^+ W'``: symmetric whatever ``AW``, so products kept from
    another free set (the start's, the previous step's) still give a symmetric preconditioner.
    """

    def __init__(self, fourier, basis, cutoff=1e-10):
        self.fourier = fourier
        self.basis = basis
        self.cutoff = cutoff
        self.W = self.AW = None
        self.stale = True

    def apply(self, residual, out, contact, count, keep_load, **kwargs):
        if not keep_load:
            return self.fourier.apply(residual, out, contact, count, keep_load, **kwargs)
        if self.stale:
            self.W, self.AW = self.basis(contact, count)
            self.stale = False
        if self.W is None:
            return self.fourier.apply(residual, out, contact, count, keep_load, **kwargs)
        W, AW = self.W, self.AW
        # Restricted to C with the mean there removed; for y zero off C with zero mean on C, W_C' y = W y.
        w_sums, aw_sums = W @ contact, AW @ contact
        E = (W * contact) @ AW.T - np.outer(w_sums, aw_sums) / count
        E = 0.5 * (E + E.T)
        values, vectors = np.linalg.eigh(E)
        keep = values > self.cutoff * values.max()
        inverse = (vectors[:, keep] / values[keep]) @ vectors[:, keep].T

        def restricted(vectors, sums, coefficients):
            v = coefficients @ vectors
            v -= coefficients @ sums / count
            return v * contact

        c = inverse @ (W @ residual)
        correction = restricted(W, w_sums, c)  # Q r
        balanced = residual - restricted(AW, aw_sums, c)  # (I - A Q) r
        self.fourier.apply(balanced, out, contact, count, keep_load, **kwargs)
        out -= restricted(W, w_sums, inverse @ (AW @ out))  # (I - Q A) B (I - A Q) r
        out += correction

    def destroy(self):
        self.fourier.destroy()
        self.basis.destroy()


def make_solver_class():
    from roughpetsc import Solver

    class PredictorSolver(Solver):
        """A load-controlled PK Solver whose predictor is ``predictor`` (see :func:`main`)."""

        def __init__(self, problem, predictor, solutions=2, recycled=0, blocks=0, deflate=0, every=1):
            super().__init__(problem, "load", None, 1e-8)
            context = self.backend.context
            keep = max(recycled, deflate)
            self.log = ProductLog(problem.operator, keep) if keep else None
            basis = block_basis(problem, blocks) if blocks else recycled_basis(self.log, deflate) if deflate \
                else None
            self.coarse = CoarseCorrection(context.fourier, basis) if basis else None
            if self.coarse:
                context.fourier = self.coarse
            self.predictor = predictor
            self.every, self.steps = every, 0  # the coarse products are refreshed every ``every`` steps
            self.keep_solutions = solutions
            self.kept = []  # (pbar, p, K p) of the last solutions, numpy copies
            self.start_kp = problem.vec()

        def solve(self, pbar=None, pstar=None, gbar=None):
            if self.log:
                self.log.recording = True
            if self.coarse:
                self.coarse.stale = self.coarse.stale or self.steps % self.every == 0
            self.steps += 1
            result = super().solve(pbar=pbar, pstar=pstar, gbar=gbar)
            if self.log:
                self.log.recording = False
                self.log.previous, self.log.pairs = self.log.pairs, []
            problem = self.problem
            target = problem.scaled_pbar(pbar, pstar)
            kp = self.gap.getArray(readonly=True) + problem.heights.getArray(readonly=True) \
                - self.last_separation
            self.kept = (self.kept + [(target, self.pressure.getArray(readonly=True).copy(), kp)])[
                -self.keep_solutions:]
            return result

        def load_start(self, target):
            if self.predictor == "linear" or len(self.kept) < 2:
                return super().load_start(target)
            problem = self.problem
            basis = [p for _, p, _ in self.kept]
            products = [kp for _, _, kp in self.kept]
            if self.log:
                basis += [x for x, _ in self.log.previous]
                products += [kx for _, kx in self.log.previous]
            h = problem.heights.getArray(readonly=True)
            c = galerkin_combination(basis, products, h, problem.n, target * problem.n)
            p = self.pressure.getArray()
            p[...] = np.dot(c, basis)
            kp = self.start_kp.getArray()
            kp[...] = np.dot(c, products)
            clipped = np.count_nonzero(p < 0)
            np.maximum(p, 0.0, out=p)
            scale = target * problem.n / p.sum()
            p *= scale
            kp *= scale
            return None if clipped else self.start_kp

        def destroy(self):
            if self.log:
                self.log.restore()
            self.start_kp.destroy()
            super().destroy()

    return PredictorSolver


VARIANTS = {
    "linear": dict(predictor="linear"),
    **{f"galerkin{k}": dict(predictor="galerkin", solutions=k) for k in (2, 3, 4, 6, 10)},
    **{f"galerkin{k}+rec{m}": dict(predictor="galerkin", solutions=k, recycled=m)
       for k in (3, 6) for m in (5, 10, 20, 40)},
    **{f"linear+coarse{b}": dict(predictor="linear", blocks=b) for b in (2, 4, 8, 16)},
    **{f"linear+coarse{b}/{s}": dict(predictor="linear", blocks=b, every=s) for b in (4, 8, 16)
       for s in (3, 10, 95)},
    **{f"linear+recycle{m}": dict(predictor="linear", deflate=m) for m in (5, 10, 20, 40)},
}


def cost_split(result, threshold=1e-3):
    """FFT pairs of one solve: (to reach ``threshold``, the tail below it, outside PK's iterations), tail rate.

    The tail rate is in decades of natural residual per iteration below ``threshold``.
    """
    h = result.history
    reached = int(np.argmax(h[:, 1] <= threshold)) if np.any(h[:, 1] <= threshold) else len(h) - 1
    start_phase = h[reached, 2] - h[0, 2]
    tail = h[-1, 2] - h[reached, 2]
    iterations = h[-1, 0] - h[reached, 0]
    rate = np.log10(h[reached, 1] / h[-1, 1]) / iterations if iterations else np.nan
    return start_phase, tail, result.operator_applications - start_phase - tail, rate


def cold_solve(problem, repeat=3):
    """The cold solve at p* = 0.5 and the median of its seconds over ``repeat`` solves (one is noisy here)."""
    from roughpetsc import Solver

    seconds = []
    for _ in range(repeat):
        solver = Solver(problem, "load", None, 1e-8)
        start = time.perf_counter()
        result = solver.solve(pstar=0.5)
        seconds.append(time.perf_counter() - start)
        solver.destroy()
    return result, float(np.median(seconds))


def history_solve(problem, loads, variant):
    solver = make_solver_class()(problem, **VARIANTS[variant])
    start = time.perf_counter()
    try:
        results = [solver.solve(pstar=p) for p in loads]
    finally:
        solver.destroy()
    return results, time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=256)
    parser.add_argument("--variants", nargs="*", default=["linear", "galerkin3"])
    args = parser.parse_args()
    common.init()
    from roughpetsc import load_history as history

    loads = history()
    problem = common.group1_problem(args.n)
    cold, cold_seconds = cold_solve(problem)
    cold_split = cost_split(cold)
    print(f"cold: {cold.iterations} its, {cold.operator_applications} pairs, {cold_seconds:.2f} s, r0 "
          f"{cold.history[0, 1]:.1e}, pairs to 1e-3 / tail / outside {cold_split[0]:.0f} / {cold_split[1]:.0f} / "
          f"{cold_split[2]:.0f}, tail rate {cold_split[3]:.2f} decades per iteration")
    rows = []
    for variant in args.variants:
        results, seconds = history_solve(problem, loads, variant)
        pairs = sum(r.operator_applications for r in results) / len(loads)
        its = sum(r.iterations for r in results) / len(loads)
        starts = np.median([r.history[0, 1] for r in results if len(r.history)])
        split = np.array([cost_split(r) for r in results if len(r.history) > 1])
        rows.append([variant, args.n, f"{its:.1f}", f"{pairs:.1f}", f"{pairs / cold.operator_applications:.3f}",
                     f"{seconds / len(loads) / cold_seconds:.3f}", f"{starts:.1e}",
                     " / ".join(f"{x:.1f}" for x in split[:, :3].mean(axis=0)), f"{np.nanmean(split[:, 3]):.2f}",
                     f"{sum(r.converged for r in results)}/{len(loads)}"])
        print(" | ".join(map(str, rows[-1])), flush=True)
    problem.destroy()
    table = common.markdown_table(["variant", "N", "its/step", "FFT pairs/step", "ratio", "time ratio", "r0 median",
                                   "pairs to 1e-3 / tail / outside PK", "tail decades/it", "certified"], rows)
    text = (f"# Warm starts along the 95-step load history (7.11): predictors and recycling\n\nGroup #1, natural KKT "
            f"1e-8 at every step, one process. Cold solve at p* = 0.5: {cold.iterations} iterations, "
            f"{cold.operator_applications} FFT pairs, {cold_seconds:.2f} s, of which {cold_split[0]:.0f} pairs reach "
            f"a natural residual of 1e-3 and {cold_split[1]:.0f} go below it. Ratio: FFT pairs per warm step / "
            f"cold FFT pairs; time ratio likewise in seconds (shared machine). Tail rate: mean over the steps of "
            f"the decades per iteration below 1e-3. Variants: see the study's docstring.\n\n{table}\n\n"
            f"Regenerate: `.venv/bin/python studies/load_path_recycling.py --n {args.n} --variants "
            f"{' '.join(args.variants)}`\n")
    report = os.path.join(common.OUTPUT, f"load_path_recycling_N{args.n}.md")
    with open(report, "w") as f:
        f.write(text)
    print(f"{text}\n(written to {report})")


if __name__ == "__main__":
    main()
