for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
(cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]")
echo "== Mitsuba 3 (peers/mitsuba/filters.py: tent, box), same call"
mkdir -p /tmp/mi
date +%T
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 320 python3 peers/mitsuba/filters.py /tmp/mi 16,64,256,1024,4096 2>&1 | tee /tmp/mi/filters.txt | grep '^{' > /tmp/mi/mitsuba.jsonl; cat /tmp/mi/mitsuba.jsonl; grep -v '^{' /tmp/mi/filters.txt | tail -5)
cp /tmp/mi/mitsuba.jsonl /tmp/mi/filters.txt $OUT/
date +%T
echo "== bench error (figures), same call"
(cd ..; timeout -s KILL 240 .dev/treelet bench error --device gpu --out $OUT/h100 --mitsuba /tmp/mi --repeats 3 2>&1 | grep -E "note|s$" | tail -14)
date +%T
rm -f $OUT/h100/*.exr
