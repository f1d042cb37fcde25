"""The Python side of the binding's overhead (docs/python.md): vrelab.predict called N times on
a case loaded once, against build/vrelab_bench_python (the same library calls in C++), and
shake from Python against the library's own timing of the run (ShakeResult.wall_s, what the
CLI prints as "s wall").

    PYTHONPATH=build/python /usr/bin/python3 python/bench/bench_predict.py [N]
"""
import sys
import time

import vrelab

n = int(sys.argv[1]) if len(sys.argv) > 1 else 10000
case = vrelab.load_case("cases/paper-predict.toml")


def per_call(f):
    """CPU time per call (the process's, s): best of 5 loops of n calls (the machine is shared)."""
    best = float("inf")
    for _ in range(5):
        t = time.process_time()
        for _ in range(n):
            f()
        best = min(best, (time.process_time() - t) / n)
    return best


print(f"{n} calls, CPU time per call, best of 5:")
print(f"  vrelab.predict_total_g(case)        {per_call(lambda: vrelab.predict_total_g(case)) * 1e6:8.2f} us")
print(f"  vrelab._core.predict(case)          {per_call(lambda: vrelab._core.predict(case, False)) * 1e6:8.2f} us")
print(f"  vrelab.predict(case)                {per_call(lambda: vrelab.predict(case)) * 1e6:8.2f} us")
print(f"  vrelab.predict(case).total_g        {per_call(lambda: vrelab.predict(case).total_g) * 1e6:8.2f} us")
print(f"  vrelab.predict(case).to_dict()      {per_call(lambda: vrelab.predict(case).to_dict()) * 1e6:8.2f} us")

shake_case = vrelab.load_case("cases/shake-sine.toml")
for _ in range(5):
    t = time.perf_counter()
    r = vrelab.shake(shake_case)
    outer = time.perf_counter() - t
    print(f"shake cases/shake-sine.toml: Python call {outer:.4f} s, library's wall_s {r.wall_s:.4f} s, "
          f"ratio {outer / r.wall_s:.4f}")
