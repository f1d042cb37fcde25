# Sourced by the MPI and checkpoint test scripts: two result JSON files compared.
same_json() {  # same_json <a> <b>: equal but for times, threads, ranks, the resume file and the program record
  python3 - "$1" "$2" <<'PY'
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if k not in ("wall_s", "simulate_s", "threads", "ranks", "program",
                             "monte_carlo_ranks", "monte_carlo_threads_per_rank",
                             "monte_carlo_checkpoint")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
a, b = (strip(json.load(open(p))) for p in sys.argv[1:3])
sys.exit(0 if a == b else 1)
PY
}
