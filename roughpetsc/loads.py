"""Load paths in p* = pbar / sqrt(m0^p): the load history (7.11) of the dissertation and user lists.

Eq. (7.11) of the dissertation divides p* in (0, 4] into three stages with n1 = 30,
n2 = 45 and n3 = 20 sub-steps::

    p*_i = i D1                              0 < i <= 30
    p*_i = exp(ln 0.2 + D2 (i - 30))        30 < i <= 75
    p*_i = 2 + D3 (i - 75)                  75 < i <= 95

with D2 = 0.0512 and D3 = 0.1. The dissertation prints D1 = 0.067, which contradicts
its own early stage (0, 0.2] with 30 steps (30 * 0.067 = 2.01); following the
erratum in docs/conventions.md we use D1 = 0.2 / 30, so the first stage ends at
exactly 0.2 and joins the second.

The second stage does not end at exactly 2: 0.2 exp(0.0512 * 45) =
0.2 exp(2.304) = 2.00283..., slightly above the third stage's origin 2, so
step 75 (2.00283) and step 76 (2.1) are 0.0972 apart instead of 0.1. The
history is nevertheless strictly increasing and ends at p*_95 = 4. We keep
the dissertation's D2 as printed (D2 = ln(10) / 45 = 0.051168... would end exactly
at 2).
"""

import math

import numpy as np

from .errors import UserError

N1, N2, N3 = 30, 45, 20
DELTA1 = 0.2 / N1          # erratum of (7.11), docs/conventions.md; the dissertation prints 0.067
DELTA2 = 0.0512
DELTA3 = 0.1


def history():
    """The 95 loads p*_1 .. p*_95 of (7.11) (with D1 = 0.2/30), strictly increasing, as an array."""
    i = np.arange(1, N1 + N2 + N3 + 1, dtype=float)
    early = i * DELTA1
    medium = np.exp(math.log(0.2) + DELTA2 * (i - N1))
    late = 2.0 + DELTA3 * (i - N1 - N2)
    return np.where(i <= N1, early, np.where(i <= N1 + N2, medium, late))


def parse(text, option):
    """Loads from an option value: ``history`` (7.11) or a comma-separated list of positive p*.

    Raises :class:`UserError` naming ``-option`` on anything else.
    """
    text = (text or "").strip()
    if text.lower() == "history":
        return history()
    try:
        values = np.array([float(item) for item in text.split(",") if item.strip()])
    except ValueError:
        raise UserError(f"-{option}: expected 'history' or comma-separated positive p* values, got '{text}'") \
            from None
    if values.size == 0:
        raise UserError(f"-{option}: the list of loads is empty")
    if not np.all(np.isfinite(values) & (values > 0)):
        raise UserError(f"-{option}: every p* must be positive and finite, got '{text}'")
    return values
