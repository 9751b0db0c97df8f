"""Issue 37, what a run reports: stop reasons quote the numbers of the JSON, options Polonsky-Keer cannot use are
unused, -tao_view shows PK's settings, -log_view names every stage, and the README's usage lines run twice."""

import json
import os
import re

import pytest

from conftest import ROOT, run_cli, run_process
from conftest import assert_one_clear_error

TINY = ["-surface_N", 32, "-surface_ks", 8, "-surface_kl", 2, "-fft_effort", "FFTW_ESTIMATE"]


def test_a_stop_reason_quotes_the_numbers_of_the_json(tmp_path):
    """ALMM stopped by its time limit: the reason quoted a load error of 0.23 where the JSON said 0.116."""
    # A tolerance it cannot reach: the solve stops short of it however fast the machine.
    out = run_cli(TINY + ["-tao_type", "almm", "-kkt_rtol", 1e-15, "-solve_max_time", 1, "-json", tmp_path / "a.json"])
    assert out.returncode == 3, out.stderr
    step = json.load(open(tmp_path / "a.json"))["steps"][0]
    kkt = step["kkt"]
    assert f"natural residual {kkt['natural']:.2g}, load error {kkt['load_error']:.2g}" in step["reason"]
    assert step["reason"] in out.stdout
    assert "best" not in step["reason"]


@pytest.mark.parametrize("option", [["-tao_ls_type", "armijo"], ["-pc_type", "jacobi"], ["-ksp_monitor"],
                                    ["-tao_bnk_ksp_type", "cg"]])
def test_options_polonsky_keer_cannot_use_are_unused(tmp_path, option):
    out = run_cli(TINY + option + ["-json", tmp_path / "p.json"])
    assert_one_clear_error(out, option[0], "not used")
    assert not (tmp_path / "p.json").exists()


def test_the_same_options_are_used_by_a_solver_that_has_them(tmp_path):
    out = run_cli(TINY + ["-gbar", 2e-3, "-tao_type", "bnls", "-tao_bnk_ksp_type", "cg", "-quiet"])
    assert out.returncode == 0, out.stderr


def test_tao_view_of_pk_shows_its_own_settings():
    out = run_cli(TINY + ["-tao_view", "-quiet", "-pk_refresh", 7])
    assert out.returncode == 0, out.stderr
    assert "Polonsky-Keer CG, active set bccg, preconditioner fourier, K p refreshed every 7 iterations" in out.stdout
    assert "stops at a natural KKT residual (and load error) of 1e-08" in out.stdout


def test_log_view_names_every_stage_and_counts_kapps():
    out = run_cli(TINY + ["-pstar_list", "0.2,0.5", "-log_view"])
    assert out.returncode == 0, out.stderr
    stages = re.findall(r"--- Event Stage \d+: (.*)", out.stdout)
    assert stages and "Unknown" not in stages, stages
    assert "RP step 001 pstar=0.5" in stages
    kapps = [int(line.split()[6]) for line in out.stdout.splitlines() if line.rstrip().endswith("CONVERGED_USER")]
    sections = out.stdout.split("--- Event Stage ")
    for index, expected in enumerate(kapps):
        section = next(part for part in sections if part.split("\n")[0].endswith(f"RP step {index:03d} "
                                                                              f"pstar={[0.2, 0.5][index]:g}"))
        counts = {line.split()[0]: int(line.split()[1]) for line in section.splitlines()
                  if line.startswith(("RPCompliance", "RPStiffness"))}
        assert counts.get("RPCompliance", 0) + counts.get("RPStiffness", 0) == expected


def readme_usage_lines():
    text = open(os.path.join(ROOT, "README.md")).read()
    block = text.split("## Usage", 1)[1].split("```sh", 1)[1].split("```", 1)[0]
    return [line.split("#", 1)[0].strip() for line in block.strip().splitlines()[1:]]


@pytest.mark.parametrize("index", [1, 3, 7])  # the path with its files, the surface file, -version
def test_readme_usage_lines_run_twice_from_a_scratch_folder(tmp_path, index):
    lines = readme_usage_lines()
    commands = [lines[1], lines[index]] if index == 3 else [lines[index]]  # line 3 reads the output of line 1
    env = dict(os.environ, R=ROOT, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    for attempt in (1, 2):
        for command in commands:
            out = run_process(["bash", "-c", command], cwd=tmp_path, env=env)
            assert out.returncode == 0, (attempt, command, out.stderr)
    assert not [name for name in os.listdir(ROOT) if name.endswith((".h5", ".json"))]
