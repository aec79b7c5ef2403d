for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render --width 1024 --height 768 --device gpu --spp 4 --out /tmp/w.png 2>&1 | tail -1
timeout -s KILL 60 ./treelet_nosobol render --width 1024 --height 768 --device gpu --spp 4 --out /tmp/w.png 2>&1 | tail -1
echo "== this build (cca8a84) --sampler independent / sobol, and the same with the Sobol branch folded away (treelet_nosobol, --sampler independent)"
for i in 1 2; do
  for scene in cornell $ROOM; do
    echo "-- $scene nee"
    timeout -s KILL 60 ./treelet_nosobol render --scene $scene $R --sampler independent --out /tmp/o.png 2>&1 | tail -1
    timeout -s KILL 60 ./treelet render --scene $scene $R --sampler independent --out /tmp/i.png 2>&1 | tail -1
    timeout -s KILL 60 ./treelet render --scene $scene $R --sampler sobol --out /tmp/s.png 2>&1 | tail -1
  done
done
