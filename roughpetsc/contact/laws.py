"""Adhesive interaction laws: an energy per unit area phi(g) of the local gap g >= 0.

``phi(0) = -w``, w the work of adhesion (pressure x length units), ``phi -> 0`` beyond the law's range (the
laws of chapter 6). ``force(g) = phi'(g) >= 0`` is the tensile stress at gap g, ``curvature(g) = phi''(g)``.

``Dugdale(work, stress)``: sigma0 up to h0 = w / sigma0, ``phi = -w + sigma0 g`` for g < h0 (Maugis,
J. Colloid Interface Sci. 150, 1992). ``Exponential(work, range_)``: ``phi = -w exp(-g / rho)``, peak stress
w / rho (Rey, Anciaux and Molinari, Comput. Mech. 60, 2017).
"""

import copy
import math

import numpy as np

from ..errors import ParameterError
from . import loops

LAWS = ("none", "dugdale", "exponential")


def _positive(name, value, what):
    """``value`` as a float; :class:`ParameterError` naming ``name`` unless given, positive and finite."""
    if value is None:
        raise ParameterError(name, f"the {what} is missing: give a positive value")
    if not (value > 0 and math.isfinite(value)):
        raise ParameterError(name, f"the {what} must be positive and finite, got {value:g}")
    return float(value)


class Dugdale:
    """The Maugis-Dugdale law: tensile stress ``stress`` (pressure units) up to the range h0 = w / stress.

    ``ramp`` (length units, 0 by default) spreads the stress's fall over the gaps h0 -+ ramp / 2, linearly, with
    the work unchanged: phi is then C^1 and concave on the ramp (phi'' = -sigma0 / ramp). On a grid a node's
    stress then follows where the cohesive zone ends inside its cell, instead of switching whole as the end
    crosses the node. With a ramp of 10-20 spacings' change of the gap at the surface's steepest slope, the
    pull-off of Johnson's wave is 4.8-900 times closer to Maugis-Dugdale's on the same grid (ten cases)
    (studies/output/adhesion/wave.md). The ramp is a law of its own, differing from Maugis' by an amount that
    vanishes with ramp / h0; shrunk with the spacing it tends to Maugis' law as the grid is refined. Shrunk as the
    square root of the spacing instead (ramp / h0 proportional to h^(1/2), so that it spans more cells on a finer
    grid), the wave's pull-off converges to Maugis-Dugdale's at first order where the step law's error falls at
    order 0.84-0.95: at h0 = 0.03 h (Maugis lambda 12.7) it is off by 1.25, 0.51, 0.32, 0.13 and 0.053 % on
    4096 to 65536 nodes (ramp / h0 from 1.45 to 0.36), against the step law's 1.6 % on 131072.
    """

    name = "dugdale"

    def __init__(self, work, stress, ramp=0.0):
        self.work = _positive("adhesion_work", work, "work of adhesion")
        self.stress = _positive("adhesion_stress", stress, "Dugdale stress")
        self.range = self.work / self.stress
        if not (ramp >= 0 and math.isfinite(ramp)):
            raise ParameterError("adhesion_ramp", f"the ramp of the Dugdale stress must be 0 or positive and "
                                                  f"finite, got {ramp:g}")
        if ramp >= 2 * self.range:
            raise ParameterError("adhesion_ramp", f"the ramp ({ramp:g}) must be narrower than twice the range "
                                                  f"h0 = w / sigma0 = {self.range:g}: it is centred on h0 and "
                                                  "starts at a positive gap")
        self.ramp = float(ramp)
        self.ramp_start = self.range - 0.5 * self.ramp
        self.curved = self.ramp > 0  # phi'' = 0 wherever it exists, except on a ramp

    @property
    def peak_stress(self):
        return self.stress

    def scaled(self, length, pressure):
        """The same law in units where lengths are ``length`` and pressures ``pressure`` (checked as given, not
        again: a ramp of just under 2 h0 stays one after rounding)."""
        law = copy.copy(self)
        law.work, law.stress = self.work / (length * pressure), self.stress / pressure
        law.range, law.ramp, law.ramp_start = self.range / length, self.ramp / length, self.ramp_start / length
        return law

    def energy(self, gap):
        if not self.ramp:
            return np.minimum(self.stress * gap - self.work, 0.0)
        across = np.clip(gap - self.ramp_start, 0.0, self.ramp)
        return (np.minimum(self.stress * gap - self.work, -0.5 * self.stress * self.ramp)
                + self.stress * (across - across * across / (2 * self.ramp)))

    def energy_change(self, gap, trial):
        """``phi(trial) - phi(gap)`` node by node, as sigma0 (min(trial, h0) - min(gap, h0)) (no w to cancel)."""
        if not self.ramp:
            return self.stress * (np.minimum(trial, self.range) - np.minimum(gap, self.range))
        gap, trial = np.broadcast_arrays(np.asarray(gap, dtype=float), np.asarray(trial, dtype=float))
        out = np.empty(gap.shape)
        loops.ramped_dugdale_changes(gap.ravel(), trial.ravel(), self.stress, self.ramp_start, self.ramp,
                                     out.ravel())
        return out

    def energy_change_along(self, gap, direction, step):
        """The local sum of :meth:`energy_change` from ``gap`` to ``gap - step direction``, in one pass."""
        if not self.ramp:
            return loops.dugdale_change_along(gap, direction, step, self.stress, self.range)
        return loops.ramped_dugdale_change_along(gap, direction, step, self.stress, self.ramp_start, self.ramp)

    def curvature_along(self, gap, direction):
        """The local sum of phi''(gap) direction^2: 0 off the ramp."""
        if not self.ramp:
            return 0.0
        return loops.ramped_dugdale_curvature_along(gap, direction, self.stress, self.ramp_start, self.ramp)

    def force(self, gap, out=None):
        if not self.ramp:
            return np.multiply(np.less(gap, self.range), self.stress, out=out)
        out = np.subtract(self.ramp_start + self.ramp, gap, out=out)
        np.clip(out, 0.0, self.ramp, out=out)
        out *= self.stress / self.ramp
        return out

    def curvature(self, gap, out=None):
        if out is None:
            out = np.zeros_like(gap, dtype=float)
        else:
            out[...] = 0.0
        if self.ramp:
            on_ramp = (gap > self.ramp_start) & (gap < self.ramp_start + self.ramp)
            out[on_ramp] = -self.stress / self.ramp
        return out

    def describe(self):
        ramp = f", its stress falling over gaps h0 -+ {0.5 * self.ramp:.6g}" if self.ramp else ""
        return f"Dugdale law: w = {self.work:.6g}, sigma0 = {self.stress:.6g}, range h0 = {self.range:.6g}{ramp}"


class Exponential:
    """``phi = -w exp(-g / rho)``: work ``work``, range ``range_`` (length units), peak stress w / rho."""

    name = "exponential"
    curved = True

    def __init__(self, work, range_):
        self.work = _positive("adhesion_work", work, "work of adhesion")
        self.range = _positive("adhesion_range", range_, "range of adhesion")

    @property
    def peak_stress(self):
        return self.work / self.range

    def scaled(self, length, pressure):
        return Exponential(self.work / (length * pressure), self.range / length)

    def energy(self, gap):
        return -self.work * np.exp(-gap / self.range)

    def energy_change(self, gap, trial):
        """``phi(trial) - phi(gap)`` node by node, without cancellation for close gaps and without a positive
        exponent, so no range however short overflows (:func:`~roughpetsc.contact.loops.exponential_changes`).

        Below g = 0 phi continues along its tangent at 0 (as Dugdale's does): a long step gains bounded energy.
        """
        gap, trial = np.broadcast_arrays(np.asarray(gap, dtype=float), np.asarray(trial, dtype=float))
        out = np.empty(gap.shape)
        loops.exponential_changes(gap.ravel(), trial.ravel(), self.work, self.range, out.ravel())
        return out

    def energy_change_along(self, gap, direction, step):
        """The local sum of :meth:`energy_change` from ``gap`` to ``gap - step direction``, in one pass."""
        return loops.exponential_change_along(gap, direction, step, self.work, self.range)

    def curvature_along(self, gap, direction):
        """The local sum of phi''(gap) direction^2, in one pass."""
        return loops.exponential_curvature_along(gap, direction, self.work, self.range)

    def force(self, gap, out=None):
        out = np.divide(gap, -self.range, out=out)
        np.exp(out, out=out)
        out *= self.peak_stress
        return out

    def curvature(self, gap, out=None):
        out = np.multiply(gap, -1.0 / self.range, out=out)
        np.exp(out, out=out)
        out *= -self.peak_stress / self.range
        return out

    def describe(self):
        return (f"exponential law: w = {self.work:.6g}, range rho = {self.range:.6g}, "
                f"peak stress w/rho = {self.peak_stress:.6g}")


def make_law(kind, work=None, stress=None, range_=None, ramp=None):
    """The law ``kind`` ("none", "dugdale", "exponential") from its parameters (None for "none").

    Dugdale takes ``stress`` (sigma0) or ``range_`` (h0, then sigma0 = w / h0), and optionally ``ramp``;
    exponential takes ``range_``.
    """
    if ramp is not None and kind != "dugdale":
        raise ParameterError("adhesion_ramp", "the ramp belongs to the Dugdale law: give -adhesion dugdale, or "
                                              "leave -adhesion_ramp out")
    if kind == "none":
        return None
    if kind == "dugdale":
        if stress is not None and range_ is not None:
            raise ParameterError("adhesion_range", "give the Dugdale stress or the range, not both (h0 = w / sigma0)")
        if stress is None and range_ is None:
            raise ParameterError("adhesion_stress", "the Dugdale law needs its stress sigma0 or its range h0 = w / "
                                                    "sigma0: give one")
        if range_ is not None:
            stress = _positive("adhesion_work", work, "work of adhesion") / \
                _positive("adhesion_range", range_, "range of adhesion")
        return Dugdale(work, stress, 0.0 if ramp is None else ramp)
    if kind == "exponential":
        return Exponential(work, range_)
    raise ParameterError("adhesion", f"the adhesion law is one of {', '.join(LAWS)}, got '{kind}'")


def tabor_parameter(law, radius, E_star):
    """Tabor's parameter mu = (R w^2 / (E*^2 z0^3))^(1/3), z0 the law's range: large mu JKR, small mu DMT."""
    return (radius * law.work ** 2 / (E_star ** 2 * law.range ** 3)) ** (1.0 / 3.0)

