"""The settings of ``-mode ensemble``: its option table, a frozen dataclass, the configuration a resume must match."""

from dataclasses import dataclass
import json

from ..contact import loads
from ..app import settings as mode_settings
from ..errors import UserError
from ..store.outputs import check_writable
from ..parallel import row_split
from .statistics import MODEL_NAMES

OPTIONS = [
    ("ensemble_size", 50, "number of surfaces (indices 0..size-1; an existing file can be extended)"),
    mode_settings.ENSEMBLE_SEED,
    ("ensemble_group_ranks", 1, "MPI ranks per group; each group solves whole surfaces (must divide the ranks)"),
    ("ensemble_loads", "history", "p* steps: 'history' (7.11, 95 steps, D1 = 0.2/30) or a comma list"),
    ("ensemble_models", "all", "statistical models stored beside the BEM: all | none | comma list of "
                               "gw,nayak_bush,greenwood,bgt,bgt_asymptotic,ciavarella,persson"),
    mode_settings.OUTPUT,
    mode_settings.KKT_RTOL,
    mode_settings.FFT_THREADS,
    mode_settings.FFT_EFFORT,
    mode_settings.QUIET,
]
# -output of an ensemble, when not given.
DEFAULT_OUTPUT = "ensemble.h5"

# Options that do not change the numbers of a surface (not part of the configuration a resume must match).
NOT_NUMBERS = ("mode", "ensemble_size", "ensemble_group_ranks", "ensemble_models", "output", "quiet",
               "fft_threads", "fft_effort", "help", "options_left", "malloc_debug", "malloc_dump")
NOT_CONFIG = ("monitor", "view", "log", "converged_reason", "options_left", "info", "history")


@dataclass(frozen=True)
class EnsembleSettings:
    """Every option of the mode, read and checked (the same on all ranks); ``loads`` the p* of the steps,
    ``surface`` the fractal parameters of every surface."""

    size: int
    seed: int
    group_ranks: int
    loads: tuple
    loads_spec: str
    models: tuple
    output: str
    rtol: float
    E_star: float
    threads: int
    effort: str
    quiet: bool
    tao_type: object
    grid: object
    surface: dict


def parse_models(text):
    """``-ensemble_models``: all | none | a comma list of :data:`MODEL_NAMES`, as a tuple of names."""
    text = (text or "").strip().lower()
    if text == "all":
        return MODEL_NAMES
    if text in ("none", ""):
        return ()
    names = tuple(item.strip() for item in text.split(","))
    if not all(names):  # 'gw,,persson' or a trailing comma: a name was left out
        raise UserError(f"-ensemble_models: empty item in '{text}' (all, none, or a comma list of "
                        f"{', '.join(MODEL_NAMES)})")
    for name in names:
        if name not in MODEL_NAMES:
            raise UserError(f"-ensemble_models: unknown model '{name}' (all, none, or a list of "
                            f"{', '.join(MODEL_NAMES)})")
    return names


def read_settings(reader, ranks):
    """Read and check every option of the mode on ``ranks`` MPI ranks; raise :class:`UserError` naming it."""
    given = mode_settings.read_table(reader, OPTIONS)
    if given["ensemble_size"] < 1:
        raise UserError(f"-ensemble_size must be at least 1, got {given['ensemble_size']}")
    if given["ensemble_seed"] < 0:
        raise UserError(f"-ensemble_seed must be a non-negative integer, got {given['ensemble_seed']}")
    group_ranks = given["ensemble_group_ranks"]
    if group_ranks < 1 or ranks % group_ranks:
        raise UserError(f"-ensemble_group_ranks {group_ranks} must be a positive divisor of the "
                        f"number of MPI ranks ({ranks})")
    path_loads = tuple(float(p) for p in loads.parse(given["ensemble_loads"], "ensemble_loads"))
    models = parse_models(given["ensemble_models"])
    mode_settings.check_rtol(given["kkt_rtol"])
    E_star = mode_settings.check_modulus(reader.getReal("E_star", 1.0))
    mode_settings.check_fft(given["fft_threads"], given["fft_effort"])
    if not reader.hasName("output"):
        given["output"] = DEFAULT_OUTPUT
    if not given["output"]:
        raise UserError("-output: give the path of the ensemble's HDF5 file")
    check_writable(given["output"], "output")
    mode_settings.check_ensemble_surfaces(reader, "mode ensemble", "ensemble")
    grid, surface = mode_settings.fractal_parameters(reader)
    with mode_settings.options_named():
        row_split(grid.n0, group_ranks)  # every rank of a group needs at least one row
    return EnsembleSettings(
        size=given["ensemble_size"], seed=given["ensemble_seed"], group_ranks=group_ranks, loads=path_loads,
        loads_spec=given["ensemble_loads"], models=models, output=given["output"], rtol=given["kkt_rtol"],
        E_star=E_star, threads=given["fft_threads"], effort=given["fft_effort"], quiet=given["quiet"],
        tao_type=reader.getString("tao_type", "") or None, grid=grid, surface=surface)


def configuration(settings, solver_name):
    """Everything that determines the numbers of a surface (a resumed file must match it): the resolved surface,
    modulus, seed, loads, tolerance and solver, and every other option given but monitors, viewers, logs and
    :data:`NOT_NUMBERS`."""
    from petsc4py import PETSc

    resolved = ("E_star", "kkt_rtol", "ensemble_seed", "ensemble_loads", "tao_type")
    solver_options = {name: value for name, value in sorted(PETSc.Options().getAll().items())
                      if name not in NOT_NUMBERS and name not in resolved and not name.startswith("surface_")
                      and not any(word in name for word in NOT_CONFIG)}
    config = {"surface": settings.surface, "E_star": settings.E_star, "ensemble_seed": settings.seed,
              "pstar_target": list(settings.loads), "kkt_rtol": settings.rtol, "solver": solver_name,
              "solver_options": solver_options, "control": "load"}
    return json.loads(json.dumps(config))
