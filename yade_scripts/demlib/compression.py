"""Load-step recording shared by the compression rigs ccs.py, ccs_expansion.py, ucs.py
(runs inside YADE). The per-step derived arrays (stiffness, force balance) and the
CSV/PNG outputs come from pycal.post.compression (pure Python).
"""
import math
import os

from yade import O

from . import loading, rigs
from .jobio import RigFailure

from pycal.post import compression as post  # pure Python, no YADE


def vertical_force(ids):
    """Sum of the z components of the forces on the bodies `ids` (N), from the last step."""
    return sum(O.forces.f(i)[2] for i in ids)


def max_overlap(scene):
    """Largest overlap (penetration depth, m) of any real contact of the scene."""
    return max((i.geom.penetrationDepth for i in scene.interactions()), default=0.0)


def top_of_bulk(scene):
    """Height of the highest particle top (m)."""
    return max(b.state.pos[2] + b.shape.radius for b in scene.live_spheres())


class StepRecorder:
    """Runs load steps and records per step the plate, bottom and wall forces, the plate
    position, strain, bulk density and solid fraction.

    mass_in_volume(z_plate) -> (mass kg, volume m3) of the bulk the plate compresses
    (CCS: all particles in the cell cross-section x height; UCS: see ucs.py)."""

    FIELDS = ("branch", "target_stress_pa", "stress_pa", "strain", "plate_force_n", "plate_position_m",
              "bulk_density_kg_m3", "solid_fraction", "bottom_force_n", "wall_force_n",
              "plate_contacts_count", "step_time_s", "step_steps_count", "step_weight_n",
              "max_overlap_ratio")

    def __init__(self, scene, plate, h0, table_ids, wall_ids, mass_in_volume, tolerance_ratio, every=None):
        self.scene, self.plate, self.h0 = scene, plate, h0
        self.table_ids, self.wall_ids = list(table_ids), list(wall_ids)
        self.mass_in_volume = mass_in_volume
        self.tol = tolerance_ratio
        self.every = every
        self.rho_p = scene.job["materials"][scene.material]["particles"]["density_kg_m3"]
        self.data = {k: [] for k in self.FIELDS}

    def step(self, target, branch):
        """Phase: load (or unload) to `target` (Pa) and record the step. Returns its row."""
        rec = yield from loading.load_to(self.scene, self.plate, target, self.tol, every=self.every)
        z = self.plate.position_m()
        mass, volume = self.mass_in_volume(z)
        rho_b = mass / volume
        row = {"branch": branch, "target_stress_pa": target, "stress_pa": rec["stress_pa"],
               "strain": (self.h0 - z) / self.h0, "plate_force_n": rec["force_n"], "plate_position_m": z,
               "bulk_density_kg_m3": rho_b, "solid_fraction": rho_b / self.rho_p,
               "bottom_force_n": -vertical_force(self.table_ids),
               "wall_force_n": -vertical_force(self.wall_ids),
               "plate_contacts_count": rec["contacts_count"], "step_time_s": rec["time_s"],
               "step_steps_count": rec["steps"],
               "step_weight_n": self.scene.particle_mass_total() * self.scene.g,
               "max_overlap_ratio": max_overlap(self.scene) / self.scene.radius}
        for k in self.FIELDS:
            self.data[k].append(row[k])
        print(f"{branch} step {target:g} Pa: stress {rec['stress_pa']:.1f} Pa, strain {row['strain']:.4f}, "
              f"bulk density {rho_b:.0f} kg/m3, plate {rec['force_n']:.2f} N, bottom {row['bottom_force_n']:.2f} N, "
              f"wall {row['wall_force_n']:.2f} N, {rec['contacts_count']} plate contacts, "
              f"max overlap {row['max_overlap_ratio']:.3f} R, {rec['time_s']:.3f} s simulated", flush=True)
        return row


def finish(job, out_dir, scene, recorder, extra):
    """Measurements dict (result.json) with the derived arrays, plus CSV and PNG files."""
    m = dict(recorder.data)
    mass = scene.particle_mass_total()
    m.update({"n_particles": len(scene.live_spheres()), "particle_mass_kg": mass,
              "particle_weight_n": mass * scene.g, "initial_height_m": recorder.h0,
              "particle_density_kg_m3": recorder.rho_p,
              "lab_sample": job["materials"][job["material"]].get("lab_sample"),
              "rig": job["rig"], "material": job["material"], "seed": job["seed"], "job": job})
    m.update(extra)
    post.derived_arrays(m)
    worst = max(abs(e) for e in m["force_balance_error"])
    m["force_balance_error_max"] = worst
    for k, rho in enumerate(m["bulk_density_kg_m3"]):
        if rho > recorder.rho_p:
            raise RigFailure(f"blow-up: bulk density {rho:.0f} kg/m3 at step {k + 1} exceeds the particle "
                             f"density {recorder.rho_p:.0f} kg/m3 (particles overlap or passed the plate)")
    out = post.write_outputs(m, out_dir)      # an error here is a bug: the run fails, nothing is hidden
    m["misfits"] = out["misfits"]
    m["output_files"] = [os.path.basename(f) for f in out["files"]]
    for k in ("rig", "material", "seed", "job"):
        m.pop(k)
    return m


def confined_setup(scene):
    """Phase: fill the cell and put the servo plate (a square lid covering the cell) on it.
    Returns (cell, plate, recorder, extra result entries)."""
    cell = yield from rigs.fill_cell(scene)
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d = g["cell_inner_diameter_m"]
    area = math.pi * d * d / 4.0
    h0 = top_of_bulk(scene)
    ids = loading.add_plate(scene, h0 + p["plate_start_gap_m"], d, g["plate_material"])
    plate = loading.ServoPlate(scene, ids, area, p["plate_speed_max_m_s"], p["servo_relaxation_time_s"],
                               p["servo_control_interval_s"], floor_z=0.0, footprint_radius_m=d / 2.0)

    def mass_in_volume(z):
        return scene.particle_mass_total(), area * z

    rec = StepRecorder(scene, plate, h0, cell["table_ids"], cell["cylinder_ids"],
                       mass_in_volume, p["step_tolerance_ratio"])
    extra = {"reference_area_m2": area, "fill_settle_time_s": cell["settle_time_s"],
             "timestep_s": cell["timestep_s"],
             "initial_bulk_density_kg_m3": scene.particle_mass_total() / (area * h0),
             "strain_reference": "h0 = highest particle top before loading (plate first-contact height)"}
    return cell, plate, rec, extra
