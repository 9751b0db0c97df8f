"""The report of ``adhesion_rough_cycles.py``: grid convergence, BEM against the adhesive GW model, pull-off and
hysteresis (issue 36, item 4 (c)-(d)).

    .venv/bin/python studies/adhesion_rough_cycles.py --report

Reads every case file of studies/output/adhesion/rough/ and writes studies/output/adhesion/rough_cycles.md with
rough_cycles_paths.png and rough_cycles_grid.png. The report opens with the campaign's status: the cells of the
plan of studies/adhesion_rough_runs.sh (``PLAN`` here) that have case files, the case a checkpoint holds, the
command that resumes the rest and its cost estimated from the CPU times the case files record; a campaign that is
not complete is called partial there, and the reading of the model's errors is stated as provisional on the
counts of surfaces and grids behind it.

Definitions (g* = gbar / sqrt(m0^h), p* = pbar / sqrt(m0^p), both exact on every grid: the moments of a
band-limited surface do not depend on N):

* At a fixed g* (the prescribed quantity, the same gaps on every grid): p* and 1 - A* of the approach.
* At a fixed p*: the first passage of the approach through p* (and of the retraction, downwards), log-linear
  interpolation of g* and 1 - A* between the two steps around it. The approach's p*(g*) is not monotone
  (a crack that snaps shut at a fixed mean gap hands its volume to the others, which open at a lower
  p*), so the first passage is what defines "the" state at a p*.
* Model: ``AdhesiveGW`` with the surface's own moments and the run's z0, loading at the p*, unloading from
  the p* the BEM turned at. Relative error (model - BEM) / BEM.
* Pull-off: the least p* of the retraction (partial protocol: within g* <= 0.6; flagged when that least
  value is the last step, i.e. the true one may lie beyond).
* Hysteresis over p* >= p*_lo (the model's range, nearly complete contact): the loop area int g* dp* along
  the path from the approach's first passage through p*_lo to the retraction's one, the quantity
  ``AdhesiveGW.dissipated_energy(p*max, p*_lo)`` gives for the model (units sqrt(m0^h) sqrt(m0^p)). The
  full protocol's -closed integral p* dg* over the whole cycle is listed beside it where run.
* Error bars: the standard deviation over the surfaces (sd) and the standard error of the mean (se).
"""

import glob
import math
import os

import numpy as np

import common
from adhesion_rough_cycles import OUT, read_rows
from grid_convergence import richardson

REPORT = os.path.join(common.OUTPUT, "adhesion", "rough_cycles.md")
RESUME = "bash studies/adhesion_rough_runs.sh > rough_runs.log 2>&1 &"
SEEDS = tuple(range(1, 11))
PLANNED_FINEST = 1024  # the finest grid of PLAN; finer case files (the n2048 stage) are reported apart
# The campaign of studies/adhesion_rough_runs.sh, stage by stage in its order: (stage, protocol, N, ratios, seeds).
PLAN = (("n512", "partial", 512, (100, 50, 20), SEEDS),
        ("n1024_r100_a", "partial", 1024, (100,), (1, 2, 3, 4, 5)),
        ("n1024_r50_20", "partial", 1024, (50, 20), (1, 2, 3)),
        ("full_512", "full", 512, (100, 50), SEEDS),
        ("n1024_r100_b", "partial", 1024, (100,), (6, 7, 8, 9, 10)),
        ("n1024_rest", "partial", 1024, (50, 20), (4, 5, 6, 7, 8, 9, 10)))
# The stages after the plan (issue 36, item 4 (c)-(d)): the full cycles' second grid, the partial cycles' third.
EXTENSION = (("full_1024", "full", 1024, (100, 50), SEEDS),
             ("n2048", "partial", 2048, (100, 50, 20), SEEDS))
PSTARS = (0.5, 1.0, 1.5, 2.0)
UNLOAD_PSTARS = (1.5, 1.0, 0.5)
P_LO = 0.5


class Case:
    """One case file: its rows as arrays, its attributes, and the approach/retraction split."""

    def __init__(self, path):
        rows, self.attrs, _ = read_rows(path)
        self.rows = rows
        for field in ("gstar", "pstar", "non_contact", "open_nodes", "clusters", "stage", "converged", "natural",
                      "applications", "seconds"):
            setattr(self, field, np.array([r[field] for r in rows]))
        self.turn = int(self.attrs["turn"])
        self.n, self.ratio, self.seed = int(self.attrs["n"]), float(self.attrs["ratio"]), int(self.attrs["seed"])
        self.protocol = str(self.attrs.get("protocol", "partial"))

    def part(self, stage):
        keep = slice(0, self.turn + 1) if stage > 0 else slice(self.turn, None)
        return self.gstar[keep], self.pstar[keep], self.non_contact[keep], self.open_nodes[keep]

    def model(self, crack_law="maugis-dugdale"):
        from roughpetsc.models.adhesion import AdhesiveGW

        a = self.attrs
        return AdhesiveGW(a["m0h"], a["m2h"], a["m4h"], a["m6h"], 1.0 / self.ratio,
                          a["z0_over_rms"] * math.sqrt(a["m0h"]), crack_law=crack_law)


def load_cases():
    return [Case(p) for p in sorted(glob.glob(os.path.join(OUT, "*.h5")))]


def first_passage(gstar, pstar, values, target, upward):
    """Interpolated (g*, each of values) where p* first passes ``target`` (upward or downward); None if never."""
    crossed = pstar >= target if upward else pstar <= target
    if not crossed.any():
        return None
    k = int(np.argmax(crossed))
    if k == 0:
        return None
    t = (target - pstar[k - 1]) / (pstar[k] - pstar[k - 1])

    def interpolate(v):
        a, b = v[k - 1], v[k]
        return math.exp((1 - t) * math.log(a) + t * math.log(b)) if a > 0 and b > 0 else (1 - t) * a + t * b

    return [interpolate(gstar)] + [interpolate(v) for v in values]


def loop_area(case, p_lo):
    """int g* dp* from the approach's first passage through p_lo to the retraction's (None if either is missing)."""
    g_a, p_a = case.part(+1)[:2]
    g_r, p_r = case.part(-1)[:2]
    start, end = first_passage(g_a, p_a, [], p_lo, True), first_passage(g_r, p_r, [], p_lo, False)
    if start is None or end is None:
        return None
    k_a = int(np.argmax(p_a >= p_lo))
    k_r = int(np.argmax(p_r <= p_lo))
    g = np.concatenate([[start[0]], g_a[k_a:], g_r[1:k_r], [end[0]]])
    p = np.concatenate([[p_lo], p_a[k_a:], p_r[1:k_r], [p_lo]])
    return float(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(p)))


def mean_sd_se(values):
    v = np.array([x for x in values if x is not None and np.isfinite(x)])
    if v.size == 0:
        return float("nan"), float("nan"), float("nan"), 0
    sd = float(v.std(ddof=1)) if v.size > 1 else float("nan")
    return float(v.mean()), sd, sd / math.sqrt(v.size) if v.size > 1 else float("nan"), int(v.size)


def spread(stats, spec, spread_spec, with_se=False):
    """``mean ± sd (se)`` of :func:`mean_sd_se`'s ``stats`` in the given formats; the mean alone for one surface."""
    mean, sd, se, _ = stats
    if not np.isfinite(sd):
        return f"{mean:{spec}}"
    return f"{mean:{spec}} ± {sd:{spread_spec}}" + (f" ({se:{spread_spec}})" if with_se else "")


def fmt(mean, sd=None, digits=3):
    if not np.isfinite(mean):
        return "-"
    return f"{mean:.{digits}g}" if sd is None or not np.isfinite(sd) else f"{mean:.{digits}g} ± {sd:.2g}"


def groups(cases, protocol="partial"):
    """{(ratio, n): [cases]} of one protocol."""
    out = {}
    for c in cases:
        if c.protocol == protocol:
            out.setdefault((c.ratio, c.n), []).append(c)
    return dict(sorted(out.items()))


def third_grid(every_grid, planned_sizes):
    """The grid sequence on the surfaces also run on a grid finer than the plan's (2048^2), at fixed approach g*."""
    lines = []
    for ratio, n in every_grid:
        if n in planned_sizes:
            continue
        sizes = [m for m in planned_sizes if (ratio, m) in every_grid] + [n]
        rows, count = convergence_at_gaps(every_grid, ratio, sizes)
        if not rows:
            continue
        planned = min(len(every_grid[(ratio, m)]) for m in sizes[:-1])
        scope = (f"As above, on all {count} surfaces of the coarser grids: the sequence is complete at this ratio."
                 if count >= planned else
                 f"As above, on these surfaces only (a subset of the {planned}: not yet the order of convergence).")
        lines += [f"### The third grid: sigma0/E* = 1/{ratio:g}, the {count} surface{'s' if count != 1 else ''} "
                  f"run on {n}^2", "", scope, "",
                  common.markdown_table(["g*"] + [f"p* N={m}" for m in sizes] + ["change"]
                                        + [f"1-A* N={m}" for m in sizes] + ["change"], rows), ""]
    return lines


def convergence_at_gaps(grouped, ratio, sizes):
    """Rows: at fixed approach g*, mean p* and 1 - A* per N (the seeds every N has)."""
    seeds = set.intersection(*(set(c.seed for c in grouped[(ratio, n)]) for n in sizes))
    if not seeds:
        return [], 0
    finest = [c for c in grouped[(ratio, sizes[-1])] if c.seed in seeds]
    rows = []
    for target in PSTARS:
        passage = [first_passage(*c.part(+1)[:2], [], target, True) for c in finest]
        gaps = [p[0] for p in passage if p is not None]
        if not gaps:
            continue
        # the path's g* nearest the finest grid's mean first passage, on every grid the same prescribed gap
        path = finest[0].gstar[:finest[0].turn + 1]
        g = float(path[np.argmin(np.abs(np.log(path) - np.log(np.mean(gaps))))])
        row = [f"{g:.3g}"]
        for field in ("pstar", "non_contact"):
            means = []
            for n in sizes:
                values = []
                for c in grouped[(ratio, n)]:
                    hit = np.flatnonzero(np.isclose(c.gstar[:c.turn + 1], g, rtol=1e-9))
                    if c.seed in seeds and hit.size:
                        values.append(getattr(c, field)[hit[0]])
                m, sd, se, count = mean_sd_se(values)
                means.append(m)
                row.append(fmt(m, se, 4))
            row.append(change(means))
        rows.append(row)
    return rows, len(seeds)


def change(means):
    """Relative changes between successive grids, e.g. '+12% / -3%'."""
    parts = [f"{(b - a) / a:+.0%}" if np.isfinite(a) and np.isfinite(b) and a else "-"
             for a, b in zip(means, means[1:])]
    return " / ".join(parts)


def states_at_p(case, target, stage):
    """(g*, 1 - A*, non-contact nodes) of the BEM at the first passage through p* = target."""
    g, p, a, nodes = case.part(stage)
    return first_passage(g, p, [a, nodes.astype(float)], target, stage > 0)


def model_errors(grouped, ratio, n, numbers=None):
    """Rows (stage, p*): BEM and model means and the relative errors of 1 - A* and g*. ``numbers``, if given,
    receives {(stage, p*): (mean rel. error 1 - A*, mean rel. error g*, surfaces)}."""
    rows = []
    cases = grouped[(ratio, n)]
    models = {c.seed: c.model() for c in cases}
    for stage, targets in ((+1, PSTARS), (-1, UNLOAD_PSTARS)):
        for target in targets:
            bem, model_a, model_g, err_a, err_g, nodes = [], [], [], [], [], []
            for c in cases:
                state = states_at_p(c, target, stage)
                if state is None:
                    continue
                model = models[c.seed]
                if stage > 0:
                    A, g = model.loading([target])
                else:
                    A, g = model.unloading([target], c.pstar[c.turn])
                bem.append(state)
                model_a.append(1 - A[0])
                model_g.append(g[0])
                err_a.append((1 - A[0] - state[1]) / state[1])
                err_g.append((g[0] - state[0]) / state[0])
                nodes.append(state[2])
            if not bem:
                continue
            b = np.array(bem)
            ea, eg = mean_sd_se(err_a), mean_sd_se(err_g)
            if numbers is not None:
                numbers[(stage, target)] = (ea[0], eg[0], len(bem))
            rows.append(["approach" if stage > 0 else "retraction", f"{target:g}", len(bem), f"{np.mean(nodes):.0f}",
                         fmt(b[:, 1].mean()), fmt(np.mean(model_a)), fmt(ea[0], ea[1], 2),
                         fmt(b[:, 0].mean()), fmt(np.mean(model_g)), fmt(eg[0], eg[1], 2),
                         f"{np.max(np.abs(err_a)):.2f}", f"{np.max(np.abs(err_g)):.2f}"])
    return rows


def extrapolated_errors(grouped, ratio, coarse, fine):
    """Rows (stage, p*): the paired surfaces' BEM values at N = coarse and fine, the first-order extrapolation
    2 Q_fine - Q_coarse (the order measured for under-resolved cohesive zones: verdict.md), and the model's
    relative error against the fine grid and against the extrapolation (mean ± sd over the surfaces)."""
    pairs = [(c, f) for c in grouped[(ratio, coarse)] for f in grouped[(ratio, fine)] if c.seed == f.seed]
    rows = []
    for stage, targets in ((+1, PSTARS), (-1, UNLOAD_PSTARS)):
        for target in targets:
            values = []
            for c, f in pairs:
                sc, sf = states_at_p(c, target, stage), states_at_p(f, target, stage)
                if sc is None or sf is None:
                    continue
                model = f.model()
                A, g = model.loading([target]) if stage > 0 else model.unloading([target], f.pstar[f.turn])
                values.append([sc[1], sf[1], 2 * sf[1] - sc[1], 1 - A[0], sc[0], sf[0], 2 * sf[0] - sc[0], g[0]])
            if not values:
                continue
            v = np.array(values)
            row = ["approach" if stage > 0 else "retraction", f"{target:g}", len(v)]
            for base in (0, 4):
                coarse_v, fine_v, extrapolated, model_v = v[:, base], v[:, base + 1], v[:, base + 2], v[:, base + 3]
                row += [fmt(coarse_v.mean()), fmt(fine_v.mean()), fmt(extrapolated.mean()),
                        fmt(*mean_sd_se((fine_v - coarse_v) / fine_v)[:2], 2),
                        fmt(*mean_sd_se((model_v - fine_v) / fine_v)[:2], 2),
                        fmt(*mean_sd_se((model_v - extrapolated) / extrapolated)[:2], 2)]
            rows.append(row)
    return rows


def surfaces_on_every_grid(every_grid, ratio, sizes):
    """[{n: case}] of the surfaces run at ``ratio`` on every grid of ``sizes``, by seed."""
    by_seed = {}
    for n in sizes:
        for c in every_grid.get((ratio, n), []):
            by_seed.setdefault(c.seed, {})[n] = c
    return [cases_ for _, cases_ in sorted(by_seed.items()) if len(cases_) == len(sizes)]


def three_grid_errors(every_grid, ratio, sizes=(512, 1024, 2048)):
    """Rows (quantity, stage, p*) on the surfaces run on all three grids ``sizes``: the BEM's mean 1 - A* or g* at
    the first passage through p* on each grid, Richardson's order p and converged value b of those means
    (grid_convergence.richardson: None where the changes do not shrink with one sign), how many surfaces' own
    values do so, and the model's relative error against the finest grid (mean ± sd over the surfaces) and against
    b, as the mean model over the mean BEM (and, against 2048^2, also surface by surface, whose mean a surface with
    a nearly closed gap can dominate). The model is the finest case's (its moments and the p*max it turned at).
    Returns (rows, surfaces)."""
    paths = surfaces_on_every_grid(every_grid, ratio, sizes)
    models = [cases_[sizes[-1]].model() for cases_ in paths]
    rows = {"1-A*": [], "g*": []}
    for stage, targets in ((+1, PSTARS), (-1, UNLOAD_PSTARS)):
        for target in targets:
            bem, model_values = [], []      # per surface: [(g*, 1 - A*) per grid], (g*, 1 - A*) of the model
            for cases_, model in zip(paths, models):
                states = [states_at_p(cases_[n], target, stage) for n in sizes]
                if None in states:
                    continue
                finest = cases_[sizes[-1]]
                A, g = (model.loading([target]) if stage > 0
                        else model.unloading([target], finest.pstar[finest.turn]))
                bem.append([state[:2] for state in states])
                model_values.append((g[0], 1 - A[0]))
            if not bem:
                continue
            for index, quantity in ((1, "1-A*"), (0, "g*")):
                v, m = np.array(bem)[:, :, index], np.array(model_values)[:, index]
                means = v.mean(axis=0)
                order, limit, _ = richardson(sizes, list(means))
                shrinking = sum(richardson(sizes, list(row))[0] is not None for row in v)
                rows[quantity].append([quantity, "approach" if stage > 0 else "retraction", f"{target:g}", len(v),
                                       *(fmt(x) for x in means), change(list(means)),
                                       f"{order:.2f}" if order is not None else "-",
                                       fmt(limit) if order is not None else "-", f"{shrinking}/{len(v)}",
                                       f"{(m.mean() - means[-1]) / means[-1]:+.0%}",
                                       fmt(*mean_sd_se((m - v[:, -1]) / v[:, -1])[:2], 2),
                                       f"{(m.mean() - limit) / limit:+.0%}" if order is not None else "-"])
    return rows["1-A*"] + rows["g*"], len(paths)


def energies(cases_by_key, ratio, n):
    """(pull-off mean, sd, se, count, count at the window's end), (loop area mean, sd, se, count), model areas."""
    cases = cases_by_key[(ratio, n)]
    pulloff, edge, areas, model_md, model_jkr = [], 0, [], [], []
    for c in cases:
        p_r = c.part(-1)[1]
        k = int(np.argmin(p_r))
        pulloff.append(float(p_r[k]))
        edge += k == len(p_r) - 1
        pmax = float(c.pstar[c.turn])
        if not pmax > P_LO:  # the approach closed the contact below P_LO (short_approaches): no loop over the window
            continue
        areas.append(loop_area(c, P_LO))
        model_md.append(c.model().dissipated_energy(pmax, P_LO))
        model_jkr.append(c.model("jkr").dissipated_energy(pmax, P_LO))
    return mean_sd_se(pulloff), edge, mean_sd_se(areas), mean_sd_se(model_md), mean_sd_se(model_jkr)


def extrapolated_loops(every_grid, sizes=(512, 1024, 2048)):
    """Rows per sigma0: the loop area over p* >= P_LO of each surface run on all three grids ``sizes`` fitted
    exactly by b + C h^p (grid_convergence.richardson; a surface whose changes do not shrink is left out), the
    grid's share falling as h^p and b the converged area; the mean ± sd over the surfaces of p and b, and the
    model against b."""
    rows = []
    for ratio in sorted({key[0] for key in every_grid}):
        orders, limits, models = [], [], []
        for cases_ in surfaces_on_every_grid(every_grid, ratio, sizes):
            areas = [loop_area(cases_[n], P_LO) for n in sizes]
            order, limit, _ = (None, None, None) if None in areas else richardson(sizes, areas)
            if order is None:
                continue
            orders.append(order)
            limits.append(limit)
            finest = cases_[sizes[-1]]
            models.append(finest.model().dissipated_energy(float(finest.pstar[finest.turn]), P_LO))
        if limits:
            p, b, m = mean_sd_se(orders), mean_sd_se(limits), mean_sd_se(models)
            rows.append([f"1/{ratio:g}", len(limits), spread(p, ".2f", ".2f"), spread(b, ".3g", ".2g", True),
                         f"{m[0]:.3g}", f"{(m[0] - b[0]) / b[0]:+.0%}"])
    return rows


def short_approaches(cases, pmax):
    """Lines on the partial cycles whose approach turned before p*max: the contact closed, the mean gap fell below
    the protocol's smallest (``SMALLEST_GAP`` of adhesion_rough_cycles.py, where it turns too), and the mean
    pressure fell, the adhesive stress holding the contact closed."""
    lines = []
    for c in cases:
        if c.protocol != "partial" or c.pstar[c.turn] >= pmax:
            continue
        top = int(np.argmax(c.pstar[:c.turn + 1]))
        lines.append(f"- surface {c.seed} at 1/{c.ratio:g}, N = {c.n}: the approach reached p* = "
                     f"{c.pstar[top]:.3g} (g* {c.gstar[top]:.3g}), then p* fell to {c.pstar[c.turn]:.3g} as g* went "
                     f"to {c.gstar[c.turn]:.2g} with {round(c.non_contact[c.turn] * c.n ** 2)} non-contact node(s) "
                     "left: the adhesive stress holds the contact closed under a tensile mean pressure. The "
                     "retraction starts there. The path enters the tables at the p* it passes; its loop area over "
                     f"p* >= {P_LO:g} and the model's are left out when it turned below {P_LO:g}.")
    if not lines:
        return []
    return ["## Approaches that closed the contact before p*max", "",
            f"These partial cycles turned before reaching p*max = {pmax:g}, when g* fell below the protocol's smallest "
            "gap:", ""] + lines + [""]


def folds(grouped):
    """Rows (ratio, N): the approach's steps at p* > 0.3 where p* falls although g* falls, and how many of them
    close a non-contact cluster or more (the count of periodic 4-connected clusters drops)."""
    rows = []
    for (ratio, n), cases in grouped.items():
        steps = drops = closing = 0
        sizes = []
        for c in cases:
            g, p = c.gstar[:c.turn + 1], c.pstar[:c.turn + 1]
            clusters = c.clusters[:c.turn + 1]
            near = p[:-1] > 0.3
            fall = near & (np.diff(p) < 0)
            steps += int(near.sum())
            drops += int(fall.sum())
            closing += int((fall & (np.diff(clusters) < 0)).sum())
            sizes.extend((-np.diff(p))[fall])
        rows.append([f"1/{ratio:g}", n, len(cases), steps, drops, closing,
                     f"{np.median(sizes):.3f}" if sizes else "-", f"{np.max(sizes):.3f}" if sizes else "-"])
    return rows


def unconverged(cases):
    lines = []
    for c in cases:
        for i in np.flatnonzero(~c.converged.astype(bool)):
            lines.append(f"- {c.protocol} N = {c.n}, 1/{c.ratio:g}, seed {c.seed}, step {i} "
                         f"({'approach' if c.stage[i] > 0 else 'retraction'}, g* = {c.gstar[i]:.3g}, "
                         f"p* = {c.pstar[i]:+.3f}): natural residual {c.natural[i]:.2g}; {c.rows[i]['reason']}")
    return lines


def core_hours(cases):
    out = {}
    for c in cases:
        key = (c.protocol, c.n)
        hours, count, steps, apps = out.get(key, (0.0, 0, 0, 0))
        out[key] = (hours + float(c.attrs["cpu_seconds"]) / 3600, count + 1, steps + len(c.rows),
                    apps + int(c.applications.sum()))
    return [[protocol, n, count, steps, apps, f"{hours:.2f}", f"{hours / count * 60:.1f}"]
            for (protocol, n), (hours, count, steps, apps) in sorted(out.items())]


def checkpoints():
    """(name, rows, turn, CPU seconds) of every checkpoint: the cases a run was inside when it stopped."""
    from adhesion_rough_cycles import CHECKPOINTS

    out = []
    for path in sorted(glob.glob(os.path.join(CHECKPOINTS, "*.h5"))):
        rows, attrs, _ = read_rows(path)
        out.append((os.path.basename(path)[:-3], len(rows), int(attrs["turn"]), float(attrs["cpu_seconds"])))
    return out


def cost_per_case(cases):
    """({(protocol, N, ratio): (core-hours per case, how)}, the 1024^2 / 512^2 cost factor).

    Measured where a cell has case files. A missing partial cell on N^2: its (N/2)^2 cost times the mean
    N^2 / (N/2)^2 ratio of the surfaces run on both grids (at any sigma0); a missing full-protocol cell: its
    partial cost times the mean full / partial ratio of the surfaces run both ways. The factor returned is
    1024^2 / 512^2's."""
    hours = {}
    for c in cases:
        hours.setdefault((c.protocol, c.n, c.ratio), {})[c.seed] = float(c.attrs["cpu_seconds"]) / 3600

    def factor(pairs):
        values = [hours[key][seed] / hours[base][seed] for key, base in pairs if key in hours and base in hours
                  for seed in hours[key] if seed in hours[base]]
        return float(np.mean(values)) if values else float("nan")

    def grid(n):
        return factor([(k, ("partial", n // 2, k[2])) for k in hours if k[:2] == ("partial", n)])

    full = factor([(k, ("partial", k[1], k[2])) for k in hours if k[0] == "full"])
    out = {key: (float(np.mean(list(v.values()))), "measured") for key, v in hours.items()}
    for _, protocol, n, ratios, _ in PLAN + EXTENSION:
        for ratio in ratios:
            key = (protocol, n, float(ratio))
            if key in out:
                continue
            if protocol == "partial":
                base = out.get(("partial", n // 2, float(ratio)), (float("nan"),))[0]
                out[key] = (base * grid(n), f"scaled: {n // 2}^2 x {grid(n):.1f}")
            else:
                base = out.get(("partial", n, float(ratio)), (float("nan"),))[0]
                out[key] = (base * full, f"scaled: partial x {full:.1f}")
    return out, grid(1024)


def status(cases):
    """The campaign's status: lines of markdown, and the headline counts {(protocol, N, ratio): seeds}."""
    have = {}
    for c in cases:
        have.setdefault((c.protocol, c.n, c.ratio), set()).add(c.seed)
    held = checkpoints()
    costs, grid_factor = cost_per_case(cases)
    planned = sum(len(ratios) * len(seeds) for _, _, _, ratios, seeds in PLAN)
    done = sum(len(have.get((protocol, n, float(r)), set()) & set(seeds))
               for _, protocol, n, ratios, seeds in PLAN for r in ratios)
    rows, total = [], 0.0
    for stage, protocol, n, ratios, seeds in PLAN + EXTENSION:
        for ratio in ratios:
            key = (protocol, n, float(ratio))
            present = sorted(have.get(key, set()) & set(seeds))
            missing = [s for s in seeds if s not in present]
            per_case, how = costs.get(key, (float("nan"), "-"))
            remaining = per_case * len(missing)
            held_here = [h for h in held if f"_n{n}_" in h[0] and f"_r{ratio:g}_" in h[0] and h[0].endswith(protocol)]
            if held_here:
                remaining -= sum(h[3] for h in held_here) / 3600
            total += remaining if np.isfinite(remaining) else 0.0
            rows.append([stage, protocol, f"{n}^2", f"1/{ratio:g}", seed_list(present) or "none",
                         (seed_list(missing) or "none")
                         + "".join(f" (surface {int(h[0].split('_s')[1][:2])}: checkpoint at step {h[1]})"
                                   for h in held_here),
                         f"{per_case:.3f} ({how})" if np.isfinite(per_case) else "-",
                         f"{remaining:.2f}" if np.isfinite(remaining) else "-"])
    extra = sorted(k for k in have if not any(k == (protocol, n, float(r)) for _, protocol, n, ratios, _ in PLAN
                                               for r in ratios))
    extension = {(protocol, n, float(r)): stage for stage, protocol, n, ratios, _ in EXTENSION for r in ratios}
    cpu = sum(float(c.attrs["cpu_seconds"]) for c in cases) / 3600
    wall = sum(float(c.attrs["wall_seconds"]) for c in cases) / 3600
    n1024 = {r: sorted(have.get(("partial", 1024, float(r)), set())) for r in (100, 50, 20)}
    third_grid_surfaces = "; ".join(f"{len(s)} surface{'s' if len(s) != 1 else ''} ({seed_list(sorted(s))}) at "
                                    f"1/{r:g}" for (protocol, n, r), s in sorted(have.items())
                                    if protocol == "partial" and n > PLANNED_FINEST)
    status = (f"**All {planned} planned cycles have case files; the third grid (2048^2, beyond the plan) is "
              f"under way.**" if done == planned else
              f"**The campaign is partial: {done} of the {planned} planned cycles have case files.**")
    lines = [f"## Status: {'the plan done, a third grid under way' if done == planned else 'a partial campaign'}", "",
             f"{status} The plan is "
             "`studies/adhesion_rough_runs.sh` (group #1, p*max = 2: 512^2 and 1024^2, ten surfaces, sigma0/E* = "
             "1/100, 1/50, 1/20, partial protocol; full cycles at 512^2, 1/100 and 1/50). What exists:", ""]
    for (protocol, n, ratio), seeds in sorted(have.items(), key=lambda kv: (kv[0][0] != "partial", kv[0][1],
                                                                          -kv[0][2])):
        lines.append(f"- {protocol}, {n}^2, sigma0/E* = 1/{ratio:g}: {len(seeds)} surface"
                     f"{'s' if len(seeds) != 1 else ''} ({seed_list(sorted(seeds))})"
                     + (f" (beyond the plan: stage {extension[protocol, n, ratio]})"
                        if (protocol, n, ratio) in extension else
                        " (outside the plan)" if (protocol, n, ratio) in extra else ""))
    lines += ["",
              "So 1024^2 has "
              + ("; ".join(f"{len(s)} surface{'s' if len(s) != 1 else ''} at 1/{r}" for r, s in n1024.items() if s)
                 or "no surface")
              + (" only" if sum(map(len, n1024.values())) == 1 else "")
              + ("; " + " and ".join(f"1/{r}" for r, s in n1024.items() if not s) + " ha"
                 + ("s" if sum(not s for s in n1024.values()) == 1 else "ve") + " no 1024^2 run, so no grid change "
                 "is measured there" if not all(n1024.values()) else "")
              + (f"; 2048^2, beyond the plan (the n2048 stage of the runs script), has {third_grid_surfaces} "
                 "(section \"The third grid\" below)" if third_grid_surfaces else
                 "; and there is **no 2048^2 run at all** (a third grid, which would give the order of "
                 "convergence, is not in the plan: about "
                 f"{costs.get(('partial', 1024, 100.0), (float('nan'),))[0] * grid_factor:.1f} core-hours a cycle "
                 "at 1/100, the 1024^2 cost scaled by the same 512^2 -> 1024^2 factor)") + "."
              + "".join(f" A run stopped inside {h[0]} (checkpoint at step {h[1]}, {h[3] / 60:.1f} CPU minutes in): "
                        "the resume starts there." for h in held), "",
              f"Resume (every stage skips finished cases and restarts an unfinished one from its checkpoint): `{RESUME}`"
              ", or the named stages, e.g. `bash studies/adhesion_rough_runs.sh n1024_r100_a n1024_r50_20`.", "",
              "Remaining cost, in core-hours of process CPU time per case as the case files record it (measured "
              "where the cell has cases, else scaled as stated; the checkpoint's CPU time already spent is "
              f"subtracted). So far {cpu:.2f} core-hours CPU in {wall:.2f} hours of wall time: the 2 cores are "
              "shared, so the wall time is several times the CPU time.", "",
              common.markdown_table(["stage", "protocol", "N", "sigma0/E*", "surfaces done", "missing",
                                     "core-hours per case", "core-hours left"], rows), "",
              f"Total left: about {total:.1f} core-hours of CPU time, "
              f"{', '.join(stage for stage, *_ in EXTENSION)} included (they extend the plan: the full cycles' "
              "second grid and the partial cycles' third).", ""]
    return lines, have


def seed_list(seeds):
    """'1-5, 7' for [1, 2, 3, 4, 5, 7]."""
    parts, run = [], []
    for s in list(seeds) + [None]:
        if run and (s is None or s != run[-1] + 1):
            parts.append(f"{run[0]}-{run[-1]}" if len(run) > 2 else ", ".join(map(str, run)))
            run = []
        if s is not None:
            run.append(s)
    return ", ".join(parts)


def provisional_reading(numbers, have, energy, grouped):
    """Markdown lines: the model's errors at p* = 1 and 2 of the approach, per cell, with the counts behind them."""
    lines = ["## Provisional reading of the adhesive GW model on these surfaces", "",
             "**Provisional, on the counts above.** Wherever no finer grid exists the model's error below is mixed "
             "with the BEM's discretisation error, and a cell of one surface has no spread. Mean relative error "
             "(model - BEM) / BEM at the approach's first passage through p* (from the tables below):", ""]
    rows = []
    for (ratio, n), values in sorted(numbers.items(), key=lambda kv: (-kv[0][0], kv[0][1])):
        row = [f"1/{ratio:g}", f"{n}^2", values.get((1, 1.0), (0, 0, 0))[2]]
        for target in (1.0, 2.0):
            a, g, _ = values.get((1, target), (float("nan"),) * 3)
            row += [f"{a:+.2f}" if np.isfinite(a) else "-", f"{g:+.2f}" if np.isfinite(g) else "-"]
        rows.append(row)
    lines += [common.markdown_table(["sigma0/E*", "N", "surfaces", "1-A* at p* = 1", "g* at p* = 1",
                                     "1-A* at p* = 2", "g* at p* = 2"], rows), ""]

    def says(error):
        if not np.isfinite(error):
            return "-"
        return f"is within {abs(error):.0%}" if abs(error) < 0.1 else \
            f"{'over' if error > 0 else 'under'}estimates by {abs(error):.0%}"

    for ratio in sorted({r for r, _ in numbers}, reverse=True):
        finest = max(n for r, n in numbers if r == ratio)
        values = numbers[(ratio, finest)]
        count = values.get((1, 1.0), (0, 0, 0))[2]
        parts = []
        for target in (1.0, 2.0):
            a, g, _ = values.get((1, target), (float("nan"),) * 3)
            parts.append(f"at p* = {target:g} the model {says(a)} (1 - A*) and {says(g)} (g*)")
        grid_note = ("no finer grid than 512^2: this is the model's error and the BEM's together"
                     + (", and the cohesive zone is narrowest here" if ratio == 20 else "")) if finest == 512 else \
            (f"{count} surface{'s' if count != 1 else ''} at {finest}^2, against "
             f"{numbers.get((ratio, 512), {}).get((1, 1.0), (0, 0, 0))[2]} at 512^2; the values are the "
             f"{finest}^2 ones")
        lines.append(f"- 1/{ratio:g} ({grid_note}): " + "; ".join(parts) + ".")
    for ratio in sorted({r for r, _ in energy}, reverse=True):
        cells = sorted(n for r, n in energy if r == ratio)
        parts = [f"BEM {energy[(ratio, n)][2][0]:.3g} on {energy[(ratio, n)][2][3]} surface"
                 f"{'s' if energy[(ratio, n)][2][3] != 1 else ''} at {n}^2, model {energy[(ratio, n)][3][0]:.3g}"
                 for n in cells]
        if len(cells) > 1:
            pairs = [(c, f) for c in grouped[(ratio, cells[-2])] for f in grouped[(ratio, cells[-1])]
                     if c.seed == f.seed]
            changes = [(loop_area(f, P_LO) - loop_area(c, P_LO)) / loop_area(c, P_LO) for c, f in pairs
                       if loop_area(c, P_LO) and loop_area(f, P_LO) is not None]
            if changes:
                parts.append(f"the BEM loop area of the {len(changes)} surface{'s' if len(changes) != 1 else ''} "
                             f"run on both grids changed by {np.mean(changes):+.0%} from {cells[-2]}^2 to "
                             f"{cells[-1]}^2, so it is not converged")
        lines.append(f"- Hysteresis at 1/{ratio:g} (loop area over p* >= {P_LO:g}): " + "; ".join(parts) + ".")
    complete = all(len(have.get(("partial", 1024, ratio), ())) >= 10 for ratio in (100, 50, 20))
    waits = ("the 1024^2 cells hold the ten surfaces at every ratio, but the BEM changes by up to tens of per cent "
             "from 512^2 to 1024^2 (the tables below)" if complete else
             "it waits for the 1024^2 cells to hold the ten surfaces at every ratio (the resume command above)")
    lines += [f"- No statement here on the adhesive GW model at rough surfaces is final: {waits}, and a convergence "
              "order would need a third grid.", ""]
    return lines


def figures(grouped, full_cases):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ratios = sorted({r for r, _ in grouped})
    sizes = sorted({n for _, n in grouped})
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    figure, axes = plt.subplots(len(ratios), 2, figsize=(11, 3.8 * len(ratios)), squeeze=False)
    p_model = np.linspace(0.3, 2.2, 96)
    for row_axes, ratio in zip(axes, ratios):
        for colour, n in zip(colours, sizes):
            for i, c in enumerate(grouped.get((ratio, n), [])):
                for stage, ls in ((+1, "-"), (-1, ":")):
                    g, p, a, _ = c.part(stage)
                    row_axes[0].plot(p, a, ls, color=colour, lw=0.6, alpha=0.6,
                                     label=f"BEM N = {n}" if i == 0 and stage > 0 else None)
                    row_axes[1].plot(p, g, ls, color=colour, lw=0.6, alpha=0.6)
        reference = grouped[(ratio, sizes[0])][0]
        model = reference.model()
        jkr = reference.model("jkr")
        for m, style, tag in ((model, "k-", "model"), (jkr, "k--", "JKR limit")):
            A, gl = m.loading(p_model)
            row_axes[0].plot(p_model, 1 - A, style, lw=1.6, label=f"{tag}, loading")
            row_axes[1].plot(p_model, gl, style, lw=1.6)
        Au, gu = model.unloading(p_model[p_model <= 2.0], 2.0)
        row_axes[0].plot(p_model[p_model <= 2.0], 1 - Au, "k-.", lw=1.6, label="model, unloading from 2")
        row_axes[1].plot(p_model[p_model <= 2.0], gu, "k-.", lw=1.6)
        for axis, label in zip(row_axes, ("1 - A*", "g*")):
            axis.set(xlabel="p*", ylabel=label, yscale="log", xlim=(0.3, 2.3), title=f"sigma0/E* = 1/{ratio:g}")
        row_axes[0].set_ylim(1e-6, 0.3)
        row_axes[0].legend(fontsize=7)
    figure.suptitle("BEM paths, every surface, in step order (approach solid, retraction dotted); model curves black",
                    fontsize=9)
    common.save_figure(figure, os.path.dirname(REPORT), "rough_cycles_paths.png")

    figure, axes = plt.subplots(1, len(ratios), figsize=(4.2 * len(ratios), 3.8), squeeze=False)
    for axis, ratio in zip(axes[0], ratios):
        for colour, n in zip(colours, sizes):
            cases = grouped.get((ratio, n), [])
            if not cases:
                continue
            approach = [c.part(+1) for c in cases]
            steps = min(len(a[0]) for a in approach)
            g = approach[0][0][:steps]
            p = np.array([a[1][:steps] for a in approach])
            axis.errorbar(g, p.mean(axis=0), yerr=p.std(axis=0, ddof=1) / math.sqrt(len(cases)) if len(cases) > 1
                          else None, color=colour, lw=1, capsize=2, label=f"N = {n} ({len(cases)} surfaces)")
        axis.set(xscale="log", xlabel="g* (prescribed)", ylabel="mean p* of the approach", xlim=(1e-5, 0.6),
                 ylim=(-1, 3), title=f"sigma0/E* = 1/{ratio:g}")
        axis.legend(fontsize=7)
    common.save_figure(figure, os.path.dirname(REPORT), "rough_cycles_grid.png")


def report(group=1, pmax=2.0):
    cases = load_cases()
    every_grid = groups(cases, "partial")
    # The planned grids carry the comparison; a finer grid run on some surfaces only gets a section of its own
    # (third_grid), so that a few surfaces do not stand in for the ten.
    grouped = {key: c for key, c in every_grid.items() if key[1] <= PLANNED_FINEST}
    full = groups(cases, "full")
    if not grouped:
        print("no partial-protocol case files yet")
        return
    ratios = sorted({r for r, _ in grouped})
    sizes = sorted({n for _, n in grouped})
    lines = ["# Adhesive BEM cycles on rough surfaces: grid convergence, the adhesive GW model, pull-off and "
             "hysteresis",
             "", f"Generated by `.venv/bin/python studies/adhesion_rough_cycles.py --report` from the case files in "
             f"`rough/` (group #{group}, p*max = {pmax:g}; set-up, protocols and definitions in the docstrings of "
             "`studies/adhesion_rough_cycles.py` and `studies/adhesion_rough_report.py`). Surfaces per cell: "
             + ", ".join(f"1/{r:g} at N = {n}: {len(grouped[(r, n)])}" for r, n in grouped) + ".", ""]
    status_lines, have = status(cases)
    lines += status_lines
    numbers = {}
    for ratio in ratios:
        for n in sizes:
            if (ratio, n) in grouped:
                numbers[(ratio, n)] = {}
    error_rows = {key: model_errors(grouped, *key, numbers=numbers[key]) for key in numbers}
    energy = {key: energies(grouped, *key) for key in grouped}
    lines += provisional_reading(numbers, have, energy, grouped)
    lines += short_approaches(cases, pmax)
    lines += ["## Grid convergence at a fixed mean gap (approach)", "",
              "Mean over the surfaces every grid has (± standard error); the gaps are those of the path nearest the "
              "finest grid's first passage through p* = 0.5, 1, 1.5, 2. Changes are relative, from one grid to the "
              "next.", ""]
    for ratio in ratios:
        have = [n for n in sizes if (ratio, n) in grouped]
        rows, count = convergence_at_gaps(grouped, ratio, have)
        if not rows:
            continue
        lines += [f"sigma0/E* = 1/{ratio:g} ({count} surfaces):", "",
                  common.markdown_table(["g*"] + [f"p* N={n}" for n in have] + ["change"]
                                        + [f"1-A* N={n}" for n in have] + ["change"], rows), ""]
    lines += third_grid(every_grid, sizes)
    lines += ["## Grid convergence and model errors at a fixed p* (first passage)", "",
              "BEM and model (`AdhesiveGW`, the surface's moments) at the p* where each path first passes it; "
              "relative error (model - BEM) / BEM, mean ± sd over the surfaces, and the largest |error| of any "
              "surface. 'nodes': mean number of non-contact nodes of the BEM state.", ""]
    for ratio in ratios:
        for n in sizes:
            if (ratio, n) not in grouped:
                continue
            rows = error_rows[(ratio, n)]
            lines += [f"sigma0/E* = 1/{ratio:g}, N = {n}:", "",
                      common.markdown_table(["stage", "p*", "surfaces", "nodes", "BEM 1-A*", "model 1-A*",
                                             "rel. error 1-A*", "BEM g*", "model g*", "rel. error g*",
                                             "max |err 1-A*|", "max |err g*|"], rows), ""]
    if len(sizes) > 1:
        lines += ["## Grid change and a first-order extrapolation", "",
                  f"The surfaces run on both N = {sizes[-2]} and {sizes[-1]}: BEM 1 - A* and g* at the first passage "
                  f"through p* on each grid, the relative change from {sizes[-2]} to {sizes[-1]}, the first-order "
                  "extrapolation 2 Q_fine - Q_coarse (an estimate, not a measurement: a third grid would give the "
                  "order), and the model's relative error against the finer grid and against the extrapolation "
                  "(mean ± sd over the surfaces).", ""]
        for ratio in ratios:
            if (ratio, sizes[-2]) in grouped and (ratio, sizes[-1]) in grouped:
                rows = extrapolated_errors(grouped, ratio, sizes[-2], sizes[-1])
                header = ["stage", "p*", "surfaces"]
                for q in ("1-A*", "g*"):
                    header += [f"{q} {sizes[-2]}", f"{q} {sizes[-1]}", f"{q} extrap.", "change", "model err",
                               "model err vs extrap."]
                lines += [f"sigma0/E* = 1/{ratio:g}:", "", common.markdown_table(header, rows), ""]
                pairs = [(c, f) for c in grouped[(ratio, sizes[-2])] for f in grouped[(ratio, sizes[-1])]
                         if c.seed == f.seed]
                rows = []
                for c, f in pairs:
                    pull = [float(np.min(x.part(-1)[1])) for x in (c, f)]
                    area = [loop_area(x, P_LO) for x in (c, f)]
                    rows.append([c.seed, f"{pull[0]:+.3f}", f"{pull[1]:+.3f}",
                                 *(fmt(a) if a is not None else "-" for a in area),
                                 f"{(area[1] - area[0]) / area[0]:+.0%}" if None not in area and area[0] else "-"])
                lines += [f"The same surfaces' least retraction p* (within g* <= 0.6) and loop area over p* >= "
                          f"{P_LO:g} on both grids (1/{ratio:g}):", "",
                          common.markdown_table(["surface", f"least p* {sizes[-2]}", f"least p* {sizes[-1]}",
                                                 f"loop area {sizes[-2]}", f"loop area {sizes[-1]}", "change"],
                                                rows), ""]
    three = [ratio for ratio in ratios if all((ratio, n) in every_grid for n in (512, 1024, 2048))]
    if three:
        lines += ["## Three grids at a fixed p*: the order, the converged value and the model against it", "",
                  "The surfaces run on 512^2, 1024^2 and 2048^2: the BEM's mean 1 - A* and g* at the first passage "
                  "through p* on each grid, the changes from grid to grid, Richardson's order p and converged "
                  "value b of the three means ('-' where the changes do not shrink with one sign: no order is "
                  "read), how many surfaces' own three values shrink so, and the model's relative error "
                  "(model - BEM) / BEM: of the mean model against the mean on 2048^2, surface by surface against "
                  "2048^2 (mean ± sd), and of the mean model against b. An order well below 1 extrapolates far "
                  "beyond the grids (b then rests on the assumption that the order holds), and the 1/20 cell is "
                  "reported on the surfaces it has.", ""]
        for ratio in three:
            rows, count = three_grid_errors(every_grid, ratio)
            if not rows:
                continue
            lines += [f"sigma0/E* = 1/{ratio:g} ({count} surfaces):", "",
                      common.markdown_table(["quantity", "stage", "p*", "surfaces", "BEM 512", "BEM 1024",
                                             "BEM 2048", "change", "order p", "b", "surfaces shrinking",
                                             "model vs 2048", "per surface vs 2048", "model vs b"], rows), ""]
    lines += ["## Pull-off and hysteresis", "",
              f"Pull-off: least p* of the retraction (within g* <= 0.6). Hysteresis: loop area int g* dp* over p* >= "
              f"{P_LO:g} (BEM) against `AdhesiveGW.dissipated_energy(p*max, {P_LO:g})` at the p*max each path "
              "turned at (Maugis-Dugdale and JKR limit). Mean ± sd (standard error in brackets). A 2048^2 row appears "
              "once its cell holds every surface of 1024^2.", ""]
    rows = []
    # A finer grid's cell joins the table once it holds every surface of the planned finest grid.
    complete = {key: cases_ for key, cases_ in every_grid.items() if key[1] > PLANNED_FINEST
                and {c.seed for c in cases_} >= {c.seed for c in grouped.get((key[0], PLANNED_FINEST), [])}}
    energy.update({key: energies(complete, *key) for key in complete})
    for (ratio, n) in sorted(list(grouped) + list(complete), key=lambda key: (key[0], key[1])):
        pulloff, edge, area, (mm, _, _, _), (jm, _, _, _) = energy[(ratio, n)]
        am = area[0]
        rows.append([f"1/{ratio:g}", n, pulloff[3], spread(pulloff, "+.3f", ".3f", True), edge,
                     spread(area, ".3g", ".2g", True), f"{mm:.3g}", f"{jm:.3g}",
                     f"{(mm - am) / am:+.0%}" if am else "-"])
    lines += [common.markdown_table(["sigma0/E*", "N", "surfaces", "BEM pull-off p*", "pull-off at the window's end",
                                     f"BEM loop area p*>={P_LO:g}", "model", "JKR-limit model",
                                     "model vs BEM"], rows), "",
              "The adhesive GW model of section 6.5 has no pull-off: it is a model of nearly complete contact, a "
              "function of p* >= 0 whose cracks never coalesce, and the dissertation defines none.", ""]
    rows = extrapolated_loops(every_grid)
    if rows:
        lines += ["The loop area extrapolated from three grids: each surface run on 512^2, 1024^2 and 2048^2 "
                  "fitted exactly by b + C h^p (h the node spacing), b being its area on a converged grid. Mean ± "
                  "sd over the surfaces (standard error of b in brackets); the model is Maugis-Dugdale's at the "
                  "p*max the 2048^2 paths turned at. An order near 1 on every surface says the grid's share falls "
                  "like the spacing, as the cohesive zone's end crossing nodes would make it; the extrapolation "
                  "assumes it keeps doing so below 2048^2.", "",
                  common.markdown_table(["sigma0/E*", "surfaces", "order p", "extrapolated loop area b", "model",
                                         "model vs b"], rows), ""]
    if full:
        rows = []
        for (ratio, n), cycles in full.items():
            p = mean_sd_se([float(c.attrs["pulloff_pstar"]) for c in cycles])
            w = mean_sd_se([float(c.attrs["dissipated_energy_star"]) for c in cycles])
            let_go = sum(bool(c.attrs["let_go"]) for c in cycles)
            rows.append([f"1/{ratio:g}", n, len(cycles), spread(p, "+.3f", ".3f"), let_go,
                         spread(w, ".3g", ".2g"), f"{max(c.gstar[-1] for c in cycles):.3g}"])
        lines += ["Full protocol (retraction until the contact lets go, at most 40 steps of 0.15 beyond the start): "
                  "pull-off and the energy dissipated over the whole cycle, -closed integral p* dg* (a lower bound "
                  "where the contact has not let go: the rest of the retraction is tensile).", "",
                  common.markdown_table(["sigma0/E*", "N", "surfaces", "pull-off p*", "let go", "dissipated energy",
                                         "largest g* reached"], rows), ""]
    lines += ["## Why the BEM's p*(g*) folds", "",
              "Approach steps in nearly complete contact (p* > 0.3 before the step) at which p* falls while the "
              "prescribed g* falls, and how many of those falls close a non-contact cluster: a crack that snaps "
              "shut at a fixed mean gap hands its volume to the others, which open at a lower p* (the two-crack "
              "test of tests/contact/test_adhesion.py checks this against the crack model). Falls of p* that close no "
              "cluster come from cracks that snap onto the full-adhesion branch or shrink by whole nodes.", "",
              common.markdown_table(["sigma0/E*", "N", "surfaces", "steps", "falls of p*", "falls that close a "
                                     "cluster", "median fall", "largest fall"], folds(grouped)), ""]
    failed = unconverged(cases)
    lines += ["## Certificates", "",
              f"{sum(len(c.rows) for c in cases)} solves; {len(failed)} stopped short of the natural residual "
              "1e-8" + (":" if failed else "."), ""] + failed + [""]
    lines += ["## Cost", "", "Process CPU time of the runs (one process each, niced, on the shared 2-core machine).",
              "",
              common.markdown_table(["protocol", "N", "cases", "steps", "operator applications", "core-hours",
                                     "core-minutes per case"], core_hours(cases)), "",
              "![paths](rough_cycles_paths.png)", "", "![grid](rough_cycles_grid.png)", ""]
    figures(grouped, full)
    with open(REPORT, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {REPORT}")


if __name__ == "__main__":
    common.init()
    report()
