for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
(cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]") &
R="--width 1024 --height 768 --device gpu"
timeout -s KILL 60 ./treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
echo "== cornell (the default scene), 1024 spp, three runs"
for i in 1 2 3; do timeout -s KILL 60 ./treelet render $R --spp 1024 --out /tmp/c.png 2>&1 | tail -1; done
for sc in ../scenes/room_disk.json fan/room_disk_mesh_walls.json fan/room_disk.json; do
  echo "== $sc, 1024 spp, three runs"
  timeout -s KILL 60 ./treelet render --scene $sc $R --spp 1024 --explain --out /tmp/r.png 2>&1 | grep -E "^(features|accel|kernel)|1024 spp"
  for i in 1 2; do timeout -s KILL 60 ./treelet render --scene $sc $R --spp 1024 --out /tmp/r.png 2>&1 | tail -1; done
done
echo "== error against time: seed 7 against a 4096-spp render of seed 99"
timeout -s KILL 120 ./treelet render --scene ../scenes/room_disk.json $R --spp 4096 --seed 99 --out /tmp/room_4096.exr 2>&1 | tail -1
for spp in 16 64 256 1024 2048; do timeout -s KILL 120 ./treelet render --scene ../scenes/room_disk.json $R --spp $spp --seed 7 --out /tmp/room_$spp.exr 2>&1 | tail -1; done
for spp in 16 64 256 1024 2048; do echo "spp $spp: $(./treelet compare --reference /tmp/room_4096.exr /tmp/room_$spp.exr 2>&1 | tail -1)"; done
wait
echo "== Mitsuba 3 (peers/mitsuba/filters.py), same call"
mkdir -p /tmp/mi
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 300 python3 peers/mitsuba/filters.py /tmp/mi 16,64,256,1024,4096 2>&1 | tee /tmp/mi/filters.txt | grep '^{' > /tmp/mi/mitsuba.jsonl; tail -3 /tmp/mi/filters.txt)
cp /tmp/mi/mitsuba.jsonl $OUT/
echo "== bench error (figures), same call"
(cd ..; timeout -s KILL 200 .dev/treelet bench error --device gpu --out $OUT/h100 --mitsuba /tmp/mi --repeats 3 2>&1 | tail -30)
rm -f $OUT/h100/*.exr
