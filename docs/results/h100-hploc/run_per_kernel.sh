for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== gpu_vs_cpu hploc"; ./gpu_vs_cpu hploc 2>&1 | grep "test result"
echo "== pipeline stats"; ./pipeline_stats 2>&1 | grep -iE "hploc|agglomerate|name|regist" | head -12
for r in 0 1; do
echo "== per kernel, keep 2 radius $r"
TREELET_HPLOC_RADIUS=$r ./treelet bench build --builder hploc --sizes 65536,1000000,4000000 --repeats 11 --per-kernel 2>&1 | grep -vE "^clocks"
done
echo "== keep 16 radius 0"; TREELET_HPLOC_KEEP=16 ./treelet bench build --builder hploc --sizes 65536,1000000 --repeats 11 --per-kernel | tail -2
