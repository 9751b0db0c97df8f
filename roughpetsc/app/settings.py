"""Option tables of the modes and the checks they share: one table feeds ``-help`` and the settings.

A table is a list of ``(name, default, help)`` tuples, the option's type its default's; :func:`read_table` reads
one, and each mode makes its frozen settings of it. :func:`user_message` turns a library
:class:`~roughpetsc.errors.ParameterError` into a message naming the option that set the parameter
(:data:`PARAMETER_OPTIONS`). The shared checks raise :class:`~roughpetsc.errors.UserError` naming the option.
"""

from contextlib import contextmanager
import math

from ..fft import plans as fftw
from . import surface_options
from ..surface.generators import check_fractal_parameters
from ..errors import ParameterError, UserError

# The general options of every mode (read into each mode's settings; roughpetsc.cli prints them first in -help).
GENERAL_OPTIONS = [
    ("mode", "solve", "solve | stats | models | ensemble"),
    ("E_star", 1.0, "composite modulus E* (1.6), pressure units"),
    ("overwrite", False, "replace existing output files (without it an existing file is refused, never replaced)"),
]

# Options several modes read, each declared once here and listed in the table of every mode that reads it.
KKT_RTOL = ("kkt_rtol", 1e-8, "stop when the natural KKT residual ||min(p/pbar, g/sqrt(m0h))||_inf (and the load "
                              "error) <= this")
OUTPUT = ("output", "", "write an HDF5 file to PATH: in -mode solve heights, the fields of -output_fields, each "
                        "step's results and residual history, units and descriptions, saved as the steps finish; in "
                        "-mode ensemble the ensemble's file (default ensemble.h5), which a rerun resumes")
FFT_THREADS = ("fft_threads", 1, "FFTW threads on one rank")
FFT_EFFORT = ("fft_effort", "FFTW_MEASURE", "FFTW planner effort: FFTW_ESTIMATE | FFTW_MEASURE | FFTW_PATIENT "
                                            "(measured plans are remembered, see -fft_wisdom)")
QUIET = ("quiet", False, "print nothing but errors")
ENSEMBLE_SEED = ("ensemble_seed", 1, "master seed of an ensemble; surface i gets SeedSequence(master).spawn(...)[i] "
                                     "(31-bit, see the file)")

# The option that sets each parameter the library names in a ParameterError (roughpetsc.errors), in every mode.
PARAMETER_OPTIONS = {**{keyword: option for option, keyword in surface_options.FRACTAL_KEYWORDS.items()},
                     "cut_offs": "surface_kl/-surface_ks",
                     "n1": "surface_N", "n0": "surface_N0/-surface_N", "length": "surface_L",
                     "kind": "surface_type", "heights": "surface_type", "path": "surface_file",
                     "amplitude": "surface_amplitude", "wavelength": "surface_wavelength", "radius": "surface_radius",
                     "effort": "fft_effort", "detrend": "surface_detrend", "E_star": "E_star", "e_star": "E_star",
                     "rtol": "kkt_rtol",
                     "tao_type": "tao_type", "pstar": "pstar", "pbar": "pbar", "gbar": "gbar",
                     "boundary": "boundary", "hardness": "hardness", "depths": "stress_depths", "nu": "nu",
                     **{name: name for name in ("adhesion", "adhesion_work", "adhesion_stress", "adhesion_range",
                                                 "adhesion_ramp")}}


def user_message(error):
    """The one line reporting a bad input: a :class:`ParameterError` prefixed by its option (else parameter)."""
    if not isinstance(error, ParameterError):
        return str(error)
    option = PARAMETER_OPTIONS.get(error.parameter)
    return f"-{option}: {error}" if option else f"{error.parameter}: {error}"


@contextmanager
def options_named():
    """Turn a :class:`ParameterError` into a :class:`UserError` naming the option that set it."""
    try:
        yield
    except ParameterError as error:
        raise UserError(user_message(error)) from None


def read_table(options, table):
    """``{name: value}`` of ``table`` from ``options`` (PETSc.Options or a Reader), with its type's getter."""
    getters = {int: options.getInt, float: options.getReal, str: options.getString, bool: options.getBool}
    return {name: getters[type(default)](name, default) for name, default, _ in table}


def check_rtol(rtol):
    """``-kkt_rtol``: the natural KKT residual to stop at, in (0, 1)."""
    if not 0 < rtol < 1:
        raise UserError(f"-kkt_rtol must lie in (0, 1), got {rtol}")
    return rtol


def check_modulus(E_star):
    """``-E_star``: the composite modulus E* (1.6), positive and finite."""
    if not (E_star > 0 and math.isfinite(E_star)):
        raise UserError(f"-E_star must be a positive, finite modulus, got {E_star}")
    return E_star


def check_fft(threads, effort):
    """``-fft_threads`` (>= 1) and ``-fft_effort`` (an FFTW planner flag; :func:`roughpetsc.fftw.planner_effort`)."""
    if threads < 1:
        raise UserError(f"-fft_threads must be at least 1, got {threads}")
    with options_named():
        fftw.planner_effort(effort)
    return threads, effort


def is_random_surface(options):
    """True when the options name generated fractal surfaces (no ``-surface_file``, ``-surface_type fractal``)."""
    return not options.getString("surface_file", "") and options.getString("surface_type", "fractal") == "fractal"


def check_ensemble_surfaces(options, option, mode):
    """Refuse an ensemble (asked for by ``-option``) of other than random surfaces seeded by ``-ensemble_seed``."""
    if not is_random_surface(options):
        raise UserError(f"-{option}: an ensemble needs random surfaces (-surface_type fractal, no -surface_file)")
    if options.hasName("surface_seed"):
        raise UserError(f"-surface_seed is not used by an ensemble of -mode {mode}: the seeds derive from "
                        "-ensemble_seed")


def fractal_parameters(options):
    """The fractal surface of the options, checked: ``{"type", "N0", "N", "L", "kl", "ks", "H", "m2", "generator"}``.

    Returns ``(grid, parameters)``, (7.1)-(7.2); ``L`` is the cell length along x.
    """
    given = surface_options.option_values(options, surface_options.TYPE_OPTIONS["fractal"])
    parameters = {"type": "fractal", "kl": given["surface_kl"], "ks": given["surface_ks"], "H": given["surface_H"],
                  "m2": given["surface_m2"], "generator": given["surface_generator"]}
    with options_named():
        grid = surface_options.grid_from_options(options)
        check_fractal_parameters(grid, parameters["kl"], parameters["ks"], parameters["H"], parameters["m2"])
    return grid, dict(parameters, N0=grid.n0, N=grid.n1, L=grid.l1)
