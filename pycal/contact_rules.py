"""Contact models and the rules for their per-pair parameters, in one place.

pycal checks every job against these rules when it is created (a combination that
cannot work is a config error naming the pair and the reason); the YADE side
(yade_scripts/demlib/contact_*.py) builds the scene from the same functions. Pure
Python: never imports YADE. docs/contact-models.md explains the physics.

Contact models (numerics key `contact_model`, copied into every job):

- ``hertz_mindlin`` (default): Hertz normal spring and Mindlin tangential spring with a
  viscous contact dashpot (Tsuji) that gives each pair its coefficient of restitution,
  Coulomb friction per pair, elastic-plastic rolling resistance per pair (moment limit
  mu_r x R x |Fn|), an elastic twisting spring, and global damping
  `global_damping_ratio` (small, gravity not damped) only so that heaps come to rest.
- ``linear_cundall``: the project's first law (linear springs, elastic-plastic rolling
  and twisting resistance, fragile bonds) whose restitution comes from heavy Cundall
  damping of the net force, gravity included: everything falls at (1 - a) g. Kept for
  comparison and to reproduce old results.
- ``viscoelastic_capillary``: chosen by the job whenever a pair uses the `liquid_bridge`
  cohesion model (YADE's Willett liquid bridge exists only on this law): dashpot
  restitution, per-pair friction, no rolling resistance.
"""
import math

CONTACT_MODELS = {
    "hertz_mindlin": "Hertz-Mindlin with a contact dashpot, per-pair restitution, friction, rolling resistance",
    "linear_cundall": "linear springs, restitution by Cundall damping of the net force (the first law)",
}
CAPILLARY_LAW = "viscoelastic_capillary"
DEFAULT_CONTACT_MODEL = "hertz_mindlin"
MAX_GLOBAL_DAMPING_RATIO = 0.05          # hertz_mindlin: damping only for rest, never a restitution device

# cohesion model -> its parameters (name -> (min, max), None = unbounded) and the laws that realise it
COHESION_MODELS = {
    "none": {"params": {}, "laws": ("hertz_mindlin", "linear_cundall", CAPILLARY_LAW)},
    # constant pull-off force = force_fraction x weight of the lighter particle (a wall counts as
    # infinitely heavy), in contact and up to adhesive_distance_m beyond it
    "force_fraction": {"params": {"force_fraction": (0.0, None), "adhesive_distance_m": (0.0, None)},
                       "laws": ("hertz_mindlin", "linear_cundall")},
    # pull-off = stiffness_fraction x (normal contact stiffness x overlap) at the largest overlap the
    # contact has had: the attraction grows with how hard the contact was pressed
    "linear": {"params": {"stiffness_fraction": (0.0, None), "adhesive_distance_m": (0.0, None),
                          "update_interval_s": (1.0e-6, None)},
               "laws": ("hertz_mindlin",)},
    # pull-off = force_fraction x weight of the lighter particle + pressure_fraction x the largest
    # compressive force the contact has carried (Luding-type)
    "hysteretic": {"params": {"force_fraction": (0.0, None), "pressure_fraction": (0.0, None),
                              "update_interval_s": (1.0e-6, None)},
                   "laws": ("hertz_mindlin", "linear_cundall")},
    # Willett liquid bridge: forms at contact, acts to the rupture distance; material with itself only
    "liquid_bridge": {"params": {"surface_tension_n_m": (0.0, None), "contact_angle_deg": (0.0, 89.0),
                                 "bridge_liquid_fraction": (0.0, 1.0), "coordination_count": (1.0, None)},
                      "laws": (CAPILLARY_LAW,)},
}

# rolling and twisting springs of hertz_mindlin: k = factor x k_t,ref x R^2 (moment_stiffness)
REFERENCE_OVERLAP_RATIO = 0.01
# Ig2_Facet_Sphere_ScGeom(hertzian=True) gives a facet the radius HERTZ_FACET_FACTOR x R: a flat wall
# for Hertz (equivalent radius R). tests/yade/test_contact_physics.py reads it back from a contact.
HERTZ_FACET_FACTOR = 1.0e8


class ContactRuleError(ValueError):
    """A job asks for a pair the contact law cannot realise: .key (dotted, in the job's
    materials) and .reason."""

    def __init__(self, key, reason):
        self.key, self.reason = key, reason
        super().__init__(f"{key}: {reason}")


# ---------------------------------------------------------------- formulas shared with the YADE side

def restitution_input(restitution, damping_ratio):
    """Dashpot restitution to give YADE so that a bounce comes out at `restitution` under
    global (Cundall) damping `damping_ratio` of the contact force: that damping scales the
    contact force by (1 + a) while a contact closes and (1 - a) while it opens, which
    multiplies the restitution by sqrt((1 - a) / (1 + a)). Capped at 1 (no dashpot)."""
    factor = math.sqrt((1.0 - damping_ratio) / (1.0 + damping_ratio))
    return min(1.0, restitution / factor)


def rolling_radius(radius_a, radius_b):
    """R of the rolling limit mu_r x R x |Fn| of a contact (m): the radius of the smaller
    sphere of the pair; a wall (radius None) does not count, so on a wall it is the
    particle's own radius, and a clump member counts with its own radius."""
    radii = [r for r in (radius_a, radius_b) if r is not None]
    return min(radii)


def mindlin_shear_stiffness_coefficient(young_a, poisson_a, radius_a, young_b, poisson_b, radius_b):
    """k_so of YADE 2023.02a's Mindlin contact (N/m^1.5): tangential stiffness = k_so x sqrt(overlap),
    k_so = 8 G* sqrt(R*), 1/G* = (2 - nu_a)/G_a + (2 - nu_b)/G_b, R* = Ra Rb / (Ra + Rb); a wall
    (radius None) is flat: R* = the sphere's radius. (Read back from contacts in the YADE tests.)"""
    ga, gb = young_a / (2.0 * (1.0 + poisson_a)), young_b / (2.0 * (1.0 + poisson_b))
    g_star = 1.0 / ((2.0 - poisson_a) / ga + (2.0 - poisson_b) / gb)
    if radius_a is None or radius_b is None:
        r_eq = radius_b if radius_a is None else radius_a
    else:
        r_eq = radius_a * radius_b / (radius_a + radius_b)
    return 8.0 * g_star * math.sqrt(r_eq)


def reference_tangential_stiffness(young, poisson, radius):
    """k_t,ref (N/m): the Mindlin tangential stiffness of two spheres of this material and
    radius at the overlap REFERENCE_OVERLAP_RATIO x radius (about the overlap under a
    particle's own weight). It scales the rolling and twisting springs of every contact the
    material takes part in, whatever the partner (a wall, another material)."""
    kso = mindlin_shear_stiffness_coefficient(young, poisson, radius, young, poisson, radius)
    return kso * math.sqrt(REFERENCE_OVERLAP_RATIO * radius)


def moment_stiffness(factor, kt_ref, radius):
    """Rolling or twisting spring stiffness (N m/rad) = factor x k_t,ref x R^2. Its rotation
    frequency sqrt(k / I) ~ sqrt(2.5 factor k_t,ref / m) stays at or below the normal contact
    frequency for factor <= 1, at any particle size, so the translational time step holds."""
    return factor * kt_ref * radius ** 2


# ---------------------------------------------------------------- which law a job runs on

def law_of_job(job):
    """The contact law the job's scene will use: the capillary law when a pair asks for
    liquid bridges, else numerics.contact_model."""
    if any(p["cohesion"]["model"] == "liquid_bridge" for _, _, p in pairs(job)):
        return CAPILLARY_LAW
    return job["rig_config"]["numerics"].get("contact_model", DEFAULT_CONTACT_MODEL)


def pairs(job):
    """(material, partner, properties) for every interaction entry of the job's materials."""
    for name, mat in job["materials"].items():
        for partner, props in mat["interactions"].items():
            yield name, partner, props


def _key(name, partner, field=""):
    return f"materials.{name}.interactions.{partner}" + (f".{field}" if field else "")


def _is_clump(mat):
    return mat["particles"]["shape"] == "clump"


def check_job(job):
    """Raise ContactRuleError for the first pair of the job that its contact law cannot
    realise (dotted key into the job's materials, and why). Returns the law's name."""
    num = job["rig_config"]["numerics"]
    model = num.get("contact_model", DEFAULT_CONTACT_MODEL)
    if model not in CONTACT_MODELS:
        raise ContactRuleError("rig_config.numerics.contact_model",
                               f"{model!r} must be one of {', '.join(CONTACT_MODELS)}")
    law = law_of_job(job)
    partners = set(job["materials"]) | set(job["boundaries"])
    for name, partner, props in pairs(job):
        if partner not in partners:
            continue            # a material absent from this job
        coh = props["cohesion"]
        if law not in COHESION_MODELS[coh["model"]]["laws"]:
            raise ContactRuleError(_key(name, partner, "cohesion.model"),
                                   f"{coh['model']!r} cannot be combined with the {law} law of this scene "
                                   f"(it runs on: {', '.join(COHESION_MODELS[coh['model']]['laws'])})")
    if law == "hertz_mindlin":
        _check_hertz_mindlin(job, num)
    elif law == "linear_cundall":
        _check_linear_cundall(job)
    else:
        _check_capillary(job)
    return law


def _check_hertz_mindlin(job, num):
    a = num.get("global_damping_ratio")
    if a is None:
        raise ContactRuleError("rig_config.numerics.global_damping_ratio", "missing (needed by hertz_mindlin)")
    if not 0.0 <= a <= MAX_GLOBAL_DAMPING_RATIO:
        raise ContactRuleError("rig_config.numerics.global_damping_ratio",
                               f"{a} must be within 0 - {MAX_GLOBAL_DAMPING_RATIO}: the dashpot sets the "
                               "restitution, global damping only brings heaps to rest")
    for k in ("rolling_stiffness_factor", "twisting_stiffness_factor"):
        if num.get(k) is None or not num[k] > 0:
            raise ContactRuleError(f"rig_config.numerics.{k}", f"{num.get(k)!r} must be a number > 0")
    for name, partner, props in pairs(job):
        coh = props["cohesion"]
        if coh.get("adhesive_distance_m", 0.0) > 0.0:
            raise ContactRuleError(_key(name, partner, "cohesion.adhesive_distance_m"),
                                   f"{coh['adhesive_distance_m']} > 0 cannot be realised: the Hertz-Mindlin law "
                                   "of YADE 2023.02a ends a contact at zero overlap (no attraction beyond "
                                   "contact); set it to 0")


def _check_linear_cundall(job):
    names = list(job["materials"])
    es = {}
    for name, partner, props in pairs(job):
        if partner in names or partner in job["boundaries"]:
            es.setdefault(props["restitution_coefficient"], (name, partner))
    if len(es) > 1:
        (e1, p1), (e2, p2) = list(es.items())[:2]
        raise ContactRuleError(_key(*p2, "restitution_coefficient"),
                               f"{e2} differs from {_key(*p1)} ({e1}): linear_cundall realises one "
                               "restitution per scene (by global damping)")
    for name, partner, props in pairs(job):
        coh = props["cohesion"]
        if coh.get("adhesive_distance_m", 0.0) > 0.0:
            raise ContactRuleError(_key(name, partner, "cohesion.adhesive_distance_m"),
                                   "must be 0 on linear_cundall (its bonds act in contact only)")
    # rolling: YADE's CohFrict law takes min(eta_a R_a, eta_b R_b) with a facet of radius 2R
    mats = job["materials"]
    for a in names:
        own_a = mats[a]["interactions"][a]["rolling_resistance_coefficient"]
        for b in names + list(job["boundaries"]):
            if b not in mats[a]["interactions"]:
                continue
            want = mats[a]["interactions"][b]["rolling_resistance_coefficient"]
            if _is_clump(mats[a]) or (b in mats and _is_clump(mats[b])):
                if want != 0:
                    raise ContactRuleError(_key(a, b, "rolling_resistance_coefficient"),
                                           f"{want}: linear_cundall takes rolling resistance 0 with clumps")
                continue
            ra = 0.5 * mats[a]["particles"]["diameter_m"]
            if b in mats:
                rb = 0.5 * mats[b]["particles"]["diameter_m"]
                got = min(own_a * ra, mats[b]["interactions"][b]["rolling_resistance_coefficient"] * rb) / min(ra, rb)
            else:
                # the wall's own value is the largest any material asks on it (demlib.contact_linear)
                wall = max(mats[n]["interactions"][b]["rolling_resistance_coefficient"] for n in names
                           if b in mats[n]["interactions"])
                got = min(own_a * ra, wall * ra) / ra
            if abs(got - want) > 1e-9:
                raise ContactRuleError(_key(a, b, "rolling_resistance_coefficient"),
                                       f"{want} cannot be realised by linear_cundall (it takes the smaller of "
                                       f"both sides' own values: {got:.4g}); use hertz_mindlin")


def _check_capillary(job):
    es = set()
    bridges = []
    names = list(job["materials"])
    for name, partner, props in pairs(job):
        if partner not in names and partner not in job["boundaries"]:
            continue
        es.add(props["restitution_coefficient"])
        if props["rolling_resistance_coefficient"] != 0:
            raise ContactRuleError(_key(name, partner, "rolling_resistance_coefficient"),
                                   f"{props['rolling_resistance_coefficient']}: the liquid-bridge law "
                                   f"({CAPILLARY_LAW}) has no rolling resistance; set it to 0")
        model = props["cohesion"]["model"]
        if model == "liquid_bridge":
            if partner != name:
                raise ContactRuleError(_key(name, partner, "cohesion.model"),
                                       "liquid_bridge acts between particles of one material only")
            if _is_clump(job["materials"][name]):
                raise ContactRuleError(_key(name, partner, "cohesion.model"), "liquid_bridge needs spheres")
            bridges.append(name)
    if len(set(bridges)) > 1:
        raise ContactRuleError(_key(bridges[1], bridges[1], "cohesion.model"),
                               "one material with liquid bridges per scene")
    if len(es) > 1:
        raise ContactRuleError("materials", f"restitution coefficients {sorted(es)}: the liquid-bridge law "
                                            "takes one restitution per scene")
