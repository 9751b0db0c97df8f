"""Why plain PK needs O(N) iterations and the preconditioned one fewer: spectra of K on the contact set.

    .venv/bin/python studies/conditioning.py [--sizes 128 256 512] [--pstar 0.5] [--deflate 0 16 64 256]

For the group #1 surface at p* (unit cell, (k_l, k_s, H) = (16, 64, 0.8), so N >= 128), the
contact set C of the solution is fixed and two operators on C are examined with SLEPc
(Krylov-Schur, extreme eigenvalues):

* ``K_CC``: the compliance restricted to C (what plain PK iterates with);
* ``B_C K_CC``: preconditioned by the Fourier preconditioner of :mod:`roughpetsc.preconditioner`
  (similar to a symmetric matrix, so its eigenvalues are real and positive).

CG needs about sqrt(condition number) iterations, so the growth of the condition numbers with N
explains the growth of the iteration counts. Where |C| <= 3000 (``--check``) the SLEPc values are
checked against a dense eigen-decomposition (numpy).

Deflation (Vollebregt 2014 deflates coarse-grid vectors): the contact set is cut by an m-block
coarse grid (sqrt(m) x sqrt(m) square blocks of the cell) and the indicator of C on each block is a
deflation vector; CG and preconditioned CG on the fixed contact set (displacement-control system
K_CC p = h_C - d) are run with and without them. The table gives the iterations to a relative
residual of 1e-8 against m, and the m operator applications the deflation space costs (K Z).

Writes studies/output/conditioning/conditioning.md and a PNG.
"""

import argparse
import os
import sys

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "conditioning")


class Restricted:
    """Operators on the contact set C (indices ``free``): K_CC, and B_C K_CC."""

    def __init__(self, problem, free):
        from roughpetsc.solvers.preconditioner import FourierPreconditioner

        self.problem = problem
        self.free = free
        self.full_in, self.full_out = problem.vec(), problem.vec()
        self.fourier = FourierPreconditioner(problem)
        self.contact = np.zeros(problem.n)
        self.contact[free] = 1.0
        self.count = float(len(free))

    def compliance(self, x):
        full = self.full_in.getArray()
        full[...] = 0.0
        full[self.free] = x
        self.problem.operator.displacement(self.full_in, self.full_out)
        return self.full_out.getArray(readonly=True)[self.free].copy()

    def preconditioner(self, r):
        residual = np.zeros(self.problem.n)
        residual[self.free] = r
        out = np.zeros(self.problem.n)
        self.fourier.apply(residual, out, self.contact, self.count, keep_load=False)
        return out[self.free]

    def destroy(self):
        self.full_in.destroy()
        self.full_out.destroy()
        self.fourier.destroy()


class _ShellContext:
    def __init__(self, apply):
        self.apply = apply

    def mult(self, mat, x, y):
        y.getArray()[...] = self.apply(x.getArray(readonly=True))


def extreme_eigenvalues(apply, size, symmetric):
    """(smallest, largest) real eigenvalue of a matrix-free operator, by SLEPc Krylov-Schur."""
    from petsc4py import PETSc
    from slepc4py import SLEPc

    mat = PETSc.Mat().createPython((size, size), context=_ShellContext(apply), comm=PETSc.COMM_SELF)
    mat.setUp()
    values = []
    for which in (SLEPc.EPS.Which.SMALLEST_REAL, SLEPc.EPS.Which.LARGEST_REAL):
        eps = SLEPc.EPS().create(PETSc.COMM_SELF)
        eps.setOperators(mat)
        eps.setProblemType(SLEPc.EPS.ProblemType.HEP if symmetric else SLEPc.EPS.ProblemType.NHEP)
        eps.setWhichEigenpairs(which)
        eps.setDimensions(nev=1, ncv=min(size, 64))
        eps.setTolerances(tol=1e-8, max_it=20000)
        eps.solve()
        if eps.getConverged() < 1:
            values.append(float("nan"))
        else:
            values.append(eps.getEigenvalue(0).real)
        eps.destroy()
    mat.destroy()
    return tuple(values)


def dense(apply, size):
    columns = []
    unit = np.zeros(size)
    for j in range(size):
        unit[j] = 1.0
        columns.append(apply(unit))
        unit[j] = 0.0
    return np.array(columns).T


def deflated_pcg(apply_a, apply_b, rhs, basis, rtol=1e-8, max_it=100000):
    """Preconditioned CG on A x = rhs with the columns of ``basis`` deflated (A-orthogonal projection).

    Returns the iterations to ||r|| <= rtol ||rhs||.
    """
    if basis is not None and basis.shape[1]:
        a_basis = np.column_stack([apply_a(z) for z in basis.T])
        coarse = basis.T @ a_basis

        def project(r):  # P r = r - A Z (Z'AZ)^-1 Z' r
            return r - a_basis @ np.linalg.solve(coarse, basis.T @ r)

        x = basis @ np.linalg.solve(coarse, basis.T @ rhs)
    else:
        def project(r):
            return r

        x = np.zeros_like(rhs)
    r = rhs - apply_a(x)
    r = project(r)
    z = apply_b(r)
    p = z.copy()
    rz = r @ z
    norm = np.linalg.norm(rhs)
    for iteration in range(1, max_it + 1):
        q = project(apply_a(p))
        step = rz / (p @ q)
        r = r - step * q
        if np.linalg.norm(r) <= rtol * norm:
            return iteration
        z = apply_b(r)
        rz_new = r @ z
        p = z + rz_new / rz * p
        rz = rz_new
    return max_it


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[128, 256, 512])
    parser.add_argument("--pstar", type=float, default=0.5)
    parser.add_argument("--deflate", type=int, nargs="*", default=[0, 16, 64, 256])
    args = parser.parse_args()
    common.init()
    from petsc4py import PETSc  # noqa: F401 (initialised by common.init)

    os.makedirs(OUT, exist_ok=True)
    rows, deflation_rows, series = [], [], {"K": [], "BK": []}
    for n in args.sizes:
        problem = common.group1_problem(n, effort="FFTW_ESTIMATE")
        result, field, _ = common.solve(problem, {"pk_pc": "fourier"}, 1e-12, pstar=args.pstar)
        free = np.flatnonzero(field.ravel() > 0)
        ops = Restricted(problem, free)
        size = len(free)
        k_min, k_max = extreme_eigenvalues(ops.compliance, size, symmetric=True)
        print(f"N={n} |C|={size}: K_CC done", flush=True)
        bk_min, bk_max = extreme_eigenvalues(lambda x: ops.preconditioner(ops.compliance(x)), size, symmetric=False)
        row = [n, size, f"{k_min:.3e}", f"{k_max:.3e}", f"{k_max / k_min:.3e}",
               f"{bk_min:.3e}", f"{bk_max:.3e}", f"{bk_max / bk_min:.3e}"]
        if size <= 3000:
            k_dense = np.linalg.eigvalsh(dense(ops.compliance, size))
            bk_dense = np.sort(np.linalg.eigvals(dense(lambda x: ops.preconditioner(ops.compliance(x)), size)).real)
            row.append(f"{k_dense[-1] / k_dense[0]:.3e} / {bk_dense[-1] / bk_dense[0]:.3e}")
        else:
            row.append("-")
        rows.append(row)
        series["K"].append(k_max / k_min)
        series["BK"].append(bk_max / bk_min)
        print(" | ".join(map(str, row)), flush=True)
        # Deflation by the indicators of C on coarse blocks.
        heights = problem.local(problem.heights, readonly=True).ravel()[free]
        rhs = heights - result.separation / problem.height_scale
        for m in args.deflate:
            basis = coarse_basis(n, free, m) if m else None
            plain = deflated_pcg(ops.compliance, lambda r: r, rhs, basis)
            preconditioned = deflated_pcg(ops.compliance, ops.preconditioner, rhs, basis)
            deflation_rows.append([n, m, plain, preconditioned, m])
            print(f"  deflate {m}: CG {plain}, PCG {preconditioned}", flush=True)
        ops.destroy()
        problem.destroy()
    exponent_k = np.polyfit(np.log(args.sizes), np.log(series["K"]), 1)[0] if len(args.sizes) > 1 else np.nan
    exponent_bk = np.polyfit(np.log(args.sizes), np.log(series["BK"]), 1)[0] if len(args.sizes) > 1 else np.nan
    plot(args.sizes, series)
    text = [
        "# Conditioning of K on the contact set, and what preconditioning and deflation do",
        "",
        f"Group #1 surface (the dissertation, 1), p* = {args.pstar}, contact set C of the converged solution (PK to 1e-12). "
        "Extreme eigenvalues by SLEPc Krylov-Schur (tolerance 1e-8); the last column checks the condition numbers "
        "against a dense eigen-decomposition where |C| <= 3000. Scaled units (rms height 1, cell length 1, E* = 1).",
        "",
        common.markdown_table(["N", "|C|", "lambda_min(K_CC)", "lambda_max(K_CC)", "cond(K_CC)",
                               "lambda_min(B K)", "lambda_max(B K)", "cond(B K)", "dense check K / BK"], rows),
        "",
        f"Growth with N: cond(K_CC) ~ N^{exponent_k:.2f}, cond(B_C K_CC) ~ N^{exponent_bk:.2f}. CG iterations grow "
        f"like sqrt(cond): N^{exponent_k / 2:.2f} plain, N^{exponent_bk / 2:.2f} preconditioned (plus the "
        "active-set changes of the contact iteration, which restart CG).",
        "",
        "## Deflation by coarse-grid vectors",
        "",
        "CG / preconditioned CG on the fixed contact set (K_CC p = h_C - d) to a relative residual of 1e-8, with "
        "the indicators of C on the m blocks of a coarse grid deflated (Vollebregt 2014). The deflation space "
        "costs m extra operator applications to build (K Z), once per contact set.",
        "",
        common.markdown_table(["N", "m deflated", "CG iterations", "PCG iterations", "applications for K Z"],
                              deflation_rows),
        "",
        "![condition numbers](conditioning.png)",
        "",
        f"Regenerate: `.venv/bin/python studies/conditioning.py --sizes {' '.join(map(str, args.sizes))} "
        f"--pstar {args.pstar:g} --deflate {' '.join(map(str, args.deflate))}`",
        "",
    ]
    with open(os.path.join(OUT, "conditioning.md"), "w") as f:
        f.write("\n".join(text))
    print("\n".join(text))


def coarse_basis(n, free, m):
    """Indicators of the contact set on the blocks of a sqrt(m) x sqrt(m) coarse grid, as columns."""
    blocks = int(round(np.sqrt(m)))
    rows, cols = np.divmod(free, n)
    block = (rows * blocks // n) * blocks + cols * blocks // n
    basis = np.zeros((len(free), blocks * blocks))
    basis[np.arange(len(free)), block] = 1.0
    return basis[:, basis.any(axis=0)]


def plot(sizes, series):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axis = plt.subplots(figsize=(6, 4.5))
    axis.loglog(sizes, series["K"], "o-", label="cond(K_CC) (plain PK)")
    axis.loglog(sizes, series["BK"], "s-", label="cond(B_C K_CC) (Fourier preconditioner)")
    axis.set_xlabel("N")
    axis.set_ylabel("condition number on the contact set")
    axis.grid(alpha=0.3, which="both")
    axis.legend()
    common.save_figure(fig, OUT, "conditioning.png")


if __name__ == "__main__":
    sys.exit(main())
