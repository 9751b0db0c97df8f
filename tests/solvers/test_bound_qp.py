"""TAO's bound types (roughpetsc/solvers/bound_qp.py: the augmented Lagrangian under load control, the Fourier initial
Hessian, fused callbacks) against Polonsky-Keer, a second algorithm, and their fused loops against numpy."""

import json
import math
import os
import re
import sys

import numpy as np
import pytest
from petsc4py import PETSc

from roughpetsc.contact import loops
from roughpetsc.contact.certificate import report
from roughpetsc.solvers import Solver, bound_qp
from roughpetsc.solvers.preconditioner import FourierPreconditioner

from conftest import MPI_ENV, ROOT, run_process
from test_tao_types import _pk_reference

TWO_RANKS = """
import json, sys
import petsc4py; petsc4py.init(sys.argv[:1])
from petsc4py import PETSc
from roughpetsc import ContactProblem, Grid, Solver, fractal
grid = Grid(64, 64)
problem = ContactProblem(grid, fractal(grid, 4, 16, 0.8, 2e-4, 7), 1.0, PETSc.COMM_WORLD, fft_effort="FFTW_ESTIMATE")
out = {}
for control, tao_type, method in (("load", "blmvm", "al"), ("load", "tron", "al"), ("load", "blmvm", "gap"),
                                  ("load", "tron", "gap"), ("displacement", "bqnls", "al")):
    solver = Solver(problem, control, tao_type, 1e-8, options={"bound_load": method})
    result = solver.solve(pstar=0.5) if control == "load" else solver.solve(gbar=3e-5)
    out[tao_type + " " + method] = [result.converged, result.pstar, result.A, result.separation]
    solver.destroy()
if PETSc.COMM_WORLD.getRank() == 0:
    print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def reference():
    """Polonsky-Keer (a second algorithm) under load control at p* = 0.5 on a 64^2 fractal surface, to 1e-12."""
    problem, result, pressure = _pk_reference(64, 4, 16)
    yield problem, result, pressure
    problem.destroy()


# GPCG under load control is left out here: its projected search stalls near 5e-8 at p* >= 0.5 on some FFTW plans
# (studies/output/tao_speed), which the next test holds it to report.
@pytest.mark.parametrize("control, tao_type", [(control, tao_type) for control in ("load", "displacement")
                                               for tao_type in ("blmvm", "bqnls", "tron", "gpcg")
                                               if (control, tao_type) != ("load", "gpcg")])
def test_bound_type_reaches_the_pk_pressure(reference, tao_type, control):
    problem, pk, pressure = reference
    solver = Solver(problem, control, tao_type, 1e-8, options={"bound_load": "al"})
    try:
        result = solver.solve(pstar=0.5) if control == "load" else solver.solve(gbar=pk.separation)
        assert result.converged, result.reason
        assert result.kkt.natural <= 1e-8
        if control == "load":
            assert result.kkt.load_error <= 1e-8
            assert result.separation == pytest.approx(pk.separation, rel=1e-6)
        assert np.abs(solver.fields()[0] - pressure).max() <= 1e-6 * np.abs(pressure).max()
    finally:
        solver.destroy()


def test_gpcg_under_load_converges_or_reports_the_residual_it_reached(reference):
    """At p* = 0.5 GPCG may stop at its floor (its result then says so with the certified figures), or converge."""
    problem, pk, pressure = reference
    solver = Solver(problem, "load", "gpcg", 1e-8, options={"bound_load": "al"})
    try:
        result = solver.solve(pstar=0.5)
        fields = solver.fields()[0]
    finally:
        solver.destroy()
    if result.converged:
        assert result.kkt.natural <= 1e-8 and result.kkt.load_error <= 1e-8
        assert np.abs(fields - pressure).max() <= 1e-6 * np.abs(pressure).max()
    else:
        # the reason quotes the certified figures to two digits ("1e-07" for 1.0e-07)
        quoted = {name: float(value) for name, value in
                  re.findall(r"(natural residual|load error) ([0-9.]+(?:e[-+]?[0-9]+)?)", result.reason)}
        assert quoted["natural residual"] == pytest.approx(result.kkt.natural, rel=0.05), result.reason
        assert quoted["load error"] == pytest.approx(result.kkt.load_error, rel=0.05), result.reason
        assert result.kkt.natural <= 1e-6  # a floor, not a divergence
        assert np.abs(fields - pressure).max() <= 1e-4 * np.abs(pressure).max()


def test_a_load_path_reuses_the_separation(reference):
    """Along loads the previous separation starts lambda: each later load needs fewer inner solves than a cold one."""
    problem, _, _ = reference
    solver = Solver(problem, "load", "blmvm", 1e-8, options={"bound_load": "al"})
    try:
        results = [solver.solve(pstar=pstar) for pstar in (0.4, 0.45, 0.5)]
    finally:
        solver.destroy()
    assert all(r.converged for r in results), [r.reason for r in results]
    inner = [int(r.reason.split("(")[1].split()[0]) for r in results]
    assert inner[1] <= inner[0] and inner[2] <= inner[0]


def test_contact_stiffness_matches_a_difference_of_pk_solves(reference):
    """k = -dP/dd of the solution against a central difference of two displacement-controlled PK solves."""
    problem, pk, _ = reference
    d = pk.separation / problem.height_scale
    loads = []
    for step in (-1e-5, 1e-5):
        solver = Solver(problem, "displacement", None, 1e-13)
        result = solver.solve(gbar=(d + step) * problem.height_scale)
        loads.append(result.pbar / problem.pressure_scale)
        solver.destroy()
    difference = -(loads[1] - loads[0]) / 2e-5
    solver = Solver(problem, "displacement", None, 1e-13)
    solver.solve(gbar=pk.separation)
    preconditioner = FourierPreconditioner(problem)
    try:
        stiffness = bound_qp.contact_stiffness(problem, solver.pressure, preconditioner, rtol=1e-10, max_it=200)
    finally:
        preconditioner.destroy()
        solver.destroy()
    assert stiffness == pytest.approx(difference, rel=1e-3)


def test_a_multiplier_out_of_contact_moves_to_where_the_surfaces_touch():
    # P = 0 at d = 3: log P has no slope there, and lambda <- d would move by only c pbar per inner solve.
    assert bound_qp.next_multiplier([(0.5, 2.0), (3.0, 0.0)], 1.0, 3.0, touch=1.5) == 1.5
    # Inside the bracket of the pairs, else their midpoint.
    assert bound_qp.next_multiplier([(1.6, 2.0), (3.0, 0.0)], 1.0, 3.0, touch=1.5) == pytest.approx(2.3)


@pytest.mark.parametrize("upper", [math.inf, 0.7])
def test_fused_natural_residual_is_that_of_report(upper):
    rng = np.random.default_rng(3)
    p = np.maximum(rng.normal(0.3, 0.5, 1000), 0.0)
    gap = rng.normal(0.0, 0.2, 1000)
    copy = np.empty_like(p)
    natural = loops.natural_and_copy(p, gap, 0.4, upper, copy)
    expected = report(PETSc.COMM_SELF.tompi4py(), p, gap, p.size, 0.4, None if math.isinf(upper) else upper)
    assert natural == pytest.approx(expected.natural, rel=1e-14)
    assert np.array_equal(copy, p)


def test_fused_gradient_step_is_the_exact_increment_of_a_quadratic():
    """(x - r)'(g(x) + g(r)) / 2 equals f(x) - f(r) of f = x'Ax/2 - b'x with g = Ax - b."""
    rng = np.random.default_rng(5)
    a = rng.normal(size=(50, 50))
    a = a @ a.T
    b, r, x = rng.normal(size=50), rng.normal(size=50), rng.normal(size=50)
    point, cached = r.copy(), a @ r - b
    out = np.empty(50)
    before, after, total = loops.gradient_step(x, point, cached, a @ x, b, 0.0, out, True)
    f = lambda v: 0.5 * v @ a @ v - b @ v
    assert 0.5 * (before + after) == pytest.approx(f(x) - f(r), rel=1e-10)
    assert np.allclose(out, a @ x - b) and np.array_equal(point, x) and total == pytest.approx(x.sum())


@pytest.mark.mpi
def test_two_ranks_equal_one():
    """The same solves on 1 and 2 ranks: converged, the same load, area and separation to the solver tolerance."""
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=ROOT, OPENBLAS_NUM_THREADS="1")
    results = []
    for ranks in (1, 2):
        command = [sys.executable, "-c", TWO_RANKS]
        if ranks > 1:
            command = ["mpiexec", "-n", "2", "--oversubscribe", *command]
        done = run_process(command, env=env, cwd=ROOT)
        assert done.returncode == 0, done.stderr[-2000:]
        results.append(json.loads(done.stdout.strip().splitlines()[-1]))
    for name, (converged, pstar, area, separation) in results[0].items():
        other = results[1][name]
        assert converged and other[0], name
        assert other[1] == pytest.approx(pstar, rel=1e-7)
        assert other[2] == pytest.approx(area, abs=2.0 / 64 ** 2)
        assert other[3] == pytest.approx(separation, rel=1e-6)
