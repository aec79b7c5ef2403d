import json,sys
def rows(f):
    out={}
    for r in json.load(open(f))['rows']:
        t=r['treelet']; out[(r['scene'],r['view'],t['layout'])]=(t['primary_mrays_per_s'],t['diffuse_mrays_per_s'],t.get('occlusion_mrays_per_s',0))
    return out
A=[rows(f) for f in sys.argv[1].split(',')]; B=[rows(f) for f in sys.argv[2].split(',')]
print(f"{'scene':16} {'view':8} {'layout':6} | {'A pri':>11} {'A dif':>11} | {'B pri':>11} {'B dif':>11} | B/A pri  dif  occl")
for k in A[0]:
    ap=[a[k][0] for a in A]; ad=[a[k][1] for a in A]; bp=[b[k][0] for b in B]; bd=[b[k][1] for b in B]
    ao=[a[k][2] for a in A]; bo=[b[k][2] for b in B]
    f=lambda v: f"{min(v):5.0f}-{max(v):5.0f}"
    m=lambda v: sum(v)/len(v)
    print(f"{k[0]:16} {k[1]:8} {k[2]:6} | {f(ap)} {f(ad)} | {f(bp)} {f(bd)} | {m(bp)/m(ap):.3f} {m(bd)/m(ad):.3f} {m(bo)/m(ao):.3f}")
