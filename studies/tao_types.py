"""Every TAO bound type on the displacement-controlled QP against Polonsky-Keer (the check of tests/test_tao_types.py, printed).

    .venv/bin/python studies/tao_types.py [rtol]

128^2 group-#1 surface (the dissertation, 1), p* = 0.5: PK to 1e-12 gives d; each type then solves at that d to rtol
(default 1e-8). Prints natural residual, iterations, operator applications, seconds, reason and
max|p - p_PK| / max p_PK.
"""
import sys, math
import petsc4py
petsc4py.init([sys.argv[0]])
from petsc4py import PETSc
import numpy as np
from roughpetsc import ContactProblem, Grid, Solver, fractal, fractal_group
grid = Grid(128, 128)
group = fractal_group(1)
h = fractal(grid, group["k_l"], group["k_s"], group["hurst"], group["m2"], 1)
prob = ContactProblem(grid, h, 1.0, PETSc.COMM_SELF, fft_effort="FFTW_ESTIMATE")
rtol = float(sys.argv[1]) if len(sys.argv) > 1 else 1e-8
s = Solver(prob, "load", None, 1e-12)
r = s.solve(pstar=0.5)
pref = s.fields()[0].copy()
s.destroy()
print('pk', r.kkt.natural, r.iterations, r.separation)
for t in ['blmvm','bqnls','bncg','bqnkls','bqnktr','bnls','bntr','tron','gpcg']:
    s = Solver(prob, 'displacement', t, rtol)
    res = s.solve(gbar=r.separation)
    p = s.fields()[0]
    print(f"{t:8s} {res.kkt.natural:9.2e} its={res.iterations:5d} apps={res.operator_applications:5d} t={res.time_s:6.2f} {res.reason:25s} dp={abs(p-pref).max()/pref.max():.2e}", flush=True)
    s.destroy()
prob.destroy()
