"""Choice of the contact-law family of a scene from the job's cohesion models.

Every family offers the interface of contact.ContactModel (mat_id, radius, particle_mass,
pair, ip2, law2, damping) plus bounding_functors(), geometry_functors() and
extra_engines(), which Scene uses to build its engines:

- ContactModel (contact.py): CohFrict law, cohesion `none` / `force_fraction`;
- HystereticContactModel (contact_hysteretic.py): the same law plus `hysteretic`;
- CapillaryContactModel (contact_capillary.py): ViscElCap law, `liquid_bridge` (fines-fines
  only; no other cohesion, no rolling resistance in that scene).

A job mixing models of different families is an error with a clear message.
"""
from yade.wrapper import Bo1_Sphere_Aabb, Bo1_Facet_Aabb, Ig2_Sphere_Sphere_ScGeom6D, Ig2_Facet_Sphere_ScGeom6D

from .contact import ContactModel
from .contact_hysteretic import HystereticContactModel
from .contact_capillary import CapillaryContactModel
from .jobio import RigFailure

# cohesion model -> contact-model class
FAMILY = {
    "none": None,                 # any family
    "force_fraction": ContactModel,
    "hysteretic": HystereticContactModel,
    "liquid_bridge": CapillaryContactModel,
}


def cohesion_models(job):
    """{model name: [pair names]} over every interaction of the job's materials."""
    out = {}
    for name, mat in job["materials"].items():
        for partner, props in mat["interactions"].items():
            out.setdefault(props["cohesion"]["model"], []).append(f"{name}-{partner}")
    return out


def contact_model_class(job):
    used = cohesion_models(job)
    classes = set()
    for model, pairs in used.items():
        if model not in FAMILY:
            raise RigFailure(f"cohesion model {model!r} (pairs {', '.join(pairs)}) has no contact law in demlib")
        if FAMILY[model] is not None:
            classes.add(FAMILY[model])
    if CapillaryContactModel not in classes and HystereticContactModel in classes:
        return HystereticContactModel      # a subclass of ContactModel: also does force_fraction
    if len(classes) > 1:
        raise RigFailure(f"cohesion models {sorted(used)} need different contact-law families in one scene")
    return classes.pop() if classes else ContactModel


def make_contact_model(job, gravity):
    model = contact_model_class(job)(job, gravity=gravity)
    for name, default in (("bounding_functors", lambda: [Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]),
                          ("geometry_functors", lambda: [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Facet_Sphere_ScGeom6D()]),
                          ("extra_engines", lambda: [])):
        if not hasattr(model, name):
            setattr(model, name, default)
    return model
