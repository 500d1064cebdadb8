"""Non-round M1 lumps as YADE clumps of spheres: the geometry rule, masses and inertias
are pycal/lump_geometry.py (numpy only, shared with pycal's step estimate and stream
planning); make_clump and the other YADE functions here import yade when called."""
import numpy as np

from pycal.lump_geometry import (REFERENCE_CELLS, bounding_radius, box_dims, lump_mass,  # noqa: F401
                                 lump_principal_inertia, member_radius, members, random_rotation,
                                 shape_members, union_properties, unit_properties)

# YADE's own grid integration (appendClumped discretization) used when making a clump;
# its result is replaced by the reference values (see make_clump).
YADE_DISCRETIZATION = 15


# ---------------------------------------------------------------- YADE (import on call)

def make_clump(shape_cfg, size, density, material_id, position, rotation=None,
               discretization=YADE_DISCRETIZATION, exact=True):
    """Append one lump to O.bodies as a clump of spheres at `position` (box centre, m),
    rotated by the 3x3 `rotation` (lump frame -> world; identity if None).

    Members are created at their final world positions (a clump moved after creation
    would leave its members at the old place until the first step: the collider would
    see false overlaps). YADE finds the centroid and principal axes by its grid
    integration (discretization); with exact=True the mass and principal inertias
    are then replaced by the reference values of unit_properties (same ascending
    order as YADE's eigen solver). Returns (clump id, [member ids])."""
    from yade import O, utils
    centres, r = shape_members(shape_cfg, size)
    R = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    world = centres @ R.T + np.asarray(position, dtype=float)
    spheres = [utils.sphere(tuple(float(v) for v in p), r, material=material_id) for p in world]
    cid, mids = O.bodies.appendClumped(spheres, discretization=discretization)
    if exact:
        from yade import Vector3
        st = O.bodies[cid].state
        st.mass = lump_mass(shape_cfg, size, density)
        st.inertia = Vector3(*(float(v) for v in lump_principal_inertia(shape_cfg, size, density)))
    return cid, list(mids)


def clump_kinetic_energy(body):
    """Translational + rotational kinetic energy (J) of a dynamic body (sphere or
    clump): the rotational part in the body's principal frame."""
    st = body.state
    ke = 0.5 * st.mass * st.vel.squaredNorm()
    w = st.ori.conjugate() * st.angVel          # angular velocity in the principal frame
    return ke + 0.5 * sum(st.inertia[k] * w[k] ** 2 for k in range(3))
