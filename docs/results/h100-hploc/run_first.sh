set -x
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== gpu_vs_cpu hploc + agglomerative"
./gpu_vs_cpu hploc 2>&1 | tail -5
./gpu_vs_cpu agglomerative 2>&1 | tail -3
echo "== build quality (bunny4)"
for b in lbvh trbvh hploc; do ./treelet build --builder $b --device gpu --scene bunny4.ply | grep -E "device|builder|treelets|valid|time"; done
./treelet build --builder hploc --rounds 1 --device gpu --scene bunny4.ply | grep -E "builder|treelets|valid|time"
echo "== bench build hploc"
./treelet bench build --builder hploc --sizes 65536,1000000,4000000,16000000 --repeats 11
./treelet bench build --builder lbvh --sizes 65536,1000000,4000000,16000000 --repeats 11
./treelet bench build --builder hploc --sizes 1000000 --repeats 11 --per-kernel
echo "== rays bunny4"
./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh,hploc --layouts bvh2 --width 1920 --height 1080
