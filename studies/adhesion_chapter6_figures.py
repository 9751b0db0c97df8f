"""Figs 6.8-6.11 of the dissertation regenerated: the adhesive adapted GW model (6.40)-(6.54) of section 6.6.

    .venv/bin/python studies/adhesion_chapter6_figures.py

Surface: the moments of Table 6.2 (m0^h = 8.35e-19 m^2, m2^h = 2e-4, m4^h = 9.58e10 m^-2, m6^h = 6.67e25 m^-4;
alpha^h = 2.00, alpha^p = 1.96), E* = 1 (only sigma0 / E* enters). The range z0 is not printed; the reading
used is z0 = 0.3 nm (an interatomic distance; ``adhesion_chapter6.Z0_OVER_RMS`` times the rms height of
Table 6.2), with w = sigma0 z0, the convention that gives (6.56); the report lists where the unloading
curves of Fig 6.8 accelerate under this reading, the text's one check of it.

What each figure draws (the captions and the text of section 6.6):

* Fig 6.8: sigma0 / E* = 1/20, one cycle (loading (6.50)-(6.51), solid; unloading (6.53)-(6.54) back to
  p* = 0, dashed) for p*max = 2, 3, 4; (a) 1 - A*, (b) g*; the non-adhesive limit (5.37)-(5.38) (black
  dashed: "all loading-unloading curves ... lie under the non-adhesive limit").
* Fig 6.9: loading, sigma0 / E* = 1/20, 1/50, 1/100 (solid), each with its JKR limit (dashed, same colour:
  ``AdhesiveGW(crack_law="jkr")``, the same w) and the non-adhesive limit (black dashed).
* Fig 6.10: the same for the unloading from p*max = 4.
* Fig 6.11: the cycles (p*max = 4) of the three ratios, loading solid and unloading dashed; the energy
  dissipated in each, the area between the g* curves (``AdhesiveGW.dissipated_energy``), is tabulated.

Output: studies/output/adhesion/fig6_8.png ... fig6_11.png and chapter6_figures.md.
"""

import os

import numpy as np

import common

TABLE_6_2 = (8.35e-19, 2e-4, 9.58e10, 6.67e25)      # m0h [m^2], m2h, m4h [m^-2], m6h [m^-4]
RATIOS = (20, 50, 100)
PMAX = (2.0, 3.0, 4.0)
OUT = os.path.join(common.OUTPUT, "adhesion")


def models(ratio, z0):
    """The Maugis-Dugdale and JKR-limit models of section 6.6 at sigma0/E* = 1/ratio."""
    from roughpetsc.models.adhesion import AdhesiveGW

    return (AdhesiveGW(*TABLE_6_2, 1.0 / ratio, z0),
            AdhesiveGW(*TABLE_6_2, 1.0 / ratio, z0, crack_law="jkr"))


def cycle(model, pmax, points=161):
    """(p*, 1 - A*, g*) of the loading up to pmax and of the unloading back to 0."""
    p = np.linspace(0.0, pmax, points)
    load = model.loading(p)
    unload = model.unloading(p, pmax)
    return p, (1 - load[0], load[1]), (1 - unload[0], unload[1])


def nonadhesive(model, p):
    """(1 - A*, g*) of the non-adhesive adapted GW model (5.37)-(5.38) on the same surface."""
    from roughpetsc.models import complete

    alpha_h = TABLE_6_2[0] * TABLE_6_2[2] / TABLE_6_2[1] ** 2
    A, g = complete("gw", p, model.alpha_p, alpha_h)
    return 1 - A, g


def panels(plt, title):
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    for axis, label in zip(axes, ("(a) 1 - A*", "(b) g*")):
        axis.set(xlabel="p*", ylabel=label.split(" ", 1)[1], yscale="log", title=f"{label}")
    figure.suptitle(title, fontsize=10)
    return figure, axes


def draw(axes, p, curves, **style):
    for axis, values in zip(axes, curves):
        positive = values > 0
        axis.plot(p[positive], values[positive], **style)


def figures(z0):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    md20 = models(20, z0)[0]
    p4 = np.linspace(0.0, 4.0, 161)
    limit = nonadhesive(md20, p4)

    figure, axes = panels(plt, "Fig 6.8: sigma0/E* = 1/20, p*max = 2, 3, 4 (loading solid, unloading dashed)")
    for colour, pmax in zip(colours, PMAX):
        p, load, unload = cycle(md20, pmax)
        draw(axes, p, load, color=colour, label=f"p*max = {pmax:g}")
        draw(axes, p, unload, color=colour, ls="--")
    draw(axes, p4, limit, color="k", ls="--", lw=1, label="non-adhesive")
    axes[0].legend(fontsize=8)
    common.save_figure(figure, OUT, "fig6_8.png")

    for name, stage, title in (("fig6_9.png", 0, "Fig 6.9: loading"),
                               ("fig6_10.png", 1, "Fig 6.10: unloading from p*max = 4")):
        figure, axes = panels(plt, f"{title} (Maugis-Dugdale solid, its JKR limit dashed, non-adhesive black dashed)")
        for colour, ratio in zip(colours, RATIOS):
            for model, ls, tag in zip(models(ratio, z0), ("-", "--"), ("", " JKR limit")):
                p, load, unload = cycle(model, 4.0)
                draw(axes, p, (load, unload)[stage], color=colour, ls=ls, label=f"1/{ratio}{tag}")
        draw(axes, p4, limit, color="k", ls="--", lw=1, label="non-adhesive")
        axes[0].legend(fontsize=7, ncol=2)
        common.save_figure(figure, OUT, name)

    figure, axes = panels(plt, "Fig 6.11: cycles to p*max = 4 (loading solid, unloading dashed)")
    for colour, ratio in zip(colours, RATIOS):
        p, load, unload = cycle(models(ratio, z0)[0], 4.0)
        draw(axes, p, load, color=colour, label=f"sigma0/E* = 1/{ratio}")
        draw(axes, p, unload, color=colour, ls="--")
    axes[0].legend(fontsize=8)
    common.save_figure(figure, OUT, "fig6_11.png")


def report(z0):
    from roughpetsc.models import complete  # noqa: F401  (the non-adhesive limit, through nonadhesive())

    rows, energy_rows, onset_rows = [], [], []
    for ratio in RATIOS:
        md, jkr = models(ratio, z0)
        c = md.crack
        rows.append([f"1/{ratio}", f"{md.sigma_star:.3f}", f"{md.C:.4f}", f"{md.C1:.4g}", f"{md.C2:.4g}",
                     f"{c.points['B'][0]:.4f}", f"{c.sigma:.4f}", f"{c.points['F'][0]:.4f}"])
        energy_rows.append([f"1/{ratio}", f"{md.dissipated_energy(4.0):.4g}", f"{jkr.dissipated_energy(4.0):.4g}",
                            f"{md.dissipated_energy(2.0):.4g}", f"{jkr.dissipated_energy(2.0):.4g}"])
    values = []
    p = np.array([1.0, 2.0, 3.0])
    md20 = models(20, z0)[0]
    limit = nonadhesive(md20, p)
    for ratio in RATIOS:
        for model, law in zip(models(ratio, z0), ("Maugis-Dugdale", "JKR limit")):
            load, unload = model.loading(p), model.unloading(p, 4.0)
            values.append([f"1/{ratio}", law] + [f"{v:.3g}" for v in (1 - load[0])] + [f"{v:.3g}" for v in load[1]]
                          + [f"{v:.3g}" for v in (1 - unload[0])] + [f"{v:.3g}" for v in unload[1]])
    values.append(["-", "non-adhesive (5.37)-(5.38)"] + [f"{v:.3g}" for v in limit[0]] + [f"{v:.3g}" for v in limit[1]]
                  + [f"{v:.3g}" for v in limit[0]] + [f"{v:.3g}" for v in limit[1]])
    c = md20.crack
    for pmax in PMAX:
        onset_rows.append([f"{pmax:g}", f"{pmax - (c.sigma - c.points['B'][0]) / md20.C:.3f}",
                           f"{pmax - (c.points['F'][0] - c.points['B'][0]) / md20.C:.3f}"])
    lines = [
        "# Figs 6.8-6.11 regenerated: the adhesive adapted GW model of section 6.6", "",
        "Generated by `.venv/bin/python studies/adhesion_chapter6_figures.py` (what each figure draws, the surface "
        "(Table 6.2) and the reading of z0 in its docstring). The model: `roughpetsc.models.adhesion.AdhesiveGW`, "
        "the JKR limit `AdhesiveGW(..., crack_law=\"jkr\")` (sigma0 -> inf at the same w = sigma0 z0; tested "
        "against the Maugis-Dugdale model as sigma0 grows and against adaptive quadrature in "
        "tests/models/test_models_adhesion.py). z0 = 0.3 nm.", "",
        "## Scales (6.4)-(6.6), (6.45), (6.48)-(6.49) and the crack's turning points (6.15), (6.38), (6.39)", "",
        common.markdown_table(["sigma0/E*", "sigma0*", "C", "C1", "C2", "p*_B", "p*_E", "p*_F"], rows), "",
        "## Values drawn (loading; unloading from p*max = 4) at p* = 1, 2, 3", "",
        common.markdown_table(["sigma0/E*", "crack law", "1-A* load 1", "2", "3", "g* load 1", "2", "3",
                               "1-A* unload 1", "2", "3", "g* unload 1", "2", "3"], values), "",
        "Every curve lies below the non-adhesive limit, as the text says of Fig 6.8; the Maugis-Dugdale curves "
        "lie between the JKR limit and the non-adhesive one on loading. On unloading the JKR limit keeps every "
        "crack that closed shut (its E is at infinity), so its 1 - A* stays orders of magnitude below the "
        "Maugis-Dugdale one at 1/50 and 1/100.", "",
        "## Fig 6.11: energy dissipated in a cycle", "",
        "The area between the loading and unloading g*(p*) curves from 0 to p*max (Fig 6.11(b); units sqrt(m0^h) "
        "sqrt(m0^p)).", "",
        common.markdown_table(["sigma0/E*", "Maugis-Dugdale, p*max = 4", "JKR limit, 4", "Maugis-Dugdale, 2",
                               "JKR limit, 2"], energy_rows), "",
        "## Fig 6.8: where the unloading accelerates (sigma0/E* = 1/20)", "",
        "A crack closed at p*max reopens on the full-adhesion branch when its local p* = (xi* - p*) C reaches "
        "E = sigma0*, and jumps to the Maugis-Dugdale branch at F; the first such cracks are those that closed "
        "last, at p*_B. Hence the unloading curve leaves the loading-like slope at p* = p*max - (p*_E - p*_B) / C "
        "and accelerates at p*max - (p*_F - p*_B) / C:", "",
        common.markdown_table(["p*max", "reopening at E starts at p* =", "jumps at F start at p* ="], onset_rows), "",
        "The text: the p*max = 4 unloading \"consists [of] two distinct regions\", and \"no accelerated unloading "
        "portions are observed\" for p*max = 2 and 3 \"because the reduction of p* from p*max is not sufficient\". "
        "With z0 = 0.3 nm the jumps at F begin at p* = 1.06 for p*max = 4, at 0.06 for 3 and never for 2: "
        "consistent with the text if the unloading is drawn to p* = 0. Since sigma0*/C = (sigma0/E*) / "
        "sqrt(m0^p*) = 5 does not depend on z0, a smaller z0 (larger sigma0*, p*_B -> 2.36) moves these onsets "
        "down (towards p*max - 5 + 2.36 / C); z0 is not printed, and the figures change with it.", "",
        "![Fig 6.8](fig6_8.png)", "", "![Fig 6.9](fig6_9.png)", "", "![Fig 6.10](fig6_10.png)", "",
        "![Fig 6.11](fig6_11.png)", ""]
    with open(os.path.join(OUT, "chapter6_figures.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    from adhesion_chapter6 import Z0_OVER_RMS

    z0 = Z0_OVER_RMS * np.sqrt(TABLE_6_2[0])
    figures(z0)
    report(z0)


if __name__ == "__main__":
    main()
