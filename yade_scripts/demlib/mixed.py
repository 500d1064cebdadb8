"""Mixed particle sets (M1 clumps + sphere materials) in one scene (runs inside YADE;
the planning and placement functions are pure Python and run anywhere).

A job of a material set (pycal.jobs.resolve_set_job) carries job["material_set"] with
each component's mass_fraction (and, for clump materials, the size classes used);
a job of one material is treated as a set of that one material.

Fill generator (plan_fill + place_in_column, reproducible by the job's seed):
1. Generated mass M = fill_overfill_ratio x fill_solid_fraction x cell volume x the
   mixture's particle density 1 / sum(w_c / rho_c) (w_c = mass fraction).
2. Component c gets the target w_c M. Sphere material: n = round(target / particle
   mass). Clump material: the target is split over its size classes (by their
   mass_percent) and each class over the shapes (by shape_percent); per (class, shape)
   lumps of size uniform in [min_size, max_size) are drawn one by one while the placed
   mass is below the target; a lump that fits is added; the lump that would pass the
   target is added with probability (missing mass / its mass) and ends the shape
   (stochastic rounding: the expected placed mass equals the target, so the mean over
   seeds has the requested fractions). Sphere materials are within half a particle's
   mass of their target, each M1 shape within one lump's mass (at most the heaviest
   lump of the class). In a 145 x 95 mm cell the M1 share is ~0.1 kg while one 50 mm
   rounded lump weighs 0.28 kg: a fill holds 0 - 4 lumps and its M1 fraction scatters
   from seed to seed around the request.
3. Random sequential placement, largest bounding sphere first: centre uniform in a
   vertical cylinder (the inscribed radius of the cell's facet polygon, R cos(pi / n),
   less the bounding radius and a 1 % gap) from the table up to a column height H = total bounding-sphere volume /
   (pour_solid_fraction x cell cross-section); a position is accepted when the
   bounding sphere overlaps no placed one; after pour_max_attempts_count failures
   H grows by 10 %. Clumps get a uniform random orientation. No member touches
   another particle or the wall at the start.
"""
import math
import random

import numpy as np

from . import clumps

# ---------------------------------------------------------------- planning (pure Python)


def components(job):
    """[(material name, mass fraction, size class names or None)] of a job."""
    mset = job.get("material_set")
    if mset is None:
        return [(job["material"], 1.0, None)]
    return [(name, c["mass_fraction"], c.get("size_classes")) for name, c in mset["components"].items()]


def particle_density(mat):
    return float(mat["particles"]["density_kg_m3"])


def sphere_mass(mat):
    return particle_density(mat) * 4.0 / 3.0 * math.pi * (mat["particles"]["diameter_m"] / 2.0) ** 3


def mixture_density(job):
    """Particle density of the mixture by mass fractions: 1 / sum(w_c / rho_c) (kg/m3)."""
    return 1.0 / sum(w / particle_density(job["materials"][name]) for name, w, _ in components(job))


def fill_mass(job):
    """Generated mass M (kg) of the fill (module doc, step 1)."""
    g, p = job["rig_config"]["geometry"], job["rig_config"]["procedure"]
    v_cell = math.pi * (g["cell_inner_diameter_m"] / 2.0) ** 2 * g["cell_height_m"]
    return p["fill_overfill_ratio"] * p["fill_solid_fraction"] * v_cell * mixture_density(job)


def _clump_classes(mat, names):
    classes = mat["particles"]["size_classes"]
    if names is not None:
        classes = [c for c in classes if c["name"] in names]
    return classes


def plan_fill(job, total_mass, rng):
    """Particles to place: list of dicts {material, kind ('sphere' | 'clump'), shape
    (clump shape name or None), size_m (sphere diameter or lump size), mass_kg,
    bound_radius_m}, and the targets {material: kg} and {(material, class, shape): kg}."""
    out, targets, sub_targets = [], {}, {}
    # names in sorted order (materials, classes by size, shapes): the draws must not depend
    # on the order of keys in job.json (the runner writes it with sorted keys)
    for name, w, class_names in sorted(components(job)):
        mat = job["materials"][name]
        target = w * total_mass
        targets[name] = target
        if mat["particles"]["shape"] == "sphere":
            m = sphere_mass(mat)
            d = mat["particles"]["diameter_m"]
            n = int(math.floor(target / m + 0.5))
            out += [{"material": name, "kind": "sphere", "shape": None, "size_m": d, "mass_kg": m,
                     "bound_radius_m": d / 2.0} for _ in range(n)]
            continue
        classes = _clump_classes(mat, class_names)
        class_total = sum(c["mass_percent"] for c in classes)
        rho = particle_density(mat)
        for cl in sorted(classes, key=lambda c: (c["min_size_m"], c["name"])):
            for shape, pct in sorted(cl["shape_percent"].items()):
                t = target * cl["mass_percent"] / class_total * pct / 100.0
                sub_targets[(name, cl["name"], shape)] = t
                scfg = mat["particles"]["shapes"][shape]
                placed = 0.0
                while placed < t:
                    size = rng.uniform(cl["min_size_m"], cl["max_size_m"])
                    m = clumps.lump_mass(scfg, size, rho)
                    # stochastic rounding: a lump heavier than what is missing is taken with
                    # probability (missing / its mass), so the expected placed mass is the target
                    if placed + m > t and rng.random() >= (t - placed) / m:
                        break
                    centres, r = clumps.shape_members(scfg, size)
                    out.append({"material": name, "kind": "clump", "shape": shape, "size_m": size,
                                "mass_kg": m, "bound_radius_m": clumps.bounding_radius(centres, r),
                                "size_class": cl["name"]})
                    placed += m
    return out, targets, sub_targets


def place_in_column(particles, cell_diameter, solid_fraction, max_attempts, rng, z_bottom=0.0,
                    facet_segments=None):
    """Random sequential placement (module doc, step 3). Returns (placements, column
    height): placements = [(particle dict, (x, y, z), rotation 3x3 or None)] in the
    order placed (largest bounding radius first). facet_segments: the cell wall is a
    polygon of that many facets with its corners on the circle (geom.facetCylinder)."""
    if not particles:
        raise ValueError("nothing to place")
    R = cell_diameter / 2.0
    if facet_segments:
        R *= math.cos(math.pi / facet_segments)
    order = sorted(range(len(particles)), key=lambda i: -particles[i]["bound_radius_m"])
    v_bound = sum(4.0 / 3.0 * math.pi * p["bound_radius_m"] ** 3 for p in particles)
    height = v_bound / (solid_fraction * math.pi * R ** 2)
    pos = np.zeros((len(particles), 3))
    rad = np.zeros(len(particles))
    n = 0
    placements = []
    for i in order:
        p = particles[i]
        b = p["bound_radius_m"]
        r_max = R - 1.01 * b
        if r_max < 0:
            raise ValueError(f"a {p['material']} particle (bounding radius {b:.4f} m) does not fit in the cell")
        while True:
            ok = False
            for _ in range(max_attempts):
                rr = r_max * math.sqrt(rng.random())
                phi = 2.0 * math.pi * rng.random()
                z = z_bottom + b + (height - 2.0 * b) * rng.random() if height > 2 * b else z_bottom + b
                c = np.array([rr * math.cos(phi), rr * math.sin(phi), z])
                if n == 0 or np.all(np.sum((pos[:n] - c) ** 2, axis=1) >= (rad[:n] + b) ** 2):
                    ok = True
                    break
            if ok:
                break
            height *= 1.1
        rot = clumps.random_rotation(rng)[0] if p["kind"] == "clump" else None
        pos[n], rad[n] = c, b
        n += 1
        placements.append((p, tuple(float(v) for v in c), rot))
    top = float(np.max(pos[:n, 2] + rad[:n])) - z_bottom
    return placements, max(height, top)


def generate(job, rng=None):
    """plan_fill + place_in_column with the job's rig config and seed. Returns
    {'placements', 'column_height_m', 'total_mass_kg', 'targets_kg', 'shape_targets_kg'}."""
    p, g = job["rig_config"]["procedure"], job["rig_config"]["geometry"]
    rng = rng or random.Random(job["seed"])
    total = fill_mass(job)
    parts, targets, sub = plan_fill(job, total, rng)
    placements, height = place_in_column(parts, g["cell_inner_diameter_m"], p["pour_solid_fraction"],
                                         p["pour_max_attempts_count"], rng,
                                         facet_segments=g["cell_facet_segments_count"])
    return {"placements": placements, "column_height_m": height, "total_mass_kg": total,
            "targets_kg": targets, "shape_targets_kg": sub}


def placed_masses(placements):
    """{material: kg} and {(material, class, shape): kg} of placements."""
    by_mat, by_shape = {}, {}
    for p, _, _ in placements:
        by_mat[p["material"]] = by_mat.get(p["material"], 0.0) + p["mass_kg"]
        if p["kind"] == "clump":
            k = (p["material"], p["size_class"], p["shape"])
            by_shape[k] = by_shape.get(k, 0.0) + p["mass_kg"]
    return by_mat, by_shape


# ---------------------------------------------------------------- the scene (YADE)

def _scene_class():
    """MixedScene is defined on first use so that this module imports without YADE."""
    from yade import O, utils, Vector3
    from .scene import Scene
    from .jobio import RigFailure

    class MixedScene(Scene):
        """Scene with several particle materials, clumps among them.

        sphere_ids = every particle sphere: free spheres and clump members (so the
        shared rig blocks - lift_cylinder, settle_pile, highest_top, remove_fallen -
        see members as particles); clumps = {clump id: [member ids]}. Dynamics
        (kinetic energy, unbalanced force, mass) use the free spheres and the clumps.
        Scene.radius = the smallest sphere radius of the set's sphere materials (the
        length scale of the rest criterion and of the fall-off threshold)."""

        def __init__(self, job):
            Scene.__init__(self, job)
            self.free_ids = []
            self.clumps = {}
            self.member_of = {}
            self.name_of_mat = {v: k for k, v in self.contact.mat_id.items()}

        def length_scale(self):
            """The smallest sphere radius of the set's sphere materials (clumps only: the
            smallest member radius of any lump)."""
            job = self.job
            radii = [self.contact.radius(n) for n in job["materials"] if not self.contact.is_clump(n)]
            if not radii:
                radii = [clumps.shape_members(s, c["min_size_m"])[1]
                         for n in job["materials"] for c in job["materials"][n]["particles"]["size_classes"]
                         for s in job["materials"][n]["particles"]["shapes"].values()]
            return min(radii)

        # ---------- particles
        def add_placements(self, placements):
            """Create the generated particles (mixed.generate placements)."""
            for p, pos, rot in placements:
                mat = self.job["materials"][p["material"]]
                mid = self.contact.mat_id[p["material"]]
                if p["kind"] == "sphere":
                    i = O.bodies.append(utils.sphere(pos, p["size_m"] / 2.0, material=mid))
                    self.free_ids.append(i)
                    self.sphere_ids.append(i)
                else:
                    scfg = mat["particles"]["shapes"][p["shape"]]
                    cid, mids = clumps.make_clump(scfg, p["size_m"], particle_density(mat), mid, pos, rot)
                    self.clumps[cid] = mids
                    for m in mids:
                        self.member_of[m] = cid
                    self.sphere_ids.extend(mids)

        def remove_spheres(self, ids):
            """Erase particles; a clump member takes its whole clump with it."""
            ids = set(ids)
            gone = set()
            for cid in {self.member_of[i] for i in ids if i in self.member_of}:
                O.bodies.erase(cid, True)
                mids = self.clumps.pop(cid)
                gone |= set(mids)
                for m in mids:
                    self.member_of.pop(m, None)
            for i in ids:
                if i not in gone:
                    O.bodies.erase(i)
                    gone.add(i)
            self.world.erased_count += 1
            self.free_ids = [i for i in self.free_ids if i not in gone]
            self.sphere_ids = [i for i in self.sphere_ids if i not in gone]

        def dynamic_bodies(self):
            return [O.bodies[i] for i in self.free_ids] + [O.bodies[c] for c in self.clumps]

        # ---------- rest and guards
        def kinetic_energy_ratio(self):
            bodies = self.dynamic_bodies()
            if not bodies:
                return 0.0
            rotation = self.num["rest_kinetic_energy"] == "total"
            ke = sum(clumps.clump_kinetic_energy(b) if rotation else 0.5 * b.state.mass * b.state.vel.squaredNorm()
                     for b in bodies)
            ref = sum(b.state.mass for b in bodies) * self.g * 2.0 * self.radius
            return ke / ref

        def body_force(self, b):
            """Net contact force on a free sphere, or on a clump = the sum over its members
            (N). (NewtonIntegrator of the OpenMP build also writes that sum into the
            clump's own slot of O.forces; the members' sum does not depend on it. No rig
            applies a force to a clump body directly.)"""
            if b.id not in self.clumps:
                return O.forces.f(b.id)
            f = Vector3(0, 0, 0)
            for m in self.clumps[b.id]:
                f += O.forces.f(m)
            return f

        def overlap_limit_m(self, interaction):
            """The overlap limit relative to the smaller sphere of the pair (clump members vary)."""
            radii = [getattr(O.bodies[k].shape, "radius", None) for k in (interaction.id1, interaction.id2)]
            return self.num["max_overlap_fraction"] * min(x for x in radii if x is not None)

        # ---------- measurements
        def particle_mass_total(self):
            return sum(b.state.mass for b in self.dynamic_bodies())

        def component_masses(self):
            """{material: kg} of the particles in the scene."""
            out = {n: 0.0 for n in self.job["materials"]}
            for i in self.free_ids:
                b = O.bodies[i]
                out[self.name_of_mat[b.material.id]] += b.state.mass
            for cid, mids in self.clumps.items():
                out[self.name_of_mat[O.bodies[mids[0]].material.id]] += O.bodies[cid].state.mass
            return out

        def particle_rows(self):
            """[(x, y, z, r, material, clump id or -1)] of every particle sphere."""
            rows = []
            for b in self.live_spheres():
                rows.append((b.state.pos[0], b.state.pos[1], b.state.pos[2], b.shape.radius,
                             self.name_of_mat[b.material.id], self.member_of.get(b.id, -1)))
            return rows

    return MixedScene


_MIXED_SCENE = None


def MixedScene(job):
    """Create the scene (see _scene_class)."""
    global _MIXED_SCENE
    if _MIXED_SCENE is None:
        _MIXED_SCENE = _scene_class()
    return _MIXED_SCENE(job)


def fill_cell_mixed(scene, gen=None):
    """Phase (a generator, demlib.phases): table + PVC cylinder; generate and place the set's particles in a column inside
    the cylinder, settle, strike (free spheres whose centre is above the strike level;
    M1 lumps stay), settle again. Returns the fill's entries for result.json and the
    cylinder/table ids."""
    from yade import O
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d = g["cell_inner_diameter_m"]
    table_half = g.get("table_radius_m", d)
    gen = gen or generate(scene.job)
    column = gen["column_height_m"]
    table = scene.add_table(table_half, g["table_material"])
    cyl = scene.add_cylinder(d, column + 2 * scene.radius, g["cell_facet_segments_count"], g["cell_material"])
    scene.set_domain((-table_half, -table_half, -0.05), (table_half, table_half, column + 0.1))
    scene.add_placements(gen["placements"])
    generated = scene.component_masses()
    dt = yield scene.timestep()
    t1 = yield from scene.settle("pour")
    above = [i for i in scene.free_ids if O.bodies[i].state.pos[2] > p["strike_level_height_m"]]
    scene.remove_spheres(above)
    t2 = yield from scene.settle("strike")
    final = scene.component_masses()
    total = sum(final.values())
    out = {"cylinder_ids": cyl, "table_ids": table, "settle_time_s": t1 + t2, "timestep_s": dt,
           "steps": O.iter, "generated_mass_kg": sum(generated.values()),
           "pour_column_height_m": column, "fill_mass_kg": total,
           "n_clumps": len(scene.clumps), "n_free_spheres": len(scene.free_ids)}
    for name, w, _ in components(scene.job):
        out[f"mass_fraction_{name}_requested"] = w
        out[f"mass_fraction_{name}_generated"] = generated[name] / sum(generated.values())
        out[f"mass_fraction_{name}_final"] = final[name] / total if total > 0 else 0.0
    return out
