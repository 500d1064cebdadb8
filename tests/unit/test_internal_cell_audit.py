"""The internal-friction audit's bookkeeping (bench/internal_cell_audit.py), without YADE:
a run is told apart by its overrides, and the table's change against the baseline is the
difference of the two settings' mean offsets from the lab with the unpaired standard error."""
import math
import statistics

import pytest

from bench_scripts import load_bench_script

audit = load_bench_script("internal_cell_audit")


def fake_run(suspect, friction, mu_12, mu_90, seed, rolling=None):
    return {"rig": "internal_friction", "material": "M3-dry", "seed": seed, "lab_sample": "fines_dry",
            "job": {"overrides": audit.settings("M3-dry", friction, suspect, rolling), "material": "M3-dry",
                    "rig": "internal_friction"},
            "stress_pa": [12000, 90000], "mu_static": [mu_12, mu_90], "sticks": [False, False],
            "provenance": {"cpu_time_s": 80.0}}


def test_each_setting_is_found_again_from_its_overrides():
    for name in audit.SUSPECTS:
        for fr in (0.1, 0.5):
            for rr in (None, 0.7):
                assert audit.suspect_of(audit.settings("M3-dry", fr, name, rr), "M3-dry") == (name, fr, rr)
    # a rolling resistance on the material alone is not the study's rolling setting (walls too)
    only_material = dict(audit.settings("M3-dry", 0.5, "baseline"),
                         **{"interactions.M3-dry.rolling_resistance_coefficient": 0.7})
    assert audit.suspect_of(only_material, "M3-dry") is None
    other = dict(audit.settings("M3-dry", 0.5, "baseline"), **{"rig.geometry.cell_gap_m": 0.004})
    assert audit.suspect_of(other, "M3-dry") is None
    # the former stage's settings are in every point
    assert audit.settings("M3-dry", 0.5, "lid_free")["rig.procedure.consolidation_stresses_pa"] == [12000, 90000]


def test_the_change_is_the_difference_of_the_mean_offsets_with_its_standard_error():
    base = [fake_run("baseline", 0.5, 0.70 + d, 0.60 + d, s) for s, d in enumerate((0.00, 0.02, -0.02), 1)]
    lid = [fake_run("lid_free", 0.5, 0.50 + d, 0.40 + d, s) for s, d in enumerate((0.00, 0.04, -0.04), 1)]
    for r, turned in zip(lid, ((0.4, 0.6), (0.5, 0.5), (0.3, 0.7))):
        r["cell_rotation_onset_deg"] = list(turned)
    other_rolling = [fake_run("baseline", 0.5, 0.10, 0.10, s, rolling=0.7) for s in (1, 2, 3)]
    text = audit.table({("baseline", 0.5, None): base, ("lid_free", 0.5, None): lid,
                        ("baseline", 0.5, 0.7): other_rolling})
    row = next(line for line in text.splitlines() if "| lid_free |" in line)
    cells = [c.strip() for c in row.split("|")]
    change, se = cells[-4].split(" +- ")
    assert cells[-3] == "0.50"                            # mean turn of the cell at the onset over steps and seeds
    base_row = next(line for line in text.splitlines() if "| start | baseline |" in line)
    assert base_row.split("|")[-3].strip() == "-"        # runs without the record
    # every step 0.2 lower, so the offset from any lab curve is 0.2 lower
    assert float(change) == pytest.approx(-0.200, abs=1e-3)
    want = math.hypot(statistics.stdev((0.0, 0.02, -0.02)), statistics.stdev((0.0, 0.04, -0.04))) / math.sqrt(3)
    assert float(se) == pytest.approx(want, abs=1e-3)
    assert cells[5].startswith("0.500 (0.040)")          # mu_static at 12 kPa, mean (seed SD)
    # the change is against the baseline at the same rolling resistance, not another one
    assert "| 0.7 | baseline | 3 | 0.100 (0.000)" in text
