for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768"
for T in ./treelet_before ./treelet; do timeout -s KILL 60 $T render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1; done
echo "== cornell 1024x768 1024 spp, process time (the summary's, and the shell's wall), five runs each, interleaved"
for i in 1 2 3 4 5; do for T in ./treelet_before ./treelet; do
  /usr/bin/time -f "$T wall %e s" timeout -s KILL 60 $T render $R --spp 1024 --explain --out /tmp/c.png 2>&1 | grep -E "^start-up|cornell:|wall" | sed -e 's/, built ahead.*//' -e 's/.*(accel none, layout -, kernel spheres, integrator nee), //' | tr '\n' ' '; echo
done; done
