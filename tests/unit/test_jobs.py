"""Job resolution: explicit, hashed, overrides validated."""
import pytest

from pycal.errors import ConfigError
from pycal.jobs import parse_set, resolve_job, job_id


def test_job_is_explicit_and_hashed():
    job = resolve_job("aor", "M2", seed=3)
    assert job["seed"] == 3 and job["material"] == "M2" and job["script"] == "aor.py"
    assert job["rig_config"]["procedure"]["lift_speed_m_s"] == 0.002
    assert job["rig_config"]["numerics"]["timestep_safety_factor"] > 0
    assert job["boundaries"]["steel"]["youngs_modulus_pa"] == 2.38e11
    assert job["job_id"].startswith("aor-M2-s3-") and job["job_id"] == job_id(job)


def test_same_inputs_same_id_different_inputs_different_id():
    a = resolve_job("fill", "M2", seed=1)
    b = resolve_job("fill", "M2", seed=1)
    c = resolve_job("fill", "M2", seed=2)
    d = resolve_job("fill", "M2", {"particles.density_kg_m3": 3000}, seed=1)
    assert a["job_id"] == b["job_id"]
    assert len({a["job_id"], c["job_id"], d["job_id"]}) == 3


def test_overrides_apply_to_material_and_rig():
    job = resolve_job("aor", "M2", {"particles.density_kg_m3": 3100,
                                    "rig.procedure.lift_speed_m_s": 0.01,
                                    "interactions.steel.friction_coefficient": 0.4})
    assert job["materials"]["M2"]["particles"]["density_kg_m3"] == 3100
    assert job["rig_config"]["procedure"]["lift_speed_m_s"] == 0.01
    assert job["materials"]["M2"]["interactions"]["steel"]["friction_coefficient"] == 0.4
    assert job["overrides"]["particles.density_kg_m3"] == 3100


def test_bad_override_is_validated():
    with pytest.raises(ConfigError, match=r"--set: particles.density_kg_m3=-5: -5 must be > 0"):
        resolve_job("fill", "M2", {"particles.density_kg_m3": -5})
    with pytest.raises(ConfigError, match=r"no such key to override"):
        resolve_job("fill", "M2", {"particles.colour": "red"})
    with pytest.raises(ConfigError, match=r"seed"):
        resolve_job("fill", "M2", seed=-1)


def test_parse_set():
    assert parse_set(["a.b=1", "c=2.5e6", "d={model: none}"]) == {"a.b": 1, "c": 2.5e6, "d": {"model": "none"}}
    with pytest.raises(ConfigError, match="KEY=VALUE"):
        parse_set(["novalue"])


def test_a_set_job_without_overrides_is_the_job_with_none():
    """No overrides and an empty dict are the same set job (the job records {}), called
    directly or through resolve_job: a cached mixed-pile run is found again whichever way
    the caller says it."""
    from pycal.jobs import resolve_set_job
    a = resolve_set_job("aor_mixed", "mixed-wet", None, seed=2)
    b = resolve_set_job("aor_mixed", "mixed-wet", {}, seed=2)
    assert a == resolve_job("aor_mixed", "mixed-wet", None, seed=2)
    assert a == b and a["overrides"] == {}
