"""Mitsuba 3 (cuda_ad_rgb, OptiX) renders scenes/room_disk.json's room, the scene of
../shared/tools/optix-peer/peer.py (from which this is adapted: smallpt's room as rectangles, its
two balls, the disk light of radius 18 under the ceiling, smallpt's camera), at several sample
counts, each a fresh render, and writes each image as linear EXR for `treelet compare` to score
against Treelet's reference. Mitsuba's path tracer samples the light at every bounce (next-event
estimation with MIS). Kernel times from Dr.Jit's kernel history (GPU time of the launches).
usage: room_disk.py OUTDIR [SPP,SPP,..]   prints one JSON line per sample count.
RFILTER=box renders with Mitsuba's box pixel filter (each sample counts in its own pixel only, as in
Treelet) instead of its tent (the default here), which splats each sample into the pixels within
one pixel of it: less noise per pixel, a blurrier image, not like for like with Treelet.
SAMPLER=ldsampler (or any of Mitsuba's samplers) draws the samples from Mitsuba's low-discrepancy
sampler (scrambled (0,2)-sequences, Kollig & Keller 2002) instead of independent numbers (the
default here and Mitsuba's), to set beside Treelet's Owen-scrambled Sobol points."""
import sys, json, time, math, os
import drjit as dr
import mitsuba as mi
mi.set_variant('cuda_ad_rgb')
from mitsuba import ScalarTransform4f as T

def kernel_ms(fn):
    dr.kernel_history_clear() if hasattr(dr, 'kernel_history_clear') else dr.kernel_history()
    fn()
    dr.sync_thread()
    h = dr.kernel_history()
    return sum(k.get('execution_time', 0.0) for k in h if k.get('type') == dr.KernelType.JIT)

dr.set_flag(dr.JitFlag.KernelHistory, True)
out = sys.argv[1]
counts = [int(s) for s in (sys.argv[2] if len(sys.argv) > 2 else '16,64,256,1024').split(',')]
# smallpt's lens: image half-height 0.5135 / 2 at unit distance.
FOV = math.degrees(2 * math.atan(0.5135 / 2))
diff_ = lambda rgb: {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': rgb}}
def wall(c, n, rgb):
    up = [0, 0, 1] if abs(n[1]) > 0.5 else [0, 1, 0]
    return {'type': 'rectangle', 'bsdf': diff_(rgb),
            'to_world': T().look_at(origin=c, target=[c[k] + n[k] for k in range(3)], up=up) @ T().scale([200, 200, 1])}
RFILTER = os.environ.get('RFILTER', 'tent')
SAMPLER = os.environ.get('SAMPLER', 'independent')
cam_o = [50, 52, 295.6]; d = [0, -0.042612, -1]; norm = math.sqrt(sum(x * x for x in d)); d = [x / norm for x in d]
scene = mi.load_dict({'type': 'scene', 'integrator': {'type': 'path', 'max_depth': -1, 'rr_depth': 5},
  'sensor': {'type': 'perspective', 'fov': FOV, 'fov_axis': 'y', 'near_clip': 140.0,
             'to_world': T().look_at(origin=cam_o, target=[cam_o[k] + d[k] for k in range(3)], up=[0, 1, 0]),
             'film': {'type': 'hdrfilm', 'width': 1024, 'height': 768, 'rfilter': {'type': RFILTER}},
             'sampler': {'type': SAMPLER, 'sample_count': 1024}},
  'left': wall([1, 40.8, 81.6], [1, 0, 0], [.75, .25, .25]),
  'right': wall([99, 40.8, 81.6], [-1, 0, 0], [.25, .25, .75]),
  'back': wall([50, 40.8, 0], [0, 0, 1], [.75, .75, .75]),
  'front': wall([50, 40.8, 170], [0, 0, -1], [0, 0, 0]),
  'bottom': wall([50, 0, 81.6], [0, 1, 0], [.75, .75, .75]),
  'top': wall([50, 81.6, 81.6], [0, -1, 0], [.75, .75, .75]),
  'mirror': {'type': 'sphere', 'center': [27, 16.5, 47], 'radius': 16.5, 'bsdf': {'type': 'conductor', 'material': 'none'}},
  'glass': {'type': 'sphere', 'center': [73, 16.5, 78], 'radius': 16.5, 'bsdf': {'type': 'dielectric', 'int_ior': 1.5, 'ext_ior': 1.0}},
  'light': {'type': 'disk', 'bsdf': diff_([0, 0, 0]), 'emitter': {'type': 'area', 'radiance': {'type': 'rgb', 'value': [12, 12, 12]}},
            'to_world': T().look_at(origin=[50, 81.5, 81.6], target=[50, 80.5, 81.6], up=[0, 0, 1]) @ T().scale([18, 18, 1])}})
# Warm-up: the first render compiles Mitsuba's kernels.
img = mi.render(scene, spp=4, seed=1000); dr.eval(img); dr.sync_thread()
for spp in counts:
    passes = max(1, spp // 128)  # at most 128 samples per launch, as the peer script does
    t0 = time.perf_counter(); ks = 0.0; acc = None
    for p in range(passes):
        last = {}
        def one():
            last['img'] = mi.render(scene, spp=spp // passes, seed=p + 17 * spp); dr.eval(last['img'])
        ks += kernel_ms(one)
        acc = last['img'] if acc is None else acc + last['img']
    acc = acc / passes; dr.eval(acc); dr.sync_thread()
    wall_s = time.perf_counter() - t0
    path = f'{out}/mitsuba_room_disk_{RFILTER}_{SAMPLER}_{spp}spp.exr'
    mi.util.write_bitmap(path, acc)
    print(json.dumps({'peer': 'Mitsuba 3.9.1 path (cuda_ad_rgb, OptiX)', 'scene': 'room_disk', 'width': 1024,
                      'height': 768, 'spp': spp, 'rfilter': RFILTER, 'sampler': SAMPLER, 'passes': passes, 'kernel_ms': ks, 'wall_s': wall_s, 'image': path}), flush=True)
