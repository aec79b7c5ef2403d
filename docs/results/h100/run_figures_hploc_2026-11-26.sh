for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for fig in pareto rays-figure; do
  echo "== $fig"; /usr/bin/time -f "%e s" timeout -s KILL 250 ./treelet bench $fig --device gpu --out $OUT/h100 2>&1 | tail -40
done
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
echo "== pareto (built with --features peers)"; /usr/bin/time -f "%e s" timeout -s KILL 250 ./treelet bench pareto --device gpu --out $OUT/h100 2>&1 | tail -30
