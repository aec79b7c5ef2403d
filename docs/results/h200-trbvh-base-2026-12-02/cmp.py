"""Each configuration of run.sh against the defaults (mean of D1 and D2): build ms, and the
best layout's primary and diffuse rates per scene and view, as ratios; geometric means last."""
import json, math, sys, os
here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "runs")
def load(n):
    rows = json.load(open(os.path.join(here, n + ".json")))["rows"]
    out = {}
    for r in rows:
        t = r["treelet"]; k = (r["scene"], r["view"])
        b = out.setdefault(k, {"build": t["build_ms"] + t["layout_ms"], "pri": 0, "dif": 0})
        b["pri"] = max(b["pri"], t["primary_mrays_per_s"]); b["dif"] = max(b["dif"], t["diffuse_mrays_per_s"])
    return out
d1, d2 = load("D1"), load("D2")
base = {k: {m: (d1[k][m] + d2[k][m]) / 2 for m in d1[k]} for k in d1}
noise = {k: {m: d2[k][m] / d1[k][m] for m in d1[k]} for k in d1}
names = ["D2", "T1R1", "T2R1", "T3R1", "T3G7", "H1R0", "H1R1", "H2R1", "H3R2", "H1G7R1"]
gm = lambda xs: math.exp(sum(map(math.log, xs)) / len(xs))
print("%-8s %-26s" % ("config", "") + "".join("%-22s" % ("%s %s" % (s[:10], v[:3])) for s, v in base))
for n in names:
    c = base if n == "D2" else load(n)
    ref = d1 if n == "D2" else base
    cells, b, p, q = [], [], [], []
    for k in base:
        rb, rp, rd = c[k]["build"] / ref[k]["build"], c[k]["pri"] / ref[k]["pri"], c[k]["dif"] / ref[k]["dif"]
        if n == "D2": rb, rp, rd = noise[k]["build"], noise[k]["pri"], noise[k]["dif"]
        b.append(rb); p.append(rp); q.append(rd)
        cells.append("%.2f %.3f %.3f" % (rb, rp, rd))
    print("%-8s build %.3f pri %.3f dif %.3f  " % (n, gm(b), gm(p), gm(q)) + "  ".join(cells))
print()
print("defaults, build ms (tree+layout, best layout's rates): " + ", ".join("%s %s %.2f" % (s, v, base[(s, v)]["build"]) for s, v in base if v == "outside"))
