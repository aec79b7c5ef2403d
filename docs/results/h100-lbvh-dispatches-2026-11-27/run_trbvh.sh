for f in treelet.xz treelet_prev.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for round in 1 2 3; do
 for b in treelet_prev treelet; do
  echo "== $b round $round"
  ./$b bench build --builder trbvh --sizes 1000000 --repeats 11 2>&1 | grep -E "^ +[0-9]+ " | head -1
 done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
