for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== gpu_vs_cpu hploc"; ./gpu_vs_cpu hploc 2>&1 | grep "test result"
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
for t in treelet_base treelet; do echo "== $t bunny4"; ./$t build --builder hploc --device gpu --scene bunny4.ply | grep -E "builder|time"; done
for round in 1 2; do for t in treelet_base treelet; do
echo "== $t round $round"; ./$t bench build --builder hploc --sizes 65536,1000000,4000000 --repeats 11 --per-kernel 2>&1 | grep -vE "^clocks"
done; done
