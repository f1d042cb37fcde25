#!/usr/bin/python3
"""The pickoff nonlinearity beyond first order against the ODE, p2 from 0 to 40 /rad.

The plant of cases/shake-second-order-navmat.toml (a 620 Hz mode along IA, k3 = -1.03e-6 /g^2
in the loop) with k1' = 2e-5, k2 = 1.5e-5 and, with --k4, k4 = 2e-7 added, at p2 = 0, 10, 20,
30, 40 /rad, under:
  - random: the case's NAVMAT-shaped 5.66 g rms along IA (ODE: 40 s in 16 blocks, seed 1);
  - sine: 8 g along IA at 100 and 300 Hz, 2 g at 600 Hz (the mode; the ODE's periodic
    steady state, CVODE at 1e-10).
Per run: `predict --frequency-dependent` (total, its second-order part and that part's stated
uncertainty) and `shake` (measured +/- sigma); the first order is the total less the second
order. Prints a Markdown table: both predictions' differences from the ODE in % and in sigma.
Run: bench/second_order_sweep.py [--k4] [build/vrelab] (about 1 min; docs/frequency.md)
"""
import json, os, re, subprocess, sys, tempfile

CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "shake-second-order-navmat.toml")


def with_values(text, p2, k4, sine):
    text = re.sub(r"^p2_per_rad = .*$", f"p2_per_rad = {p2}", text, flags=re.M)
    text = re.sub(r"^k1_asym = .*$", "k1_asym = 2.0e-5", text, flags=re.M)
    text = re.sub(r"^k2 = .*$", "k2 = 1.5e-5", text, flags=re.M)
    text = re.sub(r"^k4 = .*$", f"k4 = {k4}", text, flags=re.M)
    if sine:
        f, amplitude = sine
        start, end = text.index("[vibration]"), text.index("[plant]")
        text = (text[:start] + f'[vibration]\ntype = "sine"\namplitude_g = [{amplitude}, 0.0, 0.0]\nfrequency_Hz = {f}\n\n'
                + text[end:])
        text = text.replace("relative_tolerance = 1e-4 ", "relative_tolerance = 1e-10")
    return text


def run(binary, args):
    out = subprocess.run([binary] + args, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{' '.join(args)}: exit {out.returncode}: {out.stderr.strip()}")


def main():
    args = [a for a in sys.argv[1:] if a != "--k4"]
    k4 = 2.0e-7 if "--k4" in sys.argv else 0.0
    binary = args[0] if args else "build/vrelab"
    base = open(CASE).read()
    print(f"k4 = {k4:g} /g^3; p2 in /rad; errors in ug; differences from the ODE in % (sigma)\n")
    print("| motion | p2 | ODE | first order | second order (its uncertainty) | first - ODE | second - ODE |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as d:
        for sine in [None, (100, 8.0), (300, 8.0), (600, 2.0)]:
            for p2 in [0, 10, 20, 30, 40]:
                path = os.path.join(d, "case.toml")
                with open(path, "w") as f:
                    f.write(with_values(base, p2, k4, sine))
                run(binary, ["predict", path, "--frequency-dependent", "--json", os.path.join(d, "p.json")])
                run(binary, ["shake", path, "--json", os.path.join(d, "s.json")])
                p = json.load(open(os.path.join(d, "p.json")))["frequency_dependent"]
                s = json.load(open(os.path.join(d, "s.json")))
                total, second = p["total_g"] * 1e6, p["terms"]["pickoff_second_order"] * 1e6
                error = p["second_order_error_g"] * 1e6
                ode, sigma = s["measured_g"] * 1e6, s["sigma_g"] * 1e6
                first = total - second
                rel = lambda x: f"{100 * (x - ode) / ode:+.2f} % ({(x - ode) / sigma:+.1f})"
                motion = "random 5.66 g rms" if sine is None else f"sine {sine[1]:g} g {sine[0]} Hz"
                print(f"| {motion} | {p2} | {ode:.1f} ± {sigma:.2g} | {first:.1f} | {total:.1f} ({error:.2g}) | {rel(first)} | {rel(total)} |",
                      flush=True)


if __name__ == "__main__":
    main()
