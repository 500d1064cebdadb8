"""Rig 3: surcharge angle after vibration (docs/rigs.md, docs/lab-tests.md section 5).

Same as the AoR rig up to the settled pile and its angles (aor_* keys, pile_*.csv),
then the table facets move kinematically on an ellipse (x = A_h sin wt,
z = A_v (1 - cos wt), 90 degree phase) at vibration_frequency_hz for
vibration_duration_s, stop at their home position, the pile settles and is measured
again (surcharge_* keys, surcharge_*.csv, surcharge_side.png).
A batch job (several seeds) builds one rig per seed side by side (demlib.replicas).
Run: yade -j1 -x -n yade_scripts/surcharge.py job.json
"""

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import rigs, replicas
from yade_scripts import aor


def procedure(scene, out_dir):
    """Pile, vibration and pile again of one seed (a generator: demlib.phases)."""
    from yade import O
    job = scene.job
    p = scene.rig["procedure"]
    info, cell = yield from rigs.cylinder_lift_pile(scene)
    out = aor.pile_result(scene, out_dir, info)
    vib = yield from rigs.vibrate_table(scene, cell["table_ids"], p["vibration_frequency_hz"],
                                        p["vibration_amplitude_horizontal_m"], p["vibration_amplitude_vertical_m"],
                                        p["vibration_duration_s"])
    t_settle, n_fallen = yield from rigs.settle_pile(scene, "surcharge settle")
    keys, m = rigs.measure_pile(scene, out_dir, prefix="surcharge", files="surcharge",
                                title=f"surcharge {scene.material} seed {job['seed']}")
    out.update(keys)
    out.update({"surcharge_n_particles": m["n_particles"], "surcharge_pile_height_m": m["pile_height_m"],
                "surcharge_pile_radius_m": m["pile_radius_m"], "vibration_time_s": vib["vibration_time_s"],
                "surcharge_settle_time_s": t_settle,
                "n_fallen_off": out["n_fallen_off"] + vib["n_fallen"] + n_fallen,
                "steps": O.iter})
    return out


main = replicas.rig_main(procedure, half_width_m=rigs.table_half_width)
run_rig(main)
