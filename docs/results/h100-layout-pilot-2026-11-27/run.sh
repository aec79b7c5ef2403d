for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
cd ..
echo "== GPU tests (render: pilot, nee GPU = CPU, many samples)"; ./.dev/test_render layout_pilot nee_gpu_matches_cpu many_samples 2>&1 | grep -E "^test |test result"
R="--width 1024 --height 768 --device gpu"
for sc in scenes/room_disk.json scenes/cornell_mesh.json; do
  for r in 1 2; do
    for v in "treelet_old:auto" "treelet:auto" "treelet:bvh2" "treelet:cwbvh"; do t=${v%%:*}; l=${v##*:}
      echo -n "$sc $t layout $l round $r: "; ./.dev/$t render --scene $sc $R --spp 1024 --layout $l --explain --out /tmp/x.png 2>&1 | grep -E "as rendered|camera paths" | sed 's/.*(accel/(accel/' | tr '\n' ' '; echo
    done
  done
done
for v in "treelet_old:auto" "treelet:auto"; do t=${v%%:*}; l=${v##*:}; echo -n "terrain:1000000 $t $l: "; ./.dev/$t render --scene terrain:1000000 $R --spp 256 --layout $l --explain --out /tmp/x.png 2>&1 | grep -E "as rendered|camera paths" | sed 's/.*(accel/(accel/' | tr '\n' ' '; echo; done
