"""The suite against OptiX from optix.json (one call): per scene and view, the best Treelet layout
for primary and for diffuse rays, over OptiX's rates, with the lanes runs' diffuse rates beside
(the one-lane runs' means and the best lanes run's). usage: table.py DIR"""
import json, sys, os, glob
d = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), 'json')
o = json.load(open(os.path.join(d, 'optix.json')))['rows']
def rows(f):
    return {(r['scene'], r['view'], r['treelet']['layout']): r['treelet'] for r in json.load(open(f))['rows']}
one = [rows(f) for f in sorted(glob.glob(os.path.join(d, 'N_0_*.json')))]
views = {}
for r in o:
    views.setdefault((r['scene'], r['view']), []).append(r)
print("| scene | view | primary x OptiX (layout) | diffuse x OptiX (layout), 262144 lanes | diffuse x OptiX, one lane a ray (mean of 2 runs, best layout) | OptiX primary / diffuse M rays/s |")
print("|---|---|---|---|---|---|")
for (s, v), rs in views.items():
    x = rs[0]['optix']
    p = max(rs, key=lambda r: r['treelet']['primary_mrays_per_s'])
    q = max(rs, key=lambda r: r['treelet']['diffuse_mrays_per_s'])
    best1 = max(sum(u[(s, v, lay)]['diffuse_mrays_per_s'] for u in one) / len(one) for lay in ('bvh2', 'cwbvh'))
    print(f"| {s} | {v} | {p['treelet']['primary_mrays_per_s']/x['primary_mrays_per_s']:.2f} ({p['treelet']['layout']}) | "
          f"{q['treelet']['diffuse_mrays_per_s']/x['diffuse_mrays_per_s']:.2f} ({q['treelet']['layout']}) | {best1/x['diffuse_mrays_per_s']:.2f} | "
          f"{x['primary_mrays_per_s']:.0f} / {x['diffuse_mrays_per_s']:.0f} |")
