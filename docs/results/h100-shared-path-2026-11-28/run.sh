# EXPERIMENT: each lane's path in flight in workgroup memory (TREELET_SHARED_PATH=1)
# against registers (today's kernel), alternated.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
./pipeline_stats render::spheres::linear_cs render::spheres_linear_shared_cs render::full::linear_cs render::full_linear_shared_cs 2>&1 | tail -12
R="--width 1024 --height 768 --device gpu"
./treelet render $R --spp 16 --out /tmp/w.png >/dev/null 2>&1
TREELET_SHARED_PATH=1 ./treelet render $R --spp 16 --out /tmp/w.png >/dev/null 2>&1
./treelet render $R --spp 16 --scene ../scenes/room_disk.json --out /tmp/w.png >/dev/null 2>&1
TREELET_SHARED_PATH=1 ./treelet render $R --spp 16 --scene ../scenes/room_disk.json --out /tmp/w.png >/dev/null 2>&1
for i in 1 2 3; do
  for s in "" 1; do
    echo "shared=$s"
    env ${s:+TREELET_SHARED_PATH=1} ./treelet render $R --spp 1024 --out /tmp/c$s.pfm 2>&1 | tail -1
    env ${s:+TREELET_SHARED_PATH=1} ./treelet render $R --spp 256 --scene ../scenes/room_disk.json --explain --out /tmp/r$s.pfm 2>&1 | grep -E "kernel|room_disk:" | tail -2
  done
done
./treelet compare --reference /tmp/c.pfm /tmp/c1.pfm
./treelet compare --reference /tmp/r.pfm /tmp/r1.pfm
