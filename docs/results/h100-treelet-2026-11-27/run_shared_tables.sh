for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
./pipeline_stats treelet::treelet_restructure_cs treelet::treelet_restructure_single_cs treelet::treelet_restructure_shared_cs 2>&1 | tail -4
echo "== test treelet on the H100"
(cd .. && timeout 300 ./.dev/test_treelet 2>&1 | tail -4)
for r in 1 2; do
for sf in 4294967295 0 4096; do
 echo "== trbvh 1M shared_from $sf"; TREELET_SHARED_FROM=$sf ./treelet bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | grep -E "^ +[0-9]+ "
done
done
echo "== per level shared 0"; TREELET_SHARED_FROM=0 TREELET_PROFILE_LEVELS=1 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -2
echo "== per level shared 0 single 1"; TREELET_SINGLE_HEIGHTS=1 TREELET_SHARED_FROM=0 TREELET_PROFILE_LEVELS=1 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -2
