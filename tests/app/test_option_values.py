"""Issue 37, options: every value used as given or refused by name (valueless options, long lists, lists from
files, -pbar_list, options files, -version, the wisdom file, -progress_interval, unused options in every mode)."""

import json

import h5py
import numpy as np
import pytest

from conftest import run_cli
from conftest import assert_one_clear_error

TINY = ["-surface_N", 32, "-surface_ks", 8, "-surface_kl", 2, "-fft_effort", "FFTW_ESTIMATE"]


# --- an option of ours given without a value ------------------------------------------------------------------

@pytest.mark.parametrize("args, named", [
    (["-gbar"], "-gbar"),                              # was: displacement control at the p* default 0.5
    (["-pstar"], "-pstar"),
    (["-gbar", ""], "-gbar"),                          # an empty value is no value
    (["-surface_file"], "-surface_file"),              # was: the generated surface solved
    (["-pstar_list", "-quiet"], "-pstar_list"),        # the next option is not a value
    (["-output", "-json", "x.json"], "-output"),      # was: nothing written, exit 0
    (["-kkt_rtol"], "-kkt_rtol"),
    (["-pk_pc"], "-pk_pc"),                            # a solver option of ours
    (["-mode"], "-mode"),
])
def test_an_option_without_a_value_is_refused(tmp_path, args, named):
    out = run_cli(TINY + args, cwd=tmp_path)
    message = assert_one_clear_error(out, named, "without a value")
    assert out.stdout == "" and not list(tmp_path.iterdir()), message


def test_every_valueless_option_is_named(tmp_path):
    out = run_cli(TINY + ["-output", "-json"], cwd=tmp_path)
    assert_one_clear_error(out, "-json", "-output", "without a value")


def test_valueless_in_an_options_file_is_refused(tmp_path):
    (tmp_path / "mine.opts").write_text("# a load without its value\n-gbar\n")
    out = run_cli(TINY + ["-options_file", tmp_path / "mine.opts"], cwd=tmp_path)
    assert_one_clear_error(out, "-gbar", "without a value")


@pytest.mark.parametrize("args, named", [
    (["-tao_type", "blmvm", "-bound_al_eta", "abc"], "-bound_al_eta"),   # was: PETSc's message, naming no option
    (["-tao_type", "bqnls", "-bound_al_penalty", "1x"], "-bound_al_penalty"),
    (["-tao_type", "blmvm", "-bound_al_max_outer", "1e3"], "-bound_al_max_outer"),
    (["-tao_type", "blmvm", "-bound_al_recycle", "maybe"], "-bound_al_recycle"),
    (["-solve_max_time", "x"], "-solve_max_time"),
    (["-tao_max_it", "3.5"], "-tao_max_it"),                             # a PETSc option, read by TAO itself
    (["-tao_type", "bnls", "-tao_bnk_max_cg_its", "q"], "-tao_bnk_max_cg_its"),
])
def test_an_unreadable_solver_option_is_refused_by_name(tmp_path, args, named):
    out = run_cli(TINY + args + ["-json", "s.json"], cwd=tmp_path)
    message = assert_one_clear_error(out, named, args[-1])
    assert out.stdout == "" and not list(tmp_path.iterdir()), message


# A bound type's own option for a part that run does not have: read, then never used (all were accepted before).
@pytest.mark.parametrize("args, named", [
    (["-tao_type", "blmvm", "-bound_load", "gap", "-gbar", "1e-4"], "-bound_load"),  # displacement control
    (["-tao_type", "blmvm", "-bound_al_penalty", "1"], "-bound_al_penalty"),         # the gap form has no multiplier
    (["-tao_type", "blmvm", "-bound_load", "rootfind", "-bound_al_eta", "0.2"], "-bound_al_eta"),
    (["-tao_type", "tron", "-bound_h0", "fourier"], "-bound_h0"),                    # no L-BFGS in TRON
    (["-tao_type", "blmvm", "-bound_pc", "fourier"], "-bound_pc"),                   # no KSP in BLMVM
])
def test_a_bound_option_for_a_part_the_run_lacks_is_refused(tmp_path, args, named):
    out = run_cli(TINY + args + ["-json", "s.json"], cwd=tmp_path)
    message = assert_one_clear_error(out, named, "not used")
    assert not list(tmp_path.iterdir()), message


def test_the_augmented_lagrangian_takes_its_options(tmp_path):
    out = run_cli(TINY + ["-tao_type", "blmvm", "-bound_load", "al", "-bound_al_penalty", "1", "-json", "s.json"],
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert json.load(open(tmp_path / "s.json"))["steps"][0]["solver"] == "blmvm(al)"


@pytest.mark.parametrize("switch", [["-quiet"], ["-quiet", "1"], ["-quiet", "true"], ["-overwrite", "-quiet"]])
def test_switches_stand_alone(tmp_path, switch):
    out = run_cli(TINY + switch + ["-json", tmp_path / "s.json"])
    assert out.returncode == 0, out.stderr
    assert out.stdout == ""  # -quiet took effect
    assert json.load(open(tmp_path / "s.json"))["steps"][0]["converged"]


def test_a_negative_value_is_a_value_not_an_option(tmp_path):
    out = run_cli(TINY + ["-pbar", -1], cwd=tmp_path)
    assert_one_clear_error(out, "-pbar", "positive", "-1")


# --- load lists: whole, from files, in pressure units -----------------------------------------------------------

def long_list(count):
    """``count`` increasing p*, written with many digits: far beyond the 1023 characters of petsc4py's buffer."""
    return [0.05 + 0.0012345678901 * i for i in range(count)]


@pytest.mark.mpi
@pytest.mark.parametrize("ranks", [1, 2])
def test_a_long_load_list_is_read_whole(tmp_path, ranks):
    loads = long_list(150)
    text = ",".join(repr(v) for v in loads)
    assert len(text) > 2000
    out = run_cli(TINY + ["-pstar_list", text, "-json", tmp_path / "l.json", "-quiet"], ranks=ranks)
    assert out.returncode == 0, out.stderr
    steps = json.load(open(tmp_path / "l.json"))["steps"]
    assert len(steps) == 150
    assert [step["pstar"] for step in steps] == pytest.approx(loads, rel=1e-7)


def test_a_long_gbar_list_is_read_whole(tmp_path):
    gaps = list(np.linspace(2e-3, 1e-3, 160))
    text = ",".join(repr(float(v)) for v in gaps)
    out = run_cli(TINY + ["-gbar_list", text, "-json", tmp_path / "g.json", "-quiet"])
    assert out.returncode == 0, out.stderr
    steps = json.load(open(tmp_path / "g.json"))["steps"]
    assert [step["gbar"] for step in steps] == pytest.approx(gaps, rel=1e-9)


def test_a_list_from_a_file(tmp_path):
    loads = long_list(40)
    lines = ["# p* of the path, one or several a line"] + [f"{a!r}, {b!r}" for a, b in zip(loads[::2], loads[1::2])]
    (tmp_path / "loads.txt").write_text("\n".join(lines) + "\n")
    out = run_cli(TINY + ["-pstar_list", "@loads.txt", "-json", "f.json", "-quiet"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    steps = json.load(open(tmp_path / "f.json"))["steps"]
    assert [step["pstar"] for step in steps] == pytest.approx(loads, rel=1e-7)


def test_pbar_list_loads_in_pressure_units(tmp_path):
    out = run_cli(TINY + ["-pstar", 0.3, "-json", tmp_path / "p.json", "-quiet"])
    assert out.returncode == 0, out.stderr
    reference = json.load(open(tmp_path / "p.json"))
    sqrt_m0p = reference["sqrt_m0p"]
    pbars = [0.1 * sqrt_m0p, 0.3 * sqrt_m0p]
    out = run_cli(TINY + ["-pbar_list", ",".join(repr(p) for p in pbars), "-json", tmp_path / "b.json", "-quiet"])
    assert out.returncode == 0, out.stderr
    steps = json.load(open(tmp_path / "b.json"))["steps"]
    assert [step["pbar"] for step in steps] == pytest.approx(pbars, rel=1e-8)
    assert [step["load_option"] for step in steps] == ["pbar", "pbar"]
    # The same load by p*: the same contact area (the solutions agree to the tolerance).
    assert steps[1]["A"] == pytest.approx(reference["steps"][0]["A"], abs=2.0 / 32 ** 2)


@pytest.mark.parametrize("args, named", [
    (["-pstar_list", "@missing.txt"], "missing.txt"),
    (["-pstar_list", "@empty.txt"], "holds no numbers"),
    (["-pstar_list", "@words.txt"], "'two'"),
    (["-pbar_list", "1e-4,-2e-4"], "-pbar_list"),
    (["-gbar_list", "1e-3,,2e-3"], "empty item"),
    (["-pstar_list", "0.1", "-pbar_list", "1e-4"], "give only one of"),
])
def test_bad_lists_are_refused(tmp_path, args, named):
    (tmp_path / "empty.txt").write_text("# nothing\n\n")
    (tmp_path / "words.txt").write_text("0.1 two 0.3\n")
    out = run_cli(TINY + args, cwd=tmp_path)
    assert_one_clear_error(out, named)
    assert out.stdout == ""


# --- options files, -version, wisdom, progress interval -------------------------------------------------------

@pytest.mark.parametrize("content", [b"1 2 3\n", b"hello world\n-pstar 0.5\n", b"\x00\xff\x01binary"])
def test_a_file_that_is_not_an_options_file_is_named(tmp_path, content):
    (tmp_path / "not.opts").write_bytes(content)
    out = run_cli(TINY + ["-options_file", "not.opts"], cwd=tmp_path)
    assert_one_clear_error(out, "-options_file", "not.opts")
    assert "PETSC ERROR" not in out.stderr


def test_version_names_roughpetsc_and_petsc():
    from petsc4py import PETSc

    import roughpetsc

    out = run_cli(["-version"])
    assert out.returncode == 0, out.stderr
    first, second = out.stdout.splitlines()[:2]
    assert first == f"roughpetsc {roughpetsc.__version__}"
    assert f"PETSc {'.'.join(map(str, PETSc.Sys.getVersion()))}" in second
    assert "A*" not in out.stdout  # nothing is solved


@pytest.mark.parametrize("args, named", [
    (["-fft_wisdom", "/no/such/folder/w.json"], "does not exist"),
    (["-progress_interval", -1], "-progress_interval"),
    (["-progress_interval", 0], "-progress_interval"),
    (["-progress", "sometimes"], "-progress"),
])
def test_settings_that_would_do_nothing_are_refused(tmp_path, args, named):
    out = run_cli(TINY + args, cwd=tmp_path)
    assert_one_clear_error(out, named)


# --- the unused-option check runs before any work, in every mode ------------------------------------------------

@pytest.mark.parametrize("mode, output", [("models", "-models_json"), ("stats", "-stats_json")])
def test_an_unused_option_stops_a_mode_before_it_prints_or_writes(tmp_path, mode, output):
    surface = TINY[:6] if mode == "stats" else []
    out = run_cli(surface + ["-mode", mode, "-pstar", 0.5, output, tmp_path / "m.json"])
    assert_one_clear_error(out, "-pstar", "not used")
    assert out.stdout == ""
    assert not (tmp_path / "m.json").exists()
    again = run_cli(surface + ["-mode", mode, output, tmp_path / "m.json"])  # the corrected command runs
    assert again.returncode == 0, again.stderr


def test_stats_reports_an_option_of_another_surface_type(tmp_path):
    out = run_cli(TINY[:6] + ["-mode", "stats", "-surface_radius", 3])
    assert_one_clear_error(out, "-surface_radius", "not used")


def test_nothing_is_written_when_an_option_is_unused(tmp_path):
    """A path starting beyond complete contact runs no TAO first; the check still precedes every write."""
    out = run_cli(TINY + ["-pstar_list", "40,41,0.5", "-output", tmp_path / "o.h5", "-tao_view_x", 1])
    assert out.returncode == 2, out.stderr
    assert not (tmp_path / "o.h5").exists()
    with pytest.raises(FileNotFoundError):
        h5py.File(tmp_path / "o.h5", "r")


# --- bad values of every option: refused by name, none used silently ---------------------------------------------

@pytest.mark.parametrize("args, named", [
    (["-surface_N0", -1], ["-surface_N0", "-1"]),                  # was: named -surface_N
    (["-surface_N0", 1], ["-surface_N0", "at least 2 rows"]),       # was: named -surface_type
    (["-surface_ks", "nan"], ["-surface_ks", "nan"]),               # was: named -surface_kl
    (["-surface_ks", 0], ["-surface_ks", "positive"]),
    (["-surface_ks", 1], ["-surface_kl/-surface_ks"]),              # k_s below k_l: was named -surface_kl alone
    (["-surface_m2", "inf"], ["-surface_m2", "finite"]),            # was: named -surface_type, "NaN or Inf"
    (["-surface_seed", -1], ["-surface_seed", "non-negative"]),     # was: a traceback, exit 1
    (["-surface_type", "wave", "-surface_amplitude", "1e400"], ["-surface_amplitude", "finite"]),
    (["-surface_type", "bisinusoid", "-surface_amplitude", "inf"], ["-surface_amplitude", "finite"]),
    (["-surface_type", "sphere", "-surface_radius", "inf"], ["-surface_radius", "finite"]),  # was: "flat"
    (["-tao_type", "blmvm", "-bound_al_penalty", "inf"], ["-bound_al_penalty", "finite"]),   # was: error code 83
    (["-solve_max_time", "inf"], ["-solve_max_time", "finite"]),    # was: accepted
])
def test_a_value_out_of_range_is_refused_by_its_own_name(tmp_path, args, named):
    if "-surface_type" in args:  # a periodic wave or sphere takes no fractal cut-offs
        args = ["-surface_N", 32, "-fft_effort", "FFTW_ESTIMATE"] + args
    else:
        args = TINY + args
    out = run_cli(args + ["-json", "s.json"], cwd=tmp_path)
    message = assert_one_clear_error(out, *named)
    assert out.stdout == "" and not list(tmp_path.iterdir()), message


@pytest.mark.parametrize("args, named", [
    (["-surface_seed", 99999999999], "-surface_seed"),     # was: seed 1215752191, silently
    (["-surface_seed", 3000000000], "-surface_seed"),      # was: "must be non-negative, got -1294967296"
    (["-surface_N", 4294967328], "-surface_N"),            # was: read as 32
    (["-pk_refresh", 4294967346], "-pk_refresh"),          # a solver's integer (was: read as 50)
    (["-mode", "stats", "-stats_ensemble", 4294967298], "-stats_ensemble"),
])
def test_an_integer_beyond_petsc_integers_is_refused(tmp_path, args, named):
    surface = TINY[:6] if "stats" in args else TINY
    out = run_cli(surface + args, cwd=tmp_path)
    assert_one_clear_error(out, named, str(args[-1]), "beyond the integers")


@pytest.mark.parametrize("args, named, kind", [
    (["-E_star", "abc"], "-E_star", "as a number"),
    (["-surface_N", 2.5], "-surface_N", "as an integer"),
    (["-quiet", "maybe"], "-quiet", "as true or false"),
])
def test_an_unreadable_value_says_what_was_expected(tmp_path, args, named, kind):
    out = run_cli(TINY + args, cwd=tmp_path)
    assert_one_clear_error(out, named, f"'{args[-1]}' {kind}")


@pytest.mark.parametrize("models", ["gw,,persson", "gw,"])
def test_an_empty_item_of_ensemble_models_is_refused(tmp_path, models):
    out = run_cli(TINY + ["-mode", "ensemble", "-ensemble_size", 1, "-ensemble_loads", 0.5, "-ensemble_models",
                          models, "-output", "e.h5"], cwd=tmp_path)  # was: gw and persson, silently
    assert_one_clear_error(out, "-ensemble_models", "empty item")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("content", [b"\x00\xff garbage", b'{"grid": [1, 2], "steps": []}'])
def test_a_wisdom_file_of_something_else_is_refused_not_replaced(tmp_path, monkeypatch, content):
    monkeypatch.delenv("ROUGHPETSC_FFT_WISDOM", raising=False)  # the file of -fft_wisdom is used
    monkeypatch.delenv("ROUGHPETSC_FFT_EFFORT", raising=False)
    (tmp_path / "w.json").write_bytes(content)
    out = run_cli(TINY[:6] + ["-fft_effort", "FFTW_MEASURE", "-fft_wisdom", "w.json", "-json", "s.json"],
                  cwd=tmp_path)
    assert_one_clear_error(out, "-fft_wisdom", "w.json", "not an FFTW wisdom file")
    assert (tmp_path / "w.json").read_bytes() == content  # was: replaced by the wisdom of the run
    assert not (tmp_path / "s.json").exists()


def test_an_empty_wisdom_file_is_filled(tmp_path, monkeypatch):
    monkeypatch.delenv("ROUGHPETSC_FFT_WISDOM", raising=False)
    monkeypatch.delenv("ROUGHPETSC_FFT_EFFORT", raising=False)
    (tmp_path / "w.json").write_bytes(b"")
    out = run_cli(TINY[:6] + ["-fft_effort", "FFTW_MEASURE", "-fft_wisdom", "w.json", "-quiet"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "w.json").stat().st_size > 0
