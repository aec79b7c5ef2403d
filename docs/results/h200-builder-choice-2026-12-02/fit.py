"""The builder choice's trade-off (host/src/bvh/choice.rs) refit on the real-scene suite: per
scene and view, each tree's build (tree and bvh2 layout, ms) and its bvh2 rays (M/s), H-PLOC's and
the TRBVH's extra build against the LBVH's (a least-squares line in the primitives) and the time
they save per diffuse and per primary ray (ns, median over the scene-views)."""
import json, os, statistics, sys
here = os.path.dirname(os.path.abspath(__file__))
rows = json.load(open(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "suite.json")))["rows"]
t = {}
for r in rows:
    x = r["treelet"]
    t[(r["scene"], r["view"], x["accel"], x["layout"])] = (x["build_ms"] + x["layout_ms"], x["primary_mrays_per_s"], x["diffuse_mrays_per_s"], x["primitives"])
views = sorted({(s, v) for s, v, _, _ in t})
print("%-16s %-8s %8s | %-28s | %-28s | %-28s" % ("scene", "view", "prims", "lbvh build/pri/dif", "hploc", "trbvh"))
for s, v in views:
    cells = []
    for a in ["lbvh", "hploc", "trbvh"]:
        b, p, d, n = t[(s, v, a, "bvh2")]
        _, pc, dc, _ = t[(s, v, a, "cwbvh")]
        cells.append("%6.2f %6.0f %6.0f (cw %5.0f)" % (b, p, d, dc))
    print("%-16s %-8s %8d | %s" % (s, v, n, " | ".join(cells)))
for a in ["hploc", "trbvh"]:
    xs, ys, dif, pri = [], [], [], []
    for s, v in views:
        b0, p0, d0, n = t[(s, v, "lbvh", "bvh2")]
        b1, p1, d1, _ = t[(s, v, a, "bvh2")]
        if v == "outside":
            xs.append(n); ys.append(b1 - b0)
        dif.append(1e3 / d0 - 1e3 / d1); pri.append(1e3 / p0 - 1e3 / p1)
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    print("%s against the LBVH: extra build %.2f ms + %.2f ns/prim (each: %s); saved ns/ray diffuse median %.4f (%s), primary median %.4f"
          % (a, my - slope * mx, slope * 1e6, ", ".join("%.2f" % y for y in ys), statistics.median(dif), ", ".join("%.3f" % d for d in dif), statistics.median(pri)))
