"""The geometry of the non-round M1 lumps (docs/lab-tests.md section 7): numpy only, no
YADE; yade_scripts/demlib/clumps.py builds them as YADE clumps of spheres.

Geometry rule ("rounded box of spheres"), one rule for every shape:
- A shape has a vertical aspect ratio v and a horizontal aspect ratio h (docs/lab-tests.md
  section 7). In the lump's own frame its bounding box is (x, y, z) = (1, h, v) x L:
  x = the reference length, y = the horizontal width, z = the vertical height.
  oblong (1.7 / 0.7): 1 x 0.7 x 1.7; rounded (1.0 / 1.0): a cube; slab (0.5 / 1.0):
  1 x 1 x 0.5.
- Size rule: the size-class size S of a lump is its LARGEST bounding-box side, so the
  box is (1, h, v) / max(1, h, v) x S (the space diagonal of the rounded box is longer:
  a rounded cube of size S measures 1.37 S corner to corner).
- Every member sphere has the same radius r = min(smallest side / 2, S / 4): the
  thickest sphere that fits, capped at a quarter of the size so that no shape
  degenerates into one sphere (a cube would; and with rolling resistance 0 a sphere
  never stops rolling). This radius is also the rounding radius of edges and corners.
- Member centres fill a regular grid over the inner box (the box shrunk by r on every
  side), n_i = ceil(extent_i / r) + 1 points per axis (one where the extent is 0), so
  neighbours are at most r apart: the surface bumps are at most 0.13 r deep.
  Members: oblong 2 x 1 x 4 = 8 (r = 0.206 S), rounded 3 x 3 x 3 = 27 (r = 0.25 S),
  slab 3 x 3 x 1 = 9 (r = 0.25 S).
- Mass and inertia are those of the UNION of the member spheres at the particle
  density. YADE's O.bodies.appendClumped(..., discretization=D) with D > 0 integrates
  the union on a regular grid of cells of edge (shortest side of the clump's
  axis-aligned box) / D; with D = 0 it sums the members' own masses and inertias,
  which counts every overlap again (about 2x too heavy for these shapes). This module
  computes the union's volume and principal inertia on a fine grid (unit_properties,
  pure numpy, checked against exact sphere and two-sphere-lens values in
  tests/unit/test_clumps_geometry.py) and yade_scripts/demlib/clumps.make_clump sets those
  exact values on the YADE clump
  after YADE has found the centroid and the principal axes.

The superquadric degree of the lab table (oblong 2 = ellipsoid-like, rounded 7 and
slab 8 = boxy) is not reproduced beyond "rounded box"; smoothness and corner counts
are not used.

"""

import math

import numpy as np

# Fine grid of the reference integration: cells along the shortest side of the union's box.
REFERENCE_CELLS = 120


# ---------------------------------------------------------------- geometry (pure Python)

def box_dims(vertical_aspect_ratio, horizontal_aspect_ratio, size=1.0):
    """Bounding box (x, y, z) of a lump of the given size (largest side) (m)."""
    rel = np.array([1.0, float(horizontal_aspect_ratio), float(vertical_aspect_ratio)])
    return rel / rel.max() * float(size)


def member_radius(dims):
    """Radius of every member sphere for a box `dims` (see the module rule)."""
    dims = np.asarray(dims, dtype=float)
    return float(min(dims.min() / 2.0, dims.max() / 4.0))


def members(vertical_aspect_ratio, horizontal_aspect_ratio, size=1.0):
    """(centres (n x 3 array, lump frame, box centre at 0), radius) of a lump's members."""
    dims = box_dims(vertical_aspect_ratio, horizontal_aspect_ratio, size)
    r = member_radius(dims)
    axes = []
    for d in dims:
        extent = d - 2.0 * r
        if extent <= 1e-12 * size:
            axes.append(np.array([0.0]))
        else:
            n = int(math.ceil(extent / r - 1e-9)) + 1
            axes.append(np.linspace(-extent / 2.0, extent / 2.0, n))
    gx, gy, gz = np.meshgrid(*axes, indexing="ij")
    centres = np.column_stack([gx.ravel(), gy.ravel(), gz.ravel()])
    return centres, r


def shape_members(shape_cfg, size=1.0):
    """members() of a shape entry of the M1 config (particles.shapes.<name>)."""
    return members(shape_cfg["vertical_aspect_ratio"], shape_cfg["horizontal_aspect_ratio"], size)


def bounding_radius(centres, radius):
    """Radius of the sphere about the box centre (0) that encloses every member (m)."""
    return float(np.max(np.linalg.norm(np.asarray(centres), axis=1)) + radius)


def union_properties(centres, radii, cells=REFERENCE_CELLS):
    """Volume, centroid and inertia tensor (about the centroid, per unit density) of the
    union of spheres, by the midpoint rule on a regular grid (cell edge = shortest side
    of the union's axis-aligned box / cells); each cell also carries its own inertia
    (edge^2 / 6 per unit mass). Returns (volume m^3, centroid (3,), tensor (3, 3))."""
    c = np.asarray(centres, dtype=float).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radii, dtype=float), (len(c),))
    lo = (c - r[:, None]).min(axis=0)
    hi = (c + r[:, None]).max(axis=0)
    dx = (hi - lo).min() / cells
    xs = [np.arange(lo[k] + dx / 2.0, hi[k], dx) for k in range(3)]
    X, Y = np.meshgrid(xs[0], xs[1], indexing="ij")
    X, Y = X.ravel(), Y.ravel()
    n = 0
    s1 = np.zeros(3)
    s2 = np.zeros((3, 3))
    r2 = r ** 2
    for z in xs[2]:
        inside = np.zeros(X.shape, dtype=bool)
        for k in range(len(c)):
            dz2 = (z - c[k, 2]) ** 2
            if dz2 >= r2[k]:
                continue
            inside |= (X - c[k, 0]) ** 2 + (Y - c[k, 1]) ** 2 < r2[k] - dz2
        if not inside.any():
            continue
        P = np.column_stack([X[inside], Y[inside], np.full(inside.sum(), z)])
        n += len(P)
        s1 += P.sum(axis=0)
        s2 += P.T @ P
    dv = dx ** 3
    vol = n * dv
    centroid = s1 / n
    second = s2 / n - np.outer(centroid, centroid)          # covariance of the points
    tensor = vol * (np.trace(second) * np.eye(3) - second)  # about the centroid
    tensor += vol * dx ** 2 / 6.0 * np.eye(3)                # each cell's own inertia
    return vol, centroid, tensor


_UNIT_CACHE = {}


def unit_properties(vertical_aspect_ratio, horizontal_aspect_ratio, cells=REFERENCE_CELLS):
    """Union volume and principal inertias (ascending, per unit density) of a lump of
    size 1 m. Scale: volume x S^3, inertia x S^5. Cached."""
    key = (float(vertical_aspect_ratio), float(horizontal_aspect_ratio), int(cells))
    if key not in _UNIT_CACHE:
        centres, r = members(vertical_aspect_ratio, horizontal_aspect_ratio, 1.0)
        vol, _, tensor = union_properties(centres, r, cells)
        _UNIT_CACHE[key] = (vol, np.sort(np.linalg.eigvalsh(tensor)))
    return _UNIT_CACHE[key]


def lump_mass(shape_cfg, size, density):
    """Mass (kg) of a lump of the given shape entry and size (m) at the particle density."""
    vol, _ = unit_properties(shape_cfg["vertical_aspect_ratio"], shape_cfg["horizontal_aspect_ratio"])
    return density * vol * size ** 3


def lump_principal_inertia(shape_cfg, size, density):
    """Principal inertias (ascending, kg m^2) of a lump."""
    _, inertia = unit_properties(shape_cfg["vertical_aspect_ratio"], shape_cfg["horizontal_aspect_ratio"])
    return density * inertia * size ** 5


def random_rotation(rng):
    """Uniformly distributed random rotation matrix (Shoemake's quaternion method),
    from a random.Random instance (reproducible by its seed). Returns (3x3 array,
    quaternion (w, x, y, z))."""
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    a, b = math.sqrt(1.0 - u1), math.sqrt(u1)
    x, y = a * math.sin(2 * math.pi * u2), a * math.cos(2 * math.pi * u2)
    z, w = b * math.sin(2 * math.pi * u3), b * math.cos(2 * math.pi * u3)
    R = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    return R, (w, x, y, z)


# ---------------------------------------------------------------- radii of a job's particles

def _clump_member_radius(mat, class_names=None):
    """Smallest member-sphere radius (m) of a clump material over its size classes (the
    ones named, or all) and the shapes they use."""
    p = mat["particles"]
    radii = []
    for sc in p["size_classes"]:
        if class_names is not None and sc["name"] not in class_names:
            continue
        for shape, pct in sc["shape_percent"].items():
            if pct > 0:
                s = p["shapes"][shape]
                radii.append(member_radius(box_dims(s["vertical_aspect_ratio"], s["horizontal_aspect_ratio"],
                                                    sc["min_size_m"])))
    return min(radii)


def particle_radii(job):
    """{material: smallest particle-sphere radius (m)} of the job's materials."""
    classes = {name: c.get("size_classes") for name, c in job.get("material_set", {}).get("components", {}).items()}
    out = {}
    for name, mat in job["materials"].items():
        if mat["particles"]["shape"] == "clump":
            out[name] = _clump_member_radius(mat, classes.get(name))
        else:
            out[name] = 0.5 * mat["particles"]["diameter_m"]
    return out
