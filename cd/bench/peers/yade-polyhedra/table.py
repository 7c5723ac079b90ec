#!/usr/bin/env python3
"""make compare-yade-pile's table: cdsim's pile-polyhedra and YADE's
polyhedra on the same scene (pile.py), from DIR/cdsim/summary.toml and the
last line of DIR/yade.log. Usage: table.py DIR"""
import sys, tomllib

d = sys.argv[1]
with open(f"{d}/cdsim/summary.toml", "rb") as f:
    s = tomllib.load(f)
with open(f"{d}/yade.log") as f:
    line = [l for l in f if l.startswith("yade_pile,")][-1].strip()
y = dict(kv.split("=") for kv in line.split(",")[1:])
cd_cpu, y_cpu = float(s["cpu_time"]), float(y["cpu_s"])
print("| code | contacts | time step (s) | steps | CPU (s) | largest overlap (mean diameters) |")
print("|---|---|---|---|---|---|")
print(f"| cdsim (pile-polyhedra) | rigid, Signorini-Coulomb | 1e-3 | {s['steps']} | {cd_cpu:.1f} "
      f"| {float(s['overlap_max']):.3g} |")
print(f"| YADE polyhedra | volumetric, E = {float(y['E']):.3g} | {float(y['dt']):.3g} | {y['steps']} "
      f"| {y_cpu:.1f} | {float(y['overlap_max']):.3g} |")
print(f"\nYADE / cdsim CPU: {y_cpu / cd_cpu:.2f} (one thread each; cdsim {float(s['sweeps_mean']):.0f} "
      f"sweeps + {float(s['cg_iterations_mean']):.0f} CG iterations a step, {s['cap_steps']} steps at the cap)")
