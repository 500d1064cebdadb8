"""Rig 1: cell fill. Pour loosely into the 145 x 95 mm cell, settle, strike level, settle.

Bulk density = mass of the particles left after striking / cell volume (pi D^2/4 x H):
particles whose centre is above the rim are removed (configs/rigs/fill.yaml).
A batch job (several seeds) fills one cell per seed side by side (demlib.replicas).
Run: yade -j1 -x -n yade_scripts/fill.py job.json
"""
import math

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import rigs, replicas


def procedure(scene, out_dir):
    """The fill of one seed (a generator: demlib.phases); returns the measurements."""
    job = scene.job
    cell = yield from rigs.fill_cell(scene)
    g = scene.rig["geometry"]
    volume = math.pi * g["cell_inner_diameter_m"] ** 2 / 4.0 * g["cell_height_m"]
    mass = scene.particle_mass_total()
    n = len(scene.live_spheres())
    rho_p = job["materials"][job["material"]]["particles"]["density_kg_m3"]
    rigs.write_positions(scene, out_dir, "fill_particles.csv")
    return {
        "n_particles": n,
        "mass_kg": mass,
        "particle_density_kg_m3": rho_p,
        "bulk_density_kg_m3": mass / volume,
        "solid_fraction": mass / volume / rho_p,
        "cell_volume_m3": volume,
        "fill_height_rule": scene.rig["measure"]["fill_height_rule"],
        "settle_time_s": cell["settle_time_s"],
        "steps": cell["steps"],
        "timestep_s": cell["timestep_s"],
    }


main = replicas.rig_main(procedure, half_width_m=rigs.table_half_width)
run_rig(main)
