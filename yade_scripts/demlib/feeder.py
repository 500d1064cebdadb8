"""A falling stream fed through a horizontal window, layer by layer (transfer rig; the planning
and placement functions are pure Python and run anywhere, Feeder runs inside YADE).

The feed time is split into N equal intervals dt (pycal.rigs.transfer.stream.layer_times). At the start of
interval k one layer of particles is created just above the injection window: its mass is
what the stream carries through the window in dt (the slice's mass flow x dt), split over
the job's components by their mass fractions; each particle gets the stream's velocity at
its own height z' above the window, (v0, 0, -sqrt(vz_i^2 - 2 g z')): the free fall of the
stream, so particles at one height move alike and the layer has crossed the window when the
next one is made.

- Layer mass: per component, the cumulative target w_c x flow x (k + 1) dt less the mass
  already fed (the deficit), planned by demlib.mixed.plan_fill (spheres: the nearest whole
  number of particles; lumps: stochastic rounding per shape). Rounding never accumulates:
  the fed mass of a sphere material is within half a particle of its target at every layer,
  a lump material within about one lump.
- Layer region: a parallelogram following the stream's direction: height z' in [0, h] above
  the window (h = vz_i dt), x = window centre + u - (v0 / vz_i) z' with u in [-Lf/2, Lf/2],
  y in [0, W) (the periodic slice). Random sequential placement of the particles' bounding
  spheres, largest first, none overlapping another or a particle already in the scene near
  the window (distance in y taken across the periodic boundary); lumps randomly oriented.
- A particle that finds no place in placement_max_attempts_count tries is left out of its
  layer; its mass stays in the deficit, so the next layers make it up (the fed mass is what
  was made, and the stream's mass fractions keep to the rule above). Only when the deficit
  left over exceeds one layer's mass is the window blocked and the run refused.
"""
import math
import random

import numpy as np

from . import clumps, mixed


def plan_layer(job, deficits_kg, rng):
    """Particles of one layer: demlib.mixed.plan_fill on the positive deficits {material: kg}
    (a component with none gets nothing). Returns the particle dicts of plan_fill."""
    positive = {k: v for k, v in deficits_kg.items() if v > 0}
    total = sum(positive.values())
    if total <= 0:
        return []
    comps = job.get("material_set", {}).get("components", {})
    fake = {"materials": job["materials"],
            "material_set": {"components": {name: {"mass_fraction": d / total,
                                                   **({"size_classes": comps[name]["size_classes"]}
                                                      if "size_classes" in comps.get(name, {}) else {})}
                                            for name, d in positive.items()}}}
    parts, _, _ = mixed.plan_fill(fake, total, rng)
    return parts


def place_layer(particles, window, existing, rng, max_attempts):
    """Random sequential placement in the layer's parallelogram (module doc).

    window: dict x_m (window centre), z_m (window height), length_m (Lf), width_m (W),
    height_m (h), slope (v0 / vz_i). existing: (k x 4 array of x, y, z, bounding radius) of
    particles already in the scene near the window. Returns (placed, left): placed =
    [(particle, (x, y, z), rotation 3x3 or None)], left = the particles that found no place in
    max_attempts tries."""
    W = window["width_m"]
    order = sorted(particles, key=lambda p: -p["bound_radius_m"])
    pos = np.zeros((len(order) + len(existing), 3))
    rad = np.zeros(len(order) + len(existing))
    n = len(existing)
    if n:
        pos[:n] = np.asarray(existing, dtype=float)[:, :3]
        rad[:n] = np.asarray(existing, dtype=float)[:, 3]
    out, left = [], []
    for p in order:
        b = p["bound_radius_m"]
        for _ in range(max_attempts):
            zp = window["height_m"] * rng.random()
            c = np.array([window["x_m"] + (rng.random() - 0.5) * window["length_m"] - window["slope"] * zp,
                          W * rng.random(), window["z_m"] + zp])
            if n:
                d = pos[:n] - c
                d[:, 1] -= W * np.round(d[:, 1] / W)          # nearest periodic image in y
                if np.any(np.sum(d * d, axis=1) < (rad[:n] + b) ** 2):
                    continue
            break
        else:
            left.append(p)
            continue
        pos[n], rad[n] = c, b
        n += 1
        rot = clumps.random_rotation(rng)[0] if p["kind"] == "clump" else None
        out.append((p, tuple(float(v) for v in c), rot))
    return out, left


class Feeder:
    """Creates the stream's layers in a MixedScene (YADE). fed_kg: {material: kg} created so
    far (YADE's masses); count: particles made; bodies: {body id: material} of the particles
    made and not yet erased (free spheres and clumps); bound_radius: {body id: m}."""

    def __init__(self, scene, geo, n_layers, layer_dt, max_attempts):
        self.scene = scene
        self.geo = geo
        self.n_layers = n_layers
        self.dt = layer_dt
        self.max_attempts = max_attempts
        self.rng = random.Random(scene.job["seed"])
        self.fractions = {name: w for name, w, _ in mixed.components(scene.job)}
        self.fed_kg = {name: 0.0 for name in self.fractions}
        self.bodies = {}
        self.bound_radius = {}
        self.layers_done = 0
        self.count = 0
        self.left_count = 0           # particles left out of their layer (no room in the window)
        vz_i = geo["vertical_speed_at_injection_m_s"]
        wx, wz = geo["injection_window_centre_m"]
        self.window = {"x_m": wx, "z_m": wz, "length_m": geo["stream_length_m"], "width_m": geo["slice_width_m"],
                       "height_m": vz_i * layer_dt, "slope": geo["belt_speed_m_s"] / vz_i}
        self.velocity = (geo["belt_speed_m_s"], 0.0, -vz_i)

    def due(self, time_s):
        """True when the next layer is to be made at this time (s)."""
        return self.layers_done < self.n_layers and time_s >= self.layers_done * self.dt - 1e-12

    def _nearby(self):
        from yade import O
        lo = self.window["z_m"] - 3.0 * max(self.bound_radius.values(), default=0.0)
        hi = self.window["z_m"] + self.window["height_m"] + 3.0 * max(self.bound_radius.values(), default=0.0)
        rows = []
        for i, b in self.bound_radius.items():
            body = O.bodies[i]
            if body is None:
                continue
            p = body.state.pos
            if lo <= p[2] <= hi:
                rows.append((p[0], p[1], p[2], b))
        return rows

    def add_layer(self):
        """Plan, place and create the next layer; returns the ids of the bodies made."""
        from yade import O, Vector3
        from .jobio import RigFailure
        flow = self.geo["slice_mass_flow_kg_s"]
        k = self.layers_done
        deficits = {name: w * flow * (k + 1) * self.dt - self.fed_kg[name] for name, w in self.fractions.items()}
        parts = plan_layer(self.scene.job, deficits, self.rng)
        placed, left = place_layer(parts, self.window, self._nearby(), self.rng, self.max_attempts)
        self.left_count += len(left)
        left_kg = sum(p["mass_kg"] for p in left)
        if left_kg > flow * self.dt:
            raise RigFailure(f"stream injection: layer {k}: {len(left)} particles ({left_kg:.3g} kg, more than one "
                             f"layer's {flow * self.dt:.3g} kg) found no place in {self.max_attempts} tries each "
                             f"(stream bulk density {self.geo['stream_bulk_density_at_injection_kg_m3']:.0f} kg/m3 "
                             "at the injection window): inject lower or thin the layers")
        v0, vz_i, g = self.velocity[0], -self.velocity[2], self.geo["gravity_m_s2"]
        made = []
        for pl in placed:
            p = pl[0]
            zp = pl[1][2] - self.window["z_m"]
            vel = Vector3(v0, 0.0, -math.sqrt(max(vz_i * vz_i - 2.0 * g * zp, 0.0)))
            self.scene.add_placements([pl])
            if p["kind"] == "sphere":
                i = self.scene.free_ids[-1]
                members = [i]
            else:
                i = next(reversed(self.scene.clumps))      # the clump just made (dicts keep their order)
                members = self.scene.clumps[i]
            body = O.bodies[i]
            body.state.vel = vel
            for m in members:
                O.bodies[m].state.vel = vel
            self.bodies[i] = p["material"]
            self.bound_radius[i] = p["bound_radius_m"]
            self.fed_kg[p["material"]] += body.state.mass
            self.count += 1
            made.append(i)
        self.layers_done += 1
        return made

    def fed_mass_kg(self):
        return sum(self.fed_kg.values())
