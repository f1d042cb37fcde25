"""The paper's confirmation figure from Python: one run on the virtual shaker under the
confirmation condition of cases/paper.toml (2 g along IA at 20 Hz, IA at 45 deg), its raw
output, and the running integral of the deviation from rest against eq. (3).
    /usr/bin/python3 examples/confirmation.py   # from any folder: -> out/confirmation.png there"""
import os, tomllib
import matplotlib; matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import vrelab

CASES = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "cases")   # the repository's, not the CWD's
case = tomllib.load(open(os.path.join(CASES, "paper.toml"), "rb"))
case["orientation"] = {"a_g": [0.7071067811865476, 0.7071067811865476, 0.0]}   # IA at 45 deg
case["vibration"] = {"type": "sine", "amplitude_g": [2.0, 0.0, 0.0], "frequency_Hz": 20.0}
r = vrelab.shake(vrelab.load_case(case, "paper confirmation"), series=True)
s, K1 = r.series, case["coefficients"]["K1"]
on = s["time_s"] >= 0
t, dev = s["time_s"][on], s["output_mA"][on] / K1 - r.baseline_g                 # g
n = round(r.sample_rate_Hz / 20.0)                          # samples per period: the swing's integral is 0 over each
tk, ik = t[::n], np.concatenate([[0.0], np.cumsum(dev)[n - 1::n]])[:len(t[::n])] / r.sample_rate_Hz  # g s, whole periods
k0 = np.searchsorted(tk, r.settle_s)                         # measured from here on (settled)
fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
a1.plot(s["time_s"], s["output_mA"], lw=0.3); a1.set_ylabel("output, mA")
a2.plot(tk, ik * 1e6, ".", ms=3, label=f"running integral at whole periods: measured {r.measured_g * 1e6:.2f} ± {r.sigma_g * 1e6:.2f} µg")
a2.plot(tk[k0:], (ik[k0] + r.predicted_g * (tk[k0:] - tk[k0])) * 1e6, "--", label=f"eq. (3): {r.predicted_g * 1e6:.2f} µg")
a2.set(xlabel="time, s", ylabel="∫(U/K1 − rest) dt, µg·s"); a2.legend()
os.makedirs("out", exist_ok=True); fig.savefig("out/confirmation.png", dpi=120)
print(f"measured {r.measured_g * 1e6:.3f} ± {r.sigma_g * 1e6:.3f} µg, eq. (3) {r.predicted_g * 1e6:.3f} µg -> out/confirmation.png")
