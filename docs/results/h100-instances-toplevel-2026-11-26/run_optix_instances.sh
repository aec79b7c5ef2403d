for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
python3 subdivide.py bunny.obj 2 bunny2.ply > /dev/null
./treelet bench instances --scene bunny2.ply --grid 2 --top-sizes 10 --repeats 1 --width 640 --height 480 > /dev/null 2>&1
echo "== treelet bench instances bunny4 32x32"
./treelet bench instances --scene bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny4.json 2>&1
cd ../.whl && tar xJf site.tar.xz
echo "== OptiX instances bunny4 32x32"
PYTHONPATH=site PYTHONUNBUFFERED=1 python3 instances.py ../.dev/bunny4.ply 32 1920 1080 7 2>&1 | tail -5
echo "== OptiX instances bunny2 32x32"
PYTHONPATH=site PYTHONUNBUFFERED=1 python3 instances.py ../.dev/bunny2.ply 32 1920 1080 7 2>&1 | tail -5
cd ../.dev && echo "== treelet bench instances bunny2 32x32" && ./treelet bench instances --scene bunny2.ply --grid 32 --top-sizes 1000 --repeats 7 2>&1
