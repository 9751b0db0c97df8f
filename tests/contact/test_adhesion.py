"""Adhesive contact in the periodic BEM (roughpetsc.contact.AdhesiveProblem through the Solver facade) against closed forms.

References: Derjaguin's approximation, exact for a paraboloid against a flat when the bodies are rigid
(the force at closest gap D is 2 pi R (-phi(D)) for any law phi); the first-order conditions of
the adhesive problem checked with numpy's FFT alone; the closed forms of roughpetsc.models where
they apply.
"""

import contextlib
import json
import math
import os
import sys

import numpy as np
import pytest

import h5py

from conftest import MPI_ENV, ROOT, applications_at_time_limit, assert_one_clear_error, run_cli, run_process
from roughpetsc.contact import AdhesiveProblem, approach_retraction, dissipated_energy
from roughpetsc.solvers import Solver, drive
from roughpetsc.contact.problem import ContactProblem
from roughpetsc.errors import ParameterError
from roughpetsc.contact.laws import Dugdale, Exponential, make_law
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import fractal

RADIUS = 1.0


def sphere(n, length=1.0):
    x = (np.arange(n) - n / 2) * length / n
    xx, yy = np.meshgrid(x, x, indexing="ij")
    return Grid(n, n, length, length), -(xx ** 2 + yy ** 2) / (2 * RADIUS)


@contextlib.contextmanager
def adhesive_problem(grid, heights, E_star, law, rtol, **solver):
    """The Solver of an :class:`AdhesiveProblem` on a periodic problem (mean gaps), destroyed with it afterwards."""
    problem = ContactProblem(grid, heights, E_star, fft_effort="FFTW_ESTIMATE")
    adhesive = Solver(AdhesiveProblem(problem, law), "displacement", rtol=rtol, **solver)
    try:
        yield adhesive
    finally:
        adhesive.destroy()
        problem.destroy()


def path(solver, gbars):
    """The results of ``solver`` along the mean gaps ``gbars`` (the load-path driver)."""
    return drive(solver, [("gbar", gbar) for gbar in gbars])


def numpy_residuals(grid, heights, E_star, law, gbar, pbar, gap):
    """Equilibrium out of contact and the sign of the contact pressure, from the gap with numpy alone.

    u = g - gbar + h (zero mean), p = F^-1[pi E* |k| F[u]] + pbar. Out of contact p must be the law's
    traction -phi'(g); in contact the contact pressure p + phi'(0) must be >= 0. Both relative to
    sqrt(m0^p) of the surface.
    """
    h = heights - heights.mean()
    k0 = np.fft.fftfreq(grid.n0, grid.l0 / grid.n0)
    k1 = np.fft.fftfreq(grid.n1, grid.l1 / grid.n1)
    k = np.hypot(*np.meshgrid(k0, k1, indexing="ij"))
    u = gap - gbar + h
    pressure = np.fft.ifft2(np.pi * E_star * k * np.fft.fft2(u)).real + pbar
    scale = np.sqrt(np.mean(np.fft.ifft2(np.pi * E_star * k * np.fft.fft2(h)).real ** 2))
    out = gap > 0
    traction = -law.force(gap)
    equilibrium = np.abs(pressure - traction)[out].max() / scale
    contact_pressure = (pressure + law.force(np.zeros(1)))[~out]
    worst_contact = contact_pressure.min() / scale if contact_pressure.size else 0.0
    return equilibrium, worst_contact


def test_rigid_sphere_meets_derjaguin():
    """A stiff sphere out of contact: the force is 2 pi R w exp(-D / rho) (Derjaguin, exact for a paraboloid)."""
    grid, heights = sphere(128)
    work, range_ = 1e-3, 1e-3
    top = (heights - heights.mean()).max()
    with adhesive_problem(grid, heights, 1e7, Exponential(work, range_), 1e-10) as adhesive:
        for closest in (3 * range_, range_, 0.2 * range_):
            result = adhesive.solve(gbar=closest + top)
            assert result.converged, result.reason
            force = result.pbar * grid.area
            derjaguin = -2 * math.pi * RADIUS * work * math.exp(-closest / range_)
            assert force == pytest.approx(derjaguin, rel=1e-4)
            assert result.A == 0


@pytest.mark.parametrize("law", [Exponential(5e-5, 1e-3), Dugdale(5e-5, 5e-2)])
def test_rough_adhesive_solution_meets_its_first_order_conditions(law):
    """A rough surface in adhesive contact: the numpy check of equilibrium and of the contact pressure sign."""
    grid = Grid(64, 64, 1.0, 1.0)
    heights = fractal(grid, 2, 16, 0.8, 1e-2, seed=3)  # rms height 5.2e-3
    E_star = 1.0
    with adhesive_problem(grid, heights, E_star, law, 1e-10) as adhesive:
        for gbar in (1e-2, 7e-3, 5e-3):
            result = adhesive.solve(gbar=gbar)
            assert result.converged, result.reason
            pressure, gap = adhesive.fields()
            assert gap.min() >= 0 and gap.mean() == pytest.approx(gbar, rel=1e-12)
            assert pressure.mean() == pytest.approx(result.pbar, rel=1e-9, abs=1e-12)
            equilibrium, worst_contact = numpy_residuals(grid, heights, E_star, law, gbar, result.pbar, gap)
            assert equilibrium < 1e-9 and worst_contact > -1e-9
            assert 0 < result.A < 1


def test_approach_and_retraction_differ_and_dissipate():
    """Under displacement control the sphere jumps into contact on approach and sticks on retraction."""
    grid, heights = sphere(128)
    work, stress = 1e-5, 2e-2
    top = (heights - heights.mean()).max()
    gbars = top + approach_retraction(2e-3, -2e-3, 20)
    with adhesive_problem(grid, heights, 1.0, Dugdale(work, stress), 1e-9) as adhesive:
        results = list(path(adhesive, gbars))
    assert all(r.converged for r in results), [r.reason for r in results if not r.converged]
    pbars = np.array([r.pbar for r in results])
    areas = np.array([r.A for r in results])
    approach, retraction = areas[:21], areas[20:][::-1]
    # At equal mean gap the retracting contact is at least as large, and strictly larger somewhere.
    assert np.all(retraction >= approach) and np.any(retraction > approach)
    assert dissipated_energy(gbars, pbars) > 0


def test_a_path_resumed_from_a_saved_gap_stays_on_its_branch():
    """A retraction taken up again from the gap of its last step (a checkpoint) follows the uninterrupted path;
    a fresh solver at the same mean gaps falls onto the approach branch, with less contact."""
    grid, heights = sphere(64)
    work, stress = 1e-5, 2e-2
    gbars = (heights - heights.mean()).max() + approach_retraction(2e-3, -2e-3, 12)
    resumed_at = 16  # four steps into the retraction, where the contact sticks
    with adhesive_problem(grid, heights, 1.0, Dugdale(work, stress), 1e-10) as adhesive:
        whole = list(path(adhesive, gbars))
    with adhesive_problem(grid, heights, 1.0, Dugdale(work, stress), 1e-10) as adhesive:
        list(path(adhesive, gbars[:resumed_at]))
        saved = adhesive.fields()[1].copy()
    with adhesive_problem(grid, heights, 1.0, Dugdale(work, stress), 1e-10) as adhesive:
        adhesive.resume(saved)
        rest = list(path(adhesive, gbars[resumed_at:]))
    with adhesive_problem(grid, heights, 1.0, Dugdale(work, stress), 1e-10) as adhesive:
        fresh = adhesive.solve(gbar=gbars[resumed_at])
    assert all(r.converged for r in whole + rest + [fresh])
    assert [r.A for r in rest] == [r.A for r in whole[resumed_at:]]
    pbars = np.array([r.pbar for r in whole[resumed_at:]])
    assert np.abs(np.array([r.pbar for r in rest]) - pbars).max() < 1e-8 * np.abs(pbars).max(), pbars
    assert fresh.A < whole[resumed_at].A


def test_resume_refuses_a_pressure_path_and_a_wrong_shape():
    grid, heights = sphere(16)
    problem = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE")
    solvers = [Solver(problem, "load"), Solver(AdhesiveProblem(problem, Dugdale(1e-5, 2e-2)), "displacement")]
    try:
        for solver, shape, message in ((solvers[0], (16, 16), "only an adhesive path"),
                                       (solvers[1], (16, 15), "shape")):
            with pytest.raises(ParameterError, match=message) as error:
                solver.resume(np.zeros(shape))
            assert error.value.parameter == "resume"
    finally:
        for solver in solvers:
            solver.destroy()
        problem.destroy()


def test_bad_parameters_name_the_option():
    grid, heights = sphere(16)
    for make, parameter in ((lambda: Dugdale(-1.0, 1.0), "adhesion_work"),
                            (lambda: Exponential(1.0, 0.0), "adhesion_range"),
                            (lambda: make_law("lennard-jones", 1.0, 1.0), "adhesion")):
        with pytest.raises(ParameterError) as error:
            make()
        assert error.value.parameter == parameter
    problem = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE", boundary="free")
    try:
        with pytest.raises(ParameterError, match="periodic"):
            AdhesiveProblem(problem, Exponential(1e-3, 1e-3))
    finally:
        problem.destroy()


RANKS_SCRIPT = """
import sys
import numpy as np
import petsc4py
petsc4py.init()
from petsc4py import PETSc
from roughpetsc.contact import AdhesiveProblem
from roughpetsc.contact.problem import ContactProblem
from roughpetsc.solvers import Solver
from roughpetsc.contact.laws import Exponential
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import fractal
grid = Grid(45, 32, 1.0, 1.0)
heights = fractal(grid, 2, 10, 0.8, 1e-2, seed=5)
problem = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE")
adhesive = Solver(AdhesiveProblem(problem, Exponential(5e-5, 1e-3)), "displacement", rtol=1e-11)
rows = []
for gbar in (1e-2, 6e-3):
    result = adhesive.solve(gbar=gbar)
    assert result.converged, result.reason
    pressure, gap = adhesive.fields()
    rows.append((result.pbar, result.A, np.concatenate(problem.mpi.allgather(pressure))))
if problem.mpi.Get_rank() == 0:
    np.savez(sys.argv[1], pbar=[r[0] for r in rows], A=[r[1] for r in rows], pressure=[r[2] for r in rows])
adhesive.destroy()
problem.destroy()
"""


@pytest.mark.mpi
@pytest.mark.slow
def test_two_and_three_ranks_equal_one_rank(tmp_path):
    script = tmp_path / "ranks.py"
    script.write_text(RANKS_SCRIPT)
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    answers = []
    for ranks in (1, 2, 3):
        out = tmp_path / f"r{ranks}.npz"
        command = [sys.executable, str(script), str(out)]
        if ranks > 1:
            command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
        run = run_process(command, env=env)
        assert run.returncode == 0, run.stdout + run.stderr
        answers.append(np.load(out))
    for other in answers[1:]:
        assert np.array_equal(other["A"], answers[0]["A"])
        assert np.allclose(other["pbar"], answers[0]["pbar"], rtol=1e-9, atol=0)
        scale = np.abs(answers[0]["pressure"]).max()
        assert np.abs(other["pressure"] - answers[0]["pressure"]).max() < 1e-9 * scale


@pytest.mark.mpi
def test_command_line_cycle_on_two_ranks_equals_one_rank(tmp_path):
    """-adhesion with -gbar_list: approach and retraction, the HDF5 record, 2 ranks equal to 1.

    The path stops before the contact snaps out: after a snap the branch the iterates fall into may
    depend on round-off (two local minima of a non-convex energy), and ranks change the round-off.
    """
    args = ["-surface_N", 48, "-surface_ks", 12, "-surface_kl", 2, "-adhesion", "exponential",
            "-adhesion_work", 2e-7, "-adhesion_range", 2e-5, "-gbar_list", "2e-4,1e-4,5e-5,1e-4",
            "-kkt_rtol", 1e-11, "-fft_effort", "FFTW_ESTIMATE"]
    runs = []
    for ranks in (1, 2):
        path = tmp_path / f"cycle{ranks}.h5"
        out = run_cli(args + ["-output", path], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        assert "Tabor parameter" in out.stdout
        with h5py.File(path) as f:
            assert '"law": "exponential"' in f.attrs["adhesion"]
            steps = [f[f"steps/{i:03d}"].attrs for i in range(4)]
            runs.append(([s["pbar"] for s in steps], [s["A"] for s in steps], f["pressure"][()]))
    (pbar1, area1, p1), (pbar2, area2, p2) = runs
    assert area1 == area2 and np.allclose(pbar1, pbar2, rtol=1e-8, atol=0)
    assert np.abs(p1 - p2).max() < 1e-8 * np.abs(p1).max()
    # Retraction holds more contact and less pressure than approach at the same mean gap (steps 1 and 3).
    assert area1[3] > area1[1] and pbar1[3] < pbar1[1]


def test_command_line_cycle_reports_its_dissipated_energy(tmp_path):
    """A -gbar_list that returns to its start is a cycle: the energy it dissipated is said and recorded."""
    path = tmp_path / "cycle.h5"
    out = run_cli(["-surface_N", 48, "-surface_ks", 12, "-surface_kl", 2, "-adhesion", "exponential",
                   "-adhesion_work", 2e-7, "-adhesion_range", 2e-5, "-gbar_list", "2e-4,1e-4,5e-5,1e-4,2e-4",
                   "-fft_effort", "FFTW_ESTIMATE", "-output", path])
    assert out.returncode == 0, out.stdout + out.stderr
    assert "energy dissipated per unit area" in out.stdout
    with h5py.File(path) as f:
        recorded = json.loads(f.attrs["adhesion"])["dissipated_energy"]
        steps = [f[f"steps/{i:03d}"].attrs for i in range(5)]
        gbars, pbars = [s["gbar"] for s in steps], [s["pbar"] for s in steps]
    assert recorded == pytest.approx(dissipated_energy(gbars, pbars), rel=1e-12) and recorded > 0


CYCLE = ["-surface_N", 48, "-surface_ks", 12, "-surface_kl", 2, "-adhesion", "exponential", "-adhesion_work", 2e-7,
         "-adhesion_range", 2e-5, "-kkt_rtol", 1e-11, "-fft_effort", "FFTW_ESTIMATE"]


def recorded_steps(path):
    with h5py.File(path) as f:
        return [dict(f[f"steps/{i:03d}"].attrs) for i in range(len(f["steps"]))]


@pytest.mark.parametrize("ranks", [1, pytest.param(2, marks=pytest.mark.mpi)])
def test_command_line_resume_continues_a_cycle_on_its_branch(tmp_path, ranks):
    """-resume of an adhesive path continues from the gap of its last saved step: the retraction it solves then
    is the uninterrupted run's, and a path started afresh at those mean gaps holds less contact."""
    loads = "2e-4,1e-4,5e-5,1e-4,2e-4"
    whole = run_cli(CYCLE + ["-gbar_list", loads, "-output", tmp_path / "whole.h5"])
    part = run_cli(CYCLE + ["-gbar_list", "2e-4,1e-4,5e-5", "-output", tmp_path / "part.h5"], ranks=ranks)
    rest = run_cli(CYCLE + ["-gbar_list", loads, "-output", tmp_path / "part.h5", "-resume"], ranks=ranks)
    fresh = run_cli(CYCLE + ["-gbar_list", "1e-4", "-output", tmp_path / "fresh.h5"])
    for out in (whole, part, rest, fresh):
        assert out.returncode == 0, out.stdout + out.stderr
    assert rest.stdout.count(f"(from {tmp_path / 'part.h5'})") == 3
    expected, resumed = recorded_steps(tmp_path / "whole.h5"), recorded_steps(tmp_path / "part.h5")
    assert [s["gbar"] for s in resumed] == [s["gbar"] for s in expected]
    assert [s["A"] for s in resumed] == [s["A"] for s in expected]
    pbars = np.array([s["pbar"] for s in expected])
    assert np.abs(np.array([s["pbar"] for s in resumed]) - pbars).max() < 1e-8 * np.abs(pbars).max()
    assert "energy dissipated per unit area" in rest.stdout
    assert recorded_steps(tmp_path / "fresh.h5")[0]["A"] < expected[3]["A"]  # the approach branch


def test_command_line_resume_of_an_adhesive_path_without_its_gap_is_refused(tmp_path):
    part = run_cli(CYCLE + ["-gbar_list", "2e-4,1e-4", "-output", tmp_path / "part.h5", "-output_fields", "none"])
    assert part.returncode == 0, part.stderr
    kept = (tmp_path / "part.h5").read_bytes()
    out = run_cli(CYCLE + ["-gbar_list", "2e-4,1e-4,5e-5", "-output", tmp_path / "part.h5", "-resume"])
    assert_one_clear_error(out, "-resume", "part.h5", "does not hold the gap of step 2", "-output_fields all")
    assert (tmp_path / "part.h5").read_bytes() == kept


def test_command_line_resume_extends_a_finished_cycle(tmp_path):
    """A cycle's file records its dissipated energy with the law; the same law extends it all the same."""
    cycle = run_cli(CYCLE + ["-gbar_list", "2e-4,1e-4,5e-5,2e-4", "-output", tmp_path / "c.h5"])
    assert cycle.returncode == 0 and "energy dissipated" in cycle.stdout, cycle.stderr
    out = run_cli(CYCLE + ["-gbar_list", "2e-4,1e-4,5e-5,2e-4,1e-4", "-output", tmp_path / "c.h5", "-resume"])
    assert out.returncode == 0, out.stderr
    assert [s["gbar"] for s in recorded_steps(tmp_path / "c.h5")] == [2e-4, 1e-4, 5e-5, 2e-4, 1e-4]
    with h5py.File(tmp_path / "c.h5") as f:
        assert "dissipated_energy" not in json.loads(f.attrs["adhesion"])  # no longer a closed cycle


def test_command_line_resume_with_another_adhesion_law_is_refused(tmp_path):
    part = run_cli(CYCLE + ["-gbar_list", "2e-4,1e-4", "-output", tmp_path / "part.h5"])
    assert part.returncode == 0, part.stderr
    other = [3e-7 if value == 2e-7 else value for value in CYCLE]
    out = run_cli(other + ["-gbar_list", "2e-4,1e-4,5e-5", "-output", tmp_path / "part.h5", "-resume"])
    assert_one_clear_error(out, "-resume", "part.h5", "another problem (different adhesion)")


def test_tao_almm_meets_the_gap_cg():
    """A second algorithm: TAO ALMM with the mean-gap equality reaches the projected CG's solution.

    Weak exponential adhesion, where the local minimum next to both starts is the same one.
    """
    grid = Grid(32, 32, 1.0, 1.0)
    heights = fractal(grid, 2, 8, 0.8, 1e-2, seed=4)
    law = Exponential(5e-6, 1e-3)
    answers = []
    for solver in ("gapcg", "almm"):
        problem = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE")
        adhesive = Solver(AdhesiveProblem(problem, law), "displacement", solver, rtol=1e-9)
        try:
            result = adhesive.solve(gbar=8e-3)
            assert result.converged, result.reason
            answers.append((result, adhesive.fields()[0]))
        finally:
            adhesive.destroy()
            problem.destroy()
    (cg, p_cg), (almm, p_almm) = answers
    assert almm.A == cg.A and almm.A > 0
    assert np.abs(p_almm - p_cg).max() < 1e-7 * np.abs(p_cg).max()
    assert almm.pbar == pytest.approx(cg.pbar, rel=1e-7)


def dugdale_wave_path(n, alpha, range_over_amplitude, steps=40, ramp_cells=0):
    """Approach and retraction of Johnson's wave (lambda = 1, h = 1e-3, E* = 1) with the Dugdale law on n nodes,
    ``steps`` each way; its stress ramped over the gap's change across ``ramp_cells`` spacings at the wave's
    steepest slope (0: the step)."""
    from roughpetsc.surface.generators import wave

    amplitude = 1e-3
    work = alpha ** 2 * math.pi ** 2 * amplitude ** 2 / 2  # Johnson's alpha = sqrt(2 lambda w / (pi^2 E* h^2))
    stress = work / (range_over_amplitude * amplitude)
    grid = Grid(4, n, 4.0 / n, 1.0)
    law = Dugdale(work, stress, ramp_cells / n * 2 * math.pi * amplitude)
    with adhesive_problem(grid, wave(grid, amplitude, 1.0), 1.0, law, 1e-10) as adhesive:
        results = list(path(adhesive, approach_retraction(2.2 * amplitude, 0.05 * amplitude, steps)))
    assert all(r.converged for r in results), [r.reason for r in results if not r.converged]
    return work, stress, results


def test_dugdale_wave_meets_maugis_dugdale_wave():
    """Johnson's wave with the Dugdale law against the Maugis-Dugdale wave of roughpetsc.models.wavy_adhesion.

    Every contact state of the path (mean gap, mean pressure) lies on the closed-form solution set, and the
    least mean pressure of the path is its pull-off; the discretisation error falls at order 0.7-0.95 (measured
    pull-off errors 4.3 %, 2.7 %, 1.4 %, 0.8 % at N = 1024 ... 8192), so N = 4096 is held to 2.5 %.
    """
    from roughpetsc.models.wavy_adhesion import WavyMaugisDugdale

    amplitude = 1e-3
    work, stress, results = dugdale_wave_path(4096, 0.3, 0.1)
    model = WavyMaugisDugdale(1.0, amplitude, 1.0, work, stress)
    curve = model.curve(2000)
    for result in results:
        if result.A > 0:
            distance = np.min(np.hypot((result.gbar - curve["gbar"]) / amplitude,
                                       (result.pbar - curve["pbar"]) / model.pstar))
            assert distance < 0.01, (result.gbar, result.pbar)
    pull_off = min(r.pbar for r in results)
    assert pull_off == pytest.approx(model.pulloff()[0], rel=0.025)


def test_a_ramped_dugdale_stress_brings_the_wave_closer_to_maugis_dugdale():
    """Johnson's wave at alpha = 0.5, h0 = 0.1 h (Maugis's lambda 3.8) on 512 nodes: the step law's pull-off is
    17.6 % off the Maugis-Dugdale wave's, the law with its stress ramped over 10 spacings' change of the gap 0.7 %
    (studies/output/adhesion/wave.md: 0.83 %, 0.17 %, 0.023 % at N = 2048, 8192, 32768, against 6.9 %, 2.2 %,
    0.65 % for the step). Every state of both paths is certified, to second order for the ramp."""
    from roughpetsc.models.wavy_adhesion import WavyMaugisDugdale

    errors = {}
    for cells in (0, 10):
        work, stress, results = dugdale_wave_path(512, 0.5, 0.1, 60, ramp_cells=cells)
        reference = WavyMaugisDugdale(1.0, 1e-3, 1.0, work, stress).pulloff()[0]
        errors[cells] = min(r.pbar for r in results) / reference - 1
    assert errors[0] > 0.1
    assert abs(errors[10]) < 0.015


def test_retraction_descends_to_the_maugis_dugdale_snap_off():
    """Johnson's wave (alpha = 0.5, h0 = 0.1 h: Maugis's lambda 3.8) jumps into contact at gbar = h and is
    retracted past its snap-off. The energy never rises from one iteration of the gap CG to the next (a step
    across g = 0 once landed, after the projection, in a wider contact of higher energy: at the first iteration
    of each of the 24 retraction steps here), every solve ends below the energy of its start, the previous gap
    shifted by the step, and the contact snaps off at the largest mean gap of the Maugis-Dugdale solution set,
    1.677 h, within the grid's error (measured: 1.690 h at N = 2048) and the path's step.
    """
    from roughpetsc.models.wavy_adhesion import WavyMaugisDugdale
    from roughpetsc.surface.generators import wave

    amplitude, step, n = 1e-3, 3e-5, 2048
    work = 0.5 ** 2 * math.pi ** 2 * amplitude ** 2 / 2
    stress = work / (0.1 * amplitude)
    grid = Grid(4, n, 4.0 / n, 1.0)
    with adhesive_problem(grid, wave(grid, amplitude, 1.0), 1.0, Dugdale(work, stress), 1e-10) as adhesive:
        problem, energies = adhesive.problem, []
        rises = []

        def energy_at_each_iteration(iteration, natural, seconds):
            gap = problem.local(adhesive.path.unknown, readonly=True) * problem.height_scale
            energies.append(problem.energy_of(gap))
            if iteration > 0 and energies[-1] > energies[-2] + 1e-10 * abs(energies[-2]):
                rises.append((result.gbar, iteration, energies[-1] - energies[-2]))

        result = adhesive.solve(gbar=amplitude)
        problem.progress = energy_at_each_iteration
        while result.A > 0:
            start = problem.energy_of(adhesive.fields()[1] + step)
            energies.clear()
            result = adhesive.solve(gbar=result.gbar + step)
            assert result.converged, result.reason
            assert problem.energy_of(adhesive.fields()[1]) <= start
        assert not rises
    curve = WavyMaugisDugdale(1.0, amplitude, 1.0, work, stress).curve(2000)
    assert result.gbar - step == pytest.approx(np.nanmax(curve["gbar"]), abs=0.02 * amplitude + step)


@pytest.mark.parametrize("tabor, radius_0, median_tolerance, pulloff_tolerance",
                         [(0.5, 0.1, 0.05, 0.015), (0.1, 0.05, 0.08, 0.03)])
def test_dugdale_sphere_meets_maugis(tabor, radius_0, median_tolerance, pulloff_tolerance):
    """A sphere with the Dugdale law at Maugis's lambda: P(a) and the pull-off of Maugis-Dugdale.

    R = 1 in a unit cell, N = 256, JKR radius at zero load radius_0. Measured (studies/adhesion_sphere.py,
    which gives the grid and cell sequences): at lambda = 0.5 and radius_0 = 0.1 (25 nodes) pull-off error
    0.8 %, median error of P(a) 0.025 pi w R; at lambda = 0.1, towards DMT (-2 pi w R; Maugis -1.951 pi w R
    here, JKR -1.5), with radius_0 = 0.05 (13 nodes), whose wide cohesive zone needs the smaller sphere
    to keep the periodic images away: 1.8 % and 0.044 pi w R.
    """
    from roughpetsc.models.sphere_adhesion import maugis_parameter, md_curve, md_pulloff

    n = 256
    work = radius_0 ** 3 * 2 / (9 * math.pi)
    stress = tabor / (9 / (2 * math.pi * work)) ** (1 / 3)
    assert maugis_parameter(RADIUS, 1.0, work, stress) == pytest.approx(tabor)
    grid, heights = sphere(n)
    top = (heights - heights.mean()).max()
    gbars = top + approach_retraction(2 * work / stress, -radius_0 ** 2, 30)
    with adhesive_problem(grid, heights, 1.0, Dugdale(work, stress), 1e-9) as adhesive:
        results = list(path(adhesive, gbars))
    assert all(r.converged for r in results)
    scale = math.pi * work * RADIUS
    resolved = [r for r in results if math.sqrt(r.A_corrected / math.pi) > 4 / n]
    radii = np.array([math.sqrt(r.A_corrected / math.pi) for r in resolved])
    errors = np.abs(np.array([r.pbar for r in resolved]) - md_curve(radii, RADIUS, 1.0, work, stress)[0]) / scale
    assert np.median(errors) < median_tolerance
    pulloff = min(r.pbar for r in results)
    assert pulloff == pytest.approx(md_pulloff(RADIUS, 1.0, work, stress), rel=pulloff_tolerance)


def test_penny_shaped_adhesive_crack_meets_the_maugis_dugdale_crack():
    """One adhesive crack of a nearly complete contact against the crack model of sections 6.2-6.3.

    The pressure surface -p_c = -kappa r^2 / 2 + const (periodic distances r from the cell centre, kappa = 1)
    loads the crack with exactly the traction p0 - kappa r^2 / 2 of (6.1); its heights come from
    heights_from_pressure_surface. Dugdale law at sigma0* = 1 (6.6), the unit L of b* (6.4) is 16 nodes.
    Along an opening-closing path in the mean gap every state (p* = (max(-p_c) - pbar) / P, b* from the open
    area) lies on the model's solution set, the full-adhesion branch (6.36) from E (p* = sigma0*, (6.38)) to F
    joined to the Maugis-Dugdale curve (6.28)-(6.29); the trapped volume agrees with the set's. Measured on
    this path: largest distance (in p* / p*_F, b* / b*_F) 0.020 with 10 nodes per L and 0.0097 with 16 (first
    order; studies/adhesion_crack.py gives the grid sequence), median volume error 3.7 % and 2.4 %.
    """
    from roughpetsc.models.adhesion import AdhesiveCrack
    from roughpetsc.surface.spectra import heights_from_pressure_surface

    n, sigma, length = 384, 1.0, 16.0 / 384
    work = 16 * length ** 5 / (81 * math.pi)
    pressure = (math.pi ** 2 * work ** 2 / 72) ** 0.2
    volume_scale = 1.5 * work
    grid = Grid(n, n)
    r = (np.arange(n) - n // 2) / n
    surface = -0.5 * (r[:, None] ** 2 + r[None, :] ** 2)
    surface -= surface.mean()
    crack = AdhesiveCrack(sigma)
    p_set, b_set, _, v_set = crack.solution_set()
    p_f, b_f = crack.points["F"][:2]
    volumes = np.concatenate([np.linspace(0.1, 12.0, 12), [20.0, 40.0, 80.0]]) * volume_scale
    states = []
    with adhesive_problem(grid, heights_from_pressure_surface(grid, -surface), 1.0,
                          Dugdale(work, sigma * pressure), 1e-10) as adhesive:
        for result in path(adhesive, np.concatenate([volumes, volumes[-2::-1]])):
            assert result.converged, result.reason
            gap = adhesive.fields()[1]
            b = math.sqrt((gap > 0).sum() / grid.size / math.pi) / length
            states.append(((surface.max() - result.pbar) / pressure, b, gap.mean() / volume_scale))
    distances, volume_errors = [], []
    for p, b, v in states:
        d = np.hypot((p - p_set) / p_f, (b - b_set) / b_f)
        i = int(np.argmin(d))
        distances.append(d[i])
        volume_errors.append(abs(v - v_set[i]) / v_set[i])
    assert max(distances) < 0.02, distances
    assert np.median(volume_errors) < 0.04
    assert min(p for p, _, _ in states) > sigma  # every crack is open above E (6.38)


def test_two_cracks_fold_the_mean_pressure_where_one_snaps_onto_full_adhesion():
    """Why the adhesive BEM's p*(g*) of a rough surface folds back: two adhesive cracks under displacement control.

    Two paraboloidal dimples of the pressure surface (kappa = 1, heights from heights_from_pressure_surface) in a
    2 x 1 cell, the first deeper by 0.6 P, load each crack with the traction of (6.1); Dugdale law at sigma0* = 2
    (6.6), L of (6.4) 16 nodes. As the mean gap falls, the shallower crack passes its snap-in point and jumps onto
    the full-adhesion branch (6.36) (B -> C of Fig 6.2(b)); at a fixed mean gap its lost volume opens the deeper
    crack, which needs a lower mean pressure: pbar falls while gbar falls. After the jump both cracks lie on the
    crack model at the prescribed volume: the deeper on the Maugis-Dugdale branch, the shallower on (6.36), with
    V1(p1) + V2(p1 - 0.6) = gbar x cell area (in 3 w / (2 kappa)). Measured here: p1 2.8925 against the model's
    2.863 after the jump at V = 12; the BEM holds the shallower crack past B (its p* 2.19 against p*_B = 2.31),
    the resolution error of B that studies/adhesion_crack.py measures (1.2 % at 1024^2 with sigma0* = 2).
    """
    from scipy.optimize import brentq

    from roughpetsc.models.adhesion import AdhesiveCrack, nonadhesive_radius
    from roughpetsc.surface.spectra import heights_from_pressure_surface

    nodes, sigma, depth = 128, 2.0, 0.6
    length = 16.0 / nodes
    work = 16 * length ** 5 / (81 * math.pi)
    pressure = (math.pi ** 2 * work ** 2 / 72) ** 0.2
    volume_scale = 1.5 * work
    grid = Grid(2 * nodes, nodes, 2.0, 1.0)
    x = (np.arange(2 * nodes) + 0.5) / nodes
    y = (np.arange(nodes) + 0.5) / nodes

    def dimple(centre_x, top):
        dx = np.abs(x[:, None] - centre_x)
        dx = np.minimum(dx, 2.0 - dx)
        return top - 0.5 * (dx ** 2 + (y[None, :] - 0.5) ** 2)

    surface = np.maximum(dimple(0.5, depth * pressure), dimple(1.5, 0.0))
    surface -= surface.mean()
    tops = surface[:nodes].max(), surface[nodes:].max()
    crack = AdhesiveCrack(sigma)

    def full_adhesion_volume(p):
        return crack.volume(p, float(nonadhesive_radius(p - sigma)), 0.0)

    def stable_volume(p):
        b, m = crack.stable(np.array([p]))
        return crack.volume(p, b[0], m[0])

    states = []
    with adhesive_problem(grid, heights_from_pressure_surface(grid, -surface), 1.0,
                          Dugdale(work, sigma * pressure), 1e-10) as adhesive:
        volumes = np.arange(16.0, 10.9, -0.5)
        for volume, result in zip(volumes, path(adhesive, volumes * volume_scale / grid.area)):
            assert result.converged, result.reason
            gap = adhesive.fields()[1]
            radii = [math.sqrt((half > 0).sum() / nodes ** 2 / math.pi) / length for half in (gap[:nodes], gap[nodes:])]
            states.append((volume, result.pbar, (tops[0] - result.pbar) / pressure, *radii))
    jumps = np.diff([s[4] for s in states])
    k = int(np.argmin(jumps)) + 1                        # the step where the shallower crack's radius drops most
    volume, pbar, p1, b1, b2 = states[k]
    assert jumps[k - 1] < -0.15 and b2 > 0              # a jump, onto a crack that stays open
    assert pbar < states[k - 1][1]                       # the fold: less pressure at a smaller mean gap
    model_p1 = brentq(lambda p: stable_volume(p) + full_adhesion_volume(p - depth) - volume, sigma + depth + 1e-9, 6.0)
    assert p1 == pytest.approx(model_p1, abs=0.05)
    assert b2 == pytest.approx(float(nonadhesive_radius(p1 - depth - sigma)), abs=0.03)
    assert b1 == pytest.approx(crack.stable(np.array([p1]))[0][0], abs=0.03)


@pytest.mark.slow
def test_dugdale_wave_tends_to_johnsons_jkr_wave():
    """Johnson's wave at alpha = 0.3 with a short Dugdale range (h0 = 0.03 h, Maugis's lambda 6.4 at the crest):
    the JKR limit. The contact half-width against the load follows Johnson's pbar = p* (sin^2 psi - alpha
    sqrt(tan psi)) and the contact snaps off at his mean gap under displacement control.

    The cohesive zone (about E* h0^2 / w = 2e-3 of the wavelength) must be resolved: studies/adhesion_wave.py
    measures the largest error of pbar(a) as 0.080, 0.027 and 0.008 p* at N = 2048, 8192 and 32768 (first
    order) and the snap-off gap 1.430, 1.412, 1.394 h against Johnson's 1.392 h.
    """
    from roughpetsc.models.wavy_adhesion import jkr_mean_pressure, jkr_pulloff_displacement_control

    amplitude, steps = 1e-3, 100  # a mean-gap step of 0.0215 h, below the range: the snap-off is not premature
    work, _, results = dugdale_wave_path(8192, 0.3, 0.03, steps)
    pstar = math.pi * amplitude
    touching = [r for r in results if 0 < r.A < 1]
    radii = np.array([r.A / 2 for r in touching])
    errors = np.abs(np.array([r.pbar for r in touching]) - jkr_mean_pressure(radii, 1.0, amplitude, 1.0, work))
    assert errors.max() < 0.04 * pstar
    snap_off = max(r.gbar for r in results[steps:] if r.A > 0)
    step = 2.15 * amplitude / steps
    assert abs(snap_off - jkr_pulloff_displacement_control(1.0, amplitude, 1.0, work)[2]) < 0.02 * amplitude + step


@pytest.mark.slow
def test_tao_almm_stops_within_a_line_search_of_its_time_limit(monkeypatch):
    """The time limit ends ALMM's subsolve (a zero gradient left the augmented Lagrangian's constraint term)."""
    grid = Grid(256, 256, 1.0, 1.0)
    problem = ContactProblem(grid, fractal(grid, 4, 64, 0.8, 1e-2, seed=4), 1.0, fft_effort="FFTW_ESTIMATE")
    at_limit = applications_at_time_limit(monkeypatch, problem)
    adhesive = Solver(AdhesiveProblem(problem, Exponential(5e-6, 1e-3)), "displacement", "almm", rtol=1e-13,
                      options={"solve_max_time": 0.3})
    try:
        result = adhesive.solve(gbar=8e-3)
        assert not result.converged and "time limit" in result.reason, result.reason
        assert at_limit and problem.operator.applications - at_limit[0] <= 40  # one line search's evaluations
    finally:
        adhesive.destroy()
        problem.destroy()
