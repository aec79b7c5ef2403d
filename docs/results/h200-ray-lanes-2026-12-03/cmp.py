"""Ratios of each lanes run to the mean of the two one-lane runs (N_0_1, N_0_2), per scene, view
and layout: primary (a check: lanes touch only diffuse casts), diffuse and occlusion rays.
usage: cmp.py DIR"""
import json, sys, glob, os
d = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), 'json')
def rows(f):
    out = {}
    for r in json.load(open(f))['rows']:
        t = r['treelet']
        out[(r['scene'], r['view'], t['layout'])] = (t['primary_mrays_per_s'], t['diffuse_mrays_per_s'], t.get('occlusion_mrays_per_s', 0))
    return out
base = [rows(f) for f in sorted(glob.glob(os.path.join(d, 'N_0_*.json')))]
runs = sorted(f for f in glob.glob(os.path.join(d, 'N_*_1.json')) if not os.path.basename(f).startswith('N_0_'))
mean = lambda v: sum(v) / len(v)
print(f"one lane a ray: {len(base)} runs; ratios lanes/one-lane (primary diffuse occlusion)")
print(f"{'scene':16} {'view':8} {'layout':6} | {'1-lane dif':>10} | " + " | ".join(os.path.basename(f)[2:-7] for f in runs))
for k in base[0]:
    b = [mean([x[k][i] for x in base]) for i in range(3)]
    cells = []
    for f in runs:
        r = rows(f)[k]
        cells.append(f"{r[0]/b[0]:.2f} {r[1]/b[1]:.2f} {r[2]/b[2]:.2f}")
    print(f"{k[0]:16} {k[1]:8} {k[2]:6} | {b[1]:10.0f} | " + " | ".join(cells))
