for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== examples/tracer (release), first process"; timeout -s KILL 120 ./tracer_example 2>&1 | tail -30
echo "== examples/tracer (release), second process"; timeout -s KILL 120 ./tracer_example 2>&1 | grep -E "instanced frame|^frame" | tail -16
echo "== gpu_vs_cpu on the device"; cd .. && timeout -s KILL 200 ./.dev/test_gpu_vs_cpu --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -8
