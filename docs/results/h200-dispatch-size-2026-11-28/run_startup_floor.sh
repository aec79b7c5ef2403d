for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
echo "== Vulkan's own start-up: loader, instance, devices, device (ash alone, vkfloor_main.rs)"
for i in 1 2 3 4 5; do ./vkfloor; done
R="--width 1024 --height 768 --device gpu --spp 1024"
timeout -s KILL 60 ./treelet render $R --out /tmp/w.png 2>&1 | tail -1
for i in 1 2 3; do
  timeout -s KILL 60 ./treelet render $R --explain --out /tmp/c.png 2>&1 | grep -E "^timeline|camera paths"
done
cd ..
echo "== tests"
timeout 250 .dev/t_devices --test-threads 4 2>&1 | grep -E "^test |test result"
timeout 250 .dev/t_variants --test-threads 4 2>&1 | grep -E "^test |test result"
