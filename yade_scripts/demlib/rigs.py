"""Building blocks shared by several rigs (runs inside YADE)."""
from yade import O

from .jobio import write_csv


def fill_cell(scene):
    """Table + PVC cylinder; pour, settle, strike level at the rim, settle again.
    Returns {'cylinder_ids', 'table_ids', 'settle_time_s', 'steps', 'timestep_s'}."""
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d, h = g["cell_inner_diameter_m"], g["cell_height_m"]
    table_half = g.get("table_radius_m", d)
    table = scene.add_table(table_half, g["table_material"])
    column = p["pour_height_factor"] * h
    cyl = scene.add_cylinder(d, column + 2 * scene.radius, g["cell_facet_segments_count"], g["cell_material"])
    scene.set_domain((-table_half, -table_half, -0.05), (table_half, table_half, column + 0.1))
    scene.pour_cloud(d, 0.0, column, p["pour_porosity_ratio"])
    dt = scene.set_timestep()
    t1 = scene.settle("pour")
    above = [b.id for b in scene.live_spheres() if b.state.pos[2] > p["strike_level_height_m"]]
    scene.remove_spheres(above)
    t2 = scene.settle("strike")
    return {"cylinder_ids": cyl, "table_ids": table, "settle_time_s": t1 + t2,
            "steps": O.iter, "timestep_s": dt}


def write_positions(scene, out_dir, name):
    rows = scene.particle_positions()
    return write_csv(out_dir, name, ["x_m", "y_m", "z_m", "radius_m"], rows)
