"""Standard PETSc options work: viewers and reasons read after the solve, -log_view with our own events."""

import json

import pytest

from conftest import run_cli

SMALL = ["-surface_N", 64, "-surface_ks", 16, "-surface_kl", 4]
OUR_EVENTS = ("RPCompliance", "RPStiffness", "RPFFTPair", "RPFourierPC", "RPKKTCheck")


def event_counts(log_view, name):
    """Counts of event ``name`` in each stage of a one-rank -log_view table."""
    return [int(line.split()[1]) for line in log_view.splitlines() if line.split()[:1] == [name]]


def test_log_view_shows_our_events_and_the_operator_count(tmp_path):
    out = run_cli(SMALL + ["-pstar_list", "0.3,0.6", "-log_view", "-json", tmp_path / "l.json"])
    assert out.returncode == 0, out.stderr
    for name in OUR_EVENTS:
        assert event_counts(out.stdout, name), name
    for index in range(2):  # a stage per load step
        assert f"RP step {index:03d} pstar=" in out.stdout
    steps = json.load(open(tmp_path / "l.json"))["steps"]
    applications = sum(event_counts(out.stdout, "RPCompliance")) + sum(event_counts(out.stdout, "RPStiffness"))
    assert applications == sum(step["operator_applications"] for step in steps)


@pytest.mark.parametrize("args, shows", [
    (["-tao_view"], "Tao Object"),
    (["-options_left"], "There are no unused options"),
    (["-options_view"], "#End of PETSc Option Table entries"),
    (["-tao_type", "bnls", "-gbar", 3e-4, "-tao_bnk_ksp_converged_reason"], "Linear tao_bnk_ solve converged"),
    (["-tao_monitor_solution", "ascii"], "Vec Object"),  # the PETSc >= 3.21 name of -tao_view_solution
])
def test_options_read_during_or_after_the_solve_are_honoured(tmp_path, args, shows):
    out = run_cli(SMALL + args + ["-output", tmp_path / "o.h5"])
    assert out.returncode == 0, out.stderr
    assert shows in out.stdout
    assert (tmp_path / "o.h5").exists()


@pytest.mark.parametrize("typo", ["-tao_veiw", "-tao_view_soltion"])
def test_a_misspelled_option_is_still_refused_without_output(tmp_path, typo):
    out = run_cli(SMALL + [typo, "-output", tmp_path / "o.h5", "-json", tmp_path / "o.json"])
    assert out.returncode == 2
    errors = [line for line in out.stderr.splitlines() if line.startswith("roughpetsc: error")]
    assert len(errors) == 1 and typo in errors[0] and "Traceback" not in out.stderr
    assert not (tmp_path / "o.h5").exists() and not (tmp_path / "o.json").exists()
