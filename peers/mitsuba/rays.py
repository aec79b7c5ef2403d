"""OptiX (through Mitsuba 3's cuda_ad_rgb variant) casting `treelet bench rays` rays at a mesh, from
the mesh-only framing (centre + (0, 0.6, 0.8) times the largest extent, as
`../shared/tools/optix-peer/peer.py`) or from a camera given as `treelet bench rays --camera` takes it
(eye and target, EX,EY,EZ,TX,TY,TZ: a camera inside a building). smallpt's lens; one jittered camera
ray a pixel and one cosine bounce from each hit. Kernel times from Dr.Jit's kernel history (GPU time
of the launches), as peer.py measures them; the build is the wall time of making the scene.
usage: rays.py MESH.ply [WIDTH HEIGHT REPEATS [EX,EY,EZ,TX,TY,TZ]]   prints one JSON line."""
import json, math, sys, time
import numpy as np
import drjit as dr
import mitsuba as mi
mi.set_variant('cuda_ad_rgb')
from mitsuba import ScalarTransform4f as T
from meshes import ply_arrays, kernel_ms

dr.set_flag(dr.JitFlag.KernelHistory, True)
path = sys.argv[1]
W, H, R = (int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])) if len(sys.argv) > 4 else (1920, 1080, 7)
v, idx = ply_arrays(path)
lo, hi = v.min(0), v.max(0); center = (lo + hi) / 2; size = float((hi - lo).max())
if len(sys.argv) > 5:
    c = [float(x) for x in sys.argv[5].split(',')]
    origin, target, view = np.array(c[:3]), np.array(c[3:6]), 'camera'
else:
    origin, target, view = center + np.array([0.0, 0.6, 0.8]) * size, center, 'mesh-only framing'
mesh = mi.Mesh('m', v.shape[0], idx.shape[0])
params = mi.traverse(mesh)
params['vertex_positions'] = dr.ravel(mi.Point3f(v[:, 0], v[:, 1], v[:, 2]))
params['faces'] = dr.ravel(mi.Vector3u(*(idx[:, k].astype(np.uint32) for k in range(3))))
params.update()
dr.sync_thread()
builds = []
for r in range(R + 1):
    t0 = time.perf_counter(); scene = mi.load_dict({'type': 'scene', 'm': mesh}); dr.sync_thread()
    builds.append((time.perf_counter() - t0) * 1e3)
# smallpt's lens: image half-height 0.5135 / 2 at unit distance.
FOV = math.degrees(2 * math.atan(0.5135 / 2))
sensor = mi.load_dict({'type': 'perspective', 'fov': FOV, 'fov_axis': 'y',
    'to_world': T().look_at(origin=origin.tolist(), target=target.tolist(), up=[0, 1, 0]),
    'film': {'type': 'hdrfilm', 'width': W, 'height': H}})
n = W * H
sampler = mi.load_dict({'type': 'independent'}); sampler.seed(1, n)
i = dr.arange(mi.UInt32, n)
pos = mi.Vector2f(mi.Float(i % W) + sampler.next_1d(), mi.Float(i // W) + sampler.next_1d()) / mi.Vector2f(W, H)
ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5))
dr.eval(ray)
pri, dif, hits = [], [], 0
for r in range(R + 2):
    out = {}
    def prim():
        out['pi'] = scene.ray_intersect_preliminary(ray, coherent=True); dr.eval(out['pi'].t)
    pri.append(kernel_ms(prim))
    si = out['pi'].compute_surface_interaction(ray); valid = si.is_valid()
    d2 = mi.warp.square_to_cosine_hemisphere(sampler.next_2d())
    frame = mi.Frame3f(dr.select(dr.dot(si.n, ray.d) < 0, si.n, -si.n))
    ray2 = si.spawn_ray(frame.to_world(d2))
    ray2.maxt = dr.select(valid, ray2.maxt, 0.0)
    dr.eval(ray2, valid)
    count = dr.count(valid)
    hits = int(count[0]) if hasattr(count, '__getitem__') else int(count)
    def diff():
        out['p2'] = scene.ray_intersect_preliminary(ray2, active=valid, coherent=False); dr.eval(out['p2'].t)
    dif.append(kernel_ms(diff))
med = lambda x: sorted(x[2:])[len(x[2:]) // 2]
print(json.dumps({'peer': 'OptiX via Mitsuba 3.9.1 cuda_ad_rgb', 'mesh': path, 'view': view,
    'eye': origin.tolist(), 'target': target.tolist(), 'triangles': int(idx.shape[0]),
    'build_wall_ms_median': sorted(builds[1:])[len(builds[1:]) // 2], 'width': W, 'height': H,
    'primary_ms': med(pri), 'diffuse_ms': med(dif), 'diffuse_rays': hits,
    'primary_mrays_s': n / med(pri) / 1e3, 'diffuse_mrays_s': hits / med(dif) / 1e3}), flush=True)
