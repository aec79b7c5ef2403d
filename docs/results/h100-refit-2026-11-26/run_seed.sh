for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
cd ..
for s in 16608176954388511147 1502242694970168887 3560845619690361823; do
echo "== stiff seed $s"; TREELET_TEST_SEED=$s timeout -s KILL 100 ./.dev/test_instances stiff --test-threads 1 2>&1 | grep -E "test result|agree|same triangle" | head -3
done
for k in $(seq 1 14); do echo "== fresh $k"; timeout -s KILL 100 ./.dev/test_instances --test-threads 2 2>&1 | grep -E "test result|panicked|^seed|instanced|flattened" | head -6; done
