"""The preset files: ``solvers/*.opts`` (solver settings) and ``options/*.opts`` (surface groups), package data.

A preset is a PETSc options file; Python code reads it with :func:`read_opts`, so a surface group of Tables
7.1/8.1 is typed once, in its ``options/groupNN.opts``. This module does not import PETSc.
"""

import glob
import os

# The presets solvers/*.opts and options/*.opts: package data, installed with roughpetsc (the repository's
# top-level solvers/ and options/ link here).
ROOT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "presets")
PRESET_FOLDERS = ("solvers", "options")


def read_opts(path):
    """``{name: value}`` of an options file (names without the leading dash, values as strings)."""
    options = {}
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                key, _, value = line.partition(" ")
                options[key.lstrip("-")] = value.strip()
    return options


def preset_names(folder):
    """The names (without ``.opts``) of the presets in ``ROOT/folder``, sorted; [] if there is no such folder."""
    return sorted(os.path.basename(path)[:-5] for path in glob.glob(os.path.join(ROOT, folder, "*.opts")))


def presets(folder):
    """``{name: options}`` of every preset of ``ROOT/folder``, in name order."""
    return {name: read_opts(os.path.join(ROOT, folder, name + ".opts")) for name in preset_names(folder)}


def fractal_group(number):
    """The fractal surface of group ``number`` (``options/groupNN.opts``), defaults filled in.

    Returns
    -------
    dict
        ``n`` (nodes per side), ``length`` (cell length along x [length]) and the keywords ``k_l``, ``k_s``
        [cycles/length], ``hurst``, ``m2``, ``generator`` of :func:`roughpetsc.surfaces.fractal`.
    """
    from .surface_options import FRACTAL_KEYWORDS, SURFACE_OPTIONS

    path = os.path.join(ROOT, "options", f"group{number:02d}.opts")
    if not os.path.isfile(path):
        raise ValueError(f"no surface group {number} (no file {path})")
    given = read_opts(path)
    values = {name: type(default)(given.get(name, default)) for name, default, _ in SURFACE_OPTIONS
              if name in FRACTAL_KEYWORDS or name in ("surface_N", "surface_L")}
    group = {FRACTAL_KEYWORDS[name]: value for name, value in values.items() if name in FRACTAL_KEYWORDS}
    del group["seed"]
    return dict(group, n=values["surface_N"], length=values["surface_L"])


def fractal_groups():
    """``{number: fractal_group(number)}`` of every ``options/groupNN.opts``."""
    return {int(name[5:]): fractal_group(int(name[5:])) for name in preset_names("options")
            if name.startswith("group") and name[5:].isdigit()}
