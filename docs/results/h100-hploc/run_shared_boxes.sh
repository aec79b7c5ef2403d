for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== pipeline stats"; ./pipeline_stats fit::hploc_cs fit::agglomerate_cs 2>&1 | tail -3
for round in 1 2; do for t in treelet_base treelet; do
echo "== $t round $round"; ./$t bench build --builder hploc --sizes 1000000,4000000 --repeats 11 --per-kernel 2>&1 | grep -vE "^clocks"
done; done
