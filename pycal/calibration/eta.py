"""How long a study may still take, from what its runs cost so far: an upper bound for
the console. Each rig's median CPU seconds per run (provenance cpu_time_s of the results
the study received, cached ones included) times the runs its budget still allows,
divided by the executor's workers. A stage ends before its budget when its interval is
within tolerance, so the real time is usually shorter; a stage on a rig with no run
yet is counted as unknown."""
import statistics


class Eta:
    def __init__(self, workers):
        self.workers = max(1, int(workers or 1))
        self.cpu_s = {}                        # rig -> CPU seconds per run seen

    def add(self, rig, results):
        for r in results:
            cpu = ((r or {}).get("provenance") or {}).get("cpu_time_s")
            if isinstance(cpu, (int, float)) and cpu > 0:
                self.cpu_s.setdefault(rig, []).append(float(cpu))

    def per_run_s(self, rig):
        xs = self.cpu_s.get(rig)
        return statistics.median(xs) if xs else None

    def bound_s(self, budgets):
        """(wall seconds at most, rigs with no cost yet) for [(rig, runs left)]."""
        total, unknown = 0.0, []
        for rig, runs in budgets:
            c = self.per_run_s(rig)
            if c is None:
                unknown.append(rig)
            else:
                total += c * max(0, runs)
        return total / self.workers, sorted(set(unknown))


def text(seconds, unknown):
    """'~12 min', or '~12 min + ?' when stages on rigs with no run so far are to come."""
    out = f"~{seconds / 60:.0f} min" if seconds >= 60 else f"~{seconds:.0f} s"
    return out + (" + ?" if unknown else "")
