for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== test treelet on the H100"
(cd .. && timeout 300 ./.dev/test_treelet 2>&1 | tail -4)
for r in 1 2; do
 echo "== base (HEAD + probe branches, probe 0)"; ./treelet_probe bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | grep -E "^ +[0-9]+ "
 for ff in 4294967295 4096 0 20000; do
 echo "== new form_from $ff"; TREELET_FORM_FROM=$ff ./treelet bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | grep -E "^ +[0-9]+ "
 done
done
echo "== per level new 4096"; TREELET_PROFILE_LEVELS=1 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -2
echo "== per level new 0"; TREELET_FORM_FROM=0 TREELET_PROFILE_LEVELS=1 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -2
