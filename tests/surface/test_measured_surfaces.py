"""Issue 37, measured surfaces: x y z point lists and CSV read (or refused with the figures), -surface_detrend with
the plane reported, warnings for tilt and edge jumps, the radially averaged PSD with the fit of (2.18), wavelengths
that divide the cell, and the Python API refusing bad input at construction."""

import json

import numpy as np
import pytest

from conftest import run_cli
from roughpetsc import ContactProblem, Grid, ParameterError, Westergaard, fractal, fractal_amplitude, load_surface
from roughpetsc.surface import files, generators, spectra
from conftest import assert_one_clear_error

GRID = Grid(32, 32)
SOLVE = ["-pstar", 0.5, "-fft_effort", "FFTW_ESTIMATE"]


def periodic_heights(seed=3):
    return fractal(GRID, 2, 8, 0.8, 2e-4, seed=seed)


def point_list(heights, spacing, order=None):
    """The x y z rows of ``heights`` on nodes ``spacing`` apart (rows along y), in ``order`` if given."""
    n0, n1 = heights.shape
    y, x = np.meshgrid(np.arange(n0) * spacing, np.arange(n1) * spacing, indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), heights.ravel()])
    return points if order is None else points[order]


# --- point lists and CSV --------------------------------------------------------------------------------------

@pytest.mark.parametrize("name, delimiter, header", [("p.txt", " ", ""), ("p.csv", ",", "x,y,z"),
                                                    ("p.dat", ",", "")])
def test_a_point_list_on_a_grid_is_read_as_that_grid(tmp_path, name, delimiter, header):
    heights = periodic_heights()
    order = np.random.default_rng(1).permutation(heights.size)  # any order of the points
    np.savetxt(tmp_path / name, point_list(heights, 0.25, order), delimiter=delimiter, header=header, comments="")
    read, length = load_surface(str(tmp_path / name))
    assert read.shape == (32, 32) and length == 32 * 0.25
    assert np.allclose(read, heights - heights.mean(), rtol=0, atol=1e-18)


def test_a_16384_point_list_is_not_a_16384_by_3_surface(tmp_path):
    """The reproduction: a 128 x 128 grid given as 16384 x y z rows; solved as the 128 x 128 grid it is."""
    heights = fractal(Grid(128, 128), 4, 16, 0.8, 2e-4, seed=1)
    np.savetxt(tmp_path / "xyz.txt", point_list(heights, 1.0 / 128))
    out = run_cli(["-surface_file", "xyz.txt", "-json", "x.json", "-quiet"] + SOLVE, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    summary = json.load(open(tmp_path / "x.json"))
    assert summary["grid"] == [128, 128] and summary["length"] == [1.0, 1.0]
    np.save(tmp_path / "h.npy", heights)
    out = run_cli(["-surface_file", "h.npy", "-json", "h.json", "-quiet"] + SOLVE, cwd=tmp_path)
    assert json.load(open(tmp_path / "h.json"))["steps"][0]["A"] == summary["steps"][0]["A"]


@pytest.mark.parametrize("make, says", [
    (lambda p: p[:-1], "do not fill a grid"),                                     # a node missing
    (lambda p: np.vstack([p[:-1], p[:1]]), "more than once"),                     # one node twice, one missing
    (lambda p: p * np.array([1.0, 2.0, 1.0]), "square nodes"),                    # dx != dy
    (lambda p: np.column_stack([p[:, 0] ** 1.5, p[:, 1:]]), "not equally spaced"),
    (lambda p: np.random.default_rng(0).uniform(size=p.shape), "not equally spaced"),
])
def test_a_point_list_off_a_grid_is_refused_with_the_figures(tmp_path, make, says):
    np.savetxt(tmp_path / "bad.txt", make(point_list(periodic_heights(), 0.25)))
    out = run_cli(["-surface_file", "bad.txt"] + SOLVE, cwd=tmp_path)
    assert_one_clear_error(out, "-surface_file", "bad.txt", says)


@pytest.mark.parametrize("content, says", [("1 2\n3 4\n", "neither an x y z point list"),
                                           ("1 2 3 4\n5 6 7\n", "different numbers of values"),
                                           ("1,2,3,4\n5,6,x,8\n", "not numbers"),
                                           ("# nothing\n", "no numbers")])
def test_tables_that_are_no_surface_are_refused(tmp_path, content, says):
    name = "t.csv" if "," in content else "t.txt"
    (tmp_path / name).write_text(content)
    out = run_cli(["-surface_file", name] + SOLVE, cwd=tmp_path)
    assert_one_clear_error(out, "-surface_file", says)


# --- levelling, tilt and edge warnings -------------------------------------------------------------------------

def tilted(heights, slope_x, slope_y):
    y, x = GRID.coordinates()
    return heights + slope_x * x + slope_y * y


def test_detrend_plane_recovers_the_periodic_surface_and_reports_the_plane():
    heights = periodic_heights()
    levelled, levelling = files.level(GRID, tilted(heights, 3e-3, -1e-3), "plane")
    # The removed plane is the tilt plus the periodic surface's own best-fit plane (least squares is linear).
    _, own_x, own_y = files.fit_plane(GRID, heights)
    assert levelling.slope_x == pytest.approx(3e-3 + own_x, rel=1e-10)
    assert levelling.slope_y == pytest.approx(-1e-3 + own_y, rel=1e-10)
    expected = heights - files.plane_heights(GRID, own_x, own_y)
    assert np.allclose(levelled, expected - expected.mean(), rtol=0, atol=1e-17)
    assert levelling.removed and levelling.notes[0].startswith("-surface_detrend plane removed the plane")
    assert not any("tilted" in note for note in levelling.notes)


@pytest.mark.parametrize("k_l, k_s, n", [(2, 8, 32), (1, 16, 64), (16, 64, 256)])
def test_a_periodic_surface_gets_no_warning(k_l, k_s, n):
    grid = Grid(n, n)
    for seed in range(1, 11):
        _, levelling = files.level(grid, fractal(grid, k_l, k_s, 0.8, 2e-4, seed=seed), "mean")
        assert levelling.notes == ()


def test_tilt_and_edge_jumps_are_warned_of_with_the_figures():
    _, levelling = files.level(GRID, tilted(periodic_heights(), 3e-3, 0.0), "mean")
    warnings = [note for note in levelling.notes if note.startswith("warning")]
    assert any("tilted" in note and "-surface_detrend plane" in note for note in warnings)
    assert any("not periodic" in note and "along x" in note for note in warnings)
    cropped = fractal(Grid(256, 256), 2, 16, 0.8, 2e-4, seed=5)[:64, :64]  # a window of a larger surface
    _, levelling = files.level(Grid(64, 64), cropped, "plane")
    assert any("not periodic" in note and "along x" in note for note in levelling.notes)
    assert any("not periodic" in note and "along y" in note for note in levelling.notes)


def test_detrend_on_the_command_line(tmp_path):
    np.savetxt(tmp_path / "t.txt", tilted(periodic_heights(), 3e-3, 0.0))
    out = run_cli(["-surface_file", "t.txt", "-json", "t.json"] + SOLVE, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "roughpetsc: warning: -surface_file t.txt: the surface is tilted" in out.stderr
    tilted_alpha = json.load(open(tmp_path / "t.json"))["surface"]["alpha_h"]
    out = run_cli(["-surface_file", "t.txt", "-surface_detrend", "plane", "-json", "p.json"] + SOLVE, cwd=tmp_path)
    assert out.returncode == 0 and "tilted" not in out.stderr, out.stderr
    assert "surface: -surface_detrend plane removed the plane of slopes" in out.stdout
    summary = json.load(open(tmp_path / "p.json"))
    assert summary["surface_levelling"]["plane_removed"]
    assert summary["surface"]["alpha_h"] < tilted_alpha / 2


@pytest.mark.parametrize("args, named", [(["-surface_detrend", "cubic"], "-surface_detrend"),
                                         (["-surface_detrend", "plane", "-surface_N", 32, "-surface_kl", 2,
                                           "-surface_ks", 8], "-surface_detrend")])
def test_detrend_values_and_uses_are_checked(tmp_path, args, named):
    np.save(tmp_path / "h.npy", periodic_heights())
    file = ["-surface_file", "h.npy"] if "-surface_N" not in args else []
    out = run_cli(file + args + SOLVE, cwd=tmp_path)
    assert_one_clear_error(out, named)


# --- the radially averaged PSD and the fit of (2.18) ---------------------------------------------------------------

def test_psd_fit_of_an_exact_spectrum_is_exact():
    """generator xu gives every mode the amplitude of (2.18) exactly: the fit returns H and C of (7.1)."""
    grid = Grid(64, 64)
    heights = fractal(grid, 4, 16, 0.7, 2e-4, seed=2, generator="xu")
    fit = spectra.fit_fractal_psd(grid, heights, (4, 16))
    assert fit["hurst"] == pytest.approx(0.7, abs=1e-12)
    assert fit["C"] == pytest.approx(fractal_amplitude(4, 16, 0.7, 2e-4), rel=1e-12)


def test_psd_on_the_command_line(tmp_path):
    args = ["-mode", "stats", "-surface_N", 64, "-surface_kl", 4, "-surface_ks", 16, "-surface_H", 0.7,
            "-surface_generator", "xu", "-stats_psd", tmp_path / "psd.csv", "-stats_json", tmp_path / "s.json"]
    out = run_cli(args)
    assert out.returncode == 0, out.stderr
    assert "PSD fit of (2.18) over k in [4, 16]: H = 0.7 " in out.stdout
    table = np.genfromtxt(tmp_path / "psd.csv", delimiter=",", skip_header=3)
    k, psd, modes, fit = table.T
    amplitude = fractal_amplitude(4, 16, 0.7, 2e-4)
    band = (k >= 4) & (k <= 16)
    assert np.allclose(fit[band], amplitude * k[band] ** -3.4, rtol=1e-10) and np.all(np.isnan(fit[~band]))
    # Annuli well inside the band: the mean PSD of their modes is (2.18) at their mean |k|, close to k.
    assert np.allclose(psd[5:14], amplitude * k[5:14] ** -3.4, rtol=0.1)
    assert modes.sum() > 0 and np.all(psd[k > 17] < 1e-30)
    document = json.load(open(tmp_path / "s.json"))
    assert document["psd"]["hurst"] == pytest.approx(0.7, abs=1e-10)


@pytest.mark.mpi
def test_psd_of_an_ensemble_on_two_ranks_equals_one(tmp_path):
    args = ["-mode", "stats", "-surface_N", 32, "-surface_kl", 2, "-surface_ks", 8, "-stats_ensemble", 3]
    outs = []
    for ranks in (1, 2):
        out = run_cli(args + ["-stats_psd", tmp_path / f"p{ranks}.csv"], ranks=ranks)
        assert out.returncode == 0, out.stderr
        outs.append((tmp_path / f"p{ranks}.csv").read_text())
    assert outs[0] == outs[1]


# --- wavelengths that divide the cell ------------------------------------------------------------------------

@pytest.mark.parametrize("kind, wavelength", [("wave", 0.3), ("bisinusoid", 0.4), ("wave", 2.0)])
def test_a_wavelength_that_does_not_divide_the_cell_is_refused(tmp_path, kind, wavelength):
    out = run_cli(["-surface_type", kind, "-surface_wavelength", wavelength, "-surface_N", 32] + SOLVE, cwd=tmp_path)
    assert_one_clear_error(out, "-surface_wavelength", "does not divide")


def test_wavelengths_that_divide_the_cell_are_used():
    grid = Grid(16, 64, 0.25, 1.0)
    assert generators.wave(grid, 1e-3, 0.25).shape == (16, 64)
    assert generators.bisinusoid(grid, 1e-3, 0.125, 1.0 / 3).shape == (16, 64)
    with pytest.raises(ParameterError, match="does not divide"):
        generators.bisinusoid(grid, 1e-3, 0.1, 0.25)


# --- the Python API validates at construction ---------------------------------------------------------------

@pytest.mark.parametrize("build, parameter", [
    (lambda: Grid(-1, 4), "n0"),
    (lambda: Grid(4, 0), "n1"),
    (lambda: Grid(4, 2.5), "n1"),
    (lambda: Grid(4, 4, 0.0), "l0"),
    (lambda: Grid(4, 4, 1.0, float("inf")), "l1"),
    (lambda: ContactProblem(GRID, np.full(GRID.shape, np.nan), 1.0), "heights"),
    (lambda: ContactProblem(GRID, np.where(np.eye(32) > 0, np.inf, 0.0), 1.0), "heights"),
    (lambda: ContactProblem(GRID, np.zeros(GRID.shape), 1.0), "heights"),
    (lambda: ContactProblem(GRID, np.zeros((8, 8)), 1.0), "heights"),
    (lambda: ContactProblem(GRID, periodic_heights(), float("nan")), "E_star"),
    (lambda: ContactProblem(GRID, periodic_heights(), -1.0), "E_star"),
    (lambda: Westergaard(GRID, 0.0), "E_star"),
])
def test_the_api_refuses_bad_input_at_construction(build, parameter):
    with pytest.raises(ParameterError) as raised:
        build()
    assert raised.value.parameter == parameter


# --- instrument files through SurfaceTopography (the optional extra, tools/surfacetopography.sh) ------------------

def test_an_instrument_file_is_read_by_surfacetopography(tmp_path):
    """A NetCDF topography written by SurfaceTopography itself: heights (x along axis 0 there) and size."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from SurfaceTopography import Topography

        heights = np.random.default_rng(0).standard_normal((48, 32)) * 1e-4  # (nx, ny)
        Topography(heights, physical_sizes=(1.5, 1.0)).to_netcdf(str(tmp_path / "s.nc"))
    read, length = load_surface(str(tmp_path / "s.nc"))
    assert read.shape == (32, 48) and length == 1.5
    assert np.allclose(read, heights.T - heights.mean(), rtol=0, atol=1e-18)
    out = run_cli(["-surface_file", "s.nc", "-json", "s.json", "-quiet"] + SOLVE, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert json.load(open(tmp_path / "s.json"))["length"] == [1.0, 1.5]


def test_without_the_extra_an_instrument_file_is_refused_naming_it(tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)  # import fails as where it is not installed
    (tmp_path / "scan.opd").write_bytes(b"\x00\x01binary instrument data\xff")
    with pytest.raises(ParameterError, match="SurfaceTopography, an optional extra: bash tools/surfacetopography.sh"):
        load_surface(str(tmp_path / "scan.opd"))
    np.savetxt(tmp_path / "matrix.asc2", periodic_heights())  # an unknown suffix holding a table: read as one
    assert load_surface(str(tmp_path / "matrix.asc2"))[0].shape == (32, 32)
