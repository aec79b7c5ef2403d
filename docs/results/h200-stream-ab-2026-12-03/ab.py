"""N (main) against C (c93f0fd), per scene, view and layout: N's mean over C's mean of two runs
each, primary and diffuse M rays/s; geometric means per layout. usage: ab.py [DIR]"""
import json, sys, os, math
d = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), 'json')
def rows(f):
    return {(r['scene'], r['view'], r['treelet']['layout']): r['treelet'] for r in json.load(open(os.path.join(d, f)))['rows']}
c, n = [rows('c1.json'), rows('c2.json')], [rows('n1.json'), rows('n2.json')]
mean = lambda v: sum(v) / len(v)
geo = {}
print(f"{'scene':14} {'view':8} {'layout':6} | primary N/C | diffuse N/C | C1/C2 diffuse (noise)")
for k in c[0]:
    p = mean([x[k]['primary_mrays_per_s'] for x in n]) / mean([x[k]['primary_mrays_per_s'] for x in c])
    q = mean([x[k]['diffuse_mrays_per_s'] for x in n]) / mean([x[k]['diffuse_mrays_per_s'] for x in c])
    noise = c[0][k]['diffuse_mrays_per_s'] / c[1][k]['diffuse_mrays_per_s']
    geo.setdefault(k[2], []).append((p, q))
    print(f"{k[0]:14} {k[1]:8} {k[2]:6} | {p:11.3f} | {q:11.3f} | {noise:.3f}")
for l, v in geo.items():
    g = lambda i: math.exp(mean([math.log(x[i]) for x in v]))
    print(f"geometric mean {l}: primary {g(0):.3f}, diffuse {g(1):.3f}")
