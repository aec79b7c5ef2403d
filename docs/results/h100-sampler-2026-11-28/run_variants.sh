for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render --width 1024 --height 768 --device gpu --spp 4 --out /tmp/w.png 2>&1 | tail -1
echo "== sampler compiled into the variants: --sampler independent (general kernels) / sobol (specialized, Sobol only)"
for i in 1 2; do
  for scene in cornell $ROOM; do
    echo "-- $scene nee"
    timeout -s KILL 60 ./treelet render --scene $scene $R --sampler independent --out /tmp/i.png 2>&1 | tail -1
    timeout -s KILL 60 ./treelet render --scene $scene $R --sampler sobol --out /tmp/s.png 2>&1 | tail -1
  done
  echo "-- room caustics"
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --integrator caustics --sampler independent --out /tmp/i.png 2>&1 | tail -1
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --integrator caustics --sampler sobol --out /tmp/s.png 2>&1 | tail -1
done
echo "== the GPU render tests (GPU = CPU runner, both samplers)"
cd ..; for t in t_render t_variants; do [ -x .dev/$t ] && timeout 240 .dev/$t --test-threads 4 2>&1 | tail -4; done
