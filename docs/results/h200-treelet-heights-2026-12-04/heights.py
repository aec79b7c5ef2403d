"""Per scene and round: the heights' stages of TREELET_PROFILE_LEVELS builds (the median of the
runs), split into heights of few treelets (at most 4, one workgroup) and the rest; with `empty`
runs, what the empty launch after each height took."""
import glob, json, re, statistics, sys
d = sys.argv[1]
for levels in sorted(glob.glob(f"{d}/*_levels_1.json")):
    scene = levels.split("/")[-1][: -len("_levels_1.json")]
    runs = [json.load(open(f)) for f in sorted(glob.glob(f"{d}/{scene}_levels_*.json"))]
    empties = [json.load(open(f)) for f in sorted(glob.glob(f"{d}/{scene}_empty_*.json"))]
    def med(rs, name):
        return statistics.median(dict(r["stage_ms"]).get(name, 0.0) for r in rs)
    names = [n for n, _ in runs[0]["stage_ms"]]
    print(f"{scene}: total {statistics.median(r['total_ms'] for r in runs):.3f} ms (profiled)")
    for rnd in range(3):
        hs = [(n, int(m.group(2)), int(m.group(3))) for n in names if (m := re.match(r"r(\d) h(\d+) n(\d+)", n)) and int(m.group(1)) == rnd]
        few = [h for h in hs if h[2] <= 4]
        t_all = sum(med(runs, n) for n, _, _ in hs)
        t_few = sum(med(runs, n) for n, _, _ in few)
        e = [med(empties, f"r{rnd} h{h:02} empty") for _, h, _ in hs]
        print(f"  round {rnd + 1}: {len(hs)} heights {t_all:.3f} ms; {len(few)} with <= 4 treelets {t_few:.3f} ms "
              f"(from height {min((h for _, h, _ in few), default=0)}); empty launch median {statistics.median(e) if e else 0:.4f} ms; "
              f"head {med(runs, f'round {rnd + 1}'):.3f} ms")
        print("    " + " ".join(f"h{h}:{c}:{med(runs, n) * 1000:.0f}us" for n, h, c in hs))
