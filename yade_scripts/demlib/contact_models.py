"""Choice of the contact law of a scene (runs inside YADE).

pycal.contact_rules.law_of_job names the law: the job's numerics.contact_model
(`hertz_mindlin`, the default, or `linear_cundall`, the first law), or the
viscoelastic-capillary law when a pair uses liquid bridges. The linear_cundall law has a
subclass for the `hysteretic` cohesion model. Every class offers the interface of
contact_base.PairTable.
"""
from pycal import contact_rules

from .contact_capillary import CapillaryContactModel
from .contact_hertz import HertzMindlinContactModel
from .contact_linear import LinearCundallContactModel
from .contact_linear_hysteretic import HystereticContactModel


def contact_model_class(job):
    law = contact_rules.law_of_job(job)
    if law == contact_rules.CAPILLARY_LAW:
        return CapillaryContactModel
    if law == "hertz_mindlin":
        return HertzMindlinContactModel
    if any(p["cohesion"]["model"] == "hysteretic" for _, _, p in contact_rules.pairs(job)):
        return HystereticContactModel
    return LinearCundallContactModel


def make_contact_model(job, gravity):
    return contact_model_class(job)(job, gravity=gravity)
