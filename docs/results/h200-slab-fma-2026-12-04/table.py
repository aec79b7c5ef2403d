"""The change (new) against main (old), three rounds each: ranges and the ratio of means."""
import json, math
runs = {b: [json.load(open(f"suite_{b}_{r}.json"))["rows"] for r in (1, 2, 3)] for b in ("old", "new")}
print("| scene, view | old primary / diffuse | new primary / diffuse | new / old |")
print("|---|---|---|---|")
logs = []
for i, row in enumerate(runs["old"][0]):
    cells, means = [], {}
    for b in ("old", "new"):
        p = [r[i]["treelet"]["primary_mrays_per_s"] for r in runs[b]]
        d = [r[i]["treelet"]["diffuse_mrays_per_s"] for r in runs[b]]
        cells.append(f"{min(p):.0f}-{max(p):.0f} / {min(d):.0f}-{max(d):.0f}")
        means[b] = (sum(p) / 3, sum(d) / 3)
    rp, rd = means["new"][0] / means["old"][0], means["new"][1] / means["old"][1]
    logs += [math.log(rp), math.log(rd)]
    print(f"| {row['scene']} {row['view']} | {cells[0]} | {cells[1]} | {rp:.3f} / {rd:.3f} |")
print(f"\ngeometric mean of the 24 ratios: {math.exp(sum(logs) / len(logs)):.3f}")
