# Run with a diagnostic build (not committed) that printed each chunk's
# kernel and wall milliseconds (TCHUNK=1) and the timeline with a mark per
# chunk and around the read-back: log_chunks.txt.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
R="--width 1024 --height 768"
./treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
echo "== cornell 1024x768 1024 spp, --explain timeline, five runs"
for i in 1 2 3 4 5; do
  /usr/bin/time -f "wall %e s" ./treelet render $R --spp 1024 --explain --out /tmp/c.png 2>&1 | grep -E "^timeline|cornell:|wall" | sed -e 's/(the stages.*//' -e 's/.*integrator nee), //'
done
echo "== chunks"
TCHUNK=1 /usr/bin/time -f "wall %e s" ./treelet render $R --spp 1024 --explain --out /tmp/c.png 2>&1 | grep -E "^timeline|cornell:|wall|chunk|drop|saved|returned" | sed -e 's/(the stages.*//' -e 's/.*integrator nee), //'
