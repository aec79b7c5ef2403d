for f in treelet.xz treelet_old.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for round in 1 2 3; do
 for b in treelet treelet_old; do
  echo "== $b round $round"
  ./$b bench build --sizes 16000000 --repeats 21 2>&1 | grep -E "clocks|^ +[0-9]+ " | head -3
  sleep 8
 done
done
