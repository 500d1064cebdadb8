"""A 1-D stage on a material set (`material_set`): the config names a set that holds the
stage's material, on a rig that takes sets; each error names the file, the key and why."""
import pytest

from pycal.calibration.study_config import load_study
from pycal.errors import ConfigError

STAGE = """name: cross
seeds_count: 2
materials:
  M3-wet:
    - stage: cohesion
      name: cross_binding
      rig: {rig}
      material_set: {mset}
      response: aor_mean_deg
      target: {{value: 88.0, band_deg: 2.0}}
      parameter:
        keys: [interactions.M2.cohesion.force_fraction]
        start: 10.0
        bounds: [0.5, 50.0]
        scale: log
        response_increases: true
        tolerance_percent: 25.0
{extra}"""


def study(tmp_path, rig="aor_mixed", mset="mixed-wet", extra=""):
    p = tmp_path / "cross.yaml"
    p.write_text(STAGE.format(rig=rig, mset=mset, extra=extra))
    return p


def test_a_set_stage_loads_with_its_set(tmp_path):
    (st,) = load_study(study(tmp_path))["materials"]["M3-wet"]
    assert st["material_set"] == "mixed-wet" and st["rig"] == "aor_mixed"


@pytest.mark.parametrize("rig, mset, extra, error", [
    ("aor_mixed", "mixed-damp", "", r"materials.M3-wet\[0\].material_set: 'mixed-damp': no such material set"),
    ("aor_mixed", "mixed-dry", "", r"material_set: mixed-dry has no component M3-wet"),
    ("aor", "mixed-wet", "", r"material_set: rig aor takes one material, not a set"),
    ("aor_mixed", "mixed-wet", "      run_at: {contact.youngs_modulus_pa: 2.0e7}\n",
     r"materials.M3-wet\[0\].run_at: not with material_set"),
])
def test_a_bad_set_stage_names_the_key_and_why(tmp_path, rig, mset, extra, error):
    path = study(tmp_path, rig, mset, extra)
    with pytest.raises(ConfigError, match=error) as exc:
        load_study(path)
    assert str(path.name) in str(exc.value)
