"""Figures and report from our own BEM ensembles (issue 6, item 5): the dissertation's Figs. 3.8-3.10, 7.11-7.21,
Table 7.7, Figs. 8.1-8.3 (and an 8.6-style check), the acceptance check against the curve fit
(8.2)-(8.3) with Table 8.4, and Table 8.4 refitted from our BEM means.

    .venv/bin/python studies/ensemble_figures.py --extras   # once: the field pictures (single process)
    .venv/bin/python studies/ensemble_figures.py            # figures + report from the files

Reads the ensemble files written by studies/ensemble_runs.sh (studies/output/ensembles/group<NN>_N<N>.h5)
and the extras file (studies/output/ensembles/extras.h5); writes studies/output/ensembles/*.png and
studies/output/ensembles/report.md. Nothing is regenerated or recomputed that the files hold: the BEM
means and standard deviations, the bandwidths (spectral and finite-difference), kappa = dA*/dp* and the
model curves come from each file's /statistics and /models (roughpetsc.store.ensemble_file). A file of
format roughpetsc-ensemble-1 lacks the finite-difference bandwidths and the rms gap statistics (the table
says so, and the rms gap is then taken from its steps); an unfinished ensemble has no /models, and they are
computed at its mean bandwidths by the store's own function. Either case is printed when the file is read.

Conventions: p* = pbar / sqrt(m0^p), g* = gbar / sqrt(m0^h), d* = d / sqrt(m0^h); A* by node count (3.45)
unless "corrected" (perimeter correction of Yastrebov et al.).
"""

import argparse
import os
import time

import numpy as np

from ensemble_chapter7 import fig_3_8_to_3_10, fig_7_complete, fig_7_early, fig_7_full, table_7_7
from ensemble_common import (GROUPS_8, OUT, P_RANGE, TOLERANCE, M, bem, common_steps, compute_extras, grid_effect,
                             load_ensembles, plt, preferred, preferred_n, save, dissertation_curve)


def fig_8(ensembles, produced, report):
    ens = [e for e in (preferred_n(ensembles, g, 512) for g in sorted(GROUPS_8)) if e is not None]
    if len(ens) < 2:
        return
    p, idx = common_steps(ens)
    A = np.array([e.A[i] for e, i in zip(ens, idx)])
    g = np.array([e.g[i] for e, i in zip(ens, idx)])
    colors = plt.cm.viridis(np.linspace(0, 1, len(ens)))
    fig, ax = plt.subplots(1, 2, figsize=(11.5, 4.5))
    for e, a, c in zip(ens, A, colors):
        label = f"#{e.group} (k_s {e.surface['ks']:g}, H {e.surface['H']:g}; {e.n})"
        ax[0].plot(p, a, "-o", ms=2.5, color=c, label=label)
        ax[1].plot(p, a, "-o", ms=3, color=c, label=label)
    ax[0].set(xlabel="p*", ylabel="mean A*", title="Fig. 8.1(a): groups 18-27 (512^2)")
    ax[1].set(xlabel="p*", ylabel="mean A*", xlim=(0.8, 1.25), title="Fig. 8.1(b): detail")
    sel = (p >= 0.8) & (p <= 1.25)
    if sel.any():
        ax[1].set_ylim(A[:, sel].min() - 0.01, A[:, sel].max() + 0.01)
    ax[0].legend(fontsize=6.5)
    for a in ax:
        a.grid(alpha=0.3)
    save(fig, "fig8_1_area_groups.png", produced)

    dispersion_A = (A.max(0) - A.min(0)) / A.mean(0)
    fig, ax = plt.subplots(figsize=(6, 4.3))
    ax.semilogy(p, dispersion_A, "ko-", ms=3)
    ax.set(xlabel="p*", ylabel="(max - min) / mean of A* over groups",
           title=f"Fig. 8.2: relative dispersion of A* ({len(ens)} groups)")
    ax.grid(alpha=0.3, which="both")
    save(fig, "fig8_2_dispersion_area.png", produced)

    dispersion_g = (g.max(0) - g.min(0)) / g.mean(0)
    fig, ax = plt.subplots(1, 2, figsize=(11.5, 4.5))
    for e, gg, c in zip(ens, g, colors):
        ax[0].loglog(p, gg, "-o", ms=2.5, color=c, label=f"#{e.group}")
    ax[0].set(xlabel="p*", ylabel="mean g*", title="Fig. 8.3(a): mean gap, groups 18-27")
    ax[0].legend(fontsize=7)
    ax[1].plot(p, dispersion_g, "ko-", ms=3)
    ax[1].set(xlabel="p*", ylabel="(max - min) / mean of g*", title="Fig. 8.3(b): relative dispersion of g*")
    for a in ax:
        a.grid(alpha=0.3, which="both")
    save(fig, "fig8_3_gap_groups.png", produced)

    report += ["## Figs. 8.1-8.3: do the A*(p*) curves collapse?", "",
               f"{len(ens)} groups ({', '.join('#%d' % e.group for e in ens)}) at 512^2, compared at the "
               f"{p.size} load steps they share. Relative dispersion = (max - min) / mean over the groups.", "",
               "| p* range | max relative dispersion of A* | at p* | max relative dispersion of g* |",
               "|---|---|---|---|"]
    for lo, hi in ((0.0, 0.2), (0.2, 2.0), (2.0, 4.0), (0.0, 4.0), (0.05, 4.0)):
        s = (p > lo) & (p <= hi + 1e-12)
        if s.any():
            k = np.argmax(np.where(s, dispersion_A, -1))
            report.append(f"| ({lo:g}, {hi:g}] | {dispersion_A[k]:.4f} | {p[k]:.3f} | "
                          f"{dispersion_g[s].max():.3f} |")
    report += ["", "The dissertation (Fig. 8.2): the relative dispersion of A* stays at least one order of magnitude below 1 "
               "and is smallest for p* >= 2; Fig. 8.3(b): the dispersion of g* exceeds 1, i.e. g*(p*) does not "
               "collapse.", "",
               "Caveat: at 512^2 groups 23-27 (k_s = 128) have 4 nodes per 1/k_s, groups 18-22 (k_s = 64) have 8, so "
               "part of the spread between the two k_s families is grid bias of node-count A* (see the grid effect "
               "below), not statistics of the surfaces.", ""]


def acceptance(ensembles, produced, report):
    rows, fits = [], []
    for (group, n), e in sorted(ensembles.items()):
        if group not in GROUPS_8:
            continue
        sel = (e.p >= P_RANGE[0] - 1e-12) & (e.p <= P_RANGE[1] + 1e-12)
        p = e.p[sel]
        alphas = {"dissertation Table 8.3": M.ALPHA_P_TABLE_8_3[group], "ours spectral": e.alpha_p}
        if e.fd is not None:
            alphas["ours FD"] = e.fd["p"][0]
        dev = {}
        for key, ap in alphas.items():
            I_f = dissertation_curve(p, group, ap)
            diff = e.A[sel] - I_f
            k = int(np.argmax(np.abs(diff)))
            dev[key] = (abs(diff[k]), p[k], diff[k])
            if key == "dissertation Table 8.3":
                dev["corrected"] = (np.max(np.abs(e.Ac[sel] - I_f)),)
                sem = e.A_std[sel] / np.sqrt(max(e.n, 1))
                dev["sem"] = float(sem.max())
        rows.append((e, dev, alphas))
        b, c, d = M.fit_curvefit(e.p, e.A, e.alpha_p)
        fit_dev = np.max(np.abs(e.A[sel] - M.curvefit_area(p, e.alpha_p, b, c, d)))
        b2, c2, d2 = M.fit_curvefit(e.p, e.A, M.ALPHA_P_TABLE_8_3[group])
        fits.append((e, (b, c, d), fit_dev, (b2, c2, d2)))

    report += ["## Acceptance: mean A*(p*) against the dissertation's curve fit I(p*) f(p*)", "",
               "I(p*) is the Greenwood nearly-complete model (5.45) (the dissertation's (8.2)), f(p*) = a exp(b p*) + "
               "c exp(d p*) with Table 8.4's b, c, d and a = -c (erratum, docs/conventions.md), A* = I f for p* <= 2 "
               "and I beyond. "
               f"Deviation = max over our load steps with p* in [{P_RANGE[0]:g}, {P_RANGE[1]:g}] of "
               "|A*_mean - I f|. **Verdict** uses the dissertation's own curve (I at the dissertation's alpha^p of "
               "Table 8.3 "
               "\"Num\"); the other columns put our own alpha^p into I instead. Tolerance 0.02 (the project's "
               "acceptance target).", "",
               "| group | grid | surfaces | steps in range | max dev. (alpha^p dissertation) | at p* | signed | "
               "verdict | "
               "max dev. (our alpha^p spectral) | max dev. (our alpha^p FD) | perimeter-corrected A* (alpha^p "
               "dissertation) "
               "| max std. error of mean |",
               "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for e, dev, alphas in rows:
        s, sp, sfd = dev["dissertation Table 8.3"], dev["ours spectral"], dev.get("ours FD")
        steps = int(np.sum((e.p >= P_RANGE[0] - 1e-12) & (e.p <= P_RANGE[1] + 1e-12)))
        verdict = "**PASS**" if s[0] <= TOLERANCE else "**FAIL**"
        report.append(f"| {e.group} | {e.N}^2 | {e.n} | {steps} | {s[0]:.4f} | {s[1]:.3f} | {s[2]:+.4f} | "
                      f"{verdict} | {sp[0]:.4f} (alpha^p {alphas['ours spectral']:.3f}) | "
                      + (f"{sfd[0]:.4f} (alpha^p {alphas['ours FD']:.3f})" if sfd else "—")
                      + f" | {dev['corrected'][0]:.4f} | {dev['sem']:.4f} |")
    report.append("")

    report += ["## Table 8.4 refitted from our BEM means", "",
               "b and d by least squares on our mean A* at the steps with p* <= 2 (`roughpetsc.models.fit_curvefit`: "
               "a = -c and c = 1/(exp(2d) - exp(2b)) built in, as in the dissertation), I(p*) at our ensemble's mean "
               "alpha^p (spectral). Last columns: the same fit with the dissertation's alpha^p (Table 8.3).", "",
               "| group | grid | surfaces | b ours | b diss. | c ours | c diss. | d ours | d diss. | max dev. of our "
               "fit "
               "(p* in [0.05, 4]) | b, c, d with the dissertation's alpha^p "
               "|", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for e, (b, c, d), fit_dev, (b2, c2, d2) in fits:
        sb, sc, sd = M.TABLE_8_4[e.group]
        report.append(f"| {e.group} | {e.N}^2 | {e.n} | {b:.3f} | {sb:.3f} | {c:.3f} | {sc:.3f} | {d:.4f} | "
                      f"{sd:.3f} | {fit_dev:.4f} | {b2:.3f}, {c2:.3f}, {d2:.4f} |")
    grid = grid_effect(ensembles)
    if grid is not None:
        b, c, d = M.fit_curvefit(grid["p"], grid["A"]["inf"], grid["alpha_p"])
        sel = grid["p"] <= P_RANGE[1] + 1e-12
        fit_dev = np.max(np.abs(grid["A"]["inf"][sel] - M.curvefit_area(grid["p"][sel], grid["alpha_p"], b, c, d)))
        b2, c2, d2 = M.fit_curvefit(grid["p"], grid["A"]["inf"], M.ALPHA_P_TABLE_8_3[18])
        sb, sc, sd = M.TABLE_8_4[18]
        fine, coarse = grid["extrapolation"]
        report.append(f"| 18 extrapolated (2 A_{fine} - A_{coarse}) | h -> 0 | — | {b:.3f} | {sb:.3f} | {c:.3f} | "
                      f"{sc:.3f} | "
                      f"{d:.4f} | {sd:.3f} | {fit_dev:.4f} | {b2:.3f}, {c2:.3f}, {d2:.4f} |")
    at512 = [f for f in fits if f[0].N == 512]
    if len(at512) > 1:
        arr = np.array([f[1] for f in at512])
        published = np.array([M.TABLE_8_4[f[0].group] for f in at512])
        report += ["", f"Column means ± std over our {len(at512)} groups at 512^2 (the dissertation's over its 10 "
                       f"groups, "
                   "sentence after Table 8.4 with the names corrected: b = -1.913 ± 0.0332, c = 1.130 ± 0.0301, "
                   "d = -0.0490 ± 0.0128; the dissertation's over the same groups as ours in brackets):", "",
                   "| | b | c | d |", "|---|---|---|---|",
                   "| ours | " + " | ".join(f"{arr[:, j].mean():.3f} ± {arr[:, j].std(ddof=1):.4f}" for j in range(3))
                   + " |",
                   "| dissertation, same groups | "
                   + " | ".join(f"{published[:, j].mean():.3f} ± {published[:, j].std(ddof=1):.4f}" for j in range(3))
                   + " |"]
    report.append("")

    # Fig. 8.6 style: BEM vs the curve fits, and the slope
    for group in (18, 27):
        e = preferred_n(ensembles, group, 512) or preferred(ensembles, group)
        if e is None:
            continue
        fit = [f for f in fits if f[0] is e][0][1]
        pp = np.linspace(1e-3, 4, 400)
        fig, ax = plt.subplots(1, 2, figsize=(11.5, 4.4))
        bem(ax[0], e, e.A, e.A_std, every=1 if e.p.size < 50 else 2)
        ax[0].plot(pp, dissertation_curve(pp, group, M.ALPHA_P_TABLE_8_3[group]), "r-",
                   label=f"dissertation fit (Table 8.4), alpha^p {M.ALPHA_P_TABLE_8_3[group]:.2f}")
        ax[0].plot(pp, M.curvefit_area(pp, e.alpha_p, *fit), "b--", label=f"our refit, alpha^p {e.alpha_p:.3f}")
        ax[0].set(xlabel="p*", ylabel="A*", title=f"Fig. 8.6(a)-style: group #{group}, {e.N}^2")
        ax[0].legend(fontsize=7)
        kap = e.models["kappa"]["bem_A"]
        ax[1].plot(e.p, kap, "ko", ms=3, label="BEM mean (finite differences)")
        ax[1].plot(pp, np.gradient(dissertation_curve(pp, group, M.ALPHA_P_TABLE_8_3[group]), pp), "r-",
                   label="dissertation fit")
        ax[1].plot(pp, np.gradient(M.curvefit_area(pp, e.alpha_p, *fit), pp), "b--", label="our refit")
        ax[1].axhline(np.sqrt(np.pi / 2), color="0.5", ls=":", label="sqrt(pi/2) (asymptotic BGT)")
        ax[1].set(xlabel="p*", ylabel="dA*/dp*", title="Fig. 8.6(b)-style: slope")
        ax[1].legend(fontsize=7)
        for a in ax:
            a.grid(alpha=0.3)
        save(fig, f"fig8_6_curvefit_group{group}.png", produced)

    # deviation profiles of every group against the dissertation's curve
    fig, ax = plt.subplots(figsize=(7, 4.4))
    colors = plt.cm.viridis(np.linspace(0, 1, max(len(rows), 2)))
    for (e, _, _), c in zip(rows, colors):
        sel = (e.p >= P_RANGE[0] - 1e-12) & (e.p <= P_RANGE[1] + 1e-12)
        ax.plot(e.p[sel], e.A[sel] - dissertation_curve(e.p[sel], e.group, M.ALPHA_P_TABLE_8_3[e.group]), "-o", ms=2,
                color=c, label=f"#{e.group} ({e.N}^2, {e.n})")
    grid = grid_effect(ensembles)
    if grid is not None:
        ax.plot(grid["p"], grid["dev"]["inf"], "k--", lw=1.2, label="#18 extrapolated to h -> 0 (2 A_%d - A_%d)"
                % grid["extrapolation"])
    for y in (-TOLERANCE, TOLERANCE):
        ax.axhline(y, color="r", ls="--", lw=0.8)
    ax.set(xlabel="p*", ylabel="A*_mean - I(p*) f(p*)", title="Acceptance: BEM mean minus the dissertation's curve fit")
    ax.legend(fontsize=6.5, ncol=2)
    ax.grid(alpha=0.3)
    save(fig, "acceptance_deviation.png", produced)
    if grid is not None:
        report += ["### Grid effect (group 18)", "",
                   "Node-count A* carries a discretisation error of the order of the contact perimeter times the "
                   "node spacing h. Group 18 on each grid it ran on (the dissertation's is 1024^2), compared at their "
                   "shared "
                   f"steps ({grid['p'].size} steps in [{P_RANGE[0]:g}, {P_RANGE[1]:g}]); \"extrapolated\" is the "
                   "Richardson estimate 2 A*_fine - A*_coarse of the h -> 0 limit from the two finest grids "
                   "(error assumed proportional to h).", "",
                   "| A* from | max abs(A* - I f) (the dissertation's curve) | at p* | perimeter-corrected "
                   "|", "|---|---|---|---|"]
        for key, label in grid["labels"]:
            dev, devc = grid["dev"][key], grid["dev_corrected"][key]
            k = int(np.argmax(np.abs(dev)))
            report.append(f"| {label} | {abs(dev[k]):.4f} | {grid['p'][k]:.3f} | {np.max(np.abs(devc)):.4f} |")
        report.append("")
    return rows, fits


def notes(ensembles, report):
    report += ["## Ensembles, grids, convergence", "",
               "| file | group (k_l, k_s, H) | grid | surfaces | load steps | steps converged | max KKT natural "
               "| max load error | wall time (s) | mean s / surface |",
               "|---|---|---|---|---|---|---|---|---|---|"]
    for (group, n), e in sorted(ensembles.items()):
        s = e.surface
        report.append(f"| {os.path.basename(e.path)} | {group} ({s['kl']:g}, {s['ks']:g}, {s['H']:g}) | {n}^2 | "
                      f"{e.n}/{e.size} | {e.p.size} | {int(e.converged.sum())}/{e.converged.size} | "
                      f"{np.nanmax(e.kkt):.2e} | {np.nanmax(e.load_error):.1e} | {e.wall_seconds():.0f}"
                      + (f" (+ {len(e.runs) - sum('seconds' in r for r in e.runs)} interrupted run(s), solved "
                         f"{sum(len(r['solved']) for r in e.runs if 'seconds' not in r)} surf.)"
                         if any('seconds' not in r for r in e.runs) else "") + " | "
                      f"{e.surface_time.mean():.1f} |")
    any_e = next(iter(ensembles.values()))
    report += ["", f"Solver: {any_e.solver} (the default: Polonsky-Keer constrained CG with the Fourier "
               f"preconditioner), load control, warm start from the previous step, stop at natural KKT "
               f"residual <= kkt_rtol = {any_e.rtol:g} (docs/conventions.md). Wall times: `mpiexec -n 2`, one surface "
               f"per "
               "rank, on 2 cores shared with other jobs (so they overstate the cost). Mean s / surface = one "
               "rank's wall time for the whole load path of a surface.", ""]


def differences(ensembles, report):
    report += ["## Differences from the dissertation, and why", "",
               "- **Grid.** The dissertation used 1024^2 for groups 1-4 and 18-22 and 2048^2 for 23-27 (16 nodes per "
               "shortest "
               "wavelength 1/k_s in groups 18-27). We ran 512^2 for groups 1, 2, 18-27 to fit the time budget: 8 "
               "nodes per 1/k_s for k_s = 64 (groups 1, 18-22), 4 for k_s = 128 (groups 2, 23-27). Node-count A* "
               "overestimates the contact ratio on coarse grids (every boundary node with p > 0 counts as a whole "
               "node), most at light load; the perimeter-corrected A* is shown beside it. Group 3 (k_s = 256) ran "
               "at 1024^2 (4 nodes per 1/k_s). Group 4 (k_s = 512) would need k_s <= Nyquist/2, i.e. 2048^2; "
               "not run unless a group-4 file is listed above. Group 18 also ran on the dissertation's 1024^2 (4 "
               "surfaces) "
               "and on 2048^2 (6 surfaces), groups 22, 23 and 27 on 2048^2 (2 surfaces each; the dissertation's grid "
               "for "
               "23 and 27), to measure the grid effect.",
               "- **Surfaces per group.** The dissertation: 50 per group. Ours: see the table above.",
               "- **Load steps.** Groups 1-3 and 18 follow the 95-step history (7.11) with Delta_1 = 0.2/30 "
               "(erratum, docs/conventions.md; the printed 0.067 contradicts n1 = 30 steps over (0, 0.2]). Groups "
               "19-27 used 33 of those "
               "95 steps (every third counted back from p* = 4, plus p* = 2.0028): a step's solution does not "
               "depend on the path (the QP has a unique solution), only the warm start does, so A*(p*) at these "
               "steps is the same as on the full path, at 1/2.7 of the cost. Figs. 8.1-8.3 compare the groups at "
               "these shared steps. The 1024^2 and 2048^2 runs used the same 33 steps; group 3 (1024^2) only the "
               "steps its "
               "figures need: every second history step of the early stage (15 steps, p* <= 0.2) and of the "
               "nearly-complete stage (10 steps, p* = 2.2 ... 4).",
               "- **Cost.** The 512^2 and 1024^2 ensembles ran with PK's restart rule: the 95-step history cost "
               "~11,000 operator applications per 512^2 surface, and under the load of the time (2 shared cores, "
               "load average ~10) a 512^2 surface took 100-190 s of wall per rank, a 1024^2 one ~600 s along 33 "
               "steps. The 2048^2 ensembles ran with the BCCG active set (now the default, ~2.6x fewer "
               "applications): ~250 s per 2048^2 surface along the 33 steps. Hence the small ensembles. The "
               "surfaces of a group differ little (standard error of the "
               "mean A* <= 0.002 at every step, last column of the acceptance table), so the means are settled "
               "to well below the 0.02 tolerance; the grid is the larger effect.",
               "- **Convergence criterion.** The dissertation stopped on its composite criterion (3.47)-(3.49), "
               "(3.51); we "
               "stop on the scale-free natural KKT residual (docs/conventions.md) and check it after every solve.",
               "- **Bandwidths.** The models here use our ensemble's mean alpha^h, alpha^p from the spectral moments. "
               "The dissertation's \"Num\" values come from finite differences (7.6)/(7.7); both are in Table 7.7 "
               "above. "
               "The acceptance verdict uses the dissertation's alpha^p (Table 8.3) in I(p*), i.e. exactly the "
               "dissertation's curve.",
               "- **Curve fit.** Fitted with scipy least squares (`fit_curvefit`) instead of MATLAB's toolbox, with "
               "the dissertation's two constraints built in; the range of the fit is our steps with p* <= 2.",
               ""]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--extras", action="store_true",
                        help="compute the field pictures and FD bandwidths into extras.h5 (single process)")
    args = parser.parse_args()
    os.makedirs(OUT, exist_ok=True)
    if args.extras:
        compute_extras()
        return
    start = time.time()
    ensembles = load_ensembles()
    if not ensembles:
        raise SystemExit(f"no ensemble files in {OUT}; run studies/ensemble_runs.sh first")
    produced = []
    body = []
    fig_3_8_to_3_10(ensembles, produced, body)
    fig_7_full(ensembles, produced)
    fig_7_early(ensembles, produced)
    fig_7_complete(ensembles, produced)
    table_7_7(ensembles, body)
    fig_8(ensembles, produced, body)
    rows, fits = acceptance(ensembles, produced, body)
    tail = []
    notes(ensembles, tail)
    differences(ensembles, tail)

    head = ["# BEM ensembles against the dissertation (issue 6, item 5)", "",
            "Generated by `studies/ensemble_figures.py` from the ensemble files of `studies/ensemble_runs.sh` "
            "(HDF5 under studies/output/ensembles/, not committed). Conventions: p* = pbar / sqrt(m0^p), "
            "g* = gbar / sqrt(m0^h), d* = d / sqrt(m0^h); A* by node count (3.45) unless marked perimeter-corrected; "
            "std with ddof = 1.", ""]
    summary = ["## Summary", ""]
    for e, dev, _ in rows:
        s = dev["dissertation Table 8.3"]
        summary.append(f"- Group {e.group} ({e.N}^2, {e.n} surfaces): max |A*_mean - I f| = {s[0]:.4f} at p* = "
                       f"{s[1]:.3f} -> {'PASS' if s[0] <= TOLERANCE else 'FAIL'} (tolerance {TOLERANCE})")
    corrected = [dev["corrected"][0] for _, dev, _ in rows]
    if corrected:
        summary.append(f"- Perimeter-corrected A* (Yastrebov et al.) against the same curve: max deviation "
                       f"{max(corrected):.4f} over all {len(corrected)} ensembles "
                       f"({'within' if max(corrected) <= TOLERANCE else 'outside'} {TOLERANCE}).")
    if fits:
        arr = np.array([f[1] for f in fits if f[0].N == 512])
        if arr.size:
            summary.append(f"- Refitted (b, c, d) at 512^2: b {arr[:, 0].mean():.3f}, c {arr[:, 1].mean():.3f}, d "
                           f"{arr[:, 2].mean():.4f} (means over {len(arr)} groups) vs the dissertation's -1.913, "
                           f"1.130, "
                           "-0.049: our BEM rises faster at small p* (initial slope ~1.3 vs the dissertation's fit's "
                           "~1.07), "
                           "which the two-exponential form absorbs with a more negative b and d ~ 0; the parameters "
                           "trade off strongly (the fits agree with our means to <= 0.006).")
    grid = grid_effect(ensembles)
    if grid is not None:
        dev = grid["dev"]
        summary.append("- Group 18 grid effect: max deviation "
                       + ", ".join(f"{label} {np.max(np.abs(dev[key])):.4f}" for key, label in grid["labels"])
                       + " (see 'Grid effect' below)")
    summary.append("")
    report = head + summary + body + tail + ["## Figures", ""] + [f"- `{name}`" for name in produced] + [""]
    with open(os.path.join(OUT, "report.md"), "w") as f:
        f.write("\n".join(report))
    print(f"wrote {len(produced)} figures and report.md in {OUT} ({time.time() - start:.1f} s)")


if __name__ == "__main__":
    main()
