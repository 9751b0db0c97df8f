"""The ``stats`` mode: moments, bandwidths, pressure surface and summit PDFs of a surface or an ensemble.

Usage (the lead wires ``python -m roughpetsc -mode stats`` to :func:`run`)::

    mpiexec -n 2 python -m roughpetsc -mode stats -options_file options/group01.opts \\
        -stats_ensemble 20 -stats_json g1.json -stats_h5 g1.h5 -stats_plot g1

Ensembles: realisation ``i = 0 .. n-1`` is the fractal surface of the options
with seed ``-surface_seed + i``. Whole surfaces are dealt to the ranks
(surface ``i`` on rank ``i % size``); the per-surface values are gathered on
rank 0, which forms means and standard deviations (sample std, ddof = 1) in
seed order and sums the integer histogram counts, so any number of ranks
gives bit-identical results. With ``-stats_ensemble 0`` the one surface named
by the options (any type, or ``-surface_file``) is characterised.

Every summary quantity is also written per surface (JSON ``per_surface``, HDF5
dataset ``per_surface/<name>`` in seed order).
"""

import json

import numpy as np

from . import asperities, spectra
from .errors import UserError
from .io import atomic_path, check_outputs, on_root, versions
from .surfaces import SURFACE_OPTIONS, fractal_amplitude, from_options

OPTIONS = [
    ("stats_ensemble", 0, "number of realisations (seeds -surface_seed + i, i = 0..n-1); 0 = the one surface "
                          "of the options"),
    ("stats_json", "", "write the statistics as JSON to PATH"),
    ("stats_h5", "", "write the statistics and per-surface values to HDF5 PATH"),
    ("stats_plot", "", "write PNG plots of the PDFs against the closed forms to PREFIX_h.png and PREFIX_p.png"),
    ("stats_bin_width", 0.25, "bin width of the PDF histograms, in units of sqrt(m0) or sqrt(m4)"),
    ("stats_fd_scheme", "seed", "finite-difference stencils of (7.6)/(7.7): seed | central"),
]

PDF_RANGE = (-5.0, 5.0)
FIELDS = ("h", "p")  # the rough surface h and the pressure surface -p_c


# ----------------------------------------------------------------------------
# Options
# ----------------------------------------------------------------------------

def read_settings(options):
    """Read and check the ``-stats_*`` options and ``-E_star``; raise :class:`UserError` naming the option."""
    settings = {
        "ensemble": options.getInt("stats_ensemble", 0),
        "json": options.getString("stats_json", ""),
        "h5": options.getString("stats_h5", ""),
        "plot": options.getString("stats_plot", ""),
        "bin_width": options.getReal("stats_bin_width", 0.25),
        "fd_scheme": options.getString("stats_fd_scheme", "seed"),
        "e_star": options.getReal("E_star", 1.0),
        "base_seed": options.getInt("surface_seed", 1),
    }
    if settings["ensemble"] < 0:
        raise UserError(f"-stats_ensemble must be >= 0, got {settings['ensemble']}")
    if not (np.isfinite(settings["bin_width"]) and 0.0 < settings["bin_width"] <= 2.5):
        raise UserError(f"-stats_bin_width must lie in (0, 2.5], got {settings['bin_width']}")
    if settings["fd_scheme"] not in spectra.FD_SCHEMES:
        raise UserError(f"-stats_fd_scheme must be one of {', '.join(spectra.FD_SCHEMES)}, "
                        f"got '{settings['fd_scheme']}'")
    if not (np.isfinite(settings["e_star"]) and settings["e_star"] > 0.0):
        raise UserError(f"-E_star must be a positive finite modulus, got {settings['e_star']}")
    if settings["ensemble"] > 0 and (options.getString("surface_file", "")
                                     or options.getString("surface_type", "fractal") != "fractal"):
        raise UserError("-stats_ensemble > 0 needs random surfaces (-surface_type fractal, no -surface_file)")
    return settings


def output_paths(settings):
    """The files the run writes, as ``(option, path)``."""
    plot = settings["plot"]
    return [("stats_json", settings["json"]), ("stats_h5", settings["h5"]),
            ("stats_plot", f"{plot}_h.png" if plot else ""), ("stats_plot", f"{plot}_p.png" if plot else "")]


def surface_settings(options):
    """The surface options as read (for the record): ``{name: value}``, typed by their defaults."""
    getters = {int: options.getInt, float: options.getReal, str: options.getString}
    return {name: getters[type(default)](name, default) for name, default, _ in SURFACE_OPTIONS}


def histogram_edges(bin_width):
    """Bin edges on :data:`PDF_RANGE` with the given width (dimensionless)."""
    count = int(round((PDF_RANGE[1] - PDF_RANGE[0]) / bin_width))
    return np.linspace(PDF_RANGE[0], PDF_RANGE[1], count + 1)


# ----------------------------------------------------------------------------
# One surface
# ----------------------------------------------------------------------------

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

    ``moments`` are the isotropic finite-difference moments of ``field``
    ({0, 2, 4: m_n}); they normalise heights (sqrt(m0)) and curvatures (sqrt(m4)).
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
    """All per-surface quantities: ``(scalars, counts)``.

    ``scalars``: flat ``{name: float}`` with the directional and isotropic
    moments of h and p_c by finite differences (``_fd``) and from the spectrum
    (``_spec``), bandwidths, summit counts and GW inputs (measured and
    McCool's). ``counts``: ``{name: (bin counts, total)}`` of the dimensionless
    heights, summit heights and curvatures of h and -p_c.
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
    return scalars, counts


# ----------------------------------------------------------------------------
# Ensemble over ranks
# ----------------------------------------------------------------------------

def surface_seeds(settings):
    """Seeds of the realisations in order; ``[None]`` for the single surface of the options."""
    if settings["ensemble"] == 0:
        return [None]
    return [settings["base_seed"] + i for i in range(settings["ensemble"])]


def local_statistics(options, settings, seeds, edges, rank, size):
    """Statistics of the surfaces dealt to this rank: list of ``(index, seed, scalars, counts, grid)``."""
    results = []
    for index in range(rank, len(seeds), size):
        grid, heights = from_options(options, seed=seeds[index])
        scalars, counts = surface_statistics(grid, heights, settings, edges)
        results.append((index, seeds[index], scalars, counts, grid))
    return results


def gather_in_seed_order(comm, results_or_error):
    """Gather every rank's results on rank 0 and sort them by surface index; re-raise any rank's UserError.

    Returns the ordered list on rank 0 and None elsewhere; every rank raises
    the same :class:`UserError` if any rank failed.
    """
    gathered = comm.gather(results_or_error, root=0)
    message = None
    if comm.rank == 0:
        errors = [item for item in gathered if isinstance(item, str)]
        message = errors[0] if errors else None
    message = comm.bcast(message, root=0)
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
    pooled = {}
    for name in ordered[0][3]:
        pooled[name] = (sum(entry[3][name][0] for entry in ordered), sum(entry[3][name][1] for entry in ordered))
    return {"per_surface": table, "mean": mean, "std": std, "counts": pooled, "edges": edges}


# ----------------------------------------------------------------------------
# Closed forms and PDF comparison
# ----------------------------------------------------------------------------

def closed_forms_from_options(options, settings):
    """Closed forms (2.21)-(2.25), (2.56)-(2.59) of the fractal PSD of the options; None for other surfaces."""
    if options.getString("surface_file", "") or options.getString("surface_type", "fractal") != "fractal":
        return None
    k_l, k_s = options.getReal("surface_kl", 16.0), options.getReal("surface_ks", 64.0)
    hurst, m2 = options.getReal("surface_H", 0.8), options.getReal("surface_m2", 2e-4)
    return flatten_closed_forms(spectra.fractal_closed_forms(k_l, k_s, hurst, fractal_amplitude(k_l, k_s, hurst, m2),
                                                             settings["e_star"]))


def flatten_closed_forms(forms):
    """:func:`roughpetsc.spectra.fractal_closed_forms` as ``{"m<n>h", "m<n>p", "alpha_h", "alpha_p": value}``."""
    flat = {f"m{n}h": value for n, value in forms["h"].items()}
    flat.update({f"m{n}p": value for n, value in forms["p"].items()})
    flat.update(alpha_h=forms["alpha_h"], alpha_p=forms["alpha_p"])
    return flat


def closed_form_pdfs(alpha):
    """The closed-form densities compared with each histogram: ``{quantity: (pdf, equation)}``."""
    return {
        "height": (asperities.gaussian_pdf, "Gaussian"),
        "summit_height": (lambda x: asperities.summit_height_pdf(x, alpha), "(2.42)"),
        "mean_curvature": (asperities.summit_mean_curvature_pdf, "(7.8)"),
        "geometric_curvature": (asperities.summit_geometric_curvature_pdf, "(2.41) integrated over xi"),
    }


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


# ----------------------------------------------------------------------------
# Output
# ----------------------------------------------------------------------------

def result_document(summary, settings, surface, closed, distances, seeds, grid):
    """Everything written to JSON: a plain dict of numbers, strings and lists."""
    return {
        "mode": "stats",
        "settings": settings,
        "surface_options": surface,
        "grid": {"n0": grid.n0, "n1": grid.n1, "l0": grid.l0, "l1": grid.l1},
        "seeds": seeds,
        "realisations": len(seeds),
        "mean": summary["mean"],
        "std": summary["std"],
        "closed_form": closed,
        "pdf_l1": distances,
        "histogram_edges": summary["edges"].tolist(),
        "histogram_density": {name: asperities.density_from_counts(c, t, summary["edges"]).tolist()
                              for name, (c, t) in summary["counts"].items()},
        "per_surface": {name: values.tolist() for name, values in summary["per_surface"].items()},
        "versions": versions(),
        "conventions": "moments m_n0 (x) and m_0n (y) in [field]^2/length^n, w = 2 pi k; *_fd: finite "
                       "differences (7.6)/(7.7), *_spec: discrete spectrum (2.12); m<n>h_fd without _x/_y is "
                       "the x-y mean (the seed's 'Num'); p = pressure surface p_c (2.47) with E* = E_star; "
                       "std is the sample std over realisations (ddof=1)",
    }


def atomic_write(path, writer):
    """Call ``writer(temporary_path)`` and rename the result to ``path``; no half-written file is left."""
    with atomic_path(path) as temporary:
        writer(temporary)


def write_json(path, document):
    """Write the result document as JSON (atomically)."""
    def writer(temporary):
        with open(temporary, "w") as f:
            json.dump(document, f, indent=1, default=lambda value: value.tolist())
    atomic_write(path, writer)


def write_h5(path, document):
    """Write the result as HDF5 (atomically): groups mean, std, closed_form, per_surface, histograms, pdf_l1.

    Root attributes hold the settings, surface options and versions (as JSON
    strings and as individual attributes).
    """
    import h5py

    def writer(temporary):
        with h5py.File(temporary, "w", driver=None) as f:
            for key in ("settings", "surface_options", "versions", "grid"):
                f.attrs[key] = json.dumps(document[key])
                for name, value in document[key].items():
                    f.attrs[f"{key}.{name}"] = value
            f.attrs["conventions"] = document["conventions"]
            f.create_dataset("seeds", data=np.array([-1 if s is None else s for s in document["seeds"]]))
            for group in ("mean", "std", "closed_form"):
                g = f.create_group(group)
                for name, value in (document[group] or {}).items():
                    g.attrs[name] = value
            g = f.create_group("per_surface")
            for name, values in document["per_surface"].items():
                g.create_dataset(name, data=np.asarray(values))
            g = f.create_group("histograms")
            g.create_dataset("edges", data=np.asarray(document["histogram_edges"]))
            for name, values in document["histogram_density"].items():
                g.create_dataset(name, data=np.asarray(values))
            g = f.create_group("pdf_l1")
            for name, entry in document["pdf_l1"].items():
                sub = g.create_group(name)
                for key, value in entry.items():
                    sub.attrs[key] = value
    atomic_write(path, writer)


PLOT_QUANTITIES = (("height", "height / sqrt(m0)"), ("summit_height", "summit height xi* = xi / sqrt(m0)"),
                   ("mean_curvature", "mean curvature kappa_m* = kappa_m / sqrt(m4)"),
                   ("geometric_curvature", "geometric curvature kappa_g* = kappa_g / sqrt(m4)"))


def plot_pdfs(prefix, document):
    """PNG plots ``PREFIX_h.png`` and ``PREFIX_p.png``: measured densities (steps) against the closed forms."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    edges = np.asarray(document["histogram_edges"])
    fine = np.linspace(edges[0], edges[-1], 801)
    titles = {"h": "rough surface h", "p": "pressure surface -p_c"}
    paths = []
    for label in FIELDS:
        fig, axes = plt.subplots(1, 4, figsize=(17, 4))
        pdfs = closed_form_pdfs(document["mean"][f"alpha_{label}"])
        for ax, (quantity, xlabel) in zip(axes, PLOT_QUANTITIES):
            name = f"{quantity}_{label}"
            ax.stairs(document["histogram_density"][name], edges, label="measured")
            pdf, equation = pdfs[quantity]
            ax.plot(fine, pdf(fine), "k--", label=equation)
            entry = document["pdf_l1"][name]
            ax.set_title(f"{titles[label]}: L1 = {entry['l1']:.3f} (noise {entry['l1_noise']:.3f})", fontsize=9)
            ax.set_xlabel(xlabel)
            ax.legend(fontsize=8)
        axes[0].set_ylabel("probability density")
        fig.suptitle(f"{document['realisations']} realisation(s), alpha = {document['mean'][f'alpha_{label}']:.4f}")
        fig.tight_layout()
        path = f"{prefix}_{label}.png"
        atomic_write(path, lambda temporary: fig.savefig(temporary, dpi=90, format="png"))
        plt.close(fig)
        paths.append(path)
    return paths


REPORT_ROWS = (
    ("m0h_fd", "m0h"), ("m2h_fd", "m2h"), ("m4h_fd", "m4h"), ("m6h_fd", "m6h"),
    ("m0p_fd", "m0p"), ("m2p_fd", "m2p"), ("m4p_fd", "m4p"), ("alpha_h", "alpha_h"), ("alpha_p", "alpha_p"),
)


def format_report(document):
    """A plain-text summary table (moments by finite differences, x-y mean) and the PDF distances."""
    closed = document["closed_form"] or {}
    lines = [f"stats: {document['realisations']} realisation(s) on a {document['grid']['n0']}x"
             f"{document['grid']['n1']} grid (finite differences '{document['settings']['fd_scheme']}', "
             f"E* = {document['settings']['e_star']:g})",
             f"{'quantity':<16}{'mean':>14}{'std':>12}{'closed form':>14}{'x':>14}{'y':>14}"]
    for key, closed_key in REPORT_ROWS:
        x = document["mean"].get(key + "_x")
        y = document["mean"].get(key + "_y")
        lines.append(f"{key:<16}{document['mean'][key]:>14.5g}{document['std'][key]:>12.3g}"
                     f"{closed.get(closed_key, float('nan')):>14.5g}"
                     f"{x if x is not None else float('nan'):>14.5g}{y if y is not None else float('nan'):>14.5g}")
    lines.append("PDF L1 distances (binned, 2 x total variation; noise = expectation for an exact sample):")
    for name, entry in document["pdf_l1"].items():
        lines.append(f"  {name:<26}{entry['l1']:>8.4f}  noise {entry['l1_noise']:.4f}  vs {entry['closed_form']}"
                     f"  ({entry['samples']} samples)")
    return "\n".join(lines)


# ----------------------------------------------------------------------------
# Entry point
# ----------------------------------------------------------------------------

def compute(options, comm):
    """Compute the statistics on all ranks; the result document on rank 0, None elsewhere."""
    settings = read_settings(options)
    surface = surface_settings(options)
    seeds = surface_seeds(settings)
    edges = histogram_edges(settings["bin_width"])
    try:
        local = local_statistics(options, settings, seeds, edges, comm.rank, comm.size)
    except UserError as error:
        local = str(error)
    ordered = gather_in_seed_order(comm, local)
    if ordered is None:
        return None
    summary = ensemble_summary(ordered, edges)
    closed = closed_forms_from_options(options, settings)
    return result_document(summary, settings, surface, closed, pdf_distances(summary), seeds, ordered[0][4])


def run(options, comm):
    """The ``stats`` mode: compute, print on rank 0 and write the requested files.

    Parameters
    ----------
    options : petsc4py.PETSc.Options
    comm : mpi4py.MPI.Comm

    Returns
    -------
    The result document (dict) on rank 0, None on the other ranks.
    Raises :class:`UserError` on bad input (on every rank).
    """
    settings = read_settings(options)
    # Rank 0 checks the files and writes them; a failure there is raised on every rank (no rank left waiting).
    on_root(comm, check_outputs, output_paths(settings), options.getBool("overwrite", False),
            [("surface_file", options.getString("surface_file", ""))])
    document = compute(options, comm)
    on_root(comm, report, document)
    return document


def report(document):
    """Print the summary and write the requested files (rank 0)."""
    print(format_report(document), flush=True)
    settings = document["settings"]
    if settings["json"]:
        write_json(settings["json"], document)
    if settings["h5"]:
        write_h5(settings["h5"], document)
    if settings["plot"]:
        plot_pdfs(settings["plot"], document)
