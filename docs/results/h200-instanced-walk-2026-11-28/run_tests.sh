set -x
nvidia-smi --query-gpu=name,driver_version --format=csv
cd ../tests
for t in instances tracer render layouts; do
  xz -dc ../.dev/t_$t.xz > /tmp/t_$t; chmod +x /tmp/t_$t
  CI=true /tmp/t_$t --test-threads 8 2>&1 | grep -E "^test |test result|panicked|FAILED" | tail -40
done
