"""The objective of the contact QP (3.41)-(3.44) of the dissertation in scaled units, free of cancellation."""


class QuadraticObjective:
    """The QP objective f = p'Kp/2 + p'(d - h) and its gradient, the gap g = K p + d - h, free of cancellation.

    TAO uses f only through differences, so f is measured from the first point evaluated after
    :meth:`restart` and accumulated from the last evaluated point r: f(x) = f(r) + (x - r)'(g(x) + g(r)) / 2,
    exact for a quadratic. Evaluated directly, f = (p'g + d sum(p) - p'h) / 2 carries a round-off of
    about eps |f| while a step near the solution changes f by about (residual)^2 |f|, so below a
    residual of about 1e-8 every line search and trust-region ratio failed for round-off (TAO's
    DIVERGED_LS_FAILURE at 1.9e-9 on a 128^2 problem). The increment's round-off is relative to
    the step, and after a restart the values TAO compares are as small as the decrease left.

    The last point and its gap are cached: :meth:`gap_of` of the last evaluated point costs nothing.

    ``increments=False`` evaluates f directly instead. ALMM wants that: its augmented-Lagrangian
    updates use the size of f, and with f measured from the start it took 26272 operator
    applications instead of 14976 (128^2, p* = 0.5, 1e-8).
    """

    def __init__(self, problem, increments=True):
        self.problem = problem
        self.increments = increments
        self.separation = 0.0
        self.value = 0.0
        self.point, self.gap, self.step = problem.vec(), problem.vec(), problem.vec()
        self.cached = False

    def restart(self, separation=None):
        """Forget the cache (and set a new separation): the next evaluated point has f = 0."""
        if separation is not None:
            self.separation = separation
        self.cached = False

    def evaluate(self, x, out):
        """``out = g(x)`` (one operator application); returns f(x)."""
        if not self.increments:
            self.problem.gap(x, self.separation, out)
            self.value = 0.5 * (x.dot(out) + self.separation * x.sum() - x.dot(self.problem.heights))
        elif self.cached:
            self.step.waxpy(-1.0, self.point, x)
            increment = self.step.dot(self.gap)
            self.problem.gap(x, self.separation, out)
            self.value += 0.5 * (increment + self.step.dot(out))
        else:
            self.problem.gap(x, self.separation, out)
            self.value = 0.0
        x.copy(self.point)
        if out is not self.gap:
            out.copy(self.gap)
        self.cached = True
        return self.value

    def gap_of(self, x):
        """The gap of ``x`` as this rank's local array, from the cache when ``x`` is the last point."""
        if not (self.cached and x.equal(self.point)):
            self.evaluate(x, self.gap)
        return self.problem.local(self.gap, readonly=True)

    def destroy(self):
        for v in (self.point, self.gap, self.step):
            v.destroy()
