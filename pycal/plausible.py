"""Plausible ranges of material and boundary values, in one place, with their reason.

A value outside its range is a config error (file, key, value, range): it is a typo or
a unit slip (friction 20, density in g/cm3, E in MPa), not an experiment worth hours
of YADE. The ranges are wide: every calibration scale of the shipped study lies inside.
"""
import math

# key (the last part of a dotted key) -> (low, high, reason); both ends allowed
RANGES = {
    "density_kg_m3": (300.0, 23000.0, "solids lie between pumice (~300 kg/m3) and osmium (22600 kg/m3)"),
    "diameter_m": (1.0e-4, 1.0, "a particle between 0.1 mm and 1 m"),
    "min_size_m": (1.0e-4, 1.0, "a particle between 0.1 mm and 1 m"),
    "max_size_m": (1.0e-4, 1.0, "a particle between 0.1 mm and 1 m"),
    "youngs_modulus_pa": (1.0e5, 1.2e12, "from soft rubber (1e5 Pa: below, overlaps under self weight exceed the "
                          "overlap limit) to diamond (1.2e12 Pa); a value in MPa or GPa is a unit slip"),
    "poisson_ratio": (0.0, 0.5, "rock, ore, steel and polymers lie in 0 - 0.5"),
    "friction_coefficient": (0.0, 2.0, "sliding friction of rock, ore and steel contacts is 0.1 - 1.2; above 2 "
                             "it is not friction but a typo"),
    "rolling_resistance_coefficient": (0.0, 2.0, "the rolling moment is capped at mu_r x R x |Fn|: above 1 a "
                                       "sphere's contact already carries more than tipping it over needs"),
    "restitution_coefficient": (0.05, 1.0, "below ~0.05 the contact dashpot is near critical and the solver "
                                "may become unstable"),
    "force_fraction": (0.0, 1000.0, "pull-off / particle weight: above 1000 a particle would hang under 1000 g"),
    "pressure_fraction": (0.0, 10.0, "pull-off / largest compressive force the contact carried"),
    "stiffness_fraction": (0.0, 1.0, "pull-off / the largest elastic force of the contact"),
    "adhesive_distance_m": (0.0, 0.1, "an adhesion reach of at most 0.1 m"),
    "surface_tension_n_m": (0.0, 100.0, "an effective value: coarse spheres standing for fines carry more than "
                            "water's 0.072 N/m (one bridge holds a 25 mm ore sphere from 2.8 N/m on)"),
}


def check(key, value):
    """None if `value` is a finite number inside the plausible range of `key` (its last
    dotted part; keys without a range: only finite), else the reason it is refused."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"{value!r} must be a number"
    if not math.isfinite(value):
        return f"{value!r} must be a finite number"
    rule = RANGES.get(str(key).rsplit(".", 1)[-1])
    if rule is None:
        return None
    lo, hi, reason = rule
    if not lo <= value <= hi:
        return f"{value:g} is outside the plausible range {lo:g} - {hi:g} ({reason}; pycal/plausible.py)"
    return None
