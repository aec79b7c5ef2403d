"""Writes a scene file placing MESH (the npm bunny's frame: x -5..5,
y 0..9.7, z -3.7..3.8) N times on the floor of the disk-lit room of
scenes/pyramids.json, in a grid, each turned at random, a third of them
mirror or glass:  python3 gen_room.py MESH N OUT.json"""
import json, math, random, sys

mesh, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
random.seed(7)
k = math.ceil(math.sqrt(n))
dx, dz = 86.0 / k, 120.0 / k
scale = min(dx / 10.5, dz / 8.0)
mats = ["white", "mirror", "glass"]
def place(i):
    return {"mesh": "m", "material": mats[i % 3] if i % 3 else "white",
            "scale": [scale] * 3, "rotate": [0, random.uniform(0, 360), 0],
            "translate": [7 + dx * (i % k + 0.5), 0, 15 + dz * (i // k + 0.5)]}
first = place(0)
scene = json.load(open("pyramids_base.json"))
scene["meshes"] = [{"path": mesh, "material": "white", "name": "m", "scale": first["scale"],
                    "rotate": first["rotate"], "translate": first["translate"]}]
scene["instances"] = [place(i) for i in range(1, n)]
json.dump(scene, open(out, "w"))
