"""A fixed set of solves through the command line, digested bit for bit: the check that a refactor changes no number.

    .venv/bin/python tools/fixed_solves.py digest OUT.json      # run every case, write its digest
    .venv/bin/python tools/fixed_solves.py compare A.json B.json  # exit 1 unless the two digests are identical

Every case runs with FFTW_ESTIMATE plans (deterministic on one machine) on one rank. The digest of a case is each
step's results exactly as the JSON summary prints them (iterations, operator applications, residuals, A*, g*, ...)
and a SHA-256 of the pressure and gap fields of the HDF5 output.
"""

import hashlib
import json
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

SMALL = ["-surface_N", "64", "-surface_kl", "4", "-surface_ks", "16"]
CASES = {
    "pk_load_path": SMALL + ["-pstar_list", "0.05,0.2,0.5,1,2"],
    "pk_plain": SMALL + ["-pk_pc", "none", "-pk_active_set", "pk", "-pstar", "0.5"],
    "pk_displacement": SMALL + ["-gbar", "1e-4"],
    "root_find_blmvm": SMALL + ["-tao_type", "blmvm", "-pstar_list", "0.2,0.5"],
    "root_find_tron": SMALL + ["-tao_type", "tron", "-pstar", "0.5"],
    "al_blmvm": SMALL + ["-tao_type", "blmvm", "-bound_load", "al", "-pstar_list", "0.2,0.5"],
    "bqnls_displacement": SMALL + ["-tao_type", "bqnls", "-gbar", "1e-4"],
    "almm": SMALL + ["-tao_type", "almm", "-pstar", "0.5", "-kkt_rtol", "1e-6"],
    "free_boundary": SMALL + ["-boundary", "free", "-pstar", "0.5"],
    "hardness": SMALL + ["-hardness", "0.03", "-pstar", "0.5"],
    "adhesive_dugdale": SMALL + ["-adhesion", "dugdale", "-adhesion_work", "2e-7", "-adhesion_stress", "0.01",
                                 "-gbar_list", "2e-4,1.5e-4,1e-4,1.5e-4,2e-4"],
    "adhesive_exponential": SMALL + ["-adhesion", "exponential", "-adhesion_work", "2e-7", "-adhesion_range", "2e-5",
                                     "-gbar_list", "2e-4,1.5e-4,1e-4,1.5e-4,2e-4"],
    "adhesive_almm": SMALL + ["-adhesion", "exponential", "-adhesion_work", "2e-7", "-adhesion_range", "2e-5",
                              "-tao_type", "almm", "-gbar", "1.5e-4", "-kkt_rtol", "1e-6"],
}
# Wall time differs from run to run; everything else in a step must not.
VOLATILE = ("time_s",)


def _fields_digest(path):
    digest = hashlib.sha256()
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and name.split("/")[-1] in ("pressure", "gap"):
                digest.update(name.encode())
                digest.update(np.ascontiguousarray(obj[()]).tobytes())
        f.visititems(visit)
    return digest.hexdigest()


def _run(name, args, folder):
    json_path, h5_path = os.path.join(folder, f"{name}.json"), os.path.join(folder, f"{name}.h5")
    env = dict(os.environ, ROUGHPETSC_FFT_EFFORT="FFTW_ESTIMATE", ROUGHPETSC_FFT_WISDOM="none")
    command = [sys.executable, "-m", "roughpetsc", *args, "-json", json_path, "-output", h5_path,
               "-output_fields", "all", "-quiet"]
    run = subprocess.run(command, capture_output=True, text=True, env=env)
    if run.returncode not in (0, 3):
        raise SystemExit(f"{name}: exit {run.returncode}\n{run.stderr}")
    steps = json.load(open(json_path))["steps"]
    for step in steps:
        for key in VOLATILE:
            step.pop(key, None)
    return {"exit": run.returncode, "steps": steps, "fields_sha256": _fields_digest(h5_path)}


def digest(out):
    with tempfile.TemporaryDirectory() as folder:
        result = {}
        for name, args in CASES.items():
            result[name] = _run(name, args, folder)
            steps = result[name]["steps"]
            print(f"{name:22s} exit {result[name]['exit']}  steps {len(steps)}  iterations "
                  f"{[s.get('iterations') for s in steps]}  applications {[s.get('operator_applications') for s in steps]}")
    with open(out, "w") as f:
        json.dump(result, f, indent=1, sort_keys=True)


def compare(a_path, b_path):
    a, b = json.load(open(a_path)), json.load(open(b_path))
    differing = [name for name in sorted(set(a) | set(b)) if a.get(name) != b.get(name)]
    for name in sorted(set(a) | set(b)):
        print(f"{name:22s} {'DIFFERS' if name in differing else 'identical'}")
    return 1 if differing else 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "digest":
        digest(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        raise SystemExit(__doc__)
