"""Figures and report from our own BEM ensembles (issue 6, item 5): seed Figs. 3.8-3.10, 7.11-7.21,
Table 7.7, Figs. 8.1-8.3 (and an 8.6-style check), the acceptance check against the curve fit
(8.2)-(8.3) with Table 8.4, and Table 8.4 refitted from our BEM means.

    .venv/bin/python studies/ensemble_figures.py --extras   # once: field pictures + FD bandwidths (single process)
    .venv/bin/python studies/ensemble_figures.py            # figures + report from the files

Reads the ensemble files written by studies/ensemble_runs.sh (studies/output/ensembles/group<NN>_N<N>.h5)
and the extras file (studies/output/ensembles/extras.h5); writes studies/output/ensembles/*.png and
studies/output/ensembles/report.md.

Conventions: p* = pbar / sqrt(m0^p), g* = gbar / sqrt(m0^h), d* = d / sqrt(m0^h); A* by node count (3.45)
unless "corrected" (perimeter correction of Yastrebov et al.).
"""

import argparse
import glob
import json
import os
import re
import sys
import time

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
OUT = os.environ.get("ROUGHPETSC_ENSEMBLE_DIR", os.path.join(ROOT, "studies", "output", "ensembles"))
EXTRAS = os.path.join(OUT, "extras.h5")

import roughpetsc.models as M  # noqa: E402
from roughpetsc import ensemble  # noqa: E402

# --- the seed's numbers ---------------------------------------------------------------------------------
SEED_TABLE_7_7 = {1: ((2.7861, 0.2144), (2.3146, 0.2144)), 2: ((5.4853, 0.2787), (3.1357, 0.1854))}
GROUPS_7 = {1: (16, 64, 0.8), 2: (16, 128, 0.8), 3: (16, 256, 0.8), 4: (16, 512, 0.8)}
GROUPS_8 = {18: (16, 64, 0.1), 19: (16, 64, 0.3), 20: (16, 64, 0.5), 21: (16, 64, 0.7), 22: (16, 64, 0.9),
            23: (16, 128, 0.1), 24: (16, 128, 0.3), 25: (16, 128, 0.5), 26: (16, 128, 0.7), 27: (16, 128, 0.9)}
SEED_N_8 = {g: (1024 if g <= 22 else 2048) for g in GROUPS_8}
SEED_ALPHA_H_8_2 = {18: 2.50, 19: 2.60, 20: 2.70, 21: 2.77, 22: 2.81, 23: 3.55, 24: 4.11, 25: 4.68, 26: 5.16, 27: 5.44}
SEED_FIG_3_9_A = (0.0379, 0.4644, 0.7243, 0.8919)      # the contact ratios of Figs. 3.9/3.10
SEED_MEANS_8_4 = {"b": (-1.913, 0.0332), "c": (1.130, 0.0301), "d": (-0.0490, 0.0128)}
TOLERANCE = 0.02                                       # SPEC 4: A* within 0.02 of I f
P_RANGE = (0.05, 4.0)
EARLY_PMAX = 0.2
FIELD_GROUP, FIELD_N, FIELD_INDEX = 1, 512, 0


# ----------------------------------------------------------------------------------------------------------
# Data
# ----------------------------------------------------------------------------------------------------------

class Ens:
    """One ensemble file, with the per-step means the figures need."""

    def __init__(self, path):
        self.path = path
        m = re.match(r"group(\d+)_N(\d+)\.h5$", os.path.basename(path))
        self.group, self.N = int(m.group(1)), int(m.group(2))
        d = ensemble.read(path)
        self.d = d
        self.config = json.loads(d["@config"])
        self.surface = self.config["surface"]
        self.n = int(d["@n_finished"])
        self.size = int(d["@ensemble_size"])
        self.complete = bool(d["@complete"])
        self.p = np.asarray(d["pstar_target"], float)
        steps = lambda k: np.asarray(d["steps/" + k], float).reshape(self.n, self.p.size)  # noqa: E731
        self.A_all, self.Ac_all, self.g_all = steps("A"), steps("A_corrected"), steps("gstar")
        self.pstar_all = steps("pstar")
        self.rms_all = steps("rms_gap_contact") / np.asarray(d["surfaces/sqrt_m0h"], float)[:, None]
        self.kkt = steps("kkt_natural")
        self.load_error = steps("kkt_load_error")
        self.converged = steps("converged").astype(bool)
        self.iterations = steps("iterations")
        self.step_time = steps("time_s")
        self.surface_time = np.asarray(d["surfaces/time_s"], float)
        self.seeds = np.asarray(d["surfaces/seed"], np.int64)
        self.alpha_h_all = np.asarray(d["surfaces/alpha_h"], float)
        self.alpha_p_all = np.asarray(d["surfaces/alpha_p"], float)
        self.runs = json.loads(d["@runs"])
        self.rtol = float(d["@kkt_rtol"])
        self.solver = str(d["@solver"])
        ddof = 1 if self.n > 1 else 0
        self.A, self.A_std = self.A_all.mean(0), self.A_all.std(0, ddof=ddof)
        self.Ac, self.Ac_std = self.Ac_all.mean(0), self.Ac_all.std(0, ddof=ddof)
        self.g, self.g_std = self.g_all.mean(0), self.g_all.std(0, ddof=ddof)
        self.rms = self.rms_all.mean(0)
        self.alpha_h, self.alpha_p = self.alpha_h_all.mean(), self.alpha_p_all.mean()
        self.alpha_h_std = self.alpha_h_all.std(ddof=ddof)
        self.alpha_p_std = self.alpha_p_all.std(ddof=ddof)
        self.fd = None                               # FD bandwidths from extras.h5 (the seed's "Num")

    @property
    def name(self):
        return f"group {self.group} ({self.N}^2, {self.n} surf.)"

    def wall_seconds(self):
        return sum(r.get("seconds", 0.0) for r in self.runs)


def load_ensembles():
    out = {}
    for path in sorted(glob.glob(os.path.join(OUT, "group*_N*.h5"))):
        try:
            e = Ens(path)
        except Exception as error:      # a file being rewritten right now, or an old format
            print(f"skipping {path}: {type(error).__name__}: {error}")
            continue
        if e.n:
            out[(e.group, e.N)] = e
    if os.path.exists(EXTRAS):
        import h5py

        with h5py.File(EXTRAS, "r") as f:
            if "fd_alpha" in f:
                for key in f["fd_alpha"]:
                    m = re.match(r"group(\d+)_N(\d+)$", key)
                    e = out.get((int(m.group(1)), int(m.group(2))))
                    if e is None:
                        continue
                    seeds = f["fd_alpha"][key]["seed"][()]
                    table = dict(zip(seeds.tolist(), zip(f["fd_alpha"][key]["alpha_h"][()],
                                                         f["fd_alpha"][key]["alpha_p"][()])))
                    if all(int(s) in table for s in e.seeds):
                        e.fd = np.array([table[int(s)] for s in e.seeds])
    return out


def preferred(ensembles, group):
    """The ensemble of a group to plot: the one with the seed's grid if present and >= 4 surfaces, else the
    one with the most surfaces (ties: the finer grid)."""
    found = [e for (g, _), e in ensembles.items() if g == group]
    if not found:
        return None
    return max(found, key=lambda e: (e.n, e.N))


# ----------------------------------------------------------------------------------------------------------
# Extras: field pictures (Figs. 3.9/3.10) and FD bandwidths -- single process, run between ensembles
# ----------------------------------------------------------------------------------------------------------

def compute_extras():
    import h5py
    import petsc4py

    petsc4py.init([sys.argv[0]])
    from petsc4py import PETSc

    from roughpetsc import spectra
    from roughpetsc.contact import ContactProblem
    from roughpetsc.control import Solver
    from roughpetsc.surfaces import Grid, fractal

    ensembles = load_ensembles()
    mode = "a" if os.path.exists(EXTRAS) else "w"
    with h5py.File(EXTRAS, mode) as f:
        # FD bandwidths of every surface of every ensemble (the seed's (7.6)/(7.7) "Num")
        fd = f.require_group("fd_alpha")
        for (group, n), e in sorted(ensembles.items()):
            key = f"group{group:02d}_N{n}"
            done = set(fd[key]["seed"][()].tolist()) if key in fd else set()
            todo = [int(s) for s in e.seeds if int(s) not in done]
            if not todo:
                continue
            grid = Grid(n, n)
            s = e.surface
            rows = []
            for seed in todo:
                heights = fractal(grid, s["kl"], s["ks"], s["H"], s["m2"], seed)
                summary = spectra.surface_moment_summary(grid, heights, 1.0)
                rows.append((seed, summary["alpha_h"], summary["alpha_p"]))
            old = [(int(a), float(b), float(c)) for a, b, c in zip(fd[key]["seed"][()], fd[key]["alpha_h"][()],
                                                                   fd[key]["alpha_p"][()])] if key in fd else []
            rows = old + rows
            if key in fd:
                del fd[key]
            g = fd.create_group(key)
            g.create_dataset("seed", data=np.array([r[0] for r in rows], np.int64))
            g.create_dataset("alpha_h", data=np.array([r[1] for r in rows]))
            g.create_dataset("alpha_p", data=np.array([r[2] for r in rows]))
            print(f"FD bandwidths: {key}: {len(todo)} surfaces", flush=True)
        # Field pictures: surface FIELD_INDEX of group 1 at the four contact ratios of Fig. 3.9
        e = ensembles.get((FIELD_GROUP, FIELD_N))
        if e is not None and "fields" not in f:
            row = int(np.nonzero(np.asarray(e.d["surfaces/index"]) == FIELD_INDEX)[0][0])
            A_curve, p_curve = e.A_all[row], e.pstar_all[row]
            targets = np.interp(SEED_FIG_3_9_A, A_curve, p_curve)
            grid = Grid(FIELD_N, FIELD_N)
            s = e.surface
            seed = int(e.seeds[row])
            heights = fractal(grid, s["kl"], s["ks"], s["H"], s["m2"], seed)
            problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF)
            solver = Solver(problem, "load", None, 1e-8)
            g = f.create_group("fields")
            g.attrs.update(group=FIELD_GROUP, N=FIELD_N, index=FIELD_INDEX, seed=seed,
                           sqrt_m0h=float(problem.sqrt_m0h))
            g.create_dataset("heights", data=heights.astype(np.float32))
            for k, pstar in enumerate(targets):
                result = solver.solve(pstar=float(pstar))
                pressure, gap = solver.fields()
                sub = g.create_group(f"step{k}")
                sub.attrs.update(pstar=float(result.pstar), A=float(result.A), gstar=float(result.gstar),
                                 kkt=float(result.kkt.natural), converged=bool(result.converged))
                sub.create_dataset("contact", data=(pressure > 0).astype(np.uint8))
                sub.create_dataset("gap", data=(gap / problem.sqrt_m0h).astype(np.float32))
                print(f"fields: p* = {result.pstar:.4f}  A* = {result.A:.4f}", flush=True)
            solver.destroy()
            problem.destroy()


def read_fields():
    if not os.path.exists(EXTRAS):
        return None
    import h5py

    with h5py.File(EXTRAS, "r") as f:
        if "fields" not in f:
            return None
        g = f["fields"]
        out = {"attrs": dict(g.attrs), "heights": g["heights"][()], "steps": []}
        for k in range(4):
            sub = g[f"step{k}"]
            out["steps"].append({"attrs": dict(sub.attrs), "contact": sub["contact"][()], "gap": sub["gap"][()]})
    return out


# ----------------------------------------------------------------------------------------------------------
# Models on their own grids (seed sec. 7.3), at the ensemble's mean bandwidths
# ----------------------------------------------------------------------------------------------------------

_MODEL_CACHE = {}


def model_curves(e):
    key = (e.group, e.N)
    if key in _MODEL_CACHE:
        return _MODEL_CACHE[key]
    s = e.surface
    d = np.linspace(3.0, -0.6, 289)          # the seed's d* = 3..0 (65 steps), a little beyond to reach p* = 0.2
    early = {}
    for name in M.EARLY_MODELS:
        A, p = M.early(name, d, e.alpha_h)
        early[name] = (p, A, d)
    wide = np.linspace(3.0, -6.0, 361)       # Fig. 7.11/7.12: Greenwood (early) towards complete contact
    A, p = M.early("greenwood", wide, e.alpha_h)
    early["greenwood_wide"] = (p, A, wide)
    p = np.linspace(0.0, 4.0, 161)           # the seed's p* range (65 steps there)
    complete = {name: (p,) + tuple(M.complete(name, p, e.alpha_p, e.alpha_h)) for name in M.COMPLETE_MODELS}
    pp = np.concatenate([np.geomspace(1e-3, 0.2, 120, endpoint=False), np.linspace(0.2, 4.0, 300)])
    persson = (pp, M.persson_area(pp), M.persson_gap(pp, s["kl"], s["ks"], s["H"], s["m2"], 1.0))
    _MODEL_CACHE[key] = out = {"early": early, "complete": complete, "persson": persson}
    return out


LABEL = {"gw": "adapted GW", "nayak_bush": "Nayak-Bush", "greenwood": "Greenwood", "bgt": "BGT",
         "bgt_asymptotic": "asymptotic BGT", "ciavarella": "Ciavarella asympt."}
STYLE = {"gw": ":", "nayak_bush": "-.", "greenwood": "-", "bgt": "--", "bgt_asymptotic": "--", "ciavarella": ":"}


# ----------------------------------------------------------------------------------------------------------
# Plot helpers
# ----------------------------------------------------------------------------------------------------------

def save(fig, name, produced):
    fig.tight_layout(rect=(0, 0, 1, 0.92) if fig._suptitle is not None else (0, 0, 1, 1))
    fig.savefig(os.path.join(OUT, name), dpi=110)
    plt.close(fig)
    produced.append(name)


def bem(ax, e, y, yerr, sel=None, label=None, every=1):
    sel = np.ones(e.p.size, bool) if sel is None else sel
    idx = np.nonzero(sel)[0][::every]
    ax.errorbar(e.p[idx], y[idx], yerr=yerr[idx] if yerr is not None else None, fmt="o", ms=3, color="k",
                ecolor="0.5", capsize=2, label=label or f"BEM mean ± std ({e.n} surf., {e.N}^2)", zorder=5)


def panels(groups, ensembles):
    present = [preferred(ensembles, g) for g in groups]
    present = [e for e in present if e is not None]
    if not present:
        return None, None, []
    fig, axes = plt.subplots(1, len(present), figsize=(5.6 * len(present), 4.3), squeeze=False)
    return fig, axes[0], present


def title(e, fig):
    kl, ks, H = e.surface["kl"], e.surface["ks"], e.surface["H"]
    return f"Fig. {fig}: group #{e.group} (k_l, k_s, H) = ({kl:g}, {ks:g}, {H:g})"


# ----------------------------------------------------------------------------------------------------------
# Figures
# ----------------------------------------------------------------------------------------------------------

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
            ax.set_title(f"({'abcd'[k]}) A* = {100 * sa['A']:.2f}% (seed {100 * SEED_FIG_3_9_A[k]:.2f}%)\n"
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
               "interpolating that surface's ensemble A*(p*) at the seed's four contact ratios:", "",
               "| panel | seed A* | our A* | p* | g* | KKT natural | converged |", "|---|---|---|---|---|---|---|"]
    for k, step in enumerate(fields["steps"]):
        sa = step["attrs"]
        report.append(f"| ({'abcd'[k]}) | {100 * SEED_FIG_3_9_A[k]:.2f}% | {100 * sa['A']:.2f}% | {sa['pstar']:.4f} | "
                      f"{sa['gstar']:.4f} | {sa['kkt']:.1e} | {bool(sa['converged'])} |")
    report.append("")


def fig_7_full(ensembles, produced):
    """Figs. 7.11 (A*), 7.12 (g*), 7.13 (g* and rms gap in contact) over the whole history."""
    for fig_no, groups in (("7.11", (1, 2)), ("7.12", (1, 2)), ("7.13", (1, 2))):
        fig, axes, present = panels(groups, ensembles)
        if fig is None:
            continue
        for ax, e in zip(axes, present):
            mc = model_curves(e)
            if fig_no == "7.11":
                bem(ax, e, e.A, e.A_std, every=2)
                p, A, _ = mc["early"]["greenwood_wide"]
                ok = (p <= 4) & (A <= 1)
                ax.plot(p[ok], A[ok], STYLE["greenwood"], label="Greenwood (early)")
                p = np.linspace(0, np.sqrt(2 / np.pi), 50)
                ax.plot(p, np.sqrt(np.pi / 2) * p, STYLE["bgt_asymptotic"], label="asymptotic BGT (4.35)")
                p, A, _ = mc["complete"]["greenwood"]
                ax.plot(p, np.clip(A, 0, None), "-", label="Greenwood (nearly complete)")
                pp, Ap, _ = mc["persson"]
                ax.plot(pp, Ap, "-", color="tab:brown", label="Persson (5.59)")
                ax.set(ylabel="A*", ylim=(0, 1.05))
            elif fig_no == "7.12":
                bem(ax, e, e.g, e.g_std, every=2)
                for name in ("greenwood_wide", "bgt_asymptotic"):
                    p, _, d = mc["early"][name]
                    ok = (p <= 4) & (p > 1e-3) & (d > 1e-3)
                    name = name.replace("_wide", "")
                    ax.semilogy(p[ok], d[ok], STYLE[name], label=f"{LABEL[name]} (early, g* ~ d*)")
                p, _, g = mc["complete"]["greenwood"]
                ok = g > 0
                ax.semilogy(p[ok], g[ok], "-", label="Greenwood (nearly complete)")
                pp, _, gp = mc["persson"]
                ax.semilogy(pp, gp, "-", color="tab:brown", label="Persson (App. E)")
                ax.set(ylabel="g* = gbar / sqrt(m0^h)", ylim=(1e-4, 5))
            else:
                ax.semilogy(e.p, e.g, "ko-", ms=3, label="mean gap g*")
                ax.semilogy(e.p, e.rms, "s-", ms=3, color="tab:red",
                            label="rms gap in contact / sqrt(m0^h) (3.50)")
                ax.set(ylabel="g*, rms gap in contact (/ sqrt(m0^h))")
            ax.set(xlabel="p*", title=title(e, fig_no))
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=7)
        save(fig, f"fig{fig_no.replace('.', '_')}.png", produced)


def fig_7_early(ensembles, produced):
    """Figs. 7.14/7.15 (A*), 7.16 (kappa), 7.17 (g*) at early contact p* <= 0.2."""
    for fig_no, groups, kind in (("7.14", (1, 2), "A"), ("7.15", (3, 4), "A"), ("7.16", (1, 2), "kappa"),
                                 ("7.17", (1, 2), "g")):
        fig, axes, present = panels(groups, ensembles)
        if fig is None:
            continue
        for ax, e in zip(axes, present):
            mc = model_curves(e)
            sel = e.p <= EARLY_PMAX + 1e-12
            if kind == "A":
                bem(ax, e, e.A, e.A_std, sel)
                ax.plot(e.p[sel], e.Ac[sel], "x", color="tab:gray", ms=4, label="BEM mean, perimeter-corrected")
            elif kind == "g":
                bem(ax, e, e.g, e.g_std, sel)
            else:
                idx = np.nonzero(sel)[0]
                # one-sided at the ends, central inside (the steps of the early stage are uniform)
                ax.plot(e.p[idx], np.gradient(e.A[idx], e.p[idx], edge_order=2), "ko", ms=3,
                        label=f"BEM (mean of {e.n}, finite differences)")
                ax.plot(e.p[idx], np.gradient(e.Ac[idx], e.p[idx], edge_order=2), "x", color="tab:gray", ms=4,
                        label="BEM, perimeter-corrected")
            for name in M.EARLY_MODELS:
                p, A, d = mc["early"][name]
                ok = (p <= EARLY_PMAX) & (p > 0)
                if kind == "A":
                    ax.plot(p[ok], A[ok], STYLE[name], label=LABEL[name])
                elif kind == "g":
                    ax.plot(p[ok], d[ok], STYLE[name], label=f"{LABEL[name]} (d*)")
                else:
                    kappa = np.gradient(A, p)
                    ax.plot(p[ok], kappa[ok], STYLE[name], label=LABEL[name])
            pp, Ap, gp = mc["persson"]
            ok = pp <= EARLY_PMAX
            if kind == "A":
                ax.plot(pp[ok], Ap[ok], "-", color="tab:brown", label="Persson")
                ax.set(ylabel="A*")
            elif kind == "g":
                ax.plot(pp[ok], gp[ok], "-", color="tab:brown", label="Persson")
                ax.set(ylabel="g* (models: d*)")
            else:
                ax.plot(pp[ok], np.gradient(Ap, pp)[ok], "-", color="tab:brown", label="Persson")
                ax.axhline(np.sqrt(np.pi / 2), color="0.6", lw=0.8, ls=":")
                ax.set(ylabel="kappa = dA*/dp*")
            ax.set(xlabel="p*", xlim=(0, EARLY_PMAX), title=title(e, fig_no))
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="lower left" if kind == "kappa" else "best")
        save(fig, f"fig{fig_no.replace('.', '_')}.png", produced)


def fig_7_complete(ensembles, produced):
    """Figs. 7.18/7.19 (1 - A*) and 7.20/7.21 (g*) at nearly complete contact p* in [2, 4]."""
    for fig_no, groups, kind in (("7.18", (1, 2), "A"), ("7.19", (3, 4), "A"), ("7.20", (1, 2), "g"),
                                 ("7.21", (3, 4), "g")):
        fig, axes, present = panels(groups, ensembles)
        if fig is None:
            continue
        for ax, e in zip(axes, present):
            mc = model_curves(e)
            sel = e.p >= 2.0 - 1e-12
            if kind == "A":
                bem(ax, e, 1 - e.A, e.A_std, sel)
                ax.plot(e.p[sel], 1 - e.Ac[sel], "x", color="tab:gray", ms=4, label="BEM, perimeter-corrected")
            else:
                bem(ax, e, e.g, e.g_std, sel)
            for name in M.COMPLETE_MODELS:
                p, A, g = mc["complete"][name]
                ok = p >= 2
                y = 1 - A if kind == "A" else g
                ax.plot(p[ok], y[ok], STYLE[name], label=LABEL[name])
            pp, Ap, gp = mc["persson"]
            ok = pp >= 2
            ax.plot(pp[ok], (1 - Ap if kind == "A" else gp)[ok], "-", color="tab:brown", label="Persson")
            ax.set_yscale("log")
            ax.set(xlabel="p*", ylabel="1 - A*" if kind == "A" else "g*", xlim=(2, 4), title=title(e, fig_no))
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=7)
        save(fig, f"fig{fig_no.replace('.', '_')}.png", produced)


def table_7_7(ensembles, report):
    report += ["## Table 7.7: bandwidth parameters (mean ± std over the surfaces)", "",
               "Ours from the spectral moments of each surface (what `-mode ensemble` stores and what the models "
               "above use) and from the seed's finite differences (7.6)/(7.7) (the seed's \"Num\"); closed forms "
               "(2.25)/(2.59) of the continuous PSD.", "",
               "The seed prints the same std (0.2144) for alpha^h and alpha^p of group 1, probably a copy slip. Our "
               "spectral values agree with the closed forms; the FD values depend on the grid (at 512^2 there are only "
               "8 and 4 nodes per 1/k_s for groups 1 and 2, the seed had 16 and 8), so they exceed the seed's.", "",
               "| group | grid, surfaces | alpha^h ours (spectral) | alpha^h ours (FD) | alpha^h closed form | "
               "alpha^h seed | alpha^p ours (spectral) | alpha^p ours (FD) | alpha^p closed form | alpha^p seed |",
               "|---|---|---|---|---|---|---|---|---|---|"]
    from roughpetsc import spectra

    for group in sorted(GROUPS_7):
        for (g, n), e in sorted(ensembles.items()):
            if g != group:
                continue
            kl, ks, H = GROUPS_7[group]
            ch, cp = spectra.fractal_height_bandwidth(kl, ks, H), spectra.fractal_pressure_bandwidth(kl, ks, H)
            fd_h = fd_p = "—"
            if e.fd is not None:
                ddof = 1 if e.n > 1 else 0
                fd_h = f"{e.fd[:, 0].mean():.4f} ± {e.fd[:, 0].std(ddof=ddof):.4f}"
                fd_p = f"{e.fd[:, 1].mean():.4f} ± {e.fd[:, 1].std(ddof=ddof):.4f}"
            seed_h = seed_p = "—"
            if group in SEED_TABLE_7_7:
                (sh, ssh), (sp, ssp) = SEED_TABLE_7_7[group]
                seed_h, seed_p = f"{sh:.4f} ± {ssh:.4f}", f"{sp:.4f} ± {ssp:.4f}"
            report.append(f"| {group} | {n}^2, {e.n} | {e.alpha_h:.4f} ± {e.alpha_h_std:.4f} | {fd_h} | {ch:.4f} | "
                          f"{seed_h} | {e.alpha_p:.4f} ± {e.alpha_p_std:.4f} | {fd_p} | {cp:.4f} | {seed_p} |")
    report.append("")


def common_steps(ens):
    """p* values present (to 1e-9) in every ensemble of the list, and the index of each in each."""
    p0 = ens[0].p
    keep = [x for x in p0 if all(np.any(np.isclose(e.p, x, rtol=0, atol=1e-9)) for e in ens[1:])]
    p = np.array(keep)
    idx = [np.array([int(np.argmin(np.abs(e.p - x))) for x in p]) for e in ens]
    return p, idx


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
    report += ["", "Seed (Fig. 8.2): the relative dispersion of A* stays at least one order of magnitude below 1 "
               "and is smallest for p* >= 2; Fig. 8.3(b): the dispersion of g* exceeds 1, i.e. g*(p*) does not "
               "collapse.", "",
               "Caveat: at 512^2 groups 23-27 (k_s = 128) have 4 nodes per 1/k_s, groups 18-22 (k_s = 64) have 8, so "
               "part of the spread between the two k_s families is grid bias of node-count A* (see the grid effect "
               "below), not statistics of the surfaces.", ""]


def preferred_n(ensembles, group, n):
    return ensembles.get((group, n))


def seed_curve(p, group, alpha_p):
    b, c, d = M.TABLE_8_4[group]
    return M.curvefit_area(p, alpha_p, b, c, d)


def acceptance(ensembles, produced, report):
    rows, fits = [], []
    for (group, n), e in sorted(ensembles.items()):
        if group not in GROUPS_8:
            continue
        sel = (e.p >= P_RANGE[0] - 1e-12) & (e.p <= P_RANGE[1] + 1e-12)
        p = e.p[sel]
        alphas = {"seed Table 8.3": M.ALPHA_P_TABLE_8_3[group], "ours spectral": e.alpha_p}
        if e.fd is not None:
            alphas["ours FD"] = e.fd[:, 1].mean()
        dev = {}
        for key, ap in alphas.items():
            I_f = seed_curve(p, group, ap)
            diff = e.A[sel] - I_f
            k = int(np.argmax(np.abs(diff)))
            dev[key] = (abs(diff[k]), p[k], diff[k])
            if key == "seed Table 8.3":
                dev["corrected"] = (np.max(np.abs(e.Ac[sel] - I_f)),)
                sem = e.A_std[sel] / np.sqrt(max(e.n, 1))
                dev["sem"] = float(sem.max())
        rows.append((e, dev, alphas))
        b, c, d = M.fit_curvefit(e.p, e.A, e.alpha_p)
        fit_dev = np.max(np.abs(e.A[sel] - M.curvefit_area(p, e.alpha_p, b, c, d)))
        b2, c2, d2 = M.fit_curvefit(e.p, e.A, M.ALPHA_P_TABLE_8_3[group])
        fits.append((e, (b, c, d), fit_dev, (b2, c2, d2)))

    report += ["## Acceptance: mean A*(p*) against the seed's curve fit I(p*) f(p*)", "",
               "I(p*) is the Greenwood nearly-complete model (5.45) (the seed's (8.2)), f(p*) = a exp(b p*) + "
               "c exp(d p*) with Table 8.4's b, c, d and a = -c (SPEC erratum), A* = I f for p* <= 2 and I beyond. "
               f"Deviation = max over our load steps with p* in [{P_RANGE[0]:g}, {P_RANGE[1]:g}] of "
               "|A*_mean - I f|. **Verdict** uses the seed's own curve (I at the seed's alpha^p of Table 8.3 "
               "\"Num\"); the other columns put our own alpha^p into I instead. Tolerance 0.02 (SPEC 4).", "",
               "| group | grid | surfaces | steps in range | max dev. (alpha^p seed) | at p* | signed | verdict | "
               "max dev. (our alpha^p spectral) | max dev. (our alpha^p FD) | perimeter-corrected A* (alpha^p seed) "
               "| max std. error of mean |",
               "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for e, dev, alphas in rows:
        s, sp, sfd = dev["seed Table 8.3"], dev["ours spectral"], dev.get("ours FD")
        steps = int(np.sum((e.p >= P_RANGE[0] - 1e-12) & (e.p <= P_RANGE[1] + 1e-12)))
        verdict = "**PASS**" if s[0] <= TOLERANCE else "**FAIL**"
        report.append(f"| {e.group} | {e.N}^2 | {e.n} | {steps} | {s[0]:.4f} | {s[1]:.3f} | {s[2]:+.4f} | "
                      f"{verdict} | {sp[0]:.4f} (alpha^p {alphas['ours spectral']:.3f}) | "
                      + (f"{sfd[0]:.4f} (alpha^p {alphas['ours FD']:.3f})" if sfd else "—")
                      + f" | {dev['corrected'][0]:.4f} | {dev['sem']:.4f} |")
    report.append("")

    report += ["## Table 8.4 refitted from our BEM means", "",
               "b and d by least squares on our mean A* at the steps with p* <= 2 (`roughpetsc.models.fit_curvefit`: "
               "a = -c and c = 1/(exp(2d) - exp(2b)) built in, as in the seed), I(p*) at our ensemble's mean "
               "alpha^p (spectral). Last columns: the same fit with the seed's alpha^p (Table 8.3).", "",
               "| group | grid | surfaces | b ours | b seed | c ours | c seed | d ours | d seed | max dev. of our fit "
               "(p* in [0.05, 4]) | b, c, d with seed alpha^p |", "|---|---|---|---|---|---|---|---|---|---|---|"]
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
        seed = np.array([M.TABLE_8_4[f[0].group] for f in at512])
        report += ["", f"Column means ± std over our {len(at512)} groups at 512^2 (the seed's over its 10 groups, "
                   "sentence after Table 8.4 with the names corrected: b = -1.913 ± 0.0332, c = 1.130 ± 0.0301, "
                   "d = -0.0490 ± 0.0128; the seed's over the same groups as ours in brackets):", "",
                   "| | b | c | d |", "|---|---|---|---|",
                   "| ours | " + " | ".join(f"{arr[:, j].mean():.3f} ± {arr[:, j].std(ddof=1):.4f}" for j in range(3))
                   + " |",
                   "| seed, same groups | " + " | ".join(f"{seed[:, j].mean():.3f} ± {seed[:, j].std(ddof=1):.4f}"
                                                          for j in range(3)) + " |"]
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
        ax[0].plot(pp, seed_curve(pp, group, M.ALPHA_P_TABLE_8_3[group]), "r-",
                   label=f"seed fit (Table 8.4), alpha^p {M.ALPHA_P_TABLE_8_3[group]:.2f}")
        ax[0].plot(pp, M.curvefit_area(pp, e.alpha_p, *fit), "b--", label=f"our refit, alpha^p {e.alpha_p:.3f}")
        ax[0].set(xlabel="p*", ylabel="A*", title=f"Fig. 8.6(a)-style: group #{group}, {e.N}^2")
        ax[0].legend(fontsize=7)
        kap = np.gradient(e.A, e.p, edge_order=2)
        ax[1].plot(e.p, kap, "ko", ms=3, label="BEM mean (finite differences)")
        ax[1].plot(pp, np.gradient(seed_curve(pp, group, M.ALPHA_P_TABLE_8_3[group]), pp), "r-", label="seed fit")
        ax[1].plot(pp, np.gradient(M.curvefit_area(pp, e.alpha_p, *fit), pp), "b--", label="our refit")
        ax[1].axhline(np.sqrt(np.pi / 2), color="0.5", ls=":", label="sqrt(pi/2) (asymptotic BGT)")
        ax[1].set(xlabel="p*", ylabel="dA*/dp*", title="Fig. 8.6(b)-style: slope")
        ax[1].legend(fontsize=7)
        for a in ax:
            a.grid(alpha=0.3)
        save(fig, f"fig8_6_curvefit_group{group}.png", produced)

    # deviation profiles of every group against the seed's curve
    fig, ax = plt.subplots(figsize=(7, 4.4))
    colors = plt.cm.viridis(np.linspace(0, 1, max(len(rows), 2)))
    for (e, _, _), c in zip(rows, colors):
        sel = (e.p >= P_RANGE[0] - 1e-12) & (e.p <= P_RANGE[1] + 1e-12)
        ax.plot(e.p[sel], e.A[sel] - seed_curve(e.p[sel], e.group, M.ALPHA_P_TABLE_8_3[e.group]), "-o", ms=2,
                color=c, label=f"#{e.group} ({e.N}^2, {e.n})")
    grid = grid_effect(ensembles)
    if grid is not None:
        ax.plot(grid["p"], grid["dev"]["inf"], "k--", lw=1.2, label="#18 extrapolated to h -> 0 (2 A_%d - A_%d)"
                % grid["extrapolation"])
    for y in (-TOLERANCE, TOLERANCE):
        ax.axhline(y, color="r", ls="--", lw=0.8)
    ax.set(xlabel="p*", ylabel="A*_mean - I(p*) f(p*)", title="Acceptance: BEM mean minus the seed's curve fit")
    ax.legend(fontsize=6.5, ncol=2)
    ax.grid(alpha=0.3)
    save(fig, "acceptance_deviation.png", produced)
    if grid is not None:
        report += ["### Grid effect (group 18)", "",
                   "Node-count A* carries a discretisation error of the order of the contact perimeter times the "
                   "node spacing h. Group 18 on each grid it ran on (the seed's is 1024^2), compared at their shared "
                   f"steps ({grid['p'].size} steps in [{P_RANGE[0]:g}, {P_RANGE[1]:g}]); \"extrapolated\" is the "
                   "Richardson estimate 2 A*_fine - A*_coarse of the h -> 0 limit from the two finest grids "
                   "(error assumed proportional to h).", "",
                   "| A* from | max abs(A* - I f) (seed's curve) | at p* | perimeter-corrected |", "|---|---|---|---|"]
        for key, label in grid["labels"]:
            dev, devc = grid["dev"][key], grid["dev_corrected"][key]
            k = int(np.argmax(np.abs(dev)))
            report.append(f"| {label} | {abs(dev[k]):.4f} | {grid['p'][k]:.3f} | {np.max(np.abs(devc)):.4f} |")
        report.append("")
    return rows, fits


def grid_effect(ensembles):
    """Group 18 on every grid it ran on (at least two): deviations from the seed's curve at the shared steps,
    and the Richardson extrapolation 2 A_fine - A_coarse from the two finest grids (error ~ h)."""
    runs = {n: e for (group, n), e in sorted(ensembles.items()) if group == 18}
    if len(runs) < 2:
        return None
    grids = sorted(runs)
    p, indices = common_steps([runs[n] for n in grids])
    sel = (p >= P_RANGE[0] - 1e-12) & (p <= P_RANGE[1] + 1e-12)
    p = p[sel]
    indices = [i[sel] for i in indices]
    I_f = seed_curve(p, 18, M.ALPHA_P_TABLE_8_3[18])
    A = {n: runs[n].A[i] for n, i in zip(grids, indices)}
    Ac = {n: runs[n].Ac[i] for n, i in zip(grids, indices)}
    coarse, fine = grids[-2:]
    A["inf"], Ac["inf"] = 2 * A[fine] - A[coarse], 2 * Ac[fine] - Ac[coarse]
    labels = [(n, f"{n}^2 mean ({runs[n].n} surfaces)") for n in grids] + \
        [("inf", f"extrapolated h -> 0 (2 A_{fine} - A_{coarse})")]
    return {"p": p, "A": A, "dev": {k: v - I_f for k, v in A.items()}, "labels": labels,
            "dev_corrected": {k: v - I_f for k, v in Ac.items()}, "extrapolation": (fine, coarse),
            "alpha_p": float(np.mean([runs[n].alpha_p for n in grids[-2:]]))}


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
               f"residual <= kkt_rtol = {any_e.rtol:g} (SPEC 3.4). Wall times: `mpiexec -n 2`, one surface per "
               "rank, on 2 cores shared with other jobs (so they overstate the cost). Mean s / surface = one "
               "rank's wall time for the whole load path of a surface.", ""]


def differences(ensembles, report):
    report += ["## Differences from the seed, and why", "",
               "- **Grid.** The seed used 1024^2 for groups 1-4 and 18-22 and 2048^2 for 23-27 (16 nodes per shortest "
               "wavelength 1/k_s in groups 18-27). We ran 512^2 for groups 1, 2, 18-27 to fit the time budget: 8 "
               "nodes per 1/k_s for k_s = 64 (groups 1, 18-22), 4 for k_s = 128 (groups 2, 23-27). Node-count A* "
               "overestimates the contact ratio on coarse grids (every boundary node with p > 0 counts as a whole "
               "node), most at light load; the perimeter-corrected A* is shown beside it. Group 3 (k_s = 256) ran "
               "at 1024^2 (4 nodes per 1/k_s). Group 4 (k_s = 512) would need k_s <= Nyquist/2, i.e. 2048^2; "
               "not run unless a group-4 file is listed above. Group 18 also ran on the seed's 1024^2 (4 surfaces) "
               "and on 2048^2 (6 surfaces), groups 22, 23 and 27 on 2048^2 (2 surfaces each; the seed's grid for "
               "23 and 27), to measure the grid effect.",
               "- **Surfaces per group.** The seed: 50 per group. Ours: see the table above.",
               "- **Load steps.** Groups 1-3 and 18 follow the 95-step history (7.11) with Delta_1 = 0.2/30 (SPEC "
               "erratum; the printed 0.067 contradicts n1 = 30 steps over (0, 0.2]). Groups 19-27 used 33 of those "
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
               "- **Convergence criterion.** The seed stopped on its composite criterion (3.47)-(3.49), (3.51); we "
               "stop on the scale-free natural KKT residual (SPEC 3.4) and check it after every solve.",
               "- **Bandwidths.** The models here use our ensemble's mean alpha^h, alpha^p from the spectral moments. "
               "The seed's \"Num\" values come from finite differences (7.6)/(7.7); both are in Table 7.7 above. "
               "The acceptance verdict uses the seed's alpha^p (Table 8.3) in I(p*), i.e. exactly the seed's curve.",
               "- **Curve fit.** Fitted with scipy least squares (`fit_curvefit`) instead of MATLAB's toolbox, with "
               "the seed's two constraints built in; the range of the fit is our steps with p* <= 2.",
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

    head = ["# BEM ensembles against the seed (issue 6, item 5)", "",
            "Generated by `studies/ensemble_figures.py` from the ensemble files of `studies/ensemble_runs.sh` "
            "(HDF5 under studies/output/ensembles/, not committed). Conventions: p* = pbar / sqrt(m0^p), "
            "g* = gbar / sqrt(m0^h), d* = d / sqrt(m0^h); A* by node count (3.45) unless marked perimeter-corrected; "
            "std with ddof = 1.", ""]
    summary = ["## Summary", ""]
    for e, dev, _ in rows:
        s = dev["seed Table 8.3"]
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
                           f"{arr[:, 2].mean():.4f} (means over {len(arr)} groups) vs the seed's -1.913, 1.130, "
                           "-0.049: our BEM rises faster at small p* (initial slope ~1.3 vs the seed fit's ~1.07), "
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
