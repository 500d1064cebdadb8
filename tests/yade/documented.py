"""Every result.json key of a rig is documented in docs/rigs.md (its section or the
shared one), and holds the keys its descriptor requires (pycal/rigs/<rig>.py): a rig
that adds a key without documenting it, or drops a required one, fails its physics test."""
import re

from pycal import REPO_ROOT, rigs

# sections whose keys a rig's result also carries (docs/rigs.md: "every key of ...")
INHERITS = {"surcharge": ["aor"], "aor_mixed": ["aor"], "ccs_expansion": ["ccs"], "ucs": ["ccs"],
            "internal_friction": ["wall_friction"]}


def documented_keys(rig):
    """Backticked names in the shared section and in the rig's own (and inherited) sections."""
    text = (REPO_ROOT / "docs" / "rigs.md").read_text()
    sections = re.split(r"^## ", text, flags=re.M)
    wanted = {"What every rig shares"} | {rig} | set(INHERITS.get(rig, []))
    names = set()
    for sec in sections:
        title = sec.split("\n", 1)[0]
        if title.split(":", 1)[0].strip() in wanted:
            names |= set(re.findall(r"`([^`]+)`", sec))
    return names


def undocumented(result):
    """Keys (nested ones as a.b) of a result that docs/rigs.md does not name."""
    names = documented_keys(result["rig"])
    patterns = [re.compile("^" + re.escape(n).replace(r"<material>", r"[A-Za-z0-9-]+") + "$")
                for n in names if "<material>" in n]
    # a documented key may carry a leading dot for nested keys: `.lid_position_m`
    names |= {n.lstrip(".") for n in names}
    missing = []
    for key, value in result.items():
        if key == "job":
            continue
        if key in ("provenance", "spring_curve") and isinstance(value, dict):
            for sub in value:
                if f"{key}.{sub}" not in names and sub not in names:
                    missing.append(f"{key}.{sub}")
            continue
        if key not in names and not any(p.match(key) for p in patterns):
            missing.append(key)
    return sorted(missing)


def assert_documented(result):
    """Every key documented, and every key the rig's descriptor requires of a whole result
    (pycal/rigs/<rig>.py: the cache trusts a result only with them) present."""
    missing = undocumented(result)
    assert not missing, f"{result['rig']}: result.json keys not in docs/rigs.md: {', '.join(missing)}"
    if "replicas" not in result:
        absent = [k for k in rigs.get(result["rig"]).required_result_keys() if k not in result]
        assert not absent, f"{result['rig']}: result.json lacks the descriptor's keys {', '.join(absent)}"
