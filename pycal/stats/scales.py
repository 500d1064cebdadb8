"""A parameter's scale: linear or log, mapped onto the unit interval [0, 1].

The response models work on u in [0, 1] (u = 0 at the lower bound, 1 at the upper);
a stiffness that spans decades is modelled in log(E), a friction coefficient as is.
Values keep the parameter's own unit (Pa, kg/m3, or none).
"""
import math

import numpy as np


class Scale:
    """Map a parameter x in [lo, hi] (its unit) to u in [0, 1], linearly or in log(x)."""

    def __init__(self, lo, hi, log=False):
        lo, hi = float(lo), float(hi)
        if not lo < hi:
            raise ValueError(f"bounds [{lo}, {hi}]: need lo < hi")
        if log and lo <= 0:
            raise ValueError(f"log scale needs bounds > 0, got [{lo}, {hi}]")
        self.lo, self.hi, self.log = lo, hi, bool(log)
        self._a = math.log(lo) if log else lo
        self._b = math.log(hi) if log else hi

    def to_unit(self, x):
        """u in [0, 1] of x (array or float)."""
        x = np.asarray(x, dtype=float)
        t = np.log(x) if self.log else x
        return (t - self._a) / (self._b - self._a)

    def from_unit(self, u):
        """x (the parameter's unit) of u."""
        t = self._a + np.asarray(u, dtype=float) * (self._b - self._a)
        return np.exp(t) if self.log else t

    def __repr__(self):
        return f"Scale({self.lo:g}, {self.hi:g}, {'log' if self.log else 'linear'})"


def round_significant(x, digits=4):
    """x rounded to `digits` significant digits (a rerun asks for the same jobs)."""
    return float(f"{float(x):.{digits}g}")
