"""Issue 17, a newcomer's run: no file lost, no hang, no traceback; presets found from anywhere; -help first.

Each test is one reproduction of the issue, on small grids (seconds each).
"""

import hashlib
import json
import os
import stat
import sys

import h5py
import pytest

from conftest import ROOT, assert_one_clear_error, error_lines, run_cli, run_process

SMALL = ["-surface_N", 64, "-surface_ks", 16, "-surface_kl", 4]


def digest(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


@pytest.fixture
def solved(tmp_path):
    """A solve-mode output file, usable as a surface file."""
    path = tmp_path / "good.h5"
    out = run_cli(SMALL + ["-output", path, "-quiet"])
    assert out.returncode == 0, out.stderr
    return path


# --- 1. no file lost ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("extra", [[], ["-overwrite"]])
def test_output_naming_the_input_is_refused_and_the_input_kept(solved, extra):
    before = digest(solved)
    out = run_cli(["-surface_file", solved, "-output", solved] + extra)
    assert_one_clear_error(out, "-output", "good.h5", "-surface_file")
    assert digest(solved) == before
    with h5py.File(solved) as f:
        assert f["heights"].shape == (64, 64)


def test_output_naming_the_input_through_another_path_is_refused(solved, tmp_path):
    other = tmp_path / "sub" / ".." / "good.h5"
    (tmp_path / "sub").mkdir()
    out = run_cli(["-surface_file", solved, "-output", other, "-overwrite"])
    assert_one_clear_error(out, "-output", "-surface_file")


def test_existing_outputs_are_refused_unless_overwrite(tmp_path):
    h5, summary = tmp_path / "existing.h5", tmp_path / "existing.json"
    h5.write_text("someone else's data\n")
    summary.write_text("{\"mine\": 1}\n")
    for option, path in (("-output", h5), ("-json", summary)):
        out = run_cli(SMALL + [option, path])
        assert_one_clear_error(out, option, path.name, "-overwrite")
        assert out.stdout == ""  # refused before any work
    assert h5.read_text() == "someone else's data\n" and summary.read_text() == "{\"mine\": 1}\n"
    out = run_cli(SMALL + ["-output", h5, "-json", summary, "-overwrite", "-quiet"])
    assert out.returncode == 0, out.stderr
    assert json.load(open(summary))["steps"][0]["converged"]
    with h5py.File(h5) as f:
        assert f["pressure"].shape == (64, 64)


def test_output_and_json_naming_the_same_file_are_refused(tmp_path):
    out = run_cli(SMALL + ["-output", tmp_path / "same", "-json", tmp_path / "same"])
    assert_one_clear_error(out, "-output", "-json", "same")
    assert not (tmp_path / "same").exists()


@pytest.mark.parametrize("where, says", [("folder", "is a folder"), ("missing", "does not exist"),
                                         ("unwritable", "cannot create")])
def test_unwritable_output_is_refused_before_any_work(tmp_path, where, says):
    path = {"folder": tmp_path, "missing": tmp_path / "no" / "o.h5", "unwritable": "/proc/o.h5"}[where]
    out = run_cli(SMALL + ["-output", path])
    assert_one_clear_error(out, "-output", says)
    assert out.stdout == ""


def test_stats_and_models_outputs_are_protected_too(tmp_path):
    for mode, option in (("stats", "-stats_json"), ("stats", "-stats_h5"), ("models", "-models_json"),
                         ("models", "-models_plot")):
        path = tmp_path / ("kept.png" if option == "-models_plot" else "kept")
        path.write_text("kept\n")
        out = run_cli(["-mode", mode, option, path] + (SMALL if mode == "stats" else []))
        assert_one_clear_error(out, option, path.name, "-overwrite")
        assert path.read_text() == "kept\n"
    out = run_cli(["-mode", "models", "-models_json", tmp_path / "kept", "-overwrite"])
    assert out.returncode == 0, out.stderr
    assert "early" in json.load(open(tmp_path / "kept"))


def test_outputs_get_the_same_file_mode_everywhere(tmp_path):
    """0666 less the umask, as for any new file (mkstemp's 0600 before), in every mode."""
    previous = os.umask(0o022)
    try:
        runs = [SMALL + ["-output", tmp_path / "s.h5", "-json", tmp_path / "s.json", "-quiet"],
                SMALL + ["-mode", "stats", "-stats_json", tmp_path / "t.json", "-stats_h5", tmp_path / "t.h5"],
                ["-mode", "models", "-models_json", tmp_path / "m.json", "-models_plot", tmp_path / "m.png"]]
        for args in runs:
            out = run_cli(args)
            assert out.returncode == 0, out.stderr
    finally:
        os.umask(previous)
    for name in ("s.h5", "s.json", "t.json", "t.h5", "m.json", "m.png"):
        assert stat.S_IMODE(os.stat(tmp_path / name).st_mode) == 0o644, name
    assert not [name for name in os.listdir(tmp_path) if name.startswith(".tmp-")]


# --- 2. no hang: an error found on rank 0 reaches every rank ---------------------------------------------------

def _existing(tmp_path, name):
    path = tmp_path / name
    path.write_text("kept\n")
    return path


BAD_OUTPUTS = [
    (lambda t: ["-mode", "stats", "-stats_json", t] + SMALL, "-stats_json"),   # the reported hang
    (lambda t: ["-mode", "stats", "-stats_h5", _existing(t, "s.h5")] + SMALL, "-stats_h5"),
    (lambda t: ["-mode", "stats", "-stats_plot", t / "no" / "p"] + SMALL, "-stats_plot"),
    (lambda t: ["-mode", "models", "-models_json", t], "-models_json"),
    (lambda t: ["-mode", "models", "-models_plot", t / "m.jpgx"], "-models_plot"),
    (lambda t: ["-mode", "models", "-models_plot", _existing(t, "m.png")], "-models_plot"),
    (lambda t: ["-output", t] + SMALL, "-output"),
    (lambda t: ["-json", _existing(t, "s.json")] + SMALL, "-json"),
    (lambda t: ["-mode", "ensemble", "-output", t, "-ensemble_size", 2] + SMALL, "-output"),
]


@pytest.mark.mpi
@pytest.mark.parametrize("args, named", BAD_OUTPUTS)
def test_bad_outputs_on_two_ranks_end_with_one_message(tmp_path, args, named):
    out = run_cli(args(tmp_path), ranks=2)  # a hang fails here as TimeoutExpired
    assert out.returncode != 0
    assert "Traceback" not in out.stderr
    errors = error_lines(out)
    assert len(errors) == 1 and named in errors[0], out.stderr


# --- 3. no traceback for a user mistake ------------------------------------------------------------------------

@pytest.mark.parametrize("load", [[], ["-gbar", 2e-4]])
def test_bnls_works_without_its_preset(tmp_path, load):
    """BNLS shifts the Hessian (MatShift) when a Newton step does not descend: the shell Mat supports it."""
    out = run_cli(["-surface_N", 128, "-surface_ks", 32, "-surface_kl", 8, "-tao_type", "bnls",
                   "-json", tmp_path / "b.json"] + load)
    assert out.returncode == 0, out.stderr
    step = json.load(open(tmp_path / "b.json"))["steps"][0]
    assert step["converged"] and "bnls" in step["solver"]


def test_the_shell_hessian_takes_tao_shifts():
    """MatShift (BNK's perturbation) adds to K until the next Hessian evaluation resets it; the PC ignores it."""
    import numpy as np
    from petsc4py import PETSc

    from roughpetsc.surface.grid import Grid
    from roughpetsc.elastic.westergaard import Westergaard

    operator = Westergaard(Grid(16, 16, 1.0, 1.0), 1.0, PETSc.COMM_SELF, effort="FFTW_ESTIMATE")
    mat = operator.mat()
    x, plain, shifted = mat.createVecRight(), mat.createVecLeft(), mat.createVecLeft()
    x.setArray(np.random.default_rng(0).standard_normal(x.getLocalSize()))
    mat.mult(x, plain)
    mat.shift(0.5)
    mat.shift(0.25)
    mat.mult(x, shifted)
    assert np.allclose(shifted.getArray(), plain.getArray() + 0.75 * x.getArray(), rtol=1e-12, atol=1e-15)
    assert np.allclose(mat.getDiagonal().getArray(), operator.diagonal + 0.75)
    mat.getPythonContext().perturbation = 0.0  # what the Hessian evaluation of control.BoundQP does
    mat.mult(x, shifted)
    assert np.array_equal(shifted.getArray(), plain.getArray())
    mat.destroy()
    operator.destroy()


def test_presets_are_found_from_another_folder(tmp_path):
    out = run_cli(SMALL + ["-options_file", "solvers/pk.opts", "-json", "p.json"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert json.load(open(tmp_path / "p.json"))["steps"][0]["converged"]
    out = run_cli(SMALL + ["-options_file", "bnls", "-json", "b.json"], cwd=tmp_path)  # by bare name
    assert out.returncode == 0, out.stderr
    assert "bnls" in json.load(open(tmp_path / "b.json"))["solver"]


def test_a_missing_options_file_is_named(tmp_path):
    out = run_cli(SMALL + ["-options_file", "solvers/nope.opts"], cwd=tmp_path)
    assert_one_clear_error(out, "-options_file", "solvers/nope.opts")
    assert "PETSc" not in out.stderr


@pytest.mark.mpi
@pytest.mark.parametrize("size", [32768, 100000])
def test_a_grid_too_large_for_memory_is_refused_up_front(size):
    out = run_cli(["-surface_N", size])
    message = assert_one_clear_error(out, "-surface_N", f"{size}x{size}", "GiB", "available")
    assert out.stdout == ""
    assert message


BAD_VALUES = [
    (["-pstar_list", "0.5,,1"], "-pstar_list"),
    (["-pstar_list", "0.5,1,"], "-pstar_list"),
    (["-fft_threads", 0], "-fft_threads"),
    (["-mode", "models", "-models_plot", "m.jpgx"], "-models_plot"),
    (["-mode", "models", "-models_json", "/proc/m.json"], "-models_json"),
    (["-mode", "models", "-models_plot", "/tmp"], "-models_plot"),
]


@pytest.mark.parametrize("args, named", BAD_VALUES)
def test_bad_values_are_refused_in_one_line(tmp_path, args, named):
    out = run_cli(SMALL + args if args[0] != "-mode" else args, cwd=tmp_path)
    assert_one_clear_error(out, named)
    assert not os.listdir(tmp_path)


# --- 7. -help ---------------------------------------------------------------------------------------------------

def test_help_prints_our_options_and_presets_before_petsc(tmp_path):
    out = run_cli(["-help"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    ours = out.stdout.index("roughpetsc options")
    for text in ("-overwrite", "-surface_N", "Presets", "solvers/: ", "pk", "options/: ", "group18"):
        assert text in out.stdout
    assert ours < out.stdout.index("Presets") < out.stdout.index("Petsc Release")
    assert "ignored with -surface_file" not in out.stdout


def test_help_into_a_pager_that_stops_early_ends_quietly():
    """`-help | head` closes the pipe while help is still printing: no PETSc crash banner."""
    command = f"{sys.executable} -m roughpetsc -help | head -n 2"
    out = run_process(["bash", "-c", command], cwd=ROOT, env=dict(os.environ, PYTHONPATH=ROOT))
    assert out.stdout.startswith("roughpetsc options")
    assert "PETSC ERROR" not in out.stderr and "MPI_ABORT" not in out.stderr, out.stderr


def test_the_entry_point_exists():
    assert os.access(os.path.join(ROOT, ".venv", "bin", "roughpetsc"), os.X_OK)
