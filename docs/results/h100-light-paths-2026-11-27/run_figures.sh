for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
(cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]") &
R="--width 1024 --height 768 --device gpu"
timeout -s KILL 60 ./treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
echo "== cornell (the default scene), 1024 spp, three runs"
for i in 1 2 3; do timeout -s KILL 60 ./treelet render $R --spp 1024 --out /tmp/c.png 2>&1 | tail -1; done
echo "== scenes/room_disk.json, 1024 spp, three runs"
for I in nee caustics; do for i in 1 2 3; do timeout -s KILL 60 ./treelet render --scene ../scenes/room_disk.json $R --integrator $I --spp 1024 --out /tmp/r.png 2>&1 | tail -1; done; done
wait
echo "== Mitsuba 3 (peers/mitsuba/filters.py), same call"
mkdir -p /tmp/mi
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 300 python3 peers/mitsuba/filters.py /tmp/mi 16,64,256,1024,4096 2>&1 | tee /tmp/mi/filters.txt | grep '^{' > /tmp/mi/mitsuba.jsonl; cat /tmp/mi/mitsuba.jsonl)
cp /tmp/mi/mitsuba.jsonl $OUT/
echo "== bench error (figures), same call"
(cd ..; timeout -s KILL 420 .dev/treelet bench error --device gpu --out $OUT/h100 --mitsuba /tmp/mi --repeats 3 2>&1 | grep -E "note|s$" | tail -8)
rm -f $OUT/h100/*.exr
