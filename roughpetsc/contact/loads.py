"""Load paths in p* = pbar / sqrt(m0^p): the load history (7.11) of the dissertation and user lists.

Eq. (7.11) divides p* in (0, 4] into three stages of 30, 45 and 20 sub-steps::

    p*_i = i D1                              0 < i <= 30
    p*_i = exp(ln 0.2 + D2 (i - 30))        30 < i <= 75
    p*_i = 2 + D3 (i - 75)                  75 < i <= 95

with D1 = 0.2 / 30 (erratum of (7.11), docs/conventions.md), D2 = 0.0512 and D3 = 0.1, ending at p*_95 = 4.
"""

import math

import numpy as np

from ..errors import UserError

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


# A list option whose value starts with this reads its items from the file named after it (-pstar_list @loads.txt).
LIST_FILE_PREFIX = "@"


def parse_reals(text, name):
    """The reals of a list option: comma-separated in the value, or, for ``@FILE``, in that file.

    A file holds numbers separated by commas, blanks or line ends, ``#`` starting a comment. An empty item
    (``0.5,,1``), a word or an empty list is refused, naming ``-name`` (and the file).
    """
    text = (text or "").strip()
    if text.startswith(LIST_FILE_PREFIX):
        path = text[len(LIST_FILE_PREFIX):]
        try:
            with open(path) as handle:
                lines = [line.split("#", 1)[0] for line in handle]
        except (OSError, UnicodeDecodeError) as error:
            reason = getattr(error, "strerror", None) or str(error)
            raise UserError(f"-{name} {text}: cannot read the file {path} ({reason})") from None
        items = " ".join(lines).replace(",", " ").split()
        where = f" in the file {path}"
        if not items:
            raise UserError(f"-{name} {text}: the file {path} holds no numbers")
    else:
        if not text:
            raise UserError(f"-{name}: the list is empty")
        items = text.split(",")
        where = f" in '{text}'" if len(text) <= 80 else f" in the list of {len(items)} items"
        if not all(item.strip() for item in items):  # '0.5,,1' or a trailing comma: a value was left out
            raise UserError(f"-{name}: empty item{where} (give comma-separated numbers, e.g. 0.1,0.5,1, or "
                            f"{LIST_FILE_PREFIX}FILE)")
    values = []
    for position, item in enumerate(items, 1):
        try:
            values.append(float(item))
        except ValueError:
            raise UserError(f"-{name}: item {position} '{item.strip()}'{where} is not a number") from None
    return values


def parse(text, option):
    """Loads from an option value: ``history`` (7.11), or a list of positive p*; else :class:`UserError`."""
    text = (text or "").strip()
    if text.lower() == "history":
        return history()
    values = np.array(parse_reals(text, option))
    if not np.all(np.isfinite(values) & (values > 0)):
        bad = values[~(np.isfinite(values) & (values > 0))][0]
        raise UserError(f"-{option}: every p* must be positive and finite, got {bad:g}")
    return values
