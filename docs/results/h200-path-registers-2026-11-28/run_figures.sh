for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --out /tmp/w.png 2>&1 | tail -1
for i in 1 2; do
  timeout -s KILL 60 ./treelet render $R --out /tmp/c.png 2>&1 | tail -1
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --out /tmp/r.png 2>&1 | tail -1
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --integrator caustics --out /tmp/q.png 2>&1 | tail -1
done
timeout -s KILL 60 ./treelet render --scene $ROOM $R --explain --out /tmp/r.png 2>&1 | grep -E "^(kernel|dispatches|timeline)"
(cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]")
echo "== Mitsuba 3 (peers/mitsuba/filters.py: tent, box), same call"
mkdir -p /tmp/mi
date +%T
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 320 python3 peers/mitsuba/filters.py /tmp/mi 16,64,256,1024,4096 2>&1 | tee /tmp/mi/filters.txt | grep '^{' > /tmp/mi/mitsuba.jsonl; cat /tmp/mi/mitsuba.jsonl | cut -c1-250; grep -v '^{' /tmp/mi/filters.txt | tail -5)
cp /tmp/mi/mitsuba.jsonl /tmp/mi/filters.txt $OUT/
date +%T
echo "== bench error (figures), same call"
(cd ..; timeout -s KILL 280 .dev/treelet bench error --device gpu --out $OUT/h200 --mitsuba /tmp/mi --repeats 3 2>&1 | grep -E "note|s$" | tail -14)
date +%T
rm -f $OUT/h200/*.exr
