import json,sys
def rows(f):
    out={}
    for r in json.load(open(f))['rows']:
        t=r['treelet']; out[(r['scene'],r['view'],t['layout'])]=(t['primary_mrays_per_s'],t['diffuse_mrays_per_s'],t['build_ms']+t.get('layout_ms',0))
    return out
base=[rows(f) for f in sys.argv[1].split(',')]
others=[(f,rows(f)) for f in sys.argv[2:]]
keys=[k for k in base[0]]
hdr=f"{'scene':14} {'view':7} {'lay':5} | base pri/dif"
for f,_ in others: hdr+=f" | {f.split('/')[-1][:-5]:>11}"
print(hdr)
for k in keys:
    bp=sum(b[k][0] for b in base)/len(base); bd=sum(b[k][1] for b in base)/len(base)
    line=f"{k[0][:14]:14} {k[1]:7} {k[2]:5} | {bp:5.0f}/{bd:5.0f}"
    for f,o in others:
        if k in o: line+=f" | {o[k][0]/bp:.3f}/{o[k][1]/bd:.3f}"
        else: line+=" |      -     "
    print(line)
