#!/usr/bin/python3
"""The same sine condition in SciPy as a test engineer would write it, against `vrelab shake`.

Default plant (pendulum 50 Hz, zeta 0.3, b = 1000 rad/s^2/g, crossover 500 Hz, 50 deg phase
margin, PI zero at 0.1 x crossover), K1 = 1.25, k0 = 1.5e-3 and k2 = 15 ug/g^2 in the loop,
static a = [0.5, 0.866, 0], 5 g along IA. SciPy: solve_ivp (DOP853) from rest (every state
zero: the instrument switched on), settled for 30 slowest time constants, then the mean of
the output over 4 whole periods from the quadrature state. vrelab: `shake --json`, its
in-process CPU time solver_stats.cpu_s. Prints per frequency both answers, their
difference and CPU seconds.

SciPy runs in a child process with a CPU-time limit (--scipy-cpu-limit T seconds, default 300;
RLIMIT_CPU, so a loaded machine does not cut it short): the solver, its settings and its start
are the same with or without the limit. When SciPy does not finish within T CPU seconds (its
explicit DOP853 on the stiff loop at 1 Hz) the line says so and prints the bound
"SciPy > T s, vrelab x ms: > R x" instead of a ratio.
Run: bench/scipy_shake.py [--scipy-cpu-limit T] [build/vrelab] [frequencies...]
     (docs/performance.md)
"""
import json, math, multiprocessing, os, resource, signal, subprocess, sys, tempfile, time
import numpy as np
from scipy.integrate import solve_ivp

K1, K0, K2 = 1.25, 1.5e-3, 1.5e-5
A_STATIC = [0.5, math.sqrt(0.75), 0.0]
AMP = 5.0
FP, ZETA, B = 50.0, 0.3, 1000.0
FC, PM, RI = 500.0, 50.0, 0.1


def design_servo():
    """plant/accelerometer.cpp design_servo: PI + lead with |L(j wc)| = 1."""
    wc, wp = 2 * math.pi * FC, 2 * math.pi * FP
    jw = 1j * wc
    plant = B / (jw * jw + 2 * ZETA * wp * jw + wp * wp)
    wi = RI * wc
    pi = 1 + wi / jw
    phase = math.degrees(np.angle(plant * pi))
    lead = PM - 180 - (phase - 360 if phase > 0 else phase)
    sn = math.sin(math.radians(lead))
    alpha = (1 + sn) / (1 - sn)
    wz, wpole = wc / math.sqrt(alpha), wc * math.sqrt(alpha)
    leadc = (1 + jw / wz) / (1 + jw / wpole)
    g = 1 / abs(plant * pi * leadc)
    return g, wz, wpole, wi


G, WZ, WPOLE, WI = design_servo()
KL = WPOLE / WZ
WP = 2 * math.pi * FP
I_REST = A_STATIC[0] + K0 + K2 * A_STATIC[0] ** 2  # U/K1 at rest: m_il(a_IA)


def rhs_factory(w):
    def rhs(t, x):
        th, om, ld, integ, _q = x
        u = G * th
        y = KL * u + (1 - KL) * ld
        i = y + WI * integ
        z = (-1 + math.sqrt(1 + 4 * K2 * (i - K0))) / (2 * K2)  # m_il^-1(i): z + k0 + k2 z^2 = i
        a = A_STATIC[0] + AMP * math.sin(w * t)
        return [om, -2 * ZETA * WP * om - WP * WP * th + B * (a - z), WPOLE * (u - ld), y, i - I_REST]
    return rhs


def slowest_time_constant():
    # Linear loop (k0, k2 -> 0): states theta, omega, lead, integral.
    a = np.array([[0, 1, 0, 0],
                  [-WP * WP - B * KL * G, -2 * ZETA * WP, -B * (1 - KL), -B * WI],
                  [WPOLE * G, 0, -WPOLE, 0],
                  [KL * G, 0, 1 - KL, 0]])
    return 1 / min(-np.linalg.eigvals(a).real)


def scipy_measure(f, rtol=1e-12):
    w, period = 2 * math.pi * f, 1 / f
    tau = slowest_time_constant()
    settle = math.ceil(30 * tau / period) * period
    t0 = time.process_time()
    sol = solve_ivp(rhs_factory(w), (0, settle + 4 * period), [0.0] * 5, method="DOP853", rtol=rtol,
                    atol=1e-15, t_eval=[settle, settle + 4 * period])
    cpu = time.process_time() - t0
    q = sol.y[4]
    return (q[1] - q[0]) / (4 * period), cpu


CASE = """g_m_per_s2 = 9.81
[instrument]
output_unit = "mA"
[coefficients]
K1 = 1.25
k0 = 1.5e-3
k1_asym = 0.0
k2 = 1.5e-5
k3 = 0.0
k4 = 0.0
delta_OA = 0.0
delta_PA = 0.0
k_IP = 0.0
k_IO = 0.0
k_PO = 0.0
k_PP = 0.0
k_OO = 0.0
[orientation]
a_g = [0.5, 0.8660254037844386, 0.0]
[vibration]
type = "sine"
amplitude_g = [5.0, 0.0, 0.0]
phase_deg = [0.0, 0.0, 0.0]
frequency_Hz = {f!r}
[plant]
type = "from_coefficients"
[run]
seed = 1
"""


def vrelab_measure(binary, f):
    with tempfile.TemporaryDirectory() as d:
        case, out = os.path.join(d, "c.toml"), os.path.join(d, "o.json")
        open(case, "w").write(CASE.format(f=float(f)))
        subprocess.run([binary, "shake", case, "--json", out], check=True, stdout=subprocess.DEVNULL)
        j = json.load(open(out))
        return j["measured_g"], j["solver_stats"].get("cpu_s", j["solver_stats"]["wall_s"])


def _scipy_child(f, limit_s, conn):
    # The child's own CPU time is limited; SIGXCPU at the soft limit ends it.
    resource.setrlimit(resource.RLIMIT_CPU, (int(math.ceil(limit_s)), int(math.ceil(limit_s)) + 10))
    conn.send(scipy_measure(f))
    conn.close()


def scipy_measure_limited(f, limit_s):
    """(mean_g, cpu_s) or None when SciPy used limit_s CPU seconds without finishing."""
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_scipy_child, args=(f, limit_s, child))
    proc.start()
    child.close()
    try:
        result = parent.recv()
    except EOFError:  # the child ended without sending (SIGXCPU)
        result = None
    proc.join()
    if proc.exitcode != 0 or result is None:
        if proc.exitcode in (-signal.SIGXCPU, -signal.SIGKILL):
            return None
        raise RuntimeError(f"SciPy child at {f} Hz ended with exit code {proc.exitcode}")
    return result


def main():
    args = sys.argv[1:]
    limit_s = 300.0
    if args[:1] == ["--scipy-cpu-limit"]:
        limit_s, args = float(args[1]), args[2:]
    binary = args[0] if args else "build/vrelab"
    freqs = [float(x) for x in args[1:]] or [1, 10, 100, 1000, 5000]
    print(f"SciPy CPU limit {limit_s:g} s; load average at start {os.getloadavg()[0]:.2f}")
    print(f"{'f_Hz':>7} {'vrelab_g':>16} {'scipy_g':>16} {'diff_g':>9} {'vrelab_cpu_s':>12} {'scipy_cpu_s':>11} {'ratio':>7}")
    for f in freqs:
        v, vc = vrelab_measure(binary, f)
        r = scipy_measure_limited(f, limit_s)
        if r is None:
            print(f"{f:7g} {v:16.10e} {'-':>16} {'-':>9} {vc:12.4g} {'>' + format(limit_s, 'g'):>11} {'>' + format(limit_s / vc, '.0f'):>7}"
                  f"   SciPy > {limit_s:g} s, vrelab {1e3 * vc:.3g} ms: > {limit_s / vc:.0f} x")
        else:
            s, sc = r
            print(f"{f:7g} {v:16.10e} {s:16.10e} {s - v:+9.1e} {vc:12.4g} {sc:11.4g} {sc / vc:7.0f}")
        sys.stdout.flush()
    print(f"load average at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
