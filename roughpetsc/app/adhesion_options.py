"""The command line of adhesive contact (``-adhesion`` in ``-mode solve``): its options, checks and header.

The physics is in :mod:`roughpetsc.contact.laws` and :mod:`roughpetsc.contact.adhesive`.
"""

from ..errors import UserError
from .settings import options_named

OPTIONS = [
    ("adhesion", "none", "adhesive law: none | dugdale (tension -adhesion_stress up to the range w / sigma0) | "
                         "exponential (phi = -w exp(-g / rho), rho = -adhesion_range); periodic cell, displacement "
                         "control (-gbar, -gbar_list), solved for the gap by projected CG (or -tao_type almm)"),
    ("adhesion_work", 0.0, "work of adhesion w, pressure x length units"),
    ("adhesion_stress", 0.0, "Dugdale stress sigma0, pressure units (or -adhesion_range h0, then sigma0 = w / h0)"),
    ("adhesion_range", 0.0, "range of the law, length units: rho (exponential) or h0 (dugdale)"),
    ("adhesion_ramp", 0.0, "Dugdale only: the gap width, length units, over which the stress falls from sigma0 "
                           "to 0, centred on h0, the work unchanged (0: the step). 10-20 spacings times the "
                           "surface's steepest slope brought Johnson's wave's pull-off 4.8-900 times closer to "
                           "Maugis-Dugdale on the same grid"),
    ("adhesion_curvature", True, "certify each result a local minimum to second order: the least curvature of the "
                                 "energy on the feasible directions, kkt.min_curvature (an exponential law costs "
                                 "one or two eigen-solves, 0.07-1.3x the solve's FFT pairs; false: not checked)"),
]


PARAMETERS = ("adhesion_work", "adhesion_stress", "adhesion_range", "adhesion_ramp")


def read_law(values, given):
    """The law of ``-adhesion`` from the option values (None for none), each parameter as the user gave it.

    ``given``: the option names given. Refused: parameters without a law, one the law does not take, both
    Dugdale ranges; a missing or bad value by :func:`roughpetsc.contact.laws.make_law`.
    """
    from ..contact.laws import make_law

    kind = values["adhesion"]
    parameters = [name for name in PARAMETERS if name in given]
    if kind == "none" and parameters:
        raise UserError(f"{', '.join('-' + name for name in parameters)} given without -adhesion: choose a law "
                        "(-adhesion dugdale or exponential), or leave the parameters out")
    if kind == "dugdale" and {"adhesion_stress", "adhesion_range"} <= given:
        raise UserError("-adhesion_stress and -adhesion_range both set the Dugdale range (h0 = w / sigma0): give "
                        "one of them")
    if kind == "exponential" and "adhesion_stress" in given:
        raise UserError("-adhesion_stress: the exponential law takes -adhesion_range (its peak stress is w / rho)")
    with options_named():
        return make_law(kind, *(values[name] if name in given else None for name in PARAMETERS))


def check(settings):
    """Refuse, by option name and before any work, what the command line cannot do with adhesion.

    The solver, the boundary and the hardness are checked where the adhesive problem and its solver are made.
    """
    if settings.control != "displacement":
        raise UserError(f"-{settings.load_option}: adhesive contact is solved under displacement control (it jumps "
                        "in and out of contact under load control); prescribe -gbar or -gbar_list")
    if settings.stress_depths:
        raise UserError("-stress_depths cannot be combined with -adhesion yet (the stresses are those of a contact "
                        "pressure, not of adhesive tractions)")


def summary(law, statistics, E_star):
    """The law, its parameters and Tabor's parameter (of the mean summit radius) for a run's summary."""
    from ..contact.adhesive import summit_radius
    from ..contact.laws import tabor_parameter

    if law is None:
        return {"law": "none"}
    radius = summit_radius(statistics["m4h"])
    return {"law": law.name, "work": law.work, "range": law.range, "peak_stress": law.peak_stress,
            **({"ramp": law.ramp} if getattr(law, "ramp", 0.0) else {}),
            "summit_radius": radius, "tabor": tabor_parameter(law, radius, E_star)}


def header(law, summary):
    """The header line of an adhesive run."""
    return (f"  {law.describe()}; Tabor parameter mu = {summary['tabor']:.4g} "
            f"(summit radius {summary['summit_radius']:.4g})")


def close_cycle(record, say):
    """A path back at its first mean gap is a cycle: its dissipated energy per unit area (pressure x length) into
    the summary, and said."""
    from ..contact.adhesive import dissipated_energy

    steps = record.steps
    gaps = [step["gbar"] for step in steps]
    if len(steps) < 3 or abs(gaps[0] - gaps[-1]) > 1e-12 * abs(gaps[0]):
        return
    energy = dissipated_energy(gaps, [step["pbar"] for step in steps])
    record.summary["adhesion"]["dissipated_energy"] = energy
    say(f"  cycle of {len(steps) - 1} steps: energy dissipated per unit area {energy:.6g} (pressure x length)")
