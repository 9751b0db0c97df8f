"""Issue 37, adhesion on the command line: parameters without a law or set twice are refused, messages quote the
value given, no floating-point warning at extreme ranges, and -plot draws the cycle pbar against the mean gap."""

import json

import numpy as np
import pytest

from conftest import run_cli
from conftest import assert_one_clear_error

TINY = ["-surface_N", 32, "-surface_ks", 8, "-surface_kl", 2, "-fft_effort", "FFTW_ESTIMATE"]
CYCLE = ["-gbar_list", "1e-3,6e-4,3e-4,1.5e-4,3e-4,6e-4,1e-3"]


@pytest.mark.parametrize("args, named", [
    (["-adhesion_work", 1e-7, "-gbar", 1e-3], "-adhesion_work given without -adhesion"),
    (["-adhesion", "none", "-adhesion_range", 1e-5, "-gbar", 1e-3], "-adhesion_range given without -adhesion"),
    (["-adhesion", "dugdale", "-adhesion_work", 1e-7, "-adhesion_stress", 1e-3, "-adhesion_range", 1e-4,
      "-gbar", 1e-3], "-adhesion_stress and -adhesion_range"),
    (["-adhesion", "exponential", "-adhesion_work", 1e-7, "-adhesion_stress", 1e-3, "-adhesion_range", 1e-4,
      "-gbar", 1e-3], "-adhesion_stress: the exponential law takes -adhesion_range"),
    (["-adhesion", "dugdale", "-adhesion_work", 1e-7, "-gbar", 1e-3], "-adhesion_stress: the Dugdale law needs"),
    (["-adhesion", "exponential", "-adhesion_range", 1e-5, "-gbar", 1e-3], "-adhesion_work: the work of adhesion is "
                                                                            "missing"),
    (["-adhesion_ramp", 1e-6, "-gbar", 1e-3], "-adhesion_ramp given without -adhesion"),
    (["-adhesion", "exponential", "-adhesion_work", 1e-7, "-adhesion_range", 1e-4, "-adhesion_ramp", 1e-6,
      "-gbar", 1e-3], "-adhesion_ramp: the ramp belongs to the Dugdale law"),
    (["-adhesion", "dugdale", "-adhesion_work", 1e-7, "-adhesion_range", 1e-4, "-adhesion_ramp", 3e-4,
      "-gbar", 1e-3], "-adhesion_ramp: the ramp (0.0003) must be narrower than twice the range h0 = w / sigma0 = "
                      "0.0001"),
])
def test_adhesion_parameters_that_would_be_ignored_are_refused(tmp_path, args, named):
    out = run_cli(TINY + args, cwd=tmp_path)
    message = assert_one_clear_error(out, named)
    assert "None" not in message


@pytest.mark.parametrize("option, value, quoted", [("-adhesion_stress", 0, "got 0"),
                                                   ("-adhesion_stress", -2e-3, "got -0.002"),
                                                   ("-adhesion_work", 0, "got 0"),
                                                   ("-adhesion_ramp", -1e-6, "got -1e-06")])
def test_messages_quote_the_value_given(tmp_path, option, value, quoted):
    given = {"-adhesion_work": 1e-7, "-adhesion_stress": 1e-3, option: value}
    args = ["-adhesion", "dugdale", "-gbar", 1e-3] + [item for pair in given.items() for item in pair]
    out = run_cli(TINY + args, cwd=tmp_path)
    assert_one_clear_error(out, option, quoted)


def test_energy_change_at_extreme_ranges_is_exact_and_quiet():
    """phi(t) - phi(g) of the exponential law against 40-digit arithmetic, with warnings as errors."""
    import warnings

    import mpmath

    from roughpetsc.contact.laws import Exponential

    mpmath.mp.dps = 40
    for work, range_ in ((2.0, 0.3), (2e-7, 1e-9), (1e-3, 1e-12)):
        law = Exponential(work, range_)
        gaps = np.array([0.0, 1e-3, 5e-4, 1.0, 1.0, 4e-12, 0.0])
        trials = np.array([1e-3, 0.0, 5e-4 + 1e-15, 1.0 + 1e-12, 1.0 - 1e-9, 3e-12, -1e-3])
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            change = law.energy_change(gaps, trials)

        def phi(g):
            g = mpmath.mpf(float(g))
            if g < 0:  # continued by its tangent at 0
                return -mpmath.mpf(work) + mpmath.mpf(work) / mpmath.mpf(range_) * g
            return -mpmath.mpf(work) * mpmath.exp(-g / mpmath.mpf(range_))

        exact = np.array([float(phi(t) - phi(g)) for g, t in zip(gaps, trials)])
        scale = np.maximum(np.abs(exact), 1e-300)
        assert np.all(np.abs(change - exact) <= 4e-15 * scale + 1e-300 * work), (change, exact)


def test_a_very_short_range_solves_without_floating_point_warnings(tmp_path, monkeypatch):
    monkeypatch.setenv("PYTHONWARNINGS", "error::RuntimeWarning")
    out = run_cli(TINY + ["-adhesion", "exponential", "-adhesion_work", 2e-7, "-adhesion_range", 1e-9,
                          "-json", tmp_path / "a.json"] + CYCLE)
    assert out.returncode == 0, out.stderr
    assert "Warning" not in out.stderr
    assert all(step["converged"] for step in json.load(open(tmp_path / "a.json"))["steps"])


def test_an_adhesive_plot_draws_pbar_against_the_mean_gap(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    drawn = []
    save = Figure.savefig

    def keep(figure, *args, **kwargs):
        drawn.append(figure)
        return save(figure, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    from roughpetsc.app import plots
    from roughpetsc.surface.grid import Grid

    gaps = [1e-3, 5e-4, 2e-4, 5e-4, 1e-3]
    pbars = [1e-4, 1e-3, 3e-3, 8e-4, -2e-5]
    steps = [{"pstar": p / 0.01, "A": 0.1, "A_corrected": 0.1, "gbar": g, "pbar": p} for g, p in zip(gaps, pbars)]
    field = np.zeros((8, 8))
    plots.plot_solution(str(tmp_path / "c.png"), Grid(8, 8), field, field, steps,
                        {"law": "dugdale", "dissipated_energy": 1.5e-8})
    cycle = next(ax for ax in drawn[0].axes if ax.get_xlabel() == "mean gap gbar")
    assert cycle.get_ylabel().startswith("mean pressure pbar")
    points = next(line for line in cycle.get_lines() if line.get_marker() == ".")
    assert list(points.get_xdata()) == gaps and list(points.get_ydata()) == pbars
    assert {text.get_text() for text in cycle.get_legend().get_texts()} == {"approach", "retraction"}
    assert "1.5e-08" in cycle.get_title()


def test_the_adhesive_cycle_figure_from_the_command_line(tmp_path):
    from matplotlib.image import imread

    out = run_cli(TINY + ["-adhesion", "dugdale", "-adhesion_work", 2e-7, "-adhesion_range", 2e-5,
                          "-plot", tmp_path / "c.png"] + CYCLE)
    assert out.returncode == 0, out.stderr
    image = imread(tmp_path / "c.png")
    assert image.ndim == 3 and image.shape[1] > 2 * image.shape[0]
