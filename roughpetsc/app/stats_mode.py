"""The ``stats`` mode: moments, bandwidths, pressure surface and summit PDFs of a surface or an ensemble.

Usage::

    mpiexec -n 2 python -m roughpetsc -mode stats -options_file options/group01.opts \\
        -stats_ensemble 20 -stats_json g1.json -stats_h5 g1.h5 -stats_plot g1

An ensemble over ranks, and what is written per surface: docs/runtime.md, "Ensembles over ranks".
"""

from dataclasses import asdict, dataclass

import numpy as np

from . import surface_options
from ..surface import summits as asperities, seeds, spectra
from . import settings as mode_settings
from ..errors import ParameterError, UserError
from ..store.outputs import check_outputs, on_root
from .settings import ENSEMBLE_SEED
from .stats_output import FIELDS, closed_form_pdfs, report, result_document
from ..surface.generators import fractal_amplitude
from .surface_options import from_options

OPTIONS = [
    ("stats_ensemble", 0, "number of realisations (seeds from -ensemble_seed, as in -mode ensemble); 0 = "
                          "the one surface of the options"),
    ENSEMBLE_SEED,
    ("stats_json", "", "write the statistics as JSON to PATH"),
    ("stats_h5", "", "write the statistics and per-surface values to HDF5 PATH"),
    ("stats_plot", "", "write PNG plots of the PDFs against the closed forms to PREFIX_h.png and "
                       "PREFIX_p.png"),
    ("stats_bin_width", 0.25, "bin width of the PDF histograms, in units of sqrt(m0) or sqrt(m4)"),
    ("stats_fd_scheme", "seed", "finite-difference stencils of (7.6)/(7.7): seed (the dissertation's) | "
                                "central"),
    ("stats_psd", "", "write the radially averaged PSD of the surface(s) to PATH (CSV: k, PSD, modes, the fit) "
                      "with the fit of (2.18) C k^-2(1+H) over -stats_psd_band"),
    ("stats_psd_band", "", "k_min,k_max [cycles/length] of the PSD fit; default k_l,k_s of a fractal "
                           "surface, else the fundamental to the Nyquist wavenumber"),
]

PDF_RANGE = (-5.0, 5.0)


# --- Options

@dataclass(frozen=True)
class StatsSettings:
    """The options of the mode, read and checked; :meth:`record` is what the output files keep."""

    ensemble: int
    ensemble_seed: int
    json: str
    h5: str
    plot: str
    bin_width: float
    fd_scheme: str
    e_star: float
    psd: str = ""
    psd_band: tuple = None

    def record(self):
        """``{name: value}`` of the settings; ``psd_band`` as a list, empty for the default (HDF5 has no None)."""
        return dict(asdict(self), psd_band=list(self.psd_band or ()))


def read_settings(options):
    """Read and check :data:`OPTIONS` and ``-E_star``; raise :class:`UserError` naming the option."""
    given = mode_settings.read_table(options, OPTIONS)
    settings = StatsSettings(**{name.removeprefix("stats_"): value for name, value in given.items()
                                if name != "stats_psd_band"},
                             e_star=mode_settings.check_modulus(options.getReal("E_star", 1.0)),
                             psd_band=psd_band(options, given))
    if settings.ensemble < 0:
        raise UserError(f"-stats_ensemble must be >= 0, got {settings.ensemble}")
    if settings.ensemble_seed < 0:
        raise UserError(f"-ensemble_seed must be a non-negative integer, got {settings.ensemble_seed}")
    if not (np.isfinite(settings.bin_width) and 0.0 < settings.bin_width <= 2.5):
        raise UserError(f"-stats_bin_width must lie in (0, 2.5], got {settings.bin_width}")
    if settings.fd_scheme not in spectra.FD_SCHEMES:
        raise UserError(f"-stats_fd_scheme must be one of {', '.join(spectra.FD_SCHEMES)}, "
                        f"got '{settings.fd_scheme}'")
    if settings.ensemble > 0:
        mode_settings.check_ensemble_surfaces(options, "stats_ensemble", "stats")
    return settings


def psd_band(options, given):
    """``-stats_psd_band`` as ``(k_min, k_max)``, else (k_l, k_s) of a fractal surface, else None (each surface's
    default); read only with ``-stats_psd``."""
    if not given["stats_psd"]:
        return None
    from ..contact.loads import parse_reals

    if options.hasName("stats_psd_band"):
        band = parse_reals(given["stats_psd_band"], "stats_psd_band")
        if len(band) != 2 or not (0 < band[0] < band[1] and np.isfinite(band[1])):
            raise UserError(f"-stats_psd_band: give k_min,k_max with 0 < k_min < k_max, "
                            f"got '{given['stats_psd_band']}'")
        return tuple(band)
    if mode_settings.is_random_surface(options):
        _, surface = mode_settings.fractal_parameters(options)
        return surface["kl"], surface["ks"]
    return None


def output_paths(settings):
    """The files the run writes, as ``(option, path)``."""
    plot = settings.plot
    return [("stats_json", settings.json), ("stats_h5", settings.h5), ("stats_psd", settings.psd),
            ("stats_plot", f"{plot}_h.png" if plot else ""), ("stats_plot", f"{plot}_p.png" if plot else "")]


def histogram_edges(bin_width):
    """Bin edges on :data:`PDF_RANGE` with the given width (dimensionless)."""
    count = int(round((PDF_RANGE[1] - PDF_RANGE[0]) / bin_width))
    return np.linspace(PDF_RANGE[0], PDF_RANGE[1], count + 1)


# --- One surface

def flatten_moments(label, moments):
    """``{"x": {n: v}, "y": {n: v}}`` -> ``{"m<n><label>_x": v, "m<n><label>_y": v, "m<n><label>": mean}``."""
    flat = {}
    mean = spectra.isotropic_mean(moments)
    for n in moments["x"]:
        flat[f"m{n}{label}_x"] = moments["x"][n]
        flat[f"m{n}{label}_y"] = moments["y"][n]
        flat[f"m{n}{label}"] = mean[n]
    return flat


def field_summit_statistics(grid, field, moments, edges, label):
    """Scalars and histogram counts of the summits and heights of one field (``h`` or ``-p_c``).

    ``moments``: the isotropic finite-difference ``{0, 2, 4: m_n}`` of ``field``, normalising heights and curvatures.
    """
    summits = asperities.find_summits(grid, field)
    xi, kappa_m = asperities.normalised_summits(summits, moments[0], moments[4])
    kappa_g = summits.geometric_curvature / np.sqrt(moments[4])
    scalars = {f"summit_count_{label}": float(summits.count),
               f"indefinite_summit_fraction_{label}": float(np.mean(summits.hessian_determinant < 0.0))}
    for key, value in asperities.measured_gw_inputs(summits).items():
        scalars[f"gw_{key}_{label}"] = value
    for key, value in asperities.mccool_gw_inputs(moments[0], moments[2], moments[4]).items():
        if key != "alpha":
            scalars[f"mccool_{key}_{label}"] = float(value)
    samples = {"height": (field - field.mean()).ravel() / np.sqrt(moments[0]),
               "summit_height": xi, "mean_curvature": kappa_m, "geometric_curvature": kappa_g}
    counts = {f"{name}_{label}": asperities.binned_counts(values, edges) for name, values in samples.items()}
    return scalars, counts


def surface_statistics(grid, heights, settings, edges):
    """All per-surface quantities: ``(scalars, counts, psd)``.

    ``scalars``: the moments of h and p_c by finite differences (``_fd``) and from the spectrum (``_spec``),
    bandwidths, summit counts and GW inputs. ``counts``: ``{name: (bin counts, total)}`` of the dimensionless
    heights, summit heights and curvatures. ``psd``: with ``-stats_psd`` the radial PSD sums (the fit of (2.18)
    among the scalars), else None.
    """
    summary = spectra.surface_moment_summary(grid, heights, settings["e_star"], settings["fd_scheme"])
    scalars = {}
    for field in FIELDS:
        scalars.update(flatten_moments(f"{field}_fd", summary[f"{field}_fd"]))
        scalars.update(flatten_moments(f"{field}_spec", summary[f"{field}_spectral"]))
    for key in ("alpha_h", "alpha_p", "alpha_h_spectral", "alpha_p_spectral", "alpha_p_from_h"):
        scalars[key] = summary[key]
    counts = {}
    fields = {"h": heights, "p": -spectra.pressure_surface(grid, heights, settings["e_star"])}
    for label, field in fields.items():
        moments = spectra.isotropic_mean(spectra.fd_moments(grid, field, (0, 2, 4), settings["fd_scheme"]))
        field_scalars, field_counts = field_summit_statistics(grid, field, moments, edges, label)
        scalars.update(field_scalars)
        counts.update(field_counts)
    if not settings["psd"]:
        return scalars, counts, None
    band = settings["psd_band"] or default_psd_band(grid)
    fit = spectra.fit_fractal_psd(grid, heights, band)
    if fit is None:
        raise UserError(f"-stats_psd_band: fewer than two wavenumbers of the {grid.n0}x{grid.n1} grid with power lie "
                        f"in [{band[0]:g}, {band[1]:g}]")
    scalars.update(psd_hurst=fit["hurst"], psd_C=fit["C"], psd_rms_log_residual=fit["rms_log_residual"])
    return scalars, counts, spectra.radial_psd_sums(grid, heights)


def default_psd_band(grid):
    """The fundamental to the coarser direction's Nyquist wavenumber [cycles/length]: a non-fractal PSD fit band."""
    return spectra.radial_bin_width(grid), min(grid.n0 / grid.l0, grid.n1 / grid.l1) / 2.0


# --- Ensemble over ranks

def surface_seeds(settings):
    """Seeds of the realisations in index order; ``[None]`` for the single surface of the options."""
    return [None] if settings.ensemble == 0 else seeds.surface_seeds(settings.ensemble_seed, settings.ensemble)


def local_statistics(options, settings, seeds, edges, rank, size, levelling=None):
    """Statistics of this rank's surfaces: ``(index, seed, scalars, counts, grid, psd)``; ``levelling`` as notes."""
    results = []
    for index in range(rank, len(seeds), size):
        with mode_settings.options_named():
            grid, heights = from_options(options, seed=seeds[index], notes=levelling)
        scalars, counts, psd = surface_statistics(grid, heights, settings, edges)
        results.append((index, seeds[index], scalars, counts, grid, psd))
    return results


def gather_in_seed_order(comm, results_or_error):
    """Every rank's results (or its error message, a str) on rank 0 in surface order, None elsewhere.

    Every rank raises the same :class:`UserError` if any rank failed.
    """
    gathered = comm.gather(results_or_error, root=0)
    first_error = next((item for item in gathered if isinstance(item, str)), None) if comm.rank == 0 else None
    message = comm.bcast(first_error, root=0)
    if message is not None:
        raise UserError(message)
    if comm.rank != 0:
        return None
    return sorted((entry for part in gathered for entry in part), key=lambda entry: entry[0])


def ensemble_summary(ordered, edges):
    """Mean and sample standard deviation of every scalar in seed order, and the pooled histogram counts."""
    names = list(ordered[0][2])
    table = {name: np.array([entry[2][name] for entry in ordered]) for name in names}
    mean = {name: float(np.mean(values)) for name, values in table.items()}
    std = {name: float(np.std(values, ddof=1)) if values.size > 1 else 0.0 for name, values in table.items()}
    pooled = {name: (sum(entry[3][name][0] for entry in ordered), sum(entry[3][name][1] for entry in ordered))
              for name in ordered[0][3]}
    psd = None
    if ordered[0][5] is not None:  # the PSD sums in seed order
        psd = {name: sum(entry[5][name] for entry in ordered) for name in ordered[0][5]}
    return {"per_surface": table, "mean": mean, "std": std, "counts": pooled, "edges": edges, "psd": psd}


# --- Closed forms and PDF comparison

def closed_forms_from_options(options, settings):
    """Closed forms (2.21)-(2.25), (2.56)-(2.59) of the fractal PSD of the options; None for other surfaces."""
    if not mode_settings.is_random_surface(options):
        return None
    _, surface = mode_settings.fractal_parameters(options)
    amplitude = fractal_amplitude(surface["kl"], surface["ks"], surface["H"], surface["m2"])
    return flatten_closed_forms(spectra.fractal_closed_forms(surface["kl"], surface["ks"], surface["H"], amplitude,
                                                             settings["e_star"]))


def flatten_closed_forms(forms):
    """:func:`roughpetsc.spectra.fractal_closed_forms` as ``{"m<n>h", "m<n>p", "alpha_h", "alpha_p": value}``."""
    flat = {f"m{n}h": value for n, value in forms["h"].items()}
    flat.update({f"m{n}p": value for n, value in forms["p"].items()})
    flat.update(alpha_h=forms["alpha_h"], alpha_p=forms["alpha_p"])
    return flat


def pdf_distances(summary):
    """L1 distance of each pooled histogram to its closed form, with its sampling-noise expectation.

    The closed form of the summit heights uses the ensemble-mean alpha (finite differences) of the field.
    """
    distances = {}
    for label in FIELDS:
        alpha = summary["mean"][f"alpha_{label}"]
        for quantity, (pdf, equation) in closed_form_pdfs(alpha).items():
            counts, total = summary["counts"][f"{quantity}_{label}"]
            distance, noise = asperities.l1_distance_from_counts(counts, total, summary["edges"], pdf)
            distances[f"{quantity}_{label}"] = {"l1": distance, "l1_noise": noise, "closed_form": equation,
                                                "samples": total, "alpha": alpha}
    return distances


# --- Entry point

def compute(options, comm, settings, surface):
    """Compute the statistics on all ranks; the result document on rank 0, None elsewhere."""
    record = settings.record()
    realisation_seeds = surface_seeds(settings)
    edges = histogram_edges(settings.bin_width)
    levelling = []
    try:
        local = local_statistics(options, record, realisation_seeds, edges, comm.rank, comm.size, levelling)
    except (UserError, ParameterError) as error:  # raised on every rank by gather_in_seed_order, none left waiting
        local = mode_settings.user_message(error)
    ordered = gather_in_seed_order(comm, local)
    if ordered is None:
        return None
    summary = ensemble_summary(ordered, edges)
    closed = closed_forms_from_options(options, record)
    document = result_document(summary, record, surface, closed, pdf_distances(summary), realisation_seeds,
                               ordered[0][4])
    if levelling:  # a surface file: one surface, on rank 0
        document["surface_levelling"] = levelling[0].record()
    if summary["psd"] is not None:
        document["psd"] = psd_document(ordered[0][4], summary, settings.psd_band or default_psd_band(ordered[0][4]))
    return document


def psd_document(grid, summary, band):
    """The radially averaged PSD over the surfaces and the fit of (2.18): the mean of each surface's H and C."""
    k, psd, modes = spectra.radial_psd(grid, summary["psd"])
    hurst, amplitude = summary["mean"]["psd_hurst"], summary["mean"]["psd_C"]
    inside = (k >= band[0] * (1 - 1e-12)) & (k <= band[1] * (1 + 1e-12))
    return {"k": k.tolist(), "psd": psd.tolist(), "modes": modes.tolist(),
            "fit": np.where(inside, amplitude * k ** (-2.0 * (1.0 + hurst)), np.nan).tolist(),
            "hurst": hurst, "C": amplitude, "k_min": band[0], "k_max": band[1],
            "hurst_std": summary["std"]["psd_hurst"], "C_std": summary["std"]["psd_C"],
            "m2_of_fit": float(amplitude * (2 * np.pi) ** 3 * (band[1] ** (2 - 2 * hurst) - band[0] ** (2 - 2 * hurst))
                               / (4 * (1 - hurst))) if hurst < 1 else None}


def run(options, comm):
    """The ``stats`` mode: compute, print on rank 0 and write the requested files.

    Returns the result document on rank 0, None elsewhere; :class:`UserError` on every rank for bad input.
    """
    from .options import check_unused  # imports PETSc: only once the command line has initialised it

    settings = read_settings(options)
    surface = surface_options.parameters(options)  # those of the surface type: another is reported unused
    # Rank 0 checks the files and writes them; a failure there is raised on every rank (no rank left waiting).
    on_root(comm, check_outputs, output_paths(settings), options.getBool("overwrite", False),
            [("surface_file", options.getString("surface_file", ""))])
    check_unused()  # before any work: a run refused for an option it does not use computes and writes nothing
    document = compute(options, comm, settings, surface)
    on_root(comm, report, document)
    return document
