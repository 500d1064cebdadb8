"""How long a study may still take, from what its runs cost so far: a bound for the
console. Each (material, rig)'s median CPU seconds per run (provenance cpu_time_s of the
results the study received, cached ones included; a material not yet run on a rig takes
the costliest material's median there) times the runs its budget still allows, divided
by the runs that truly go in parallel (the workers, at most the machine's cores for a
local executor). A stage ends before its budget when its interval is within tolerance,
so the real time is usually shorter; a stage on a rig with no run yet is counted as
unknown. Keyed by rig alone, the bound was 4x short on the main job's wet cohesion stage:
the dry fines' 110 s internal-friction runs set the median, the wet ones cost 520 - 640 s,
and 3 workers on 2 cores were counted as 3."""
import statistics


class Eta:
    def __init__(self, workers, cores=None):
        workers = max(1, int(workers or 1))
        self.workers = min(workers, cores) if cores else workers    # runs that go in parallel
        self.cpu_s = {}                        # (material, rig) -> CPU seconds per run seen

    def add(self, material, rig, results):
        for r in results:
            cpu = ((r or {}).get("provenance") or {}).get("cpu_time_s")
            if isinstance(cpu, (int, float)) and cpu > 0:
                self.cpu_s.setdefault((material, rig), []).append(float(cpu))

    def per_run_s(self, material, rig):
        xs = self.cpu_s.get((material, rig))
        if xs:
            return statistics.median(xs)
        others = [statistics.median(v) for (m, r), v in self.cpu_s.items() if r == rig]
        return max(others) if others else None

    def bound_s(self, budgets):
        """(wall seconds at most, rigs with no cost yet) for [(material, rig, runs left)]."""
        total, unknown = 0.0, []
        for material, rig, runs in budgets:
            c = self.per_run_s(material, rig)
            if c is None:
                unknown.append(rig)
            else:
                total += c * max(0, runs)
        return total / self.workers, sorted(set(unknown))


def text(seconds, unknown):
    """'~12 min', or '~12 min + ?' when stages on rigs with no run so far are to come."""
    out = f"~{seconds / 60:.0f} min" if seconds >= 60 else f"~{seconds:.0f} s"
    return out + (" + ?" if unknown else "")
