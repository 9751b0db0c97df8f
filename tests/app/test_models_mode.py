"""The ``models`` CLI mode: options through PETSc.Options, outputs, errors."""

import json

import numpy as np
import pytest

from mpi4py import MPI
from petsc4py import PETSc

from roughpetsc.errors import UserError
from roughpetsc.models import ALPHA_P_TABLE_8_3, TABLE_8_4, complete, correction, early
from roughpetsc.app import models_mode as mode

from conftest import run_cli
import dissertation_formulas as reference_formulas


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


def _curvefit(tmp_path, extra):
    vals = {"models_n": "9", "models_group": "18", "models_json": str(tmp_path / "c.json"), **extra}
    try:
        mode.run(_options(vals), MPI.COMM_WORLD)
    finally:
        _clear(vals)
    return json.loads((tmp_path / "c.json").read_text())["curvefit"]


def test_curvefit_is_drawn_with_5_37_by_default(tmp_path):
    """-mode models -models_group 18 draws Table 8.4's curve with I of (5.37) and the PDF (2.42), checked point by
    point against that formula integrated by adaptive quad (tests/dissertation_formulas.py)."""
    curve = _curvefit(tmp_path, {})
    b, c, d = TABLE_8_4[18]
    assert curve["model"] == "gw" and (curve["b"], curve["c"], curve["d"]) == (b, c, d)
    reference = [reference_formulas.curve_fit_area(p, ALPHA_P_TABLE_8_3[18], b, c, d) for p in curve["pstar"]]
    assert curve["A"] == pytest.approx(reference, rel=1e-7, abs=1e-9)


def test_curvefit_model_option_selects_5_45(tmp_path):
    """-models_curvefit_model greenwood draws I f with the text's (5.45); it differs from the default by > 0.01."""
    curve = _curvefit(tmp_path, {"models_curvefit_model": "greenwood"})
    p, ap = np.array(curve["pstar"]), ALPHA_P_TABLE_8_3[18]
    I = complete("greenwood", p, ap, ap)[0]
    expected = np.where(p <= 2, I * correction(p, *TABLE_8_4[18]), I)
    assert curve["model"] == "greenwood" and curve["A"] == pytest.approx(list(expected), rel=1e-13, abs=1e-15)
    default = [reference_formulas.curve_fit_area(x, ap, *TABLE_8_4[18]) for x in p]
    assert np.max(np.abs(np.array(curve["A"]) - default)) > 0.01


def test_help_names_the_curvefit_model_option():
    out = run_cli(["-help"])
    assert out.returncode == 0 and "-models_curvefit_model" in out.stdout and "(5.37)" in out.stdout


@pytest.mark.parametrize("bad", [{"models_alpha_h": "1.2"}, {"models_hurst": "1.5"},
                                 {"models_json": "/nonexistent/dir/x.json"}, {"models_group": "3"},
                                 {"models_curvefit_model": "persson"}, {"models_curvefit_model": ""}])
def test_bad_input_names_option(bad):
    try:
        with pytest.raises(UserError) as err:
            mode.run(_options(bad), MPI.COMM_WORLD)
    finally:
        _clear(bad)
    assert "-" + list(bad)[0] in str(err.value)
