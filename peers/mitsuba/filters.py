"""Mitsuba 3's noise on the disk-lit room by pixel filter: runs room_disk.py (same folder) with
RFILTER=tent and RFILTER=box (independent numbers; SAMPLERS=ldsampler adds a tent-filtered series
with Mitsuba's low-discrepancy sampler, which on the H100 returned only its 16 and 64 spp renders,
2026-11-28), and scores each render against the same filter and sampler's largest sample count
(RMSE over all pixels and channels, as `treelet compare` computes it), so that the filters' noise
at equal time can be compared, and Treelet's (whose samples count in their own pixel only, as with
box) set beside the like-for-like one.
usage: filters.py OUTDIR [SPP,SPP,..]   prints one JSON line per render."""
import json, os, subprocess, sys
import numpy as np
import mitsuba as mi
mi.set_variant('scalar_rgb')

out = sys.argv[1]
counts = sys.argv[2] if len(sys.argv) > 2 else '16,64,256,1024'
here = os.path.dirname(os.path.abspath(__file__))
extra = [('tent', s) for s in os.environ.get('SAMPLERS', '').split(',') if s]
for rfilter, sampler in [('tent', 'independent'), ('box', 'independent')] + extra:
    env = dict(os.environ, RFILTER=rfilter, SAMPLER=sampler)
    lines = subprocess.run([sys.executable, os.path.join(here, 'room_disk.py'), out, counts], env=env,
                           check=True, capture_output=True, text=True).stdout.splitlines()
    runs = [json.loads(l) for l in lines if l.startswith('{')]
    top = max(runs, key=lambda r: r['spp'])
    ref = np.array(mi.Bitmap(top['image']), dtype=np.float64)
    for r in runs:
        img = np.array(mi.Bitmap(r['image']), dtype=np.float64)
        r['rmse_own_top'] = float(np.sqrt(np.mean((img - ref) ** 2))) if r is not top else None
        print(json.dumps(r), flush=True)
