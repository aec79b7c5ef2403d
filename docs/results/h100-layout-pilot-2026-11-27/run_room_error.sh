for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]"; cd .dev
R="--scene ../scenes/room_disk.json --width 1024 --height 768 --device gpu"
timeout -s KILL 60 ./treelet render $R --spp 4 --out /tmp/w.exr 2>&1 | tail -1
timeout -s KILL 120 ./treelet render $R --spp 4096 --seed 99 --explain --out /tmp/room_4096.exr 2>&1 | grep -E "as rendered|room_disk.json:"
for spp in 16 64 256 1024; do timeout -s KILL 120 ./treelet render $R --spp $spp --seed 7 --out /tmp/room_$spp.exr 2>&1 | tail -1; done
for spp in 16 64 256 1024; do echo "spp $spp: $(./treelet compare --reference /tmp/room_4096.exr /tmp/room_$spp.exr 2>&1 | tail -1)"; done
echo "== Mitsuba 3 (peers/mitsuba/filters.py), same call"
cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 300 python3 peers/mitsuba/filters.py /tmp/mi 16,64,256,1024,4096 2>&1 | grep '^{'
