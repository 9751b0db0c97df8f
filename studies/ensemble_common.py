"""What the ensemble figures share: the files (studies/output/ensembles), the dissertation's numbers, plot helpers.

Each ensemble file is read with roughpetsc's readers: its surfaces and steps, and the statistics and models
it stores (/statistics, /models; :class:`Ens`). The field pictures of Figs. 3.9/3.10 (``--extras``) are
the one thing solved here, into extras.h5.
"""

import glob
import json
import os
import re
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import roughpetsc.models as M  # noqa: E402
from roughpetsc import ensemble  # noqa: E402
from roughpetsc.app.presets import fractal_group, fractal_groups  # noqa: E402
from roughpetsc.store.ensemble_file import stored_config  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the repository
OUT = os.environ.get("ROUGHPETSC_ENSEMBLE_DIR", os.path.join(ROOT, "studies", "output", "ensembles"))
EXTRAS = os.path.join(OUT, "extras.h5")

# --- the dissertation's numbers ----------------------------------------------------------------------
DISSERTATION_TABLE_7_7 = {1: ((2.7861, 0.2144), (2.3146, 0.2144)), 2: ((5.4853, 0.2787), (3.1357, 0.1854))}


def group_table(numbers):
    """``{group: (k_l, k_s, H)}`` of the surface groups ``numbers``, as options/groupNN.opts type them."""
    groups = fractal_groups()
    return {number: (groups[number]["k_l"], groups[number]["k_s"], groups[number]["hurst"]) for number in numbers}


GROUPS_7 = group_table(range(1, 5))      # the ensembles of chapter 7 (Table 7.1)
GROUPS_8 = group_table(range(18, 28))    # the ensembles of chapter 8 (Table 8.1): the dissertation's 10 groups
# Ours, beyond the dissertation's alpha^p < 3 (options/group28.opts ... group30.opts; issue 14, item 4)
OUR_GROUPS_8 = group_table([number for number in range(28, 31) if number in fractal_groups()])
# The column means of Table 8.4 the dissertation prints after it (names corrected): b, c, d
DISSERTATION_TABLE_8_4_MEANS = (-1.913, 1.130, -0.049)
DISSERTATION_FIG_3_9_A = (0.0379, 0.4644, 0.7243, 0.8919)      # the contact ratios of Figs. 3.9/3.10
TOLERANCE = 0.005    # the acceptance target of SPEC section 4: mean A* within 0.005 of I f, I = (5.37) + (2.42)
P_RANGE = (0.05, 4.0)
EARLY_PMAX = ensemble.EARLY_PMAX                       # the early-contact stage the store's models cover
FIELD_GROUP, FIELD_N, FIELD_INDEX = 1, 1024, 0    # the chapter 7 ensemble of group #1


# ----------------------------------------------------------------------------------------------------------
# Data
# ----------------------------------------------------------------------------------------------------------

class Ens:
    """One ensemble file: its surfaces and steps, and the statistics and models it stores.

    The means, standard deviations (ddof = 1), bandwidths, kappa = dA*/dp* and the model curves are
    read from ``/statistics`` and ``/models`` (``roughpetsc.ensemble.stored_statistics`` and
    ``stored_models``, which complete an older or unfinished file and say so).
    """

    def __init__(self, path):
        self.path = path
        m = re.match(r"group(\d+)_N(\d+)\.h5$", os.path.basename(path))
        self.group, self.N = int(m.group(1)), int(m.group(2))
        d = ensemble.read(path)
        self.d = d
        self.config = stored_config(d["@config"], d.get("@options"))
        self.surface = self.config["surface"]
        self.n = int(d["@n_finished"])
        self.size = int(d["@ensemble_size"])
        self.complete = bool(d["@complete"])
        self.p = np.asarray(d["pstar_target"], float)
        steps = lambda k: np.asarray(d["steps/" + k], float).reshape(self.n, self.p.size)  # noqa: E731
        self.A_all, self.pstar_all, self.g_all = steps("A"), steps("pstar"), steps("gstar")
        self.kkt = steps("kkt_natural")
        self.load_error = steps("kkt_load_error")
        self.converged = steps("converged").astype(bool)
        self.surface_time = np.asarray(d["surfaces/time_s"], float)
        self.seeds = np.asarray(d["surfaces/seed"], np.int64)
        self.runs = json.loads(d["@runs"])
        self.rtol = float(d["@kkt_rtol"])
        self.solver = str(d["@solver"])
        say = lambda text: print(f"{os.path.basename(path)}: {text}")  # noqa: E731
        self.statistics = s = ensemble.stored_statistics(d, say) if self.n else {}
        self.models = ensemble.stored_models(d, s, say) if self.n else {}
        if not self.n:
            return
        self.A, self.A_std = s["A_mean"], s["A_std"]
        self.Ac, self.Ac_std = s["A_corrected_mean"], s["A_corrected_std"]
        self.g, self.g_std = s["gstar_mean"], s["gstar_std"]
        self.rms = s["rms_gap_star_mean"]
        self.alpha_h, self.alpha_h_std = float(s["alpha_h_mean"]), float(s["alpha_h_std"])
        self.alpha_p, self.alpha_p_std = float(s["alpha_p_mean"]), float(s["alpha_p_std"])
        # Finite-difference bandwidths (7.6)/(7.7), the dissertation's "Num": files of format 2 on.
        self.fd = None
        if "alpha_h_fd_mean" in s:
            self.fd = {"h": (float(s["alpha_h_fd_mean"]), float(s["alpha_h_fd_std"])),
                       "p": (float(s["alpha_p_fd_mean"]), float(s["alpha_p_fd_std"]))}

    @property
    def name(self):
        return f"group {self.group} ({self.N}^2, {self.n} surf.)"

    def wall_seconds(self):
        return sum(r.get("seconds", 0.0) for r in self.runs)

    def rank_hours(self):
        """Rank-hours of the finished surfaces: each one's recorded time times the ranks that solved it."""
        ranks = {int(r["run"]): int(r.get("group_ranks", 1)) for r in self.runs}
        run = np.asarray(self.d["surfaces/run"], int)
        return float(sum(t * ranks.get(int(k), 1) for t, k in zip(self.surface_time, run))) / 3600.0

    def model(self, family, name, key):
        """A stored model curve at the steps (``family`` early | complete | persson), or None if not stored."""
        curves = self.models.get(family, {})
        curves = curves if family == "persson" else curves.get(name, {})
        return curves.get(key)


def load_ensembles():
    out = {}
    for path in sorted(glob.glob(os.path.join(OUT, "group*_N*.h5"))):
        try:
            e = Ens(path)
        except Exception as error:      # a file being rewritten right now, or not an ensemble file
            print(f"skipping {path}: {type(error).__name__}: {error}")
            continue
        if e.n:
            out[(e.group, e.N)] = e
    return out


def preferred(ensembles, group):
    """The ensemble of a group to plot: the one with the most surfaces (ties: the finer grid), or None."""
    found = [e for (g, _), e in ensembles.items() if g == group]
    if not found:
        return None
    return max(found, key=lambda e: (e.n, e.N))


# ----------------------------------------------------------------------------------------------------------
# Extras: field pictures (Figs. 3.9/3.10) -- single process, run between ensembles
# ----------------------------------------------------------------------------------------------------------

def compute_extras():
    """Solve surface FIELD_INDEX of group FIELD_GROUP at the four contact ratios of Fig. 3.9 (into extras.h5).

    The surface is rebuilt from the white-noise seed its ensemble file records (the pressure and gap fields are not
    kept in an ensemble file); everything else the figures need is in the ensemble files.
    """
    import h5py
    import petsc4py

    petsc4py.init([sys.argv[0]])
    from petsc4py import PETSc

    from roughpetsc.contact.problem import ContactProblem
    from roughpetsc.solvers.facade import Solver
    from roughpetsc.surface.grid import Grid
    from roughpetsc.surface.generators import fractal

    ensembles = load_ensembles()
    mode = "a" if os.path.exists(EXTRAS) else "w"
    with h5py.File(EXTRAS, mode) as f:
        e = ensembles.get((FIELD_GROUP, FIELD_N))
        if e is not None and "fields" not in f:
            row = int(np.nonzero(np.asarray(e.d["surfaces/index"]) == FIELD_INDEX)[0][0])
            A_curve, p_curve = e.A_all[row], e.pstar_all[row]
            targets = np.interp(DISSERTATION_FIG_3_9_A, A_curve, p_curve)
            grid = Grid(FIELD_N, FIELD_N)
            s = e.surface
            seed = int(e.seeds[row])
            heights = fractal(grid, s["kl"], s["ks"], s["H"], s["m2"], seed, s["generator"])
            problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF)
            recorded = float(np.asarray(e.d["surfaces/sqrt_m0h"])[row])
            if not np.isclose(problem.sqrt_m0h, recorded, rtol=1e-10, atol=0):
                raise RuntimeError(f"surface {FIELD_INDEX} of {e.path} rebuilt from seed {seed} has sqrt(m0^h) "
                                   f"{problem.sqrt_m0h:.12g}, the file records {recorded:.12g}: not the same surface")
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
# Models: the curves the ensemble file stores at its load steps (roughpetsc.ensemble.statistics)
# ----------------------------------------------------------------------------------------------------------

def early_curve(e, name, key, sel):
    """An early-contact model (ch. 4) at the steps of ``sel`` with p* <= 0.2 where it is defined: (p*, values)."""
    values = e.model("early", name, key)
    if values is None:
        return np.array([]), np.array([])
    ok = sel & np.isfinite(values)
    return e.p[ok], values[ok]


LABEL = {"gw": "adapted GW", "nayak_bush": "Nayak-Bush", "greenwood": "Greenwood", "bgt": "BGT",
         "bgt_asymptotic": "asymptotic BGT", "ciavarella": "Ciavarella asympt."}
STYLE = {"gw": ":", "nayak_bush": "-.", "greenwood": "-", "bgt": "--", "bgt_asymptotic": "--", "ciavarella": ":"}


# ----------------------------------------------------------------------------------------------------------
# Plot helpers
# ----------------------------------------------------------------------------------------------------------

def save(fig, name, produced):
    # A suptitle is the one figure-level text these figures have (matplotlib 3.6 has no get_suptitle).
    fig.tight_layout(rect=(0, 0, 1, 0.92) if fig.texts else (0, 0, 1, 1))
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


def panel_figures(table, ensembles, produced):
    """For each ``(fig_no, groups[, kind])`` of ``table``: one figure, a panel per group present.

    Yields ``(fig_no, kind, ax, e)`` for every panel to draw; saves each figure once its panels are drawn.
    """
    for fig_no, groups, *kind in table:
        fig, axes, present = panels(groups, ensembles)
        if fig is None:
            continue
        for ax, e in zip(axes, present):
            yield fig_no, (kind[0] if kind else None), ax, e
        save(fig, f"fig{fig_no.replace('.', '_')}.png", produced)


def title(e, fig):
    kl, ks, H = e.surface["kl"], e.surface["ks"], e.surface["H"]
    return f"Fig. {fig}: group #{e.group} (k_l, k_s, H) = ({kl:g}, {ks:g}, {H:g})"


def common_steps(ens):
    """p* values present (to 1e-9) in every ensemble of the list, and the index of each in each."""
    p0 = ens[0].p
    keep = [x for x in p0 if all(np.any(np.isclose(e.p, x, rtol=0, atol=1e-9)) for e in ens[1:])]
    p = np.array(keep)
    idx = [np.array([int(np.argmin(np.abs(e.p - x))) for x in p]) for e in ens]
    return p, idx


def preferred_n(ensembles, group, n):
    """The ensemble of a group on the n x n grid, or None."""
    return ensembles.get((group, n))


def preset_grid(group):
    """The grid (nodes per side) options/groupNN.opts names for a group: the dissertation's, for its groups; or None."""
    try:
        return fractal_group(group)["n"]
    except ValueError:
        return None


def dissertation_grid(ensembles, group):
    """The ensemble of a group on the grid its preset names (:func:`preset_grid`) if present, else the one with the
    most surfaces (ties: the finer grid), else None."""
    found = {n: e for (g, n), e in ensembles.items() if g == group}
    if not found:
        return None
    n = preset_grid(group)
    if n in found:
        return found[n]
    return max(found.values(), key=lambda e: (e.n, e.N))


def nodes_per_wavelength(e):
    """Nodes per shortest wavelength 1/k_s of an ensemble's surfaces."""
    return e.N / (e.surface["ks"] * e.surface.get("L", 1.0))


def describe(ens):
    """``#18: 1024^2, 50 surfaces; ...`` of a list of ensembles, an unfinished one marked with its planned size, one off
    the grid of its preset (options/groupNN.opts) with that grid."""
    out = []
    for e in ens:
        text = f"#{e.group}: {e.N}^2, {e.n}" + ("" if e.complete else f" of {e.size}") + " surfaces"
        n = preset_grid(e.group)
        if n is not None and n != e.N:
            text += f" (not its preset's {n}^2)"
        out.append(text)
    return "; ".join(out)


def dissertation_curve(p, group, alpha_p, model=M.CURVEFIT_MODEL):
    """The dissertation's curve fit I(p*) f(p*) (8.2)-(8.3) of a group of Table 8.4 at bandwidth alpha_p; a group not
    in Table 8.4 (ours, 28-30) gets the column means the dissertation prints after it. I is the adapted GW model
    (5.37) with (2.42), whose curve Table 8.4 is (studies/output/table_8_4), unless ``model`` names another."""
    b, c, d = M.TABLE_8_4.get(group, DISSERTATION_TABLE_8_4_MEANS)
    return M.curvefit_area(p, alpha_p, b, c, d, model=model)


def grid_effects(ensembles, p_range=P_RANGE):
    """{group: effect} for every group run on at least two grids: its mean A* on each grid at the shared steps with
    p* in ``p_range``, deviations from the dissertation's curve I f, and the Richardson value 2 A_fine - A_coarse from
    the two finest grids (node-count and corrected A* converge at first order in h: studies/output/grid_convergence),
    with the standard error of that value from the surfaces of both grids (independent surfaces: the white noise
    of the generator is drawn per grid)."""
    return {group: effect for group in sorted({g for g, _ in ensembles})
            if (effect := grid_effect(ensembles, group, p_range)) is not None}


def grid_effect(ensembles, group, p_range=P_RANGE):
    """The grid effect of one group (:func:`grid_effects`), or None if it ran on fewer than two grids."""
    runs = {n: e for (g, n), e in sorted(ensembles.items()) if g == group}
    if len(runs) < 2:
        return None
    grids = sorted(runs)
    p, indices = common_steps([runs[n] for n in grids])
    sel = (p >= p_range[0] - 1e-12) & (p <= p_range[1] + 1e-12)
    p = p[sel]
    indices = [i[sel] for i in indices]
    coarse, fine = grids[-2:]
    alpha_p = float(np.mean([runs[n].alpha_p for n in (coarse, fine)]))
    I_f = dissertation_curve(p, group, M.ALPHA_P_TABLE_8_3.get(group, alpha_p))
    A = {n: runs[n].A[i] for n, i in zip(grids, indices)}
    Ac = {n: runs[n].Ac[i] for n, i in zip(grids, indices)}
    A["inf"], Ac["inf"] = 2 * A[fine] - A[coarse], 2 * Ac[fine] - Ac[coarse]
    at = dict(zip(grids, indices))

    def error(std):
        return np.sqrt(4 * std(runs[fine])[at[fine]] ** 2 / runs[fine].n
                       + std(runs[coarse])[at[coarse]] ** 2 / runs[coarse].n)

    labels = [(n, f"{n}^2 mean ({runs[n].n} surfaces)") for n in grids] + \
        [("inf", f"extrapolated h -> 0 (2 A_{fine} - A_{coarse})")]
    return {"group": group, "p": p, "A": A, "A_corrected": Ac, "dev": {k: v - I_f for k, v in A.items()},
            "labels": labels, "dev_corrected": {k: v - I_f for k, v in Ac.items()}, "extrapolation": (fine, coarse),
            "error": error(lambda e: e.A_std), "error_corrected": error(lambda e: e.Ac_std), "alpha_p": alpha_p,
            "runs": runs, "steps": at}
