for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
cd ..
T=./.dev/treelet_old
for sc in scenes/room_disk.json scenes/cornell_mesh.json terrain:256 terrain:1024 terrain:4096 terrain:16384 terrain:65536 terrain:262144 terrain:1000000 random:1000 random:100000; do
  for r in 1 2; do for l in bvh2 cwbvh; do
    echo -n "$sc $l round $r: "; $T render --scene $sc --width 1024 --height 768 --device gpu --spp 64 --accel trbvh --layout $l --out /tmp/x.png 2>&1 | tail -1 | grep -o "kernels [0-9.]* s"
  done; done
done
