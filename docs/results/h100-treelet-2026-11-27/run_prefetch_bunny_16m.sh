for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
(python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null 2>&1 &)
echo "== test treelet on the H100 (prefetch build)"
(cd .. && timeout 300 ./.dev/test_treelet 2>&1 | tail -4)
for r in 1 2 3; do
 for b in treelet_small treelet_prefetch; do
 echo "== $b"; ./$b bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | grep -E "^ +[0-9]+ "
 done
done
echo "== per level prefetch"; TREELET_PROFILE_LEVELS=1 ./treelet_prefetch bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -1
echo "== 16M trbvh"; for b in treelet_small treelet_prefetch; do echo "== $b"; ./$b bench build --builder trbvh --sizes 16000000 --repeats 5 2>&1 | grep -E "clocks|^ +[0-9]+ "; done
wait; sleep 1; ls -la bunny4.ply
for b in treelet_small treelet_prefetch; do
echo "== rays $b"; ./$b bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh,hploc --layouts bvh2 --width 1920 --height 1080 2>&1 | tail -8
done
