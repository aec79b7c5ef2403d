"""Each configuration of run.sh against the defaults (mean of D1 and D2) and against OptiX (run O):
build ms (tree + layout), and the best layout's primary and diffuse rates per scene and view;
geometric means over the twelve scene-views. Usage: cmp.py RUNS_DIR."""
import json, math, sys, os
here = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "runs")
def rows(n):
    p = os.path.join(here, n + ".json")
    return json.load(open(p))["rows"] if os.path.exists(p) else None
def load(n, accel=None):
    rs = rows(n)
    if rs is None:
        return None
    out = {}
    for r in rs:
        t = r["treelet"]
        if accel and t.get("accel") != accel:
            continue
        k = (r["scene"], r["view"])
        b = out.setdefault(k, {"build": t["build_ms"] + t["layout_ms"], "pri": 0, "dif": 0})
        b["build"] = min(b["build"], t["build_ms"] + t["layout_ms"])
        b["pri"] = max(b["pri"], t["primary_mrays_per_s"]); b["dif"] = max(b["dif"], t["diffuse_mrays_per_s"])
    return out
gm = lambda xs: math.exp(sum(map(math.log, xs)) / len(xs))
d1, d2 = load("D1"), load("D2") or load("D1")
base = {k: {m: (d1[k][m] + d2[k][m]) / 2 for m in d1[k]} for k in d1}
optix = {}
for r in rows("O") or []:
    if r.get("optix"):
        optix[(r["scene"], r["view"])] = r["optix"]
configs = [("D2", "D2", None), ("O:trbvh", "O", "trbvh"), ("O:hploc", "O", "hploc")]
for n in ["S05R2", "S05R4", "T1S05R4", "T1S10R8", "HS05R4", "HS05R8", "HS02R8", "HS10R4", "HS05R8C0", "HR2"]:
    configs.append((n, n, None))
print("ratios to the defaults (build, primary, diffuse), then to OptiX (primary, diffuse; build)")
for label, n, accel in configs:
    c = load(n, accel)
    if not c:
        continue
    b, p, q, po, qo, bo = [], [], [], [], [], []
    cells = []
    for k in base:
        if k not in c:
            continue
        b.append(c[k]["build"] / base[k]["build"]); p.append(c[k]["pri"] / base[k]["pri"]); q.append(c[k]["dif"] / base[k]["dif"])
        if k in optix:
            o = optix[k]
            po.append(c[k]["pri"] / o["primary_mrays_per_s"]); qo.append(c[k]["dif"] / o["diffuse_mrays_per_s"]); bo.append(c[k]["build"] / o["build_ms"])
            cells.append("%s %s %.2fms %.2f/%.2f" % (k[0][:9], k[1][:3], c[k]["build"], po[-1], qo[-1]))
    line = "%-9s vs default: build %.3f pri %.3f dif %.3f" % (label, gm(b), gm(p), gm(q))
    if po:
        line += " | vs OptiX: pri %.2f (min %.2f) dif %.2f (min %.2f) build x%.2f (max %.2f)" % (gm(po), min(po), gm(qo), min(qo), gm(bo), max(bo))
    print(line)
    if cells:
        print("    " + "; ".join(cells))
print()
print("defaults' build ms: " + ", ".join("%s %.2f" % (s, base[(s, v)]["build"]) for s, v in base if v == "outside"))
print("OptiX build ms: " + ", ".join("%s %.2f" % (s, optix[(s, v)]["build_ms"]) for s, v in optix if v == "outside"))
