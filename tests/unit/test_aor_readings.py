"""Pile readings (pycal.post.aor_readings) on a synthetic cone of known angle: spheres of
5 mm radius stacked on a square grid under z = h - tan(angle) r, the measure settings
scaled to that size (slices of one radius, first layer and apex left out). Every reading
must find the angle within 3 degrees (the staircase of a 10 mm grid)."""
import math

import numpy as np
import pytest

from pycal.post import aor_readings

MEASURE = {"sector_half_width_deg": 45, "silhouette_slice_height_m": 0.005, "exclude_bottom_m": 0.01,
           "exclude_apex_m": 0.005}


def cone_pile(angle_deg, radius=0.005, base_m=0.3):
    t = math.tan(math.radians(angle_deg))
    h = t * base_m / 2
    pts = []
    step = 2 * radius
    for x in np.arange(-base_m / 2, base_m / 2 + 1e-9, step):
        for y in np.arange(-base_m / 2, base_m / 2 + 1e-9, step):
            top = h - t * math.hypot(x, y)
            z = radius
            while z + radius <= top + radius:
                pts.append((x, y, z, radius))
                z += step
    return np.array(pts)


@pytest.mark.parametrize("angle", [30.0, 40.0])
@pytest.mark.parametrize("name", sorted(aor_readings.READINGS))
def test_every_reading_finds_the_angle_of_a_cone(angle, name):
    got = aor_readings.READINGS[name](cone_pile(angle), MEASURE)
    assert abs(got - angle) < 3.0, (name, got)


def test_the_readings_rise_with_the_cone_angle():
    for name, f in aor_readings.READINGS.items():
        assert f(cone_pile(25.0), MEASURE) < f(cone_pile(45.0), MEASURE), name
