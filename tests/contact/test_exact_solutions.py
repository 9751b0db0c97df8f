"""Solutions against exact ones: Westergaard's 1-D wave and the bisinusoid asymptotes (3.53)-(3.55)."""

import math

import numpy as np
import pytest
from petsc4py import PETSc

from roughpetsc.contact.problem import ContactProblem
from roughpetsc.solvers.facade import Solver
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import bisinusoid, wave

E_STAR = 2.5
AMPLITUDE = 0.01


def westergaard_exact(load_ratio):
    """A and gbar/h of 2h sin^2(pi x / lambda) at pbar = P p_star (Johnson, Contact Mechanics 13.2)."""
    P = load_ratio
    return (2 / math.pi) * math.asin(math.sqrt(P)), 1 - P + P * math.log(P)


def wave_problem(n):
    grid = Grid(2, n, 2.0 / n, 1.0)
    return ContactProblem(grid, wave(grid, AMPLITUDE, 1.0), E_STAR, PETSc.COMM_SELF, fft_effort="FFTW_ESTIMATE")


def solve_wave(n, load_ratio, control, tao_type=None):
    problem = wave_problem(n)
    p_star = math.pi * E_STAR * AMPLITUDE / 1.0
    area, gap_ratio = westergaard_exact(load_ratio)
    # TAO's line searches stall near 1e-9 (the objective's round-off); PK reaches 1e-12.
    solver = Solver(problem, control, tao_type, 1e-10 if tao_type is None else 1e-8)
    try:
        if control == "load":
            result = solver.solve(pbar=load_ratio * p_star)
        else:
            result = solver.solve(gbar=gap_ratio * AMPLITUDE)
        assert result.converged, result.reason
        return result, area, gap_ratio * AMPLITUDE, p_star
    finally:
        solver.destroy()
        problem.destroy()


@pytest.mark.parametrize("load_ratio", [0.05, 0.3, 0.7, 0.95])
def test_westergaard_load_control(load_ratio):
    result, area, gbar, _ = solve_wave(1024, load_ratio, "load")
    assert abs(result.A - area) <= 2 / 1024
    assert abs(result.gbar - gbar) <= 1e-4 * gbar


@pytest.mark.parametrize("load_ratio", [0.05, 0.3, 0.7, 0.95])
def test_westergaard_displacement_control(load_ratio):
    result, area, gbar, p_star = solve_wave(1024, load_ratio, "displacement", "blmvm")
    assert abs(result.A - area) <= 2 / 1024
    # Under displacement control the prescribed mean gap is met exactly; the load is the answer.
    assert abs(result.gbar - gbar) <= 1e-4 * gbar
    assert abs(result.pbar / p_star - load_ratio) <= 1e-4 * load_ratio


def test_westergaard_error_shrinks_with_n():
    errors = []
    for n in (128, 512):
        result, area, gbar, _ = solve_wave(n, 0.3, "load")
        errors.append((abs(result.A - area), abs(result.gbar - gbar) / gbar))
    assert errors[1][0] < errors[0][0]
    assert errors[1][1] < errors[0][1]


def bisinusoid_solutions(load_ratios, n=128):
    grid = Grid(n, n)
    delta = 0.01
    problem = ContactProblem(grid, bisinusoid(grid, delta, 1.0, 1.0), E_STAR, PETSc.COMM_SELF,
                             fft_effort="FFTW_ESTIMATE")
    p_star = 0.5 * E_STAR * math.hypot(2 * math.pi, 2 * math.pi) * delta  # (3.53)
    assert problem.complete_contact_pbar * problem.pressure_scale == pytest.approx(p_star, rel=1e-12)
    solver = Solver(problem, "load", None, 1e-10)
    try:
        results = [solver.solve(pbar=ratio * p_star) for ratio in load_ratios]
        assert all(r.converged for r in results)
        return results, delta
    finally:
        solver.destroy()
        problem.destroy()


def test_bisinusoid_near_complete_contact_asymptotes():
    """(3.54) and (3.55): the BEM approaches both as pbar -> p* (as in Fig. 3.3)."""
    ratios = [0.85, 0.9, 0.95]
    results, delta = bisinusoid_solutions(ratios)
    area_errors, gap_errors = [], []
    for ratio, result in zip(ratios, results):
        area = 1 - 3 / (2 * math.pi) * (1 - ratio)
        gap = 16 * delta / (15 * math.pi ** 2) * 1.5 ** 1.5 * (1 - ratio) ** 2.5
        area_errors.append(abs(result.A - area) / (1 - area))
        gap_errors.append(abs(result.gbar - gap) / gap)
    assert area_errors[-1] < 0.15 and gap_errors[-1] < 0.15
    assert area_errors[-1] < area_errors[0] and gap_errors[-1] < gap_errors[0]


def test_bisinusoid_early_contact_is_hertzian():
    """Light load: two Hertz contacts per cell, R = 1 / (Delta alpha^2), F = pbar lambda^2 / 2."""
    ratios = [0.002, 0.01]
    results, delta = bisinusoid_solutions(ratios, n=256)
    p_star = 0.5 * E_STAR * math.hypot(2 * math.pi, 2 * math.pi) * delta
    errors = []
    for ratio, result in zip(ratios, results):
        radius = 1 / (delta * (2 * math.pi) ** 2)
        force = ratio * p_star / 2
        a = (3 * force * radius / (4 * E_STAR)) ** (1 / 3)
        errors.append(abs(result.A_corrected - 2 * math.pi * a ** 2) / (2 * math.pi * a ** 2))
    assert errors[-1] < 0.05
