# bench placed on the H100: a scene file placing the bunny by reference
# (a 32x32 grid of the 58k-triangle bunny turned at random, 1.25 of its
# extent apart; 8x8 of the 940k one; and the 32x32 grid packed four times
# as tight, copies overlapping), against the same scene flattened (60M
# triangles each).
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 2 /tmp/bunny2.ply > /dev/null
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
python3 - <<'PY'
import json, random
random.seed(1)
for tag, name, side, step in [("bunny2", "bunny2", 32, 12.5), ("bunny4", "bunny4", 8, 12.5), ("bunny2_packed", "bunny2", 32, 3.1)]:
    inst = [{"mesh": "b", "translate": [(k % side) * step, 0, (k // side) * step], "rotate": [0, random.uniform(0, 360), 0]}
            for k in range(1, side * side)]
    s = {"camera": {"origin": [0, 1, 3], "direction": [0, -0.3, -1]},
         "materials": {"w": {"type": "diffuse", "color": [0.7, 0.7, 0.7]}},
         "meshes": [{"path": f"{name}.ply", "material": "w", "name": "b"}], "instances": inst}
    json.dump(s, open(f"/tmp/grid_{tag}.json", "w"))
PY
head -c 300 /tmp/grid_bunny2.json; echo
for g in bunny2 bunny4 bunny2_packed; do
  echo "== bench placed grid_$g"
  /usr/bin/time -f "process %e s, %M KB" ./treelet bench placed --scene /tmp/grid_$g.json --repeats 7 --json /tmp/p.json 2>&1 | tail -9
  cp /tmp/p.json $OUT/placed_$g.json
done
