"""Rig: transfer. A belt stream of the study's design case falls onto an inclined steel plate
and runs off (docs/rigs.md, transfer; configs/rigs/transfer.yaml).

A slice of the stream, `slice_width_m` wide, between periodic boundaries across the stream
(y). The stream is injected through a horizontal window just above the plate with the
velocity and bulk density it has there after its fall from the belt (pycal.rigs.transfer.stream,
demlib.feeder), for `feed_time_s`; the scene then runs `holdup_wait_s` more. Particles whose
centre passes the plate's lower end have run off, those that fall back past its top end (upstream of
it and below it) have spilled upstream: both are
erased and their mass counted. The collider sorts all its bounds afresh at every time step
(YADE 2023.02a's incremental periodic sort, InsertionSortCollider::insertionSortPeri, never
returned in this scene: after an erasure, and with lumps in the stream even without one -
a mixed-dry run hung at t = 0.085 s, gdb showed the loop; the full sort of a few hundred
bounds costs little). A particle is in flight
from its injection to its first contact with anything (checked with the plate forces, every
force_sample_interval_count steps), then on the plate. Every record interval the masses in
flight, on the plate and gone are recorded with the plate's normal forces averaged over the
interval; pycal.post.transfer turns the record into the measurements.

Periodic boundaries with facets in YADE 2023.02a: the collider pairs a body larger than the
period (here the plate, flag allowBiggerThanPeriod) with a particle's unwrapped position, so
a plate facet exactly one period wide loses the particles that drift across the boundary
(they fell through or hit its edge in a test). The plate is therefore one facet that spans
+-10 m across the slice, far beyond any particle's drift (a particle that still reaches
+-4 m fails the run as escaped); particle-particle contacts are periodic as usual.

The procedure is a generator (demlib.phases) driven by demlib.replicas.rig_main like every
rig; lone jobs only (a periodic cell has no room for replicas side by side).

Outputs: result.json, transfer_record.csv, plate_stress_profile.csv, transfer_record.png,
frames/transfer_NNNN.png (side view every frame_interval_s).
Run: yade -j1 -x -n yade_scripts/transfer.py job.json
"""
import math
import os
import sys

from yade_scripts.demlib.jobio import RigFailure, run_rig, write_csv
from yade_scripts.demlib import mixed, replicas
from yade_scripts.demlib.feeder import Feeder

SORT_HOOK = "_pycal_transfer_full_sort"
GUARD_HALF_WIDTH_M = 4.0     # a particle drifting farther across the slice than this has escaped


class Plate:
    """The steel plate: one facet, and the normal forces of its contacts by position."""

    def __init__(self, scene, geo):
        from yade import O, utils, Vector3
        self.geo = geo
        top, t, L = geo["plate_top_m"], geo["plate_tangent"], geo["plate_length_m"]
        from pycal.rigs.transfer.stream import PLATE_HALF_WIDTH_M
        W, Y = geo["slice_width_m"], PLATE_HALF_WIDTH_M
        apex = Vector3(top[0] + 2.0 * L * t[0], 0.5 * W, top[1] + 2.0 * L * t[1])
        a = Vector3(top[0], -Y, top[1])
        b = Vector3(top[0], Y + W, top[1])
        mat = scene.contact.mat_id[scene.rig["geometry"]["plate_material"]]
        self.id = O.bodies.append(utils.facet([a, apex, b], material=mat, fixed=True))
        self.n = Vector3(geo["plate_normal"][0], 0.0, geo["plate_normal"][1])
        self.top, self.t = top, t
        self.foot = (geo["footprint_start_m"], geo["footprint_end_m"])
        bin_m = scene.rig["measure"]["stress_profile_bin_m"]
        nb = max(1, int(round(L / bin_m)))
        self.edges = [L * k / nb for k in range(nb + 1)]
        self.profile = [[0.0, self._in_foot(k)] for k in range(nb)]
        self.profile_samples = 0
        self.reset_interval()

    def _in_foot(self, k):
        mid = 0.5 * (self.edges[k] + self.edges[k + 1])
        return self.foot[0] <= mid <= self.foot[1]

    def reset_interval(self):
        self.sum_foot = self.sum_all = 0.0
        self.samples = 0

    def sample(self, profile):
        """Add the normal load of every contact (N, pressing the plate positive) to the
        footprint / whole-plate sums; with profile=True also to the bins along the plate."""
        from yade import O
        foot = all_ = 0.0
        s0, s1 = self.foot
        n, top, t = self.n, self.top, self.t
        L = self.edges[-1]
        nb = len(self.profile)
        for i in O.bodies[self.id].intrs():
            if not i.isReal:
                continue
            f = i.phys.normalForce.dot(n)
            if i.id2 == self.id:
                f = -f
            cp = i.geom.contactPoint
            s = (cp[0] - top[0]) * t[0] + (cp[2] - top[1]) * t[1]
            all_ += f
            if s0 <= s <= s1:
                foot += f
            if profile and 0.0 <= s < L:
                self.profile[min(nb - 1, int(s / L * nb))][0] += f
        self.sum_foot += foot
        self.sum_all += all_
        self.samples += 1
        if profile:
            self.profile_samples += 1

    def means(self):
        """(mean footprint normal force N, mean whole-plate normal force N) since the last reset."""
        k = max(self.samples, 1)
        return self.sum_foot / k, self.sum_all / k


class Transfer:
    """The scene, the feeder, the plate and the bookkeeping of where the mass is."""

    def __init__(self, scene):
        from yade import O
        from pycal.rigs.transfer import stream
        from pycal.step_estimate import critical_timestep
        job = scene.job
        self.job = job
        self.geo = stream.check_job(job)
        self.scene = scene
        sc = self.scene
        g = self.geo
        top, L = g["plate_top_m"], g["plate_length_m"]
        W = g["slice_width_m"]
        wx, wz = g["injection_window_centre_m"]
        size_x = top[0] + 2.0 * L * g["plate_tangent"][0] + stream.CELL_MARGIN_M
        size_z = max(top[1], wz) + stream.CELL_MARGIN_M
        O.periodic = True
        O.cell.setBox(size_x, W, size_z)
        self.collider = [e for e in O.engines if type(e).__name__ == "InsertionSortCollider"][0]
        self.collider.allowBiggerThanPeriod = True
        self._sort_every_step()
        self.plate = Plate(sc, g)
        sc.set_domain((top[0] - 1.0, -GUARD_HALF_WIDTH_M, stream.PLATE_APEX_Z_M - 0.5),
                      (top[0] + L * g["plate_tangent"][0] + 1.0, GUARD_HALF_WIDTH_M, wz + 1.0))
        O.dt = critical_timestep(job)[0]     # the smallest particle the feed can make (lumps: smallest member)
        n_layers, layer_dt = stream.layer_times(job)
        p = sc.rig["procedure"]
        self.feeder = Feeder(sc, g, n_layers, layer_dt, p["placement_max_attempts_count"])
        self.feed_time = n_layers * layer_dt
        self.flying = set()
        self.run_off = self.spilled = 0.0
        self.gauge_z = g["impact_point_centre_m"][1] + sc.rig["measure"]["speed_gauge_height_m"]
        self.gauged = set()
        self.gauge_speeds, self.gauge_heights = [], []
        self.max_overlap_ratio = 0.0

    # ---------- where each body is
    def _plate_coords(self, pos):
        top, t, n = self.geo["plate_top_m"], self.geo["plate_tangent"], self.geo["plate_normal"]
        dx, dz = pos[0] - top[0], pos[2] - top[1]
        return dx * t[0] + dz * t[1], dx * n[0] + dz * n[1]

    def _touching(self, i):
        from yade import O
        members = self.scene.clumps.get(i, [i])
        return any(x.isReal for m in members for x in O.bodies[m].intrs())

    def fed(self, ids):
        """Bodies just made by the feeder: in flight."""
        self.flying.update(ids)

    def track_flight(self):
        """Bodies in flight that touch anything now have landed (for good); those still in
        flight below the gauge height give their speed once (called every force sample, so
        that a contact is seen while it lasts)."""
        from yade import O
        cz = self.geo["impact_point_centre_m"][1]
        for i in list(self.flying):
            if self._touching(i):
                self.flying.discard(i)
                continue
            if i not in self.gauged:
                b = O.bodies[i]
                if b.state.pos[2] < self.gauge_z:
                    self.gauged.add(i)
                    self.gauge_speeds.append(b.state.vel.norm())
                    self.gauge_heights.append(b.state.pos[2] - cz)

    def classify(self):
        """Erase bodies past the plate's ends (counting their mass); returns (in flight kg, on
        the plate kg) of the rest."""
        from yade import O
        sc, g = self.scene, self.geo
        L, top = g["plate_length_m"], g["plate_top_m"]
        gone_low, gone_top = [], []
        in_flight = on_plate = 0.0
        for i in list(self.feeder.bodies):
            b = O.bodies[i]
            pos = b.state.pos
            s, h = self._plate_coords(pos)
            if h < -0.5 * sc.radius and 0.0 <= s <= L:
                raise RigFailure(f"particle {i} passed through the plate at s = {s:.3f} m, {h:.4f} m below it "
                                 f"(t={O.time:.4f} s)")
            if s > L:
                gone_low.append((i, b.state.mass))
            elif pos[0] < top[0] and pos[2] < top[1]:      # upstream of the top end and below it
                gone_top.append((i, b.state.mass))
            elif i in self.flying:
                in_flight += b.state.mass
            else:
                on_plate += b.state.mass
        for group, counter in ((gone_low, "run_off"), (gone_top, "spilled")):
            if group:
                setattr(self, counter, getattr(self, counter) + sum(m for _, m in group))
                ids = [i for i, _ in group]
                sc.remove_spheres([sc.clumps[i][0] if i in sc.clumps else i for i in ids])
                self.resort()
                for i in ids:
                    self.feeder.bodies.pop(i, None)
                    self.feeder.bound_radius.pop(i, None)
                    self.flying.discard(i)
        return in_flight, on_plate

    def _sort_every_step(self):
        """A PyRunner first in the engines sets the collider's doSort flag before every step
        (module doc: the periodic collider's incremental sort hangs on this YADE build)."""
        import __main__
        from yade import O
        from yade.wrapper import PyRunner
        collider = self.collider

        def force_sort():
            collider.doSort = True
        setattr(__main__, SORT_HOOK, force_sort)
        O.engines = [PyRunner(command=SORT_HOOK + "()", iterPeriod=1, label="transfer_full_sort")] + list(O.engines)

    def resort(self):
        """Make the collider sort all bounds again at its next run. YADE 2023.02a: after bodies
        are erased from a periodic scene, InsertionSortCollider's incremental sort never
        returns (a test erasing one sphere every 100 steps hung at the 7th; with a forced sort
        it ran on)."""
        self.collider.doSort = True

    def guard(self):
        """Scene guards (NaN, escape, overlap beyond numerics.max_overlap_fraction) and the
        largest overlap ratio seen."""
        from yade import O
        self.scene.check()
        for i in O.interactions:
            if i.isReal:
                r = self.scene.overlap_limit_m(i) / self.scene.num["max_overlap_fraction"]
                self.max_overlap_ratio = max(self.max_overlap_ratio, i.geom.penetrationDepth / r)

    def frame_rows(self):
        from yade import O
        rows = []
        for b in self.scene.live_spheres():
            rows.append((b.state.pos[0], b.state.pos[2], b.shape.radius, self.scene.name_of_mat[b.material.id],
                         self.scene.member_of.get(b.id, -1)))
        return rows


def procedure(scene, out_dir):
    """The transfer run (a generator: demlib.phases): feed, then wait; returns the measurements.
    Steps are asked for in chunks that end at every force sample (each
    measure.force_sample_interval_count steps) and at every layer's injection time."""
    from yade import O
    from pycal.post import transfer as post
    job = scene.job
    rig = Transfer(scene)
    sc, g, plate, feeder = rig.scene, rig.geo, rig.plate, rig.feeder
    m, p = sc.rig["measure"], sc.rig["procedure"]
    t_end = rig.feed_time + p["holdup_wait_s"]
    every = m["force_sample_interval_count"]
    next_record, next_guard, next_frame = m["record_interval_s"], sc.num["rest_check_interval_s"], 0.0
    steady = m["steady_from_s"]
    records, frames = [], []
    k = 0
    while O.time < t_end - 1e-12:
        while feeder.due(O.time):
            rig.fed(feeder.add_layer())
            rig.resort()
        if O.time >= next_frame - 1e-12:
            frames.append((O.time, rig.frame_rows()))
            next_frame += m["frame_interval_s"]
        chunk = every - k % every
        if feeder.layers_done < feeder.n_layers:      # stop at the next layer's time
            chunk = min(chunk, max(1, int(math.ceil((feeder.layers_done * feeder.dt - O.time) / O.dt - 1e-9))))
        yield chunk
        k += chunk
        if k % every == 0:
            plate.sample(profile=steady <= O.time <= rig.feed_time)
            rig.track_flight()
        if O.time >= next_record - 1e-12:
            in_flight, on_plate = rig.classify()
            foot, whole = plate.means()
            plate.reset_interval()
            records.append((O.time, feeder.fed_mass_kg(), in_flight, on_plate, rig.run_off, rig.spilled,
                            foot, whole, len(feeder.bodies)))
            next_record += m["record_interval_s"]
        if O.time >= next_guard - 1e-12:
            rig.guard()
            next_guard += sc.num["rest_check_interval_s"]
    frames.append((O.time, rig.frame_rows()))
    rig.guard()

    write_csv(out_dir, "transfer_record.csv", post.RECORD_COLUMNS, records)
    profile = post.stress_profile_rows(plate.edges, plate.profile, plate.profile_samples, g["slice_width_m"])
    write_csv(out_dir, "plate_stress_profile.csv", post.PROFILE_COLUMNS, profile)
    out = post.summarise(records, g, m, rig.feed_time, p["holdup_wait_s"])
    title = (f"transfer {job['material']} seed {job['seed']}: plate {g['plate_inclination_rad'] * 180 / math.pi:g} deg, "
             f"{g['slice_mass_flow_kg_s']:.1f} kg/s in a {g['slice_width_m']:g} m slice")
    post.plot_record(os.path.join(out_dir, "transfer_record.png"), records, g, out, title)
    os.makedirs(os.path.join(out_dir, "frames"), exist_ok=True)
    limits = post.frame_limits(g)
    for n, (t, rows) in enumerate(frames):
        post.draw_frame(os.path.join(out_dir, "frames", f"transfer_{n:04d}.png"), rows, g, t, title, limits)
    fed = feeder.fed_kg
    total_fed = sum(fed.values())
    speeds = rig.gauge_speeds
    out.update({
        "footprint_start_m": g["footprint_start_m"],
        "footprint_end_m": g["footprint_end_m"],
        "footprint_length_m": g["footprint_length_m"],
        "footprint_area_m2": g["footprint_area_m2"],
        "slice_mass_flow_kg_s": g["slice_mass_flow_kg_s"],
        "stream_bulk_density_at_plate_kg_m3": g["stream_bulk_density_at_plate_kg_m3"],
        "stream_bulk_density_at_injection_kg_m3": g["stream_bulk_density_at_injection_kg_m3"],
        "design_impact_speed_m_s": g["speed_at_plate_m_s"],
        "injection_speed_m_s": g["speed_at_injection_m_s"],
        "stream_speed_at_gauge_m_s": sum(speeds) / len(speeds) if speeds else None,
        "stream_gauge_height_m": sum(rig.gauge_heights) / len(speeds) if speeds else None,
        "stream_gauge_count": len(speeds),
        "feed_time_s": rig.feed_time,
        "layers_count": feeder.n_layers,
        "n_particles_fed": feeder.count,
        "n_particles_left_out": feeder.left_count,
        "n_particles_end": len(feeder.bodies),
        "n_particle_spheres_end": len(sc.live_spheres()),
        "max_overlap_ratio": rig.max_overlap_ratio,
        "frames_count": len(frames),
        "steps": O.iter,
        "timestep_s": O.dt,
    })
    for name, w, _ in mixed.components(job):
        out[f"mass_fraction_{name}_requested"] = w
        out[f"mass_fraction_{name}_fed"] = fed[name] / total_fed if total_fed > 0 else 0.0
    return out


main = replicas.rig_main(procedure, scene_class=mixed.MixedScene)

if __name__ == "__main__" and os.path.basename(sys.argv[0]) == "transfer.py":
    run_rig(main)
