for t in render instances gpu_vs_cpu variants; do xz -dkf .dev/test_$t.xz; chmod +x .dev/test_$t; done
for t in render instances gpu_vs_cpu variants; do
  echo "== $t"
  (cd tests && CI=true timeout -s KILL 150 ../.dev/test_$t --test-threads 8 2>&1 | grep -E "test result|FAILED|panicked|failed" | head -20)
done
