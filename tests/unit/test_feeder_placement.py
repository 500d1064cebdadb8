"""The transfer rig's layer placement (yade_scripts/demlib/feeder.py, pure Python): a
particle that finds no room is left out and handed back (the feeder makes its mass up in
the next layers), the others are placed without overlap, inside the layer's region."""
import random

import numpy as np

from yade_scripts.demlib.feeder import place_layer

WINDOW = {"x_m": 0.0, "z_m": 0.0, "length_m": 0.1, "width_m": 0.1, "height_m": 0.05, "slope": 0.0}


def sphere(r):
    return {"material": "M2", "kind": "sphere", "shape": None, "size_m": 2 * r, "mass_kg": 1.0,
            "bound_radius_m": r}


def test_a_particle_with_no_room_is_left_out_and_the_rest_placed():
    # a 0.1 x 0.1 x 0.05 m layer holds one sphere of radius 0.07 at most: two need 0.14 m
    # between centres, the layer's longest span is sqrt(0.1^2 + 0.05^2 + 0.05^2) = 0.122 m
    # (x 0.1, y 0.05 at most across the periodic side, z 0.05)
    placed, left = place_layer([sphere(0.07), sphere(0.07)], WINDOW, [], random.Random(1), 2000)
    assert len(placed) == 1 and len(left) == 1
    x, y, z = placed[0][1]
    assert -0.05 <= x <= 0.05 and 0 <= y < 0.1 and 0 <= z <= 0.05


def test_small_particles_all_placed_without_overlap_across_the_periodic_side():
    parts = [sphere(0.005) for _ in range(20)]
    placed, left = place_layer(parts, WINDOW, [], random.Random(2), 2000)
    assert left == [] and len(placed) == 20
    c = np.array([p[1] for p in placed])
    d = c[:, None, :] - c[None, :, :]
    d[:, :, 1] -= 0.1 * np.round(d[:, :, 1] / 0.1)
    dist = np.sqrt((d ** 2).sum(-1)) + np.eye(20)
    assert dist.min() >= 0.01


def test_an_existing_particle_filling_the_window_leaves_everything_out():
    existing = [(0.0, 0.05, 0.025, 0.2)]          # one big body over the whole layer
    placed, left = place_layer([sphere(0.005)] * 3, WINDOW, existing, random.Random(3), 200)
    assert placed == [] and len(left) == 3
