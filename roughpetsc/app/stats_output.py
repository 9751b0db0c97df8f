"""What ``-mode stats`` prints and writes: the result document, the report table, the PDF plots, the files.

Rank 0 prints the document (:func:`result_document`, a plain dict) and writes it as JSON, HDF5 and PNG plots of
the pooled PDFs against their closed forms; the statistics are computed in :mod:`roughpetsc.app.stats_mode`.
"""

import numpy as np

from ..surface import summits as asperities
from ..store.outputs import atomic_path, versions, write_json
from ..store import stats_file

FIELDS = ("h", "p")  # the rough surface h and the pressure surface -p_c


def closed_form_pdfs(alpha):
    """The closed-form densities compared with each histogram: ``{quantity: (pdf, equation)}``."""
    return {
        "height": (asperities.gaussian_pdf, "Gaussian"),
        "summit_height": (lambda x: asperities.summit_height_pdf(x, alpha), "(2.42)"),
        "mean_curvature": (asperities.summit_mean_curvature_pdf, "(7.8)"),
        "geometric_curvature": (asperities.summit_geometric_curvature_pdf, "(2.41) integrated over xi"),
    }


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
                       "the x-y mean (the dissertation's 'Num', Table 7.7); p = pressure surface p_c (2.47) with E* = "
                       "E_star; std is the sample std over realisations (ddof=1)",
    }


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
        with atomic_path(path) as temporary:  # no half-written figure is left
            fig.savefig(temporary, dpi=90, format="png")
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
    psd = document.get("psd")
    if psd is not None:
        m2 = "" if psd["m2_of_fit"] is None else f", m2 of (7.1) with that band {psd['m2_of_fit']:.5g}"
        lines.append(f"PSD fit of (2.18) over k in [{psd['k_min']:g}, {psd['k_max']:g}]: H = {psd['hurst']:.5g} "
                     f"(std {psd['hurst_std']:.2g}), C = {psd['C']:.5g} (std {psd['C_std']:.2g}){m2}")
    lines.append("PDF L1 distances (binned, 2 x total variation; noise = expectation for an exact sample):")
    for name, entry in document["pdf_l1"].items():
        lines.append(f"  {name:<26}{entry['l1']:>8.4f}  noise {entry['l1_noise']:.4f}  vs {entry['closed_form']}"
                     f"  ({entry['samples']} samples)")
    return "\n".join(lines)


def report(document):
    """Print the summary and write the requested files (rank 0); the warnings of a surface file to stderr."""
    import sys

    for note in document.get("surface_levelling", {}).get("notes", []):
        if note.startswith("warning: "):
            print(f"roughpetsc: warning: -surface_file {document['surface_options']['surface_file']}: "
                  f"{note[len('warning: '):]}", file=sys.stderr, flush=True)
        else:
            print(f"surface: {note}", flush=True)
    print(format_report(document), flush=True)
    settings = document["settings"]
    if settings["json"]:
        write_json(settings["json"], document)
    if settings["h5"]:
        stats_file.write(settings["h5"], document)
    if settings["plot"]:
        plot_pdfs(settings["plot"], document)
    if settings["psd"]:
        write_psd(settings["psd"], document["psd"])


def write_psd(path, psd):
    """The radially averaged PSD and its fit as CSV (atomically): ``k, psd, modes, fit`` (empty outside the band)."""
    with atomic_path(path) as temporary, open(temporary, "w") as handle:
        handle.write(f"# radially averaged PSD S(k), [height]^2 length^2, annuli of width {psd['k'][0]:g} "
                     "cycles/length\n")
        handle.write(f"# fit of (2.18) S = C k^-2(1+H) over k in [{psd['k_min']:g}, {psd['k_max']:g}]: "
                     f"H = {psd['hurst']!r}, C = {psd['C']!r}\n")
        handle.write("k,psd,modes,fit\n")
        for k, value, modes, fit in zip(psd["k"], psd["psd"], psd["modes"], psd["fit"]):
            handle.write(f"{k!r},{value!r},{int(modes)},{'' if not np.isfinite(fit) else repr(fit)}\n")
