"""Diagnose a lab's campaign from Python: cases/lab-example (a hand-written campaign in the lab
data format), the verdict, the effects ranked by held-out evidence, and the held-out gap
per run before and after the chosen effect.
    /usr/bin/python3 examples/diagnose_campaign.py   # from any folder: -> out/lab-example-gap.png there"""
import os
import matplotlib; matplotlib.use("Agg")
import matplotlib.pyplot as plt
import vrelab

CASES = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "cases")   # the repository's, not the CWD's
d = vrelab.diagnose(os.path.join(CASES, "lab-example"))
print(d.brief_report())
effects = d.effects_columns()                     # NumPy columns of to_dict()["effects"] (effects_frame(): pandas)
for name, p_name, p, unit, evidence in list(zip(*(effects[k] for k in ("name", "parameter_name", "parameter", "unit", "evidence"))))[:3]:
    print(f"  {name:<24} {p_name} = {p:.4g} {unit}, evidence {evidence:.3g}")
runs = d.runs_columns()                           # NumPy columns of to_dict()["runs"] (runs_frame(): pandas)
fig, ax = plt.subplots(figsize=(9, 4))
x = range(len(runs["id"]))
ax.plot(x, runs["heldout_before_g"] * 1e6, "o", label="held out, model (1)")
ax.plot(x, runs["heldout_after_g"] * 1e6, "s", label=f"held out, with {d.chosen}")
ax.set_xticks(list(x), list(runs["id"]), rotation=45, ha="right", fontsize=7)
ax.set(ylabel="measured − predicted, µg", title=f"{os.path.basename(os.path.normpath(d.dir))}: {d.verdict}"); ax.legend()
os.makedirs("out", exist_ok=True); fig.tight_layout(); fig.savefig("out/lab-example-gap.png", dpi=120)
print("-> out/lab-example-gap.png")
