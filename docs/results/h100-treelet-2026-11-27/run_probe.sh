for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for r in 1 2; do
for pr in 0 8 9 2 10; do
 echo "== probe $pr"; TREELET_PROBE=$pr TREELET_PROFILE_LEVELS=1 ./treelet_probe bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -2
done
done
