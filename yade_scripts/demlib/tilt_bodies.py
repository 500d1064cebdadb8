"""The rigid bodies of the tilt-table friction rigs (runs inside YADE).

- add_bearing_plate: a long steel plate (two facets) for the cell to slide on;
- RigidBody / add_rigid_cell: PVC facets clumped into one rigid body with the
  configured mass and thin-walled-tube inertia;
- Lid: the steel lid (loading.add_plate facets): servo plate while loading, free dead
  weight once unloaded; join()/split() make cell + lid one rigid body for the tilt and
  separate them again for the next load (or Lid.free() leaves it free on the contents);
- set_damped, stop_all, force_sum: small helpers on body ids.
"""
from yade import O, utils, geom
from yade import Vector3


def add_bearing_plate(scene, x_min, x_max, half_width, material, z=0.0):
    """Rectangular plate [x_min, x_max] x [-half_width, half_width] in the plane z (two
    facets, fixed). Returns the facet ids."""
    mat = scene.contact.mat_id[material]
    a, b = Vector3(x_min, -half_width, z), Vector3(x_max, -half_width, z)
    c, d = Vector3(x_max, half_width, z), Vector3(x_min, half_width, z)
    facets = [utils.facet((a, b, c), material=mat, fixed=True),
              utils.facet((a, c, d), material=mat, fixed=True)]
    return O.bodies.append(facets)


class RigidBody:
    """A clump of facets moving as one body, with its configured mass and
    inertia. Positions are read from a reference member (clump centres move
    when members join or leave)."""

    def __init__(self, clump_id, member_ids, mass, inertia, bottom_z):
        self.id = clump_id
        self.members = list(member_ids)
        self.mass = mass
        self.inertia = inertia
        self.ref = self.members[0]
        self.ref_to_bottom = bottom_z - O.bodies[self.ref].state.pos[2]
        self.rotations_free = False
        self.rim_offset = None        # body frame: centre of mass -> centre of the bottom rim (see hold)

    @property
    def body(self):
        return O.bodies[self.id]

    @property
    def pos(self):
        """Position of the reference member (moves with the body)."""
        return O.bodies[self.ref].state.pos

    def bottom_z(self):
        return O.bodies[self.ref].state.pos[2] + self.ref_to_bottom

    def hold(self, hold=True, rotations_free=False, read_at_shear_plane=False):
        """Fix it in place (all six DOFs) or release its translations (rotations stay
        blocked: the cell and lid are guided, they do not tip; rotations_free releases
        them too, and the slide is then read at the body's centre of mass, or with
        read_at_shear_plane at the centre of its bottom rim, which moves with the body:
        a tipping cell moves its centre of mass, not the rim on the shear plane)."""
        st = O.bodies[self.id].state
        st.vel = Vector3(0, 0, 0)
        st.angVel = Vector3(0, 0, 0)
        st.blockedDOFs = "xyzXYZ" if hold else ("" if rotations_free else "XYZ")
        self.rotations_free = rotations_free and not hold
        self.rim_offset = None
        if self.rotations_free and read_at_shear_plane:
            rim = Vector3(st.pos[0], st.pos[1], self.bottom_z())      # the axis is vertical at release
            self.rim_offset = st.ori.conjugate() * (rim - st.pos)       # in the body's own frame

    def slide_point(self):
        """Where the slide is read (m): the reference member while the body only translates
        (as the rig has always read it), the centre of mass once it may also turn, or the
        centre of its bottom rim (hold(read_at_shear_plane=True))."""
        st = O.bodies[self.id].state
        if self.rotations_free and self.rim_offset is not None:
            return st.pos + st.ori * self.rim_offset
        if self.rotations_free:
            return st.pos
        return self.pos

    def lift_bottom_to(self, z):
        """Move the (held) body vertically so that its lowest edge is at z."""
        st = O.bodies[self.id].state
        st.pos = st.pos + Vector3(0, 0, z - self.bottom_z())

    def set_mass(self, mass, inertia):
        st = O.bodies[self.id].state
        st.mass = mass
        st.inertia = Vector3(*inertia)


def _clump(ids, mass, inertia):
    """Clump bodies `ids` (their own masses are placeholders) and give the clump the
    configured mass and inertia (kg, kg m2)."""
    for i in ids:
        st = O.bodies[i].state
        st.mass = mass / len(ids)
        st.inertia = Vector3(1e-6, 1e-6, 1e-6)
    cid = O.bodies.clump(ids)
    c = O.bodies[cid]
    c.state.mass = mass
    c.state.inertia = Vector3(*inertia)
    return cid


def join(cell, lid):
    """Make lid and cell one rigid body (the cell then hangs on the lid, which rests on
    the contents: with no vertical support from outside, all of cell + lid + contents
    weighs on the plate). The cell's clump id is kept; its mass becomes cell + lid."""
    lid.make_rigid()
    # YADE 2023.02a: addToClump of a clump (or of a member of another clump) trips an
    # assertion in Clump::addForceTorqueFromMembers; erasing the lid clump body (members
    # kept) first and adding its free members works
    O.bodies.erase(lid.id)
    O.bodies.addToClump(list(lid.members), cell.id)
    cell.set_mass(cell.mass + lid.mass, tuple(a + b for a, b in zip(cell.inertia, lid.inertia)))
    lid.id = None


def split(cell, lid):
    """Undo join(): the lid members leave the cell clump and become kinematic facets
    at rest (ready for the servo of the next load)."""
    for m in lid.members:
        O.bodies.releaseFromClump(m, cell.id)
    cell.set_mass(cell.mass, cell.inertia)
    lid.id = None
    lid.make_kinematic()


def add_rigid_cell(scene, diameter, height, segments, material, z0, mass):
    """PVC tube wall (no bottom) from z0 to z0 + height as one rigid clump of the given
    mass. Returns a RigidBody."""
    r = diameter / 2.0
    facets = geom.facetCylinder((0, 0, z0 + height / 2.0), r, height, segmentsNumber=segments,
                                wallMask=4, material=scene.contact.mat_id[material])
    ids = O.bodies.append(facets)
    inertia = (mass * (r * r / 2.0 + height * height / 12.0),) * 2 + (mass * r * r,)
    cid = _clump(ids, mass, inertia)
    return RigidBody(cid, ids, mass, inertia, z0)


class Lid:
    """The steel lid: a square plate of facets (demlib.loading.add_plate, circumscribing
    the cell: its corners stick out through the wall, harmless as facets never touch
    facets). Kinematic under the servo while a load is applied (loading.ServoPlate),
    a rigid clump of lid_mass_kg (a free dead weight) once unloaded, and joined to the
    cell for the tilt (join/split)."""

    def __init__(self, scene, cell_diameter, material, z, mass):
        from .loading import add_plate
        self.scene = scene
        self.members = add_plate(scene, z, cell_diameter, material)
        self.mass = mass
        xs = [O.bodies[i].state.pos[0] + v[0] for i in self.members for v in O.bodies[i].shape.vertices]
        half = 0.5 * (max(xs) - min(xs))
        self.inertia = (mass * half * half / 3.0,) * 2 + (2.0 * mass * half * half / 3.0,)
        self.id = None          # clump id while rigid
        self.ref = self.members[0]

    def z(self):
        return O.bodies[self.ref].state.pos[2]

    def make_rigid(self):
        """Kinematic facets -> one dynamic clump of the lid mass (translation z only)."""
        if self.id is None:
            self.id = _clump(self.members, self.mass, self.inertia)
            st = O.bodies[self.id].state
            st.vel = Vector3(0, 0, 0)
            st.blockedDOFs = "xyXYZ"

    def free(self):
        """The rigid lid free on the contents (translations x, y, z; not damped; it stays
        level): the lid_during_tilt: free option, instead of join()."""
        st = O.bodies[self.id].state
        st.blockedDOFs = "XYZ"
        st.isDamped = False

    def make_kinematic(self):
        """Rigid clump (or freed members) -> fixed kinematic facets at rest (for the servo)."""
        if self.id is not None:
            O.bodies.erase(self.id)     # members are kept
            self.id = None
        for m in self.members:
            b = O.bodies[m]
            b.dynamic = False
            b.state.vel = Vector3(0, 0, 0)
            b.state.angVel = Vector3(0, 0, 0)


def set_damped(ids, damped):
    for i in ids:
        O.bodies[i].state.isDamped = damped


def force_sum(ids):
    """Sum of the contact forces acting on bodies `ids` (N), after a step."""
    f = Vector3(0, 0, 0)
    for i in ids:
        f += O.forces.f(i)
    return f


def stop_all(ids):
    for i in ids:
        st = O.bodies[i].state
        st.vel = Vector3(0, 0, 0)
        st.angVel = Vector3(0, 0, 0)
