"""The dissertation's Figs. 3.7-3.10 and 7.11-7.21 and Table 7.7 from our BEM ensembles (ensemble_figures.py runs them).

BEM means, standard deviations, kappa = dA*/dp* and the model curves at the load steps are those the
ensemble files store (:class:`ensemble_common.Ens`).
"""

import numpy as np

from ensemble_common import (DISSERTATION_FIG_3_9_A, DISSERTATION_TABLE_7_7, EARLY_PMAX, FIELD_GROUP, FIELD_N,
                             GROUPS_7, LABEL, STYLE, M, bem, early_curve, fractal_group, nodes_per_wavelength,
                             panel_figures, plt, preferred, read_fields, save, title)


def fig_3_8_to_3_10(ensembles, produced, report):
    e = ensembles.get((FIELD_GROUP, FIELD_N)) or preferred(ensembles, FIELD_GROUP)
    if e is None:
        return
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for k in range(e.n):
        ax[0].plot(e.p, e.A_all[k], color="0.75", lw=0.6)
        ax[1].semilogy(e.p, e.g_all[k], color="0.75", lw=0.6)
    ax[0].plot(e.p, e.A, "k-", lw=1.6, label=f"mean of {e.n} surfaces")
    ax[1].semilogy(e.p, e.g, "k-", lw=1.6, label=f"mean of {e.n} surfaces")
    ax[0].set(xlabel="p* = pbar / sqrt(m0^p)", ylabel="A*", title="Fig. 3.8(a): contact ratio (grey: each surface)")
    ax[1].set(xlabel="p* = pbar / sqrt(m0^p)", ylabel="g* = gbar / sqrt(m0^h)", title="Fig. 3.8(b): mean gap")
    for a in ax:
        a.legend()
        a.grid(alpha=0.3)
    fig.suptitle(f"BEM, group #{e.group}, {e.N}^2")
    save(fig, "fig3_8_area_gap.png", produced)

    fields = read_fields()
    if fields is None:
        report += ["Figs. 3.9/3.10: not drawn (run `ensemble_figures.py --extras` first).", ""]
        return
    at = fields["attrs"]
    n = fields["heights"].shape[0]
    for name, fig_no, what in (("contact", "3.9", "contact area (black: p > 0)"),
                               ("gap", "3.10", "gap g / sqrt(m0^h)")):
        fig, axes = plt.subplots(1, 4, figsize=(17, 4.6))
        for k, (ax, step) in enumerate(zip(axes, fields["steps"])):
            if name == "contact":
                ax.imshow(step["contact"], cmap="gray_r", origin="lower", extent=(0, 1, 0, 1),
                          interpolation="nearest")
            else:
                im = ax.imshow(step["gap"], cmap="viridis", origin="lower", extent=(0, 1, 0, 1),
                               interpolation="nearest")
                fig.colorbar(im, ax=ax, shrink=0.75)
            sa = step["attrs"]
            ax.set_title(f"({'abcd'[k]}) A* = {100 * sa['A']:.2f}% (dissertation "
                         f"{100 * DISSERTATION_FIG_3_9_A[k]:.2f}%)\n"
                         f"p* = {sa['pstar']:.4f}", fontsize=9)
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle(f"Fig. {fig_no}: {what}; group #{at['group']} surface {at['index']} (seed {at['seed']}), "
                     f"{n}^2 nodes")
        save(fig, f"fig{fig_no.replace('.', '_')}_{name}.png", produced)
    fig, ax = plt.subplots(figsize=(5.5, 4.6))
    im = ax.imshow(fields["heights"] / at["sqrt_m0h"], cmap="terrain", origin="lower", extent=(0, 1, 0, 1))
    fig.colorbar(im, ax=ax)
    ax.set_title(f"Fig. 3.7: h / sqrt(m0^h), group #{at['group']} surface {at['index']}")
    save(fig, "fig3_7_heights.png", produced)
    report += ["### Figs. 3.9/3.10 (contact area and gap pictures)", "",
               f"Surface {at['index']} of group #{at['group']} (seed {at['seed']}), {n}^2 nodes; p* chosen by "
               "interpolating that surface's ensemble A*(p*) at the dissertation's four contact ratios:", "",
               "| panel | dissertation A* | our A* | p* | g* | KKT natural | converged "
               "|", "|---|---|---|---|---|---|---|"]
    for k, step in enumerate(fields["steps"]):
        sa = step["attrs"]
        report.append(f"| ({'abcd'[k]}) | {100 * DISSERTATION_FIG_3_9_A[k]:.2f}% | {100 * sa['A']:.2f}% | "
                      f"{sa['pstar']:.4f} | "
                      f"{sa['gstar']:.4f} | {sa['kkt']:.1e} | {bool(sa['converged'])} |")
    report.append("")


def fig_7_full(ensembles, produced):
    """Figs. 7.11 (A*), 7.12 (g*), 7.13 (g* and rms gap in contact) over the whole history.

    Model curves are the file's, at its load steps: early-contact models up to p* = 0.2 (where the
    store defines them), nearly-complete ones and Persson's everywhere.
    """
    table = (("7.11", (1, 2)), ("7.12", (1, 2)), ("7.13", (1, 2)))
    for fig_no, _, ax, e in panel_figures(table, ensembles, produced):
        every = np.ones(e.p.size, bool)
        if fig_no == "7.11":
            bem(ax, e, e.A, e.A_std, every=2)
            for name, label in (("greenwood", "Greenwood (early)"), ("bgt_asymptotic", "asymptotic BGT (4.35)")):
                p, A = early_curve(e, name, "A", every)
                ax.plot(p, A, STYLE[name], label=label)
            A = e.model("complete", "greenwood", "A")
            if A is not None:
                ax.plot(e.p, np.clip(A, 0, None), "-", label="Greenwood (nearly complete)")
            A = e.model("persson", None, "A")
            if A is not None:
                ax.plot(e.p, A, "-", color="tab:brown", label="Persson (5.59)")
            ax.set(ylabel="A*", ylim=(0, 1.05))
        elif fig_no == "7.12":
            bem(ax, e, e.g, e.g_std, every=2)
            for name in ("greenwood", "bgt_asymptotic"):
                p, d = early_curve(e, name, "dstar", every)
                ok = d > 1e-3
                ax.semilogy(p[ok], d[ok], STYLE[name], label=f"{LABEL[name]} (early, g* ~ d*)")
            g = e.model("complete", "greenwood", "gstar")
            if g is not None:
                ok = g > 0
                ax.semilogy(e.p[ok], g[ok], "-", label="Greenwood (nearly complete)")
            g = e.model("persson", None, "gstar")
            if g is not None:
                ax.semilogy(e.p, g, "-", color="tab:brown", label="Persson (App. E)")
            ax.set(ylabel="g* = gbar / sqrt(m0^h)", ylim=(1e-4, 5))
        else:
            ax.semilogy(e.p, e.g, "ko-", ms=3, label="mean gap g*")
            ax.semilogy(e.p, e.rms, "s-", ms=3, color="tab:red",
                        label="rms gap in contact / sqrt(m0^h) (3.50)")
            ax.set(ylabel="g*, rms gap in contact (/ sqrt(m0^h))")
        ax.set(xlabel="p*", title=title(e, fig_no))
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)


def fig_7_early(ensembles, produced):
    """Figs. 7.14/7.15 (A*), 7.16 (kappa = dA*/dp*), 7.17 (g*) at early contact p* <= 0.2."""
    table = (("7.14", (1, 2), "A"), ("7.15", (3, 4), "A"), ("7.16", (1, 2), "kappa"), ("7.17", (1, 2), "g"))
    for fig_no, kind, ax, e in panel_figures(table, ensembles, produced):
        sel = e.p <= EARLY_PMAX + 1e-12
        kappa = e.models["kappa"]
        if kind == "A":
            bem(ax, e, e.A, e.A_std, sel)
            ax.plot(e.p[sel], e.Ac[sel], "x", color="tab:gray", ms=4, label="BEM mean, perimeter-corrected")
        elif kind == "g":
            bem(ax, e, e.g, e.g_std, sel)
        else:
            ax.plot(e.p[sel], kappa["bem_A"][sel], "ko", ms=3, label=f"BEM (mean of {e.n}, finite differences)")
            ax.plot(e.p[sel], kappa["bem_A_corrected"][sel], "x", color="tab:gray", ms=4,
                    label="BEM, perimeter-corrected")
        for name in M.EARLY_MODELS:
            if kind == "kappa":
                if "early_" + name in kappa:
                    ok = sel & np.isfinite(kappa["early_" + name])
                    ax.plot(e.p[ok], kappa["early_" + name][ok], STYLE[name], label=LABEL[name])
                continue
            p, y = early_curve(e, name, "A" if kind == "A" else "dstar", sel)
            ax.plot(p, y, STYLE[name], label=LABEL[name] if kind == "A" else f"{LABEL[name]} (d*)")
        y = e.model("persson", None, "A" if kind == "A" else "gstar") if kind != "kappa" else kappa.get("persson")
        if y is not None:
            ax.plot(e.p[sel], y[sel], "-", color="tab:brown", label="Persson")
        if kind == "A":
            ax.set(ylabel="A*")
        elif kind == "g":
            ax.set(ylabel="g* (models: d*)")
        else:
            ax.axhline(np.sqrt(np.pi / 2), color="0.6", lw=0.8, ls=":")
            ax.set(ylabel="kappa = dA*/dp*")
        ax.set(xlabel="p*", xlim=(0, EARLY_PMAX), title=title(e, fig_no))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower left" if kind == "kappa" else "best")


def fig_7_complete(ensembles, produced):
    """Figs. 7.18/7.19 (1 - A*) and 7.20/7.21 (g*) at nearly complete contact p* in [2, 4]."""
    table = (("7.18", (1, 2), "A"), ("7.19", (3, 4), "A"), ("7.20", (1, 2), "g"), ("7.21", (3, 4), "g"))
    for fig_no, kind, ax, e in panel_figures(table, ensembles, produced):
        sel = e.p >= 2.0 - 1e-12
        if kind == "A":
            bem(ax, e, 1 - e.A, e.A_std, sel)
            ax.plot(e.p[sel], 1 - e.Ac[sel], "x", color="tab:gray", ms=4, label="BEM, perimeter-corrected")
        else:
            bem(ax, e, e.g, e.g_std, sel)
        for name, label, style, color in [(name, LABEL[name], STYLE[name], None) for name in M.COMPLETE_MODELS] \
                + [(None, "Persson", "-", "tab:brown")]:
            family = "complete" if name else "persson"
            y = e.model(family, name, "A" if kind == "A" else "gstar")
            if y is not None:
                ax.plot(e.p[sel], (1 - y if kind == "A" else y)[sel], style, color=color, label=label)
        ax.set_yscale("log")
        ax.set(xlabel="p*", ylabel="1 - A*" if kind == "A" else "g*", xlim=(2, 4), title=title(e, fig_no))
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)


COMPLETE_STEPS = (2.0, 2.5, 3.1, 4.0)  # p* of Figs. 7.18-7.21 compared in numbers (the nearest stored step)
# p* of Figs. 7.11-7.17 compared in numbers, and how far the nearest stored step may lie from each: the early stage
# (Figs. 7.14-7.17, p* <= 0.2) and the middle of the load history drawn by Figs. 7.11/7.12.
EARLY_STEPS = ((0.0133, 0.005), (0.05, 0.005), (0.1, 0.01), (0.2, 0.01), (0.5, 0.05), (1.0, 0.05), (1.5, 0.1))


def nearest_steps(e, targets):
    """Indices of the stored steps nearest to each (p*, tolerance) of ``targets`` that lie within the tolerance."""
    out = []
    for pstar, tolerance in targets:
        i = int(np.argmin(np.abs(e.p - pstar)))
        if abs(e.p[i] - pstar) <= tolerance and i not in out:
            out.append(i)
    return out


def table_7_early(ensembles, report):
    """Figs. 7.11-7.17 in numbers: each model's A* and g* over the BEM mean at EARLY_STEPS, with the BEM standard
    error. The early-contact models give the separation d*, which the figures draw as g* (with the Westergaard
    kernel the mean gap is the separation, (3.38)); they are stored up to p* = EARLY_PMAX."""
    read = [preferred(ensembles, g) for g in sorted(GROUPS_7)]
    read = [e for e in read if e is not None]
    if not read:
        return []
    columns = [("early", name, LABEL[name]) for name in M.EARLY_MODELS] + \
        [("complete", "greenwood", "Greenwood (nearly complete)"), ("persson", None, "Persson")]
    report += ["## Figs. 7.11-7.17 in numbers: the models over the BEM, early contact and the middle of the load", "",
               "Model / BEM mean of A* and of g* at the stored step nearest to each p*, the models at the ensemble's "
               "mean bandwidths (as drawn); the early-contact models (chapter 4) give d* for g* and are stored up to "
               f"p* = {EARLY_PMAX:g}. Their d* is the separation of the flat from the mean plane, which the BEM's "
               "mean gap equals under the periodic kernel (3.38), so the g* ratio compares like with like; near "
               "p* = 0.2 it falls to 0 or below because those models put the flat at or under the mean plane "
               "(d* <= 0) where the BEM's mean gap is still about 0.6: a failure of the models, not of the table. "
               "BEM: mean (standard error of the mean, std / sqrt(surfaces)); a ratio is "
               "significant where it differs from 1 by several times the relative standard error, given last. "
               "\"corrected / node\": the perimeter-corrected BEM A* over the node-count one, the size of the grid "
               "effect on A* at that load. The nearly-complete Greenwood model, drawn over the whole history in "
               f"Figs. 7.11/7.12, is compared beyond p* = {EARLY_PMAX:g} only.", "",
               "| group | grid, surfaces | quantity | p* | BEM mean (s.e.) | "
               + " | ".join(label for _, _, label in columns) + " | corrected / node | relative s.e. |",
               "|---|---|---|---|---|" + "---|" * (len(columns) + 2)]
    for e in read:
        steps = nearest_steps(e, EARLY_STEPS)
        for quantity, mean, std, keys in (("A*", e.A, e.A_std, {"early": "A", "complete": "A", "persson": "A"}),
                                          ("g*", e.g, e.g_std, {"early": "dstar", "complete": "gstar",
                                                                "persson": "gstar"})):
            for i in steps:
                error = std[i] / np.sqrt(e.n)
                cells = []
                for family, name, _ in columns:
                    y = e.model(family, name, keys[family])
                    outside = family == "complete" and e.p[i] <= EARLY_PMAX + 1e-12  # drawn, not meant, there
                    value = None if y is None or outside else y[i]
                    cells.append("—" if value is None or not np.isfinite(value) or mean[i] == 0
                                 else f"{value / mean[i]:.3f}")
                corrected = f"{e.Ac[i] / e.A[i]:.3f}" if quantity == "A*" else "—"
                report.append(f"| {e.group} | {e.N}^2, {e.n} | {quantity} | {e.p[i]:.3f} | {mean[i]:.4g} "
                              f"({error:.1g}) | " + " | ".join(cells) + f" | {corrected} | {error / mean[i]:.1e} |")
    report.append("")
    return [early_summary(read)]


def early_summary(read, pstar=0.05):
    """One line for the report's summary: each early model's A* / BEM at the step nearest ``pstar``, over the groups."""
    ratios = {}
    for e in read:
        i = int(np.argmin(np.abs(e.p - pstar)))
        for name in M.EARLY_MODELS + ("persson",):
            y = e.model("persson", None, "A") if name == "persson" else e.model("early", name, "A")
            if y is not None and np.isfinite(y[i]):
                ratios.setdefault(name, []).append(y[i] / e.A[i])
    return (f"- Early contact (Figs. 7.11-7.17 in numbers, groups {', '.join(str(e.group) for e in read)}): model / "
            f"BEM A* at p* = {pstar:g}: " + "; ".join(f"{LABEL.get(name, 'Persson')} {min(r):.2f} to {max(r):.2f}"
                                                   for name, r in ratios.items())
            + " (relative standard error of the BEM means <= "
            + f"{max(np.max(e.A_std[e.p <= EARLY_PMAX] / np.sqrt(e.n) / e.A[e.p <= EARLY_PMAX]) for e in read):.1e}"
            + "; node-count A*, which the perimeter correction lowers by up to "
            + f"{max(1 - np.min(e.Ac[e.p <= EARLY_PMAX] / e.A[e.p <= EARLY_PMAX]) for e in read):.0%} there).")


def table_7_complete(ensembles, report):
    """Figs. 7.18-7.21 in numbers: each nearly-complete model's 1 - A* and g* over the BEM mean at COMPLETE_STEPS."""
    read = [preferred(ensembles, g) for g in sorted(GROUPS_7)]
    read = [e for e in read if e is not None]
    if not read:
        return
    report += ["## Figs. 7.18-7.21 in numbers: the nearly-complete models over the BEM", "",
               "Model / BEM mean of 1 - A* and of g* at the stored step nearest to each p*, the models at the "
               "ensemble's mean bandwidths (as drawn). BEM spread = std / mean over the surfaces.", "",
               "| group | grid, surfaces | quantity | p* | BEM spread | "
               + " | ".join(LABEL.get(name, name) for name in M.COMPLETE_MODELS) + " | Persson |",
               "|---|---|---|---|---|" + "---|" * (len(M.COMPLETE_MODELS) + 1)]
    for e in read:
        steps = sorted({int(np.argmin(np.abs(e.p - p))) for p in COMPLETE_STEPS if e.p.max() >= p - 0.05})
        for quantity, bem_mean, bem_std, key in (("1 - A*", 1 - e.A, e.A_std, "A"), ("g*", e.g, e.g_std, "gstar")):
            models = [e.model("complete", name, key) for name in M.COMPLETE_MODELS] + [e.model("persson", None, key)]
            for i in steps:
                cells = []
                for y in models:
                    value = None if y is None else (1 - y[i] if key == "A" else y[i])
                    cells.append("—" if value is None or bem_mean[i] == 0 else f"{value / bem_mean[i]:.2f}")
                spread = bem_std[i] / bem_mean[i] if bem_mean[i] else float("nan")
                report.append(f"| {e.group} | {e.N}^2, {e.n} | {quantity} | {e.p[i]:.2f} | {spread:.2f} | "
                              + " | ".join(cells) + " |")
    report.append("")


def table_7_7(ensembles, report):
    read = [e for (g, _), e in sorted(ensembles.items()) if g in GROUPS_7]
    nodes = "; ".join(f"group {e.group} at {e.N}^2: {nodes_per_wavelength(e):g}" for e in read) or "no file read"
    presets = {g: fractal_group(g) for g in sorted(DISSERTATION_TABLE_7_7)}
    theirs = ", ".join(f"{s['n'] / (s['k_s'] * s['length']):g} for group {g} at {s['n']}^2" for g, s in presets.items())
    report += ["## Table 7.7: bandwidth parameters (mean ± std over the surfaces)", "",
               "Ours from the spectral moments of each surface (what `-mode ensemble` stores and what the models "
               "above use) and from the dissertation's finite differences (7.6)/(7.7) (the dissertation's \"Num\"); "
               "closed forms "
               "(2.25)/(2.59) of the continuous PSD.", "",
               "The dissertation prints the same std (0.2144) for alpha^h and alpha^p of group 1, probably a copy "
               "slip. The FD values depend on the grid, through the nodes per shortest wavelength 1/k_s (ours: "
               f"{nodes}; the dissertation's: {theirs}).", "",
               "| group | grid, surfaces | alpha^h ours (spectral) | alpha^h ours (FD) | alpha^h closed form | "
               "alpha^h dissertation | alpha^p ours (spectral) | alpha^p ours (FD) | alpha^p closed form | alpha^p "
               "dissertation |",
               "|---|---|---|---|---|---|---|---|---|---|"]
    from roughpetsc.surface import spectra

    for group in sorted(GROUPS_7):
        for (g, n), e in sorted(ensembles.items()):
            if g != group:
                continue
            kl, ks, H = GROUPS_7[group]
            ch, cp = spectra.fractal_height_bandwidth(kl, ks, H), spectra.fractal_pressure_bandwidth(kl, ks, H)
            fd_h = fd_p = "— (file of format 1: rerun the ensemble to store them)"
            if e.fd is not None:
                fd_h, fd_p = (f"{e.fd[key][0]:.4f} ± {e.fd[key][1]:.4f}" for key in ("h", "p"))
            diss_h = diss_p = "—"
            if group in DISSERTATION_TABLE_7_7:
                (sh, ssh), (sp, ssp) = DISSERTATION_TABLE_7_7[group]
                diss_h, diss_p = f"{sh:.4f} ± {ssh:.4f}", f"{sp:.4f} ± {ssp:.4f}"
            report.append(f"| {group} | {n}^2, {e.n} | {e.alpha_h:.4f} ± {e.alpha_h_std:.4f} | {fd_h} | {ch:.4f} | "
                          f"{diss_h} | {e.alpha_p:.4f} ± {e.alpha_p_std:.4f} | {fd_p} | {cp:.4f} | {diss_p} |")
    report.append("")


