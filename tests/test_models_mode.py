"""The ``models`` CLI mode: options through PETSc.Options, outputs, errors."""

import json

import pytest

from mpi4py import MPI
from petsc4py import PETSc

from roughpetsc.errors import UserError
from roughpetsc.models import early, mode


def _options(values):
    opts = PETSc.Options()
    for k, v in values.items():
        opts.setValue(k, v)
    return opts


def _clear(values):
    opts = PETSc.Options()
    for k in values:
        opts.delValue(k)


def test_option_names():
    names = [n for n, _, _ in mode.OPTIONS]
    assert all(n.startswith("models_") for n in names) and len(set(names)) == len(names)


def test_run_writes_json_and_png(tmp_path):
    vals = {"models_alpha_h": "10", "models_n": "9", "models_json": str(tmp_path / "c.json"),
            "models_plot": str(tmp_path / "c.png")}
    try:
        curves = mode.run(_options(vals), MPI.COMM_WORLD)
    finally:
        _clear(vals)
    data = json.loads((tmp_path / "c.json").read_text())
    assert (tmp_path / "c.png").read_bytes()[:4] == b"\x89PNG"
    A, p = early("greenwood", data["early"]["greenwood"]["dstar"], 10.0)
    assert data["early"]["greenwood"]["A"] == pytest.approx(list(A), rel=1e-14)
    assert set(data["complete"]) == {"gw", "nayak_bush", "greenwood", "ciavarella"}
    assert curves["alpha_h"] == 10.0


@pytest.mark.parametrize("bad", [{"models_alpha_h": "1.2"}, {"models_hurst": "1.5"},
                                 {"models_json": "/nonexistent/dir/x.json"}, {"models_group": "3"}])
def test_bad_input_names_option(bad):
    try:
        with pytest.raises(UserError) as err:
            mode.run(_options(bad), MPI.COMM_WORLD)
    finally:
        _clear(bad)
    assert "-" + list(bad)[0] in str(err.value)
