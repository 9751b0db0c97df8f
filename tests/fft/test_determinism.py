"""The same command gives the same iterates: measured FFTW plans are remembered in a wisdom file.

Under FFTW_MEASURE two runs may plan different algorithms, which round differently, and a
quasi-Newton solver turns that into different iterate sequences. With the wisdom cache the
second and every later run reuse the first run's plans: iterations and residuals repeat exactly.
"""

import pytest
import json
import os

from conftest import run_cli

SMALL = ["-surface_N", 64, "-surface_ks", 16, "-surface_kl", 4]


def _steps(tmp_path, name, extra, ranks):
    out = run_cli(SMALL + extra + ["-json", tmp_path / name], ranks=ranks)
    assert out.returncode == 0, out.stderr
    return [(s["iterations"], s["operator_applications"], s["kkt"]["natural"], s["A"], s["gbar"])
            for s in json.load(open(tmp_path / name))["steps"]]


@pytest.mark.mpi
@pytest.mark.slow
def test_measured_plans_are_remembered_and_runs_repeat(tmp_path, monkeypatch):
    monkeypatch.delenv("ROUGHPETSC_FFT_EFFORT", raising=False)  # this test is about MEASURE itself
    monkeypatch.delenv("ROUGHPETSC_FFT_WISDOM", raising=False)
    wisdom = tmp_path / "wisdom.json"
    extra = ["-fft_effort", "FFTW_MEASURE", "-fft_wisdom", wisdom, "-tao_type", "blmvm", "-pstar_list", "0.2,0.6"]
    _steps(tmp_path, "first.json", extra, ranks=2)
    assert wisdom.exists() and wisdom.stat().st_size > 0
    second = _steps(tmp_path, "second.json", extra, ranks=2)
    third = _steps(tmp_path, "third.json", extra, ranks=2)
    assert second == third  # bit for bit: the same plans, the same iterates


def test_no_wisdom_file_without_measuring_or_when_disabled(tmp_path, monkeypatch):
    monkeypatch.delenv("ROUGHPETSC_FFT_EFFORT", raising=False)
    monkeypatch.delenv("ROUGHPETSC_FFT_WISDOM", raising=False)
    estimate = tmp_path / "estimate.json"
    _steps(tmp_path, "e.json", ["-fft_effort", "FFTW_ESTIMATE", "-fft_wisdom", estimate], ranks=1)
    assert not estimate.exists()
    monkeypatch.setenv("ROUGHPETSC_FFT_WISDOM", "none")
    _steps(tmp_path, "n.json", ["-fft_effort", "FFTW_MEASURE"], ranks=1)
    assert not any(name.startswith("fftw-wisdom") for name in os.listdir(tmp_path))


def test_forced_planner_effort_is_checked(monkeypatch):
    monkeypatch.setenv("ROUGHPETSC_FFT_EFFORT", "FFTW_SLOPPY")
    out = run_cli(SMALL)
    assert out.returncode == 2
    assert "ROUGHPETSC_FFT_EFFORT" in out.stderr and "Traceback" not in out.stderr
