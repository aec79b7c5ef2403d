for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
(cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]") &
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render --width 1024 --height 768 --device gpu --spp 4 --out /tmp/w.png 2>&1 | tail -1
timeout -s KILL 60 ./treelet_old render --width 1024 --height 768 --device gpu --spp 4 --out /tmp/w.png 2>&1 | tail -1
echo "== A/B: old build (dcc013a), new build --sampler independent, new build --sampler sobol; 1024x768x1024"
for i in 1 2; do
  for scene in cornell $ROOM; do
    echo "-- $scene nee"
    timeout -s KILL 60 ./treelet_old render --scene $scene $R --out /tmp/o.png 2>&1 | tail -1
    timeout -s KILL 60 ./treelet render --scene $scene $R --sampler independent --out /tmp/i.png 2>&1 | tail -1
    timeout -s KILL 60 ./treelet render --scene $scene $R --sampler sobol --out /tmp/s.png 2>&1 | tail -1
  done
  echo "-- room caustics"
  timeout -s KILL 60 ./treelet_old render --scene $ROOM $R --integrator caustics --out /tmp/o.png 2>&1 | tail -1
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --integrator caustics --sampler independent --out /tmp/i.png 2>&1 | tail -1
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --integrator caustics --sampler sobol --out /tmp/s.png 2>&1 | tail -1
done
wait
echo "== Mitsuba diagnostic"
mkdir -p /tmp/mi
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 120 python3 peers/mitsuba/room_disk.py /tmp/mi 16 2>&1 | tail -20)
(cd ..; SAMPLER=ldsampler PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 120 python3 peers/mitsuba/room_disk.py /tmp/mi 16 2>&1 | tail -20)
