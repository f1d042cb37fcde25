"""Diagnose a lab's campaign from Python: cases/lab-example (a hand-written campaign in the lab
data format), the verdict, the effects ranked by held-out evidence, and the held-out gap
per run before and after the chosen effect.
    /usr/bin/python3 examples/diagnose_campaign.py   # -> out/lab-example-gap.png"""
import os
import matplotlib; matplotlib.use("Agg")
import matplotlib.pyplot as plt
import vrelab

d = vrelab.diagnose("cases/lab-example")
print(d.brief_report())
j = d.to_dict()                                   # the same as `vrelab diagnose --json`
for e in j["effects"][:3]:
    print(f"  {e['name']:<24} {e['parameter_name']} = {e['parameter']:.4g} {e['unit']}, evidence {e['evidence']:.3g}")
runs = j["runs"]
fig, ax = plt.subplots(figsize=(9, 4))
x = range(len(runs))
ax.plot(x, [r["heldout_before_g"] * 1e6 for r in runs], "o", label="held out, model (1)")
ax.plot(x, [r["heldout_after_g"] * 1e6 for r in runs], "s", label=f"held out, with {d.chosen}")
ax.set_xticks(list(x), [r["id"] for r in runs], rotation=45, ha="right", fontsize=7)
ax.set(ylabel="measured − predicted, µg", title=f"{d.dir}: {d.verdict}"); ax.legend()
os.makedirs("out", exist_ok=True); fig.tight_layout(); fig.savefig("out/lab-example-gap.png", dpi=120)
