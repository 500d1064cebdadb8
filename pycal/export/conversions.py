"""Conversions from this toolkit's contact conventions to other DEM codes' (pure maths).

Each function names both conventions. Ours (docs/contact-models.md): Hertz-Mindlin with a
contact dashpot set from the restitution coefficient; Coulomb friction; an elastic-plastic
rolling spring whose moment is capped at mu_r x R x |Fn|, R the smaller radius of a
particle pair (the particle's own radius on a wall).
"""
import math


def liggghts_rolling_coefficient(mu_r, radius_a_m, radius_b_m=None):
    """LIGGGHTS-PUBLIC `rolling_friction epsd2` caps the rolling torque at
    rmu x reff x |Fn| with reff = Ra Rb / (Ra + Rb) between particles and the particle's
    radius on a wall (src/rolling_model_epsd2.h); ours caps it at mu_r x min(Ra, Rb) x |Fn|.
    The same cap needs rmu = mu_r x min(Ra, Rb) / reff: 2 mu_r between equal spheres,
    mu_r on a wall (radius_b_m None)."""
    if radius_b_m is None:
        return mu_r
    reff = radius_a_m * radius_b_m / (radius_a_m + radius_b_m)
    return mu_r * min(radius_a_m, radius_b_m) / reff


def shear_modulus_pa(youngs_modulus_pa, poisson_ratio):
    """EDEM asks for the shear modulus G (Pa) and Poisson's ratio; we state Young's modulus
    E: G = E / (2 (1 + nu))."""
    return youngs_modulus_pa / (2.0 * (1.0 + poisson_ratio))


def hertz_timestep_s(radius_m, youngs_modulus_pa, density_kg_m3, safety_factor):
    """The time step our rigs run at (s): safety_factor x R sqrt(density / E) of the
    smallest particle sphere (YADE's PWaveTimeStep). LIGGGHTS does not derive one; a
    step of a fraction of the Rayleigh time is its usual rule, which this is below."""
    return safety_factor * radius_m * math.sqrt(density_kg_m3 / youngs_modulus_pa)


def rayleigh_time_s(radius_m, youngs_modulus_pa, poisson_ratio, density_kg_m3):
    """Rayleigh time (s) of a sphere: pi R sqrt(rho / G) / (0.1631 nu + 0.8766), the basis
    of the time-step rules of EDEM and Rocky (typically 10 - 40 % of it)."""
    g = shear_modulus_pa(youngs_modulus_pa, poisson_ratio)
    return math.pi * radius_m * math.sqrt(density_kg_m3 / g) / (0.1631 * poisson_ratio + 0.8766)


def pull_off_force_n(force_fraction, radius_m, density_kg_m3, gravity_m_s2=9.81):
    """Our `force_fraction` cohesion: a constant pull-off force = fraction x the weight of
    the lighter particle of the pair (N); the absolute force another code's constant-force
    model needs."""
    return force_fraction * density_kg_m3 * 4.0 / 3.0 * math.pi * radius_m ** 3 * gravity_m_s2
