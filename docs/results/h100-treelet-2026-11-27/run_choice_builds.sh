for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for r in 1 2; do
for b in lbvh trbvh; do
echo "== $b"; ./treelet_small bench build --builder $b --sizes 4096,65536,262144,1000000 --repeats 7 2>&1 | grep -E "^ +[0-9]+ "
done
done
