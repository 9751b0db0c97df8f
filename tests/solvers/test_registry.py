"""The solver registry, the options prefix of a Solver, and load_path."""

import pytest
from petsc4py import PETSc

from roughpetsc.errors import ParameterError
from roughpetsc.solvers import Solver, backend_names, load_path, make_backend, register, unregister

LOADS = [0.05, 0.2, 0.5, 1.0]


@pytest.fixture(scope="module")
def problem(small_problem):
    return small_problem


class Recorder:
    """A toy backend: Polonsky-Keer from the registry, recording every call of the protocol."""

    def __init__(self, problem, control, name, settings):
        self.inner = make_backend(problem, control, "pk", settings)
        self.name, self.tao = f"toy[{self.inner.name}]", self.inner.tao
        self.keeps_displacement = self.inner.keeps_displacement
        self.calls = []
        CREATED.append(self)

    def solve(self, target, pressure, guess):
        self.calls.append(("solve", target))
        return self.inner.solve(target, pressure, guess)

    def destroy(self):
        self.calls.append(("destroy",))
        self.inner.destroy()


CREATED = []


@pytest.fixture
def toy():
    register("toy", Recorder, controls=("load",))
    CREATED.clear()
    yield CREATED
    unregister("toy")


def test_registry_lists_the_existing_names():
    names = backend_names()
    for name in ("pk", "none", "python", "almm", "blmvm", "bqnls", "bncg", "bnls", "bntr", "tron", "gpcg"):
        assert name in names
    assert "almm" in backend_names("load") and "almm" not in backend_names("displacement")


def test_a_registered_backend_is_reachable_by_name_through_solver(problem, toy):
    assert "toy" in backend_names("load") and "toy" not in backend_names("displacement")
    solver = Solver(problem, "load", "toy", 1e-9)
    try:
        result = solver.solve(pstar=0.5)
        assert solver.name == result.solver == "toy[pk(fourier)]" and solver.tao is toy[0].tao
        assert result.converged and toy[0].calls == [("solve", problem.scaled_pbar(None, 0.5))]
    finally:
        solver.destroy()
    assert toy[0].calls[-1] == ("destroy",)
    with pytest.raises(ParameterError, match="load control only") as error:
        Solver(problem, "displacement", "toy", 1e-9)
    assert error.value.parameter == "tao_type"


def test_load_path_gives_the_results_of_a_solve_loop(problem):
    solver = Solver(problem, "load", None, 1e-10)
    try:
        looped = [solver.solve(pstar=pstar) for pstar in LOADS]
    finally:
        solver.destroy()
    path = list(load_path(problem, pstars=LOADS, rtol=1e-10))
    assert len(path) == len(LOADS)
    for a, b in zip(path, looped):
        assert a.converged and b.converged
        assert (a.iterations, a.A, a.reason) == (b.iterations, b.A, b.reason)
        for name in ("pstar", "gbar", "separation", "A_corrected"):
            assert getattr(a, name) == pytest.approx(getattr(b, name), rel=1e-12, abs=1e-300)


def test_load_path_destroys_its_solver_when_closed(problem, toy):
    path = load_path(problem, pstars=LOADS, tao_type="toy")
    assert toy == []  # the Solver is made at the first result
    first = next(path)
    assert first.converged and toy[0].calls == [("solve", problem.scaled_pbar(None, LOADS[0]))]
    path.close()
    assert toy[0].calls[-1] == ("destroy",)


@pytest.mark.parametrize("loads, parameter", [({}, "pstars"), ({"pstars": [1.0], "gbars": [0.1]}, "pstars")])
def test_load_path_wants_exactly_one_list_of_loads(problem, loads, parameter):
    with pytest.raises(ParameterError) as error:
        load_path(problem, **loads)
    assert error.value.parameter == parameter


@pytest.mark.parametrize("control, tao_type, load, parameter", [
    ("load", "nelder", {"pstar": 0.5}, "tao_type"), ("displacement", "almm", {"gbar": 1.0}, "tao_type"),
    ("load", None, {"pstar": -1.0}, "pstar"), ("load", None, {"pbar": 0.0}, "pbar"),
    ("displacement", None, {"gbar": 0.0}, "gbar")])
def test_bad_values_are_parameter_errors(problem, control, tao_type, load, parameter):
    with pytest.raises(ParameterError) as error:
        solver = Solver(problem, control, tao_type, 1e-8)
        try:
            solver.solve(**load)
        finally:
            solver.destroy()
    assert error.value.parameter == parameter and "-" + parameter not in str(error.value)


def test_options_prefix_scopes_the_solver_options(problem):
    """A prefixed Solver reads its own options, ignores the unprefixed ones, and leaves no defaults behind."""
    options = PETSc.Options()
    options.setValue("pk_pc", "multigrid")  # would be refused by an unprefixed Solver
    options.setValue("rp_pk_pc", "none")
    try:
        solver = Solver(problem, "load", None, 1e-8, prefix="rp_")
        assert solver.name == "pk(none)" and solver.tao.getOptionsPrefix() == "rp_"
        solver.destroy()
        solver = Solver(problem, "displacement", "bnls", 1e-8, prefix="rp_")
        assert solver.tao.getOptionsPrefix() == "rp_"
        solver.destroy()
        assert not options.hasName("rp_tao_bnk_ksp_type") and not options.hasName("tao_bnk_ksp_type")
    finally:
        options.delValue("pk_pc")
        options.delValue("rp_pk_pc")


@pytest.mark.parametrize("name", ["pk", "none", "python"])
def test_command_line_names_of_polonsky_keer_in_the_options_database(problem, name):
    """``-tao_type pk|none`` names the backend, not a TAO type: the PK TAO must not read it as one."""
    options = PETSc.Options()
    options.setValue("tao_type", name)
    try:
        solver = Solver(problem, "load", name, 1e-8)
        try:
            assert solver.solve(pstar=0.5).converged and solver.name == "pk(fourier)"
        finally:
            solver.destroy()
        assert options.getString("tao_type") == name
    finally:
        options.delValue("tao_type")
