"""``-mode ensemble``: the load history (7.11), seeds, MPI groups, the HDF5 file, kill and resume."""

import json
import os
import re
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import MPI_ENV, ROOT, SUBPROCESS_TIMEOUT, run_cli
from roughpetsc import ensemble
from roughpetsc.contact import loads
from roughpetsc.errors import UserError

SMALL = ["-mode", "ensemble", "-surface_N", 64, "-surface_kl", 4, "-surface_ks", 16, "-ensemble_seed", 7,
         "-ensemble_models", "greenwood,bgt_asymptotic,ciavarella,persson"]
FEW_LOADS = ",".join(repr(float(p)) for p in loads.history()[[4, 14, 29, 44, 59, 74, 84, 94]])


# ----------------------------------------------------------------------------
# File comparison "to 1e-12", timings and run bookkeeping excluded
# ----------------------------------------------------------------------------

def assert_same_ensemble(a, b, rtol=1e-12):
    """Two ensemble files (paths or ``ensemble.read`` dicts) hold the same numbers to ``rtol``."""
    worst = ensemble.compare(a, b)
    bad = {name: value for name, value in worst.items() if not value <= rtol}
    assert not bad, bad


# ----------------------------------------------------------------------------
# (a) load history and seeds
# ----------------------------------------------------------------------------

def test_load_history_7_11_with_the_delta1_erratum():
    p = loads.history()
    assert p.shape == (95,)
    assert p[0] == pytest.approx(0.2 / 30, rel=1e-15)          # Delta_1 = 0.2/30 (erratum of (7.11)), not 0.067
    assert p[29] == pytest.approx(0.2, rel=1e-15)              # end of the early stage
    assert p[30] == pytest.approx(0.2 * np.exp(0.0512), rel=1e-15)
    assert p[74] == pytest.approx(0.2 * np.exp(0.0512 * 45), rel=1e-15)
    assert p[74] == pytest.approx(2.00283, abs=1e-5)           # the medium stage ends slightly above 2
    assert p[75] == pytest.approx(2.1, rel=1e-15)
    assert p[94] == pytest.approx(4.0, rel=1e-15)
    assert np.all(np.diff(p) > 0)
    assert np.allclose(np.diff(p[:30]), 0.2 / 30) and np.allclose(np.diff(p[75:]), 0.1)


def test_load_lists_and_their_errors():
    assert np.array_equal(loads.parse("history", "x"), loads.history())
    assert list(loads.parse("0.1, 0.5,2", "x")) == [0.1, 0.5, 2.0]
    for bad in ("", "0.1,abc", "0.1,-1", "nan", "0,1"):
        with pytest.raises(UserError, match="-ensemble_loads"):
            loads.parse(bad, "ensemble_loads")


def test_seeds_derive_from_the_master_seed():
    seeds = [ensemble.surface_seed(3, i) for i in range(50)]
    assert seeds == [ensemble.surface_seed(3, i) for i in range(50)]
    assert len(set(seeds)) == 50 and all(0 <= s < 2 ** 31 for s in seeds)
    children = np.random.SeedSequence(3).spawn(5)
    assert [int(c.generate_state(1, np.uint32)[0] & 0x7FFFFFFF) for c in children] == seeds[:5]
    assert seeds != [ensemble.surface_seed(4, i) for i in range(50)]


# ----------------------------------------------------------------------------
# (b) the file; the same numbers on 1 and 2 ranks
# ----------------------------------------------------------------------------

@pytest.mark.mpi
@pytest.mark.slow
def test_file_layout_and_same_numbers_on_one_and_two_ranks(tmp_path, monkeypatch):
    args = SMALL + ["-ensemble_size", 3, "-ensemble_loads", FEW_LOADS, "-kkt_rtol", 1e-12]
    runs = {"r1": ([], 1), "r2": ([], 2), "g2": (["-ensemble_group_ranks", 2], 2)}
    contents = {}
    for name, (extra, ranks) in runs.items():
        if name == "r2":   # the work counter by messages (the fallback when MPI windows are unusable)
            monkeypatch.setenv("ROUGHPETSC_ENSEMBLE_COUNTER", "messages")
        out = run_cli(args + extra + ["-output", tmp_path / f"{name}.h5"], ranks=ranks)
        monkeypatch.delenv("ROUGHPETSC_ENSEMBLE_COUNTER", raising=False)
        assert out.returncode == 0, out.stderr
        assert len(_solved(out.stdout)) == 3 and out.stdout.count("8/8 steps converged") == 3
        assert "ETA" in out.stdout
        contents[name] = ensemble.read(tmp_path / f"{name}.h5")
    c = contents["r1"]
    m = len(FEW_LOADS.split(","))
    assert c["@format"] == ensemble.FORMAT and c["@complete"] and c["@n_finished"] == 3
    assert json.loads(c["@options"])["ensemble_size"] == "3" and "petsc" in json.loads(c["@versions"])
    assert "-mode ensemble" in c["@command"]
    assert list(c["surfaces/index"]) == [0, 1, 2]
    assert list(c["surfaces/seed"]) == [ensemble.surface_seed(7, i) for i in range(3)]
    for key in ("m0h", "m2h", "m4h", "m0p", "m2p", "m4p", "alpha_h", "alpha_p"):
        assert c[f"surfaces/{key}"].shape == (3,) and np.all(c[f"surfaces/{key}"] > 0)
    for key in ensemble.STEP_FIELDS + ("reason",):
        assert c[f"steps/{key}"].shape == (3, m)
    assert np.all(c["steps/converged"] == 1) and np.all(c["steps/kkt_natural"] <= 1e-12)
    assert np.allclose(c["steps/pstar"], c["pstar_target"], rtol=1e-10)
    assert np.array_equal(c["statistics/A_mean"], c["steps/A"].mean(axis=0))
    assert np.array_equal(c["statistics/gstar_std"], c["steps/gstar"].std(axis=0, ddof=1))
    assert np.all(np.diff(c["statistics/A_mean"]) > 0) and c["statistics/A_mean"][-1] > 0.999
    assert c["statistics/alpha_h_mean"] == pytest.approx(c["models@alpha_h"], rel=0)
    # Models at the steps: early ones only on the early stage (p* <= 0.2), nearly-complete ones everywhere.
    early = c["pstar_target"] <= 0.2
    assert np.all(np.isfinite(c["models/early/greenwood/A"][early]))
    assert np.all(np.isnan(c["models/early/greenwood/A"][~early]))
    assert np.all(np.isfinite(c["models/complete/greenwood/A"])) and "models/early/bgt/A" not in c
    assert np.all(c["models/kappa/bem_A"][early] > 0)
    assert max(ensemble.compare(c, c).values()) == 0.0
    # What studies read: /statistics and /models as stored, and the same numbers computed for a file without them.
    stored = ensemble.stored_models(c)
    assert np.array_equal(stored["complete"]["greenwood"]["A"], c["models/complete/greenwood/A"])
    assert ensemble.stored_statistics(c)["A_mean"] is c["statistics/A_mean"]
    unfinished = {name: value for name, value in c.items() if not name.startswith(("models", "statistics"))}
    notes = []
    assert np.array_equal(ensemble.stored_statistics(unfinished, notes.append)["gstar_std"], c["statistics/gstar_std"])
    computed = ensemble.stored_models(unfinished, say=notes.append)
    for family, model, curve in (("early", "greenwood", "A"), ("complete", "ciavarella", "gstar")):
        assert np.array_equal(computed[family][model][curve], stored[family][model][curve], equal_nan=True)
    assert np.array_equal(computed["kappa"]["bem_A"], c["models/kappa/bem_A"], equal_nan=True)
    assert "statistics" in notes[0] and "no /models" in notes[-1]
    assert ensemble.compare(c, dict(c, **{"steps/A": c["steps/A"] * (1 + 1e-9)}))["steps/A"] > 1e-12
    assert_same_ensemble(contents["r1"], contents["r2"])
    assert_same_ensemble(contents["r1"], contents["g2"])
    runs_log = json.loads(contents["r2"]["@runs"])
    assert runs_log[0]["counter"] == "messages" and sorted(runs_log[0]["solved"]) == [0, 1, 2]


# ----------------------------------------------------------------------------
# (c) SIGKILL in the middle, rerun: same file, no finished surface solved twice
# ----------------------------------------------------------------------------

def _finished(path):
    try:
        with h5py.File(path, "r") as f:
            return int(f.attrs["n_finished"])
    except Exception:
        return -1


def _session_members(session):
    """Live processes of a session (mpiexec puts each rank in its own process group, not in the session's)."""
    members = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as handle:
                    fields = handle.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[3]) == session and fields[0] != "Z":
                members.append(int(entry))
    return members


def _kill_session(session):
    """SIGKILL mpiexec and the ranks it started (all in the session the test created), and wait for their end."""
    deadline = time.time() + 30
    while time.time() < deadline:
        members = _session_members(session)
        if not members:
            return
        for pid in members:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        time.sleep(0.05)
    raise AssertionError(f"processes of session {session} survive SIGKILL")


def _solved(stdout):
    return [int(i) for i in re.findall(r"^surface\s+(\d+) seed", stdout, re.M)]


@pytest.mark.mpi
@pytest.mark.slow
def test_kill_and_resume_gives_the_same_file(tmp_path):
    size = 6
    args = ["-mode", "ensemble", "-surface_N", 128, "-surface_kl", 8, "-surface_ks", 32, "-ensemble_size", size,
            "-ensemble_loads", ",".join(repr(float(p)) for p in loads.history()[2::3]), "-ensemble_models", "none"]
    killed = tmp_path / "killed.h5"
    command = ["mpiexec", "-n", "2", "--oversubscribe", sys.executable, "-m", "roughpetsc",
               *[str(a) for a in args], "-output", str(killed)]
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    process = subprocess.Popen(command, cwd=ROOT, env=env, start_new_session=True, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.time() + SUBPROCESS_TIMEOUT
        while process.poll() is None and time.time() < deadline and _finished(killed) < 1:
            time.sleep(0.02)
        assert process.poll() is None, "the run ended before it could be killed"
    finally:
        _kill_session(process.pid)     # start_new_session: the session id is mpiexec's pid
        process.communicate()
    # The file is readable and holds whole surfaces only.
    partial = ensemble.read(killed)
    finished = set(int(i) for i in partial["surfaces/index"])
    assert 1 <= len(finished) < size and not partial["@complete"]
    assert partial["steps/A"].shape[0] == len(finished) == partial["@n_finished"]

    rerun = run_cli(args + ["-output", killed], ranks=2)
    assert rerun.returncode == 0, rerun.stderr
    solved_again = set(_solved(rerun.stdout))
    assert solved_again == set(range(size)) - finished           # no finished surface solved twice
    assert f"({len(finished)} finished in" in rerun.stdout
    final = ensemble.read(killed)
    log = json.loads(final["@runs"])
    assert [r["run"] for r in log] == [0, 1]
    assert set(log[0]["solved"]) == finished and set(log[1]["solved"]) == solved_again
    assert {int(i) for i, r in zip(final["surfaces/index"], final["surfaces/run"]) if r == 0} == finished

    straight = run_cli(args + ["-output", tmp_path / "straight.h5"], ranks=2)
    assert straight.returncode == 0, straight.stderr
    assert_same_ensemble(ensemble.read(tmp_path / "straight.h5"), final)

    # A third run finds everything done: it solves nothing and leaves the same numbers.
    again = run_cli(args + ["-output", killed], ranks=1)
    assert again.returncode == 0, again.stderr
    assert _solved(again.stdout) == []
    assert_same_ensemble(final, ensemble.read(killed), rtol=0.0)


# ----------------------------------------------------------------------------
# (d) bad input, non-convergence, the solve-mode hook
# ----------------------------------------------------------------------------

@pytest.mark.parametrize("extra, named", [
    (["-ensemble_group_ranks", 2], "-ensemble_group_ranks"),
    (["-ensemble_size", 0], "-ensemble_size"),
    (["-ensemble_loads", "0.1,oops"], "-ensemble_loads"),
    (["-ensemble_models", "greenwod"], "-ensemble_models"),
    (["-surface_seed", 3], "-surface_seed"),
    (["-ensemble_sise", 3], "-ensemble_size"),
    (["-kkt_rtol", 2], "-kkt_rtol"),
])
def test_bad_option_gives_exit_2_and_one_message(tmp_path, extra, named):
    out = run_cli(SMALL + ["-ensemble_size", 2, "-ensemble_loads", "0.1", "-output", tmp_path / "e.h5"] + extra)
    assert out.returncode == 2, out.stdout + out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and named in lines[0] and "Traceback" not in out.stderr
    assert not os.path.exists(tmp_path / "e.h5")


def test_foreign_or_different_file_is_not_overwritten(tmp_path):
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = [1.0]
    out = run_cli(SMALL + ["-ensemble_size", 1, "-ensemble_loads", "0.1", "-output", foreign])
    assert out.returncode == 2 and "-output" in out.stderr and "not a roughpetsc ensemble" in out.stderr
    with h5py.File(foreign) as f:
        assert list(f) == ["x"]
    path = tmp_path / "e.h5"
    assert run_cli(SMALL + ["-ensemble_size", 1, "-ensemble_loads", "0.1", "-output", path]).returncode == 0
    before = open(path, "rb").read()
    out = run_cli(SMALL + ["-ensemble_size", 1, "-ensemble_loads", "0.2", "-output", path])
    assert out.returncode == 2 and "pstar_target" in out.stderr
    assert open(path, "rb").read() == before


def test_a_file_resumes_only_with_its_surface_generator(tmp_path):
    """Surfaces of two generators never share a file; a file whose configuration predates the generator's place in
    it is read with the generator its recorded options name."""
    path = tmp_path / "e.h5"
    first = SMALL + ["-ensemble_loads", "0.1", "-output", path, "-surface_generator", "xu"]
    assert run_cli(first + ["-ensemble_size", 1]).returncode == 0
    before = open(path, "rb").read()
    out = run_cli(SMALL + ["-ensemble_loads", "0.1", "-output", path, "-surface_generator", "filter",
                           "-ensemble_size", 2])
    assert out.returncode == 2 and "-output" in out.stderr and "differs in surface" in out.stderr
    assert open(path, "rb").read() == before
    with h5py.File(path, "r+") as f:     # the configuration as files written before the generator was in it
        config = json.loads(f.attrs["config"])
        assert config["surface"].pop("generator") == "xu"
        f.attrs["config"] = json.dumps(config, sort_keys=True)
    out = run_cli(first + ["-ensemble_size", 2])
    assert out.returncode == 0, out.stderr
    assert ensemble.read(path)["@n_finished"] == 2
    assert json.loads(ensemble.read(path)["@config"])["surface"]["generator"] == "xu"


def test_non_converged_steps_are_recorded_and_exit_3(tmp_path):
    out = run_cli(SMALL + ["-ensemble_size", 2, "-ensemble_loads", "0.05,0.1", "-tao_max_it", 2,
                           "-output", tmp_path / "n.h5"])
    assert out.returncode == 3, out.stderr
    assert "NOT CONVERGED" in out.stdout
    c = ensemble.read(tmp_path / "n.h5")
    assert np.all(c["steps/converged"] == 0) and np.all(c["statistics/converged_count"] == 0)
    assert c["@complete"] and all(r for r in c["steps/reason"].ravel())


def test_solve_mode_takes_the_history(tmp_path):
    out = run_cli(["-surface_N", 32, "-surface_kl", 2, "-surface_ks", 8, "-pstar_list", "history",
                   "-json", tmp_path / "h.json"])
    assert out.returncode == 0, out.stderr
    steps = json.load(open(tmp_path / "h.json"))["steps"]
    assert np.allclose([s["pstar"] for s in steps], loads.history(), rtol=1e-8)
