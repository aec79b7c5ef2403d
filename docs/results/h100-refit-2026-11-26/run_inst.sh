for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
cd ..
echo "== instances, default"; timeout -s KILL 200 ./.dev/test_instances --test-threads 1 2>&1 | grep -v "^$" | head -40
echo "== instances, TREELET_SORT_HIGH_FIRST=0"; TREELET_SORT_HIGH_FIRST=0 timeout -s KILL 200 ./.dev/test_instances --test-threads 1 2>&1 | grep -E "test result|panicked|FAILED" | head -10
cd .dev
for b in treelet_old treelet; do
  echo "== $b bench dynamic terrain:1000000"; timeout -s KILL 150 ./$b bench dynamic --scene terrain:1000000 --frames 7 2>&1 | tail -8
done
