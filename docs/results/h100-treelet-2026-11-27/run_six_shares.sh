for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== test treelet on the H100 (six build)"
(cd .. && timeout 300 ./.dev/test_treelet 2>&1 | tail -4)
for r in 1 2 3; do
 for b in treelet_small treelet_six; do
 echo "== $b"; ./$b bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | grep -E "^ +[0-9]+ "
 done
done
