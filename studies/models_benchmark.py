"""Time 65-point A*(d*) curves of the early-contact models (targets: < 0.5 s for
GW, Nayak-Bush, Greenwood; < 3 s for BGT) and their accuracy against a much
finer rule.  Writes studies/output/models/benchmark.md."""

import os
import time

import numpy as np

from roughpetsc.models import early

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output", "models")
FINE = {"gw": (40,), "nayak_bush": (40, 40), "greenwood": (40, 40), "bgt": (24, 24, 24)}


def main():
    os.makedirs(OUT, exist_ok=True)
    d = 3 - 0.0469 * np.arange(65)           # the dissertation's 65 separations (7.3)
    lines = ["# Early-contact curve timing (65 points, d* = 3 .. 0)", "",
             "| model | alpha_h | time [s] (best of 3) | max rel. error vs fine rule |", "|---|---|---|---|"]
    for name in ("gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic"):
        for a in (2.0, 10.0):
            best = np.inf
            for _ in range(3):
                t = time.perf_counter()
                A, p = early(name, d, a)
                best = min(best, time.perf_counter() - t)
            if name in FINE:
                sub = d[::8]
                Af, pf = early(name, sub, a, elements=FINE[name])
                err = max(np.max(np.abs(A[::8] / Af - 1)), np.max(np.abs(p[::8] / pf - 1)))
                err = "%.1e" % err
            else:
                err = "closed form"
            lines.append("| %s | %g | %.4f | %s |" % (name, a, best, err))
            print(lines[-1])
    with open(os.path.join(OUT, "benchmark.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
