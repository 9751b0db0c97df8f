"""Regenerate the dissertation's Tables 7.2-7.7 and 8.2-8.3 for our generator, the rule of thumb (7.10) and PDF plots.

Usage (from the repository root, Debian's python)::

    /usr/bin/python3 studies/surface_statistics.py --realisations 50 --realisations-2048 50

Realisation i of a group has seed i + 1 (i = 0..R-1), made by the generator its ``options/groupNN.opts`` names
(``xu``, (7.2)-(7.5)) unless ``--generator filter`` is given. Each group is kept in ``ensemble.json`` as it
finishes, so a rerun with the same settings continues with the groups missing. Writes under
``studies/output/statistics/``: ``surface_statistics.md`` (tables beside the
dissertation's numbers), ``ensemble.json`` (all means, stds and PDF distances),
``pdf_groupNN_{h,p}.png`` and ``rule_of_thumb.png``. ``--render-only`` rebuilds
the markdown and figures from ``ensemble.json``.
"""

import argparse
import json
import os
import sys
import time

import numpy as np

from roughpetsc import Grid, fractal, fractal_amplitude
from roughpetsc.surface import spectra
from roughpetsc.app import stats_mode, stats_output
from roughpetsc.app.presets import fractal_groups
from roughpetsc.store.outputs import write_json

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output", "statistics")

# Tables 7.1 and 8.1 as options/groupNN.opts type them: group -> (k_l, k_s, H, N); every group has m2 = 2e-4.
GROUPS = {number: (group["k_l"], group["k_s"], group["hurst"], group["n"]) for number, group in fractal_groups().items()}
M2 = {number: group["m2"] for number, group in fractal_groups().items()}
GENERATORS = {number: group["generator"] for number, group in fractal_groups().items()}  # every preset: "xu"

# The dissertation's numbers as printed (None: illegible in the text of the dissertation we have).
# Table 7.2: mean m20, m02, m40, m04, m60, m06 of h.
SEED_7_2 = {
    1: (1.97e-4, 1.97e-4, 9.00, 9.02, 6.59e5, 6.59e5), 2: (1.91e-4, 1.91e-4, 27.01, 26.97, 6.94e6, 6.94e6),
    3: (None, 1.73e-4, 78.90, 79.85, 5.43e7, 5.43e7), 4: (1.35e-4, 1.35e-4, 172.77, 172.97, None, 1.20e8),
    5: (None, None, 5.92, 5.88, 4.19e5, 4.19e5), 6: (1.94e-4, None, 20.48, 20.44, 5.23e6, 5.23e6),
    7: (None, None, 66.15, 66.10, 4.49e7, 4.49e7), 8: (None, None, 151.37, 151.35, 1.05e8, 1.05e8),
    9: (None, None, 4.90, None, 3.47e5, 3.47e5), 10: (1.99e-4, None, 17.94, 17.93, 4.58e6, None),
    11: (None, None, 79.90, 79.85, None, None), 12: (None, None, 141.29, 141.45, None, None),
    13: (None, None, 43.30, None, None, None), 14: (None, None, None, None, None, None),
    15: (None, None, 31.55, None, None, None), 16: (None, None, 24.26, None, None, 6.41e6),
    17: (1.96e-4, 1.96e-4, 16.78, 16.79, 4.12e6, 4.12e6),
}
# Table 7.3: mean m20p*, m02p*, m40p*, m04p*.
SEED_7_3 = {
    1: (2.98, 2.98, 2.04e5, 2.05e5), 2: (2.98, 2.98, 2.37e6, 2.36e6), 3: (23.08, 23.08, 2.68e7, 2.68e7),
    4: (36.05, 36.05, 1.95e8, 1.95e8), 5: (1.96, 1.96, 1.30e5, 1.29e5), 6: (6.59, 6.59, 1.78e6, 1.78e6),
    7: (19.11, 19.11, 2.22e7, 2.22e7), 8: (31.59, 31.59, 1.71e8, 1.71e8), 9: (1.62, 1.62, 1.08e5, 1.08e5),
    10: (5.77, 5.77, 1.56e6, 1.56e6), 11: (23.08, 23.08, 2.68e7, 2.68e7), 12: (29.49, 29.49, 1.59e8, 1.60e8),
    13: (13.83, 13.83, 4.55e6, 4.55e6), 14: (12.14, 12.14, 3.83e6, 3.84e6), 15: (10.12, 10.12, 3.03e6, 3.02e6),
    16: (7.80, 7.80, 2.19e6, 3.02e6), 17: (5.41, 5.41, 1.40e6, 1.40e6),
}
# Tables 7.4-7.6 "Num": m0h, m2h, m4h, m6h (and m0p, m2p, m4p where legible).
SEED_NUM_H = {
    1: (1.20e-8, 1.97e-4, 9.01, 6.59e5), 2: (7.44e-9, 1.91e-4, 26.99, 6.94e6), 3: (4.87e-9, 1.73e-4, 79.38, 5.43e7),
    4: (3.32e-9, 1.35e-4, 172.87, 1.20e8), 5: (8.37e-8, 1.91e-4, 5.90, 4.19e5), 9: (1.02e-6, 1.73e-4, 4.91, 3.47e5),
    13: (5.70e-9, 1.86e-4, 43.31, 1.32e7), 14: (1.06e-8, 1.87e-4, 38.04, 1.11e7),
    15: (2.09e-8, 1.90e-4, 31.52, 8.83e6), 16: (4.14e-8, 1.93e-4, 24.28, 6.41e6),
    17: (7.71e-8, 1.96e-4, 16.79, 4.12e6),
}
SEED_NUM_P = {1: (1.00e-4, 2.98, 2.05e5), 13: (1.00e-4, 13.83, 4.55e6), 14: (1.00e-4, 12.14, 3.84e6),
              15: (1.00e-4, 10.12, 3.03e6), 16: (1.00e-4, 7.80, 2.19e6), 17: (1.01e-4, 5.41, 1.40e6)}
# Table 7.7: alpha^h, alpha^p (mean, std).
SEED_7_7 = {1: ((2.7861, 0.2144), (2.3146, 0.2144)), 2: ((5.4853, 0.2787), (3.1357, 0.1854))}
# Tables 8.2 / 8.3 "Num": (m0h, m2h, m4h, alpha_h), (m0p, m2p, m4p, alpha_p).
SEED_8_2 = {18: (7.79e-9, 1.96e-4, 12.27, 2.50), 19: (8.81e-9, 1.96e-4, 11.39, 2.60),
            20: (9.99e-9, 1.97e-4, 10.47, 2.70), 21: (1.13e-8, 1.97e-4, 9.52, 2.77),
            22: (1.28e-8, 1.98e-4, 8.57, 2.81), 23: (2.95e-9, 1.96e-4, 46.24, 3.55),
            24: (3.81e-9, 1.96e-4, 41.63, 4.11), 25: (4.99e-9, 1.97e-4, 36.41, 4.68),
            26: (6.53e-9, 1.98e-4, 30.89, 5.16), 27: (8.43e-9, 1.98e-4, 25.37, 5.44)}
SEED_8_3 = {18: (1e-4, 4.03, 3.25e5, 2.00), 19: (1e-4, 3.75, 2.91e5, 2.08), 20: (1e-4, 3.44, 2.57e5, 2.17),
            21: (1e-4, 3.13, 2.22e5, 2.27), 22: (1e-4, 2.82, 1.89e5, 2.38), 23: (1e-4, 15.26, 4.88e6, 2.10),
            24: (1e-4, 13.70, 4.23e6, 2.25), 25: (1e-4, 11.99, 3.53e6, 2.46), 26: (1e-4, 10.18, 2.83e6, 2.73),
            27: (1e-4, 8.37, 2.16e6, 3.10)}

PLOT_GROUPS = (1, 2, 4, 5, 9, 13, 17, 18, 27)
SETTINGS = {"e_star": 1.0, "fd_scheme": spectra.SEED_STENCILS}


# ----------------------------------------------------------------------------
# Computation
# ----------------------------------------------------------------------------

def group_statistics(group, realisations, edges, generator):
    """Ensemble of one group: stats-mode summary plus the moments of the literal 'central' FD reading."""
    k_l, k_s, hurst, n = GROUPS[group]
    grid = Grid(n, n, 1.0, 1.0)
    entries = []
    for i in range(realisations):
        heights = fractal(grid, k_l, k_s, hurst, M2[group], i + 1, generator=generator or GENERATORS[group])
        scalars, counts = stats_mode.surface_statistics(grid, heights, SETTINGS, edges)
        central = spectra.isotropic_mean(spectra.fd_moments(grid, heights, spectra.MOMENT_ORDERS, "central"))
        scalars.update({f"m{order}h_central": value for order, value in central.items()})
        entries.append((i, i + 1, scalars, counts, grid))
    summary = stats_mode.ensemble_summary(entries, edges)
    closed = spectra.fractal_closed_forms(k_l, k_s, hurst, fractal_amplitude(k_l, k_s, hurst, M2[group]))
    document = stats_output.result_document(
        summary, SETTINGS, {"k_l": k_l, "k_s": k_s, "H": hurst, "N": n}, stats_mode.flatten_closed_forms(closed),
        stats_mode.pdf_distances(summary), [i + 1 for i in range(realisations)], grid)
    document.pop("per_surface")
    return document


def compute_all(realisations, realisations_2048, groups, generator, cache, note):
    """Every group of ``groups``, each saved into ``cache`` as it finishes; groups already there (same note) kept."""
    edges = stats_mode.histogram_edges(0.25)
    stored = {"groups": {}, "note": note, "elapsed": 0.0}
    if os.path.exists(cache):
        with open(cache) as f:
            previous = json.load(f)
        if previous.get("note") == note:
            stored = previous
    results = stored["groups"]
    for group in groups:
        if str(group) in results:
            continue
        count = realisations if GROUPS[group][3] == 1024 else realisations_2048
        start = time.time()
        results[str(group)] = group_statistics(group, count, edges, generator)
        results[str(group)]["seconds"] = time.time() - start
        stored["elapsed"] += time.time() - start
        write_json(cache, stored)
        print(f"group {group}: {count} realisations in {time.time() - start:.1f} s", flush=True)
    return {str(g): results[str(g)] for g in groups}, stored["elapsed"]


# ----------------------------------------------------------------------------
# Rendering
# ----------------------------------------------------------------------------

def fmt(value, digits=3):
    if value is None:
        return "—"
    return f"{value:.{digits}g}"


def pm(document, key, digits=3):
    return f"{fmt(document['mean'][key], digits)} ± {fmt(document['std'][key], 2)}"


def deviation(ours, seed):
    return "—" if seed is None else f"{100.0 * (ours / seed - 1.0):+.1f} %"


def table_7_2(results):
    lines = ["| # | m20 ours | m20 dissertation | m02 ours | m02 dissertation | m40 ours | m40 dissertation | m04 ours | m04 dissertation | "
             "m60 ours | m60 dissertation | m06 ours | m06 dissertation |", "|" + "---|" * 13]
    for group in range(1, 18):
        d = results[str(group)]
        seed = SEED_7_2[group]
        cells = []
        for (n, axis), s in zip(((2, "x"), (2, "y"), (4, "x"), (4, "y"), (6, "x"), (6, "y")), seed):
            cells += [pm(d, f"m{n}h_fd_{axis}"), fmt(s)]
        lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def table_7_3(results):
    lines = ["| # | m20p ours | m20p dissertation | m02p ours | m02p dissertation | m40p ours | m40p dissertation | m04p ours | m04p dissertation |",
             "|" + "---|" * 9]
    for group in range(1, 18):
        d = results[str(group)]
        cells = []
        for (n, axis), s in zip(((2, "x"), (2, "y"), (4, "x"), (4, "y")), SEED_7_3[group]):
            cells += [pm(d, f"m{n}p_fd_{axis}"), fmt(s)]
        lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def table_moments_vs_closed(results, groups):
    """Tables 7.4-7.6: closed form, our finite differences (the dissertation's stencils), our spectrum, the dissertation's Num."""
    lines = ["| # | moment | closed form | ours FD (the dissertation's stencils) | ours FD (repeated central) | ours spectrum "
             "| the dissertation's Num | ours FD vs dissertation |", "|" + "---|" * 8]
    for group in groups:
        d = results[str(group)]
        seed_h = SEED_NUM_H.get(group, (None,) * 4)
        seed_p = SEED_NUM_P.get(group, (None,) * 3)
        for n, s in zip((0, 2, 4, 6), seed_h):
            fd = d["mean"][f"m{n}h_fd"]
            lines.append(f"| {group} | m{n}h | {fmt(d['closed_form'][f'm{n}h'])} | {fmt(fd, 4)} | "
                         f"{fmt(d['mean'][f'm{n}h_central'], 4)} | {fmt(d['mean'][f'm{n}h_spec'], 4)} | "
                         f"{fmt(s)} | {deviation(fd, s)} |")
        for n, s in zip((0, 2, 4), seed_p):
            fd = d["mean"][f"m{n}p_fd"]
            lines.append(f"| {group} | m{n}p* | {fmt(d['closed_form'][f'm{n}p'])} | {fmt(fd, 4)} | — | "
                         f"{fmt(d['mean'][f'm{n}p_spec'], 4)} | {fmt(s)} | {deviation(fd, s)} |")
    return "\n".join(lines)


def table_7_7(results):
    lines = ["| # | alpha^h ours (mean ± std) | alpha^h dissertation | alpha^p ours | alpha^p dissertation | inside the dissertation's spread? |",
             "|---|---|---|---|---|---|"]
    for group, ((ah, sh), (ap, sp)) in SEED_7_7.items():
        d = results[str(group)]
        inside = abs(d["mean"]["alpha_h"] - ah) <= sh and abs(d["mean"]["alpha_p"] - ap) <= sp
        lines.append(f"| {group} | {pm(d, 'alpha_h', 5)} | {ah} ± {sh} | {pm(d, 'alpha_p', 5)} | {ap} ± {sp} | "
                     f"{'yes' if inside else 'NO'} |")
    return "\n".join(lines)


def table_8(results, seed_table, field):
    keys = [f"m0{field}_fd", f"m2{field}_fd", f"m4{field}_fd", f"alpha_{field}"]
    closed_keys = [f"m0{field}", f"m2{field}", f"m4{field}", f"alpha_{field}"]
    names = [f"m0{field}", f"m2{field}", f"m4{field}", f"alpha^{field}"]
    header = "| # | N | " + " | ".join(f"{n} closed | {n} ours | {n} the dissertation's Num | dev." for n in names) + " |"
    lines = [header, "|" + "---|" * (2 + 4 * len(names))]
    for group, seed in seed_table.items():
        d = results[str(group)]
        cells = []
        for key, closed_key, s in zip(keys, closed_keys, seed):
            ours = d["mean"][key]
            cells += [fmt(d["closed_form"][closed_key]), fmt(ours, 4), fmt(s), deviation(ours, s)]
        lines.append(f"| {group} | {GROUPS[group][3]} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def rule_of_thumb_rows(results):
    rows = []
    for group in sorted(int(g) for g in results):
        k_l, k_s, hurst, n = GROUPS[group]
        d = results[str(group)]
        rows.append({
            "group": group, "kl_L": k_l * 1.0, "nodes_per_shortest_wavelength": n / k_s,
            "m0_dev": d["mean"]["m0h_fd"] / d["closed_form"]["m0h"] - 1.0,
            "m2_dev": d["mean"]["m2h_fd"] / d["closed_form"]["m2h"] - 1.0,
            "m4_dev": d["mean"]["m4h_fd"] / d["closed_form"]["m4h"] - 1.0,
            "m6_dev": d["mean"]["m6h_fd"] / d["closed_form"]["m6h"] - 1.0,
            "l1_height_h": d["pdf_l1"]["height_h"]["l1"], "l1_summit_h": d["pdf_l1"]["summit_height_h"]["l1"],
            "l1_kappa_h": d["pdf_l1"]["mean_curvature_h"]["l1"], "l1_height_p": d["pdf_l1"]["height_p"]["l1"],
            "l1_summit_p": d["pdf_l1"]["summit_height_p"]["l1"], "l1_kappa_p": d["pdf_l1"]["mean_curvature_p"]["l1"],
            "noise_summit_h": d["pdf_l1"]["summit_height_h"]["l1_noise"],
        })
    return rows


def table_rule_of_thumb(rows):
    lines = ["| # | k_l L | N/(k_s L) | m0h dev. | m2h dev. | m4h dev. | m6h dev. | L1 height h | L1 summit xi h "
             "(noise) | L1 kappa_m h | L1 height p | L1 summit xi p | L1 kappa_m p |", "|" + "---|" * 13]
    for r in rows:
        lines.append(
            f"| {r['group']} | {r['kl_L']:g} | {r['nodes_per_shortest_wavelength']:g} | {100 * r['m0_dev']:+.1f} % | "
            f"{100 * r['m2_dev']:+.1f} % | {100 * r['m4_dev']:+.1f} % | {100 * r['m6_dev']:+.1f} % | "
            f"{r['l1_height_h']:.3f} | {r['l1_summit_h']:.3f} ({r['noise_summit_h']:.3f}) | {r['l1_kappa_h']:.3f} | "
            f"{r['l1_height_p']:.3f} | {r['l1_summit_p']:.3f} | {r['l1_kappa_p']:.3f} |")
    return "\n".join(lines)


def plot_rule_of_thumb(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for r in rows:
        colour = plt.cm.viridis(np.log2(r["kl_L"]) / 4.0)
        axes[0].semilogx(r["nodes_per_shortest_wavelength"], 100 * abs(r["m6_dev"]), "o", color=colour)
        axes[0].annotate(str(r["group"]), (r["nodes_per_shortest_wavelength"], 100 * abs(r["m6_dev"])), fontsize=7)
        axes[1].semilogx(r["kl_L"], r["l1_height_h"], "o", color=colour)
        axes[1].annotate(str(r["group"]), (r["kl_L"], r["l1_height_h"]), fontsize=7)
    axes[0].set_xlabel("nodes per shortest wavelength N / (k_s L)  [second criterion of (7.10)]")
    axes[0].set_ylabel("|m6h (FD) / (2.24) - 1|  [%]")
    axes[1].set_xlabel("k_l L  [first criterion of (7.10)]")
    axes[1].set_ylabel("L1 distance of height PDF of h to the Gaussian")
    fig.suptitle("Rule of thumb (7.10) on our ensembles (colour: k_l)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def render(results, realisations_note, elapsed):
    for group in PLOT_GROUPS:
        if str(group) in results:
            stats_output.plot_pdfs(os.path.join(OUT, f"pdf_group{group:02d}"), results[str(group)])
    rows = rule_of_thumb_rows(results)
    plot_rule_of_thumb(rows, os.path.join(OUT, "rule_of_thumb.png"))
    text = f"""# Surface statistics of our generator against the dissertation (Tables 7.2-7.7, 8.2-8.3)

Generated by `studies/surface_statistics.py`. {realisations_note} Total run time {elapsed:.0f} s.
Surfaces: `roughpetsc.surfaces.fractal` (sec. 7.1), unit cell, m2 = 2e-4, E* = 1 (so p* = p); realisation i has
seed i + 1. "ours" = mean ± sample std over the realisations. Moments by finite differences (7.6)/(7.7) with the
dissertation's stencils (central first derivative, three-point second derivative, central difference of the three-point
second derivative for the third); "repeated central" is the literal reading (central difference applied n/2
times); "spectrum" is the discrete (2.12). The dissertation's numbers are as printed ("—": illegible in our copy).
PDF distances: L1 = sum over bins of width 0.25 on [-5, 5] (plus the mass outside) of |measured − closed-form
probability| (= 2 × total variation); "noise" is the L1 expected from sampling alone for the same number of
independent samples.

## Which "Num" definition reproduces the dissertation (Tables 7.4-7.6)

{table_moments_vs_closed(results, [1, 2, 3, 4, 5, 9, 13, 14, 15, 16, 17])}

## Table 7.2 — moments of h in x and y

{table_7_2(results)}

## Table 7.3 — moments of the pressure surface in x and y

{table_7_3(results)}

## Table 7.7 — bandwidth parameters of groups 1 and 2

{table_7_7(results)}

## Table 8.2 — rough surface, groups 18-27

{table_8(results, SEED_8_2, "h")}

## Table 8.3 — pressure surface, groups 18-27

{table_8(results, SEED_8_3, "p")}

## Rule of thumb (7.10) on our data

k_l ≫ 1/L and k_s ≪ N/L. Deviations are of the FD means from the closed forms (2.21)-(2.24); L1 as above.
![rule of thumb](rule_of_thumb.png)

{table_rule_of_thumb(rows)}

## PDF plots

""" + "\n".join(f"- group {g}: ![h](pdf_group{g:02d}_h.png) ![p](pdf_group{g:02d}_p.png)"
                for g in PLOT_GROUPS if str(g) in results) + "\n"
    with open(os.path.join(OUT, "surface_statistics.md"), "w") as f:
        f.write(text)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--realisations", type=int, default=30, help="realisations per 1024^2 group")
    parser.add_argument("--realisations-2048", type=int, default=10, help="realisations per 2048^2 group")
    parser.add_argument("--groups", type=int, nargs="*", default=sorted(GROUPS))
    parser.add_argument("--generator", choices=["filter", "xu"], default=None,
                        help="override the generator of the presets (default: each group's own, xu)")
    parser.add_argument("--render-only", action="store_true")
    args = parser.parse_args()
    os.makedirs(OUT, exist_ok=True)
    cache = os.path.join(OUT, "ensemble.json")
    start = time.time()
    if args.render_only:
        with open(cache) as f:
            stored = json.load(f)
        results, note, elapsed = stored["groups"], stored["note"], stored["elapsed"]
    else:
        generator = args.generator or "each group's own (options/groupNN.opts: xu)"
        note = (f"Realisations: {args.realisations} per 1024^2 group, {args.realisations_2048} per 2048^2 group "
                f"(the dissertation used 1000); generator: {generator}.")
        results, elapsed = compute_all(args.realisations, args.realisations_2048, args.groups, args.generator, cache,
                                       note)
    missing = sorted(set(GROUPS) - {int(g) for g in results})
    if missing:
        print(f"groups {missing} not computed: the tables need every group, nothing rendered")
        return
    render(results, note, elapsed)
    print(f"wrote {OUT}/surface_statistics.md in {time.time() - start:.0f} s")


if __name__ == "__main__":
    main()
