"""OptiX's instances (through Mitsuba 3's cuda_ad_rgb variant: a `shapegroup` holding the mesh, and
`instance`s of it, which Mitsuba gives OptiX as one geometry acceleration structure under an instance
one) beside `treelet bench instances`, with its scene: the mesh alone, then a GRIDxGRID grid of copies,
1.25 times the mesh's largest extent apart, each turned about the vertical by a random angle (its own
random sequence: the same distribution, not the same angles), seen from the side (centre + (0, 0.6,
0.8) times the framing's largest extent) and from nearly above (0, 1, 0.2), smallpt's lens; one camera
ray a pixel through its centre and one cosine bounce from each hit. Kernel times from Dr.Jit's kernel
history (GPU time of the launches), as `../shared/tools/optix-peer/peer.py` measures them. Also the
wall time of moving every copy (new transforms through `mi.traverse`, then `update()`: Mitsuba
rebuilds the instance level), which includes Mitsuba's Python-side work per instance.
usage: instances.py MESH.ply [GRID WIDTH HEIGHT REPEATS]   prints JSON lines."""
import json, math, sys, time
import numpy as np
import drjit as dr
import mitsuba as mi
mi.set_variant('cuda_ad_rgb')
from mitsuba import ScalarTransform4f as T
from meshes import ply_arrays, kernel_ms

dr.set_flag(dr.JitFlag.KernelHistory, True)
path = sys.argv[1]
GRID, W, H, R = (int(a) for a in sys.argv[2:6]) if len(sys.argv) > 5 else (32, 1920, 1080, 7)
v, idx = ply_arrays(path)
lo, hi = v.min(0), v.max(0); centre = (lo + hi) / 2; extent = float((hi - lo).max())
def mesh_shape():
    m = mi.Mesh('m', v.shape[0], idx.shape[0])
    p = mi.traverse(m)
    p['vertex_positions'] = dr.ravel(mi.Point3f(v[:, 0], v[:, 1], v[:, 2]))
    p['faces'] = dr.ravel(mi.Vector3u(*(idx[:, k].astype(np.uint32) for k in range(3))))
    p.update()
    return m
HALF = 0.5135 / 2
FOV = math.degrees(2 * math.atan(HALF))

def rays_per_second(scene, frame_lo, frame_hi, view):
    """Primary and diffuse M rays/s (medians of R after two warm-ups), and the counts."""
    c = (frame_lo + frame_hi) / 2
    eye = c + np.array(view) * float((frame_hi - frame_lo).max())
    sensor = mi.load_dict({'type': 'perspective', 'fov': FOV, 'fov_axis': 'y',
        'to_world': T().look_at(origin=eye.tolist(), target=c.tolist(), up=[0, 1, 0]),
        'film': {'type': 'hdrfilm', 'width': W, 'height': H}})
    n = W * H
    i = dr.arange(mi.UInt32, n)
    pos = mi.Vector2f(mi.Float(i % W) + 0.5, mi.Float(i // W) + 0.5) / mi.Vector2f(W, H)
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5))
    dr.eval(ray)
    sampler = mi.load_dict({'type': 'independent'}); sampler.seed(7, n)
    out = {}
    def prim():
        out['p'] = scene.ray_intersect_preliminary(ray, coherent=True); dr.eval(out['p'].t)
    pri = [kernel_ms(prim) for _ in range(R + 2)]
    si = out['p'].compute_surface_interaction(ray); valid = si.is_valid()
    frame = mi.Frame3f(dr.select(dr.dot(si.n, ray.d) < 0, si.n, -si.n))
    ray2 = si.spawn_ray(frame.to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d())))
    ray2.maxt = dr.select(valid, ray2.maxt, 0.0)
    dr.eval(ray2, valid)
    hits = dr.count(valid); hits = int(hits[0]) if hasattr(hits, '__getitem__') else int(hits)
    def diff():
        out['d'] = scene.ray_intersect_preliminary(ray2, active=valid, coherent=False); dr.eval(out['d'].t)
    dif = [kernel_ms(diff) for _ in range(R + 2)]
    med = lambda x: sorted(x[2:])[len(x[2:]) // 2]
    return n / med(pri) / 1e3, hits / med(dif) / 1e3, n, hits

report = {'peer': 'OptiX instances via Mitsuba 3.9.1 cuda_ad_rgb', 'mesh': path, 'triangles': int(idx.shape[0]),
          'width': W, 'height': H, 'grid': GRID}
alone = mi.load_dict({'type': 'scene', 'm': mesh_shape()})
report['single_primary_mrays'], report['single_diffuse_mrays'], _, _ = rays_per_second(alone, lo, hi, (0, 0.6, 0.8))
del alone

rng = np.random.default_rng(1)
step = 1.25 * extent
def transforms(count):
    angles = rng.uniform(0, 360, count)
    return [T().translate([float((k % GRID) * step), 0.0, float((k // GRID) * step)]) @ T().rotate([0, 1, 0], float(a))
            for k, a in enumerate(angles)]
scene_d = {'type': 'scene', 'group': {'type': 'shapegroup', 'm': mesh_shape()}}
for k, t in enumerate(transforms(GRID * GRID)):
    scene_d[f'i{k}'] = {'type': 'instance', 'shape': {'type': 'ref', 'id': 'group'}, 'to_world': t}
t0 = time.perf_counter(); grid = mi.load_dict(scene_d); dr.sync_thread()
report['grid_load_wall_ms'] = (time.perf_counter() - t0) * 1e3
at = np.array([[(k % GRID) * step, 0.0, (k // GRID) * step] for k in range(GRID * GRID)])
frame_lo, frame_hi = (at + centre - extent / 2).min(0), (at + centre + extent / 2).max(0)
(report['instanced_primary_mrays'], report['instanced_diffuse_mrays'],
 report['instanced_rays'], report['instanced_diffuse_rays']) = rays_per_second(grid, frame_lo, frame_hi, (0, 0.6, 0.8))
report['above_primary_mrays'], report['above_diffuse_mrays'], _, _ = rays_per_second(grid, frame_lo, frame_hi, (0, 1, 0.2))
print(json.dumps(report), flush=True)
# Moving every copy: the instance level rebuilt (with Mitsuba's Python-side work per instance).
try:
    params = mi.traverse(grid)
    keys = [k for k in params.keys() if k.endswith('to_world')]
    moves = []
    for r in range(R + 1):
        new = transforms(GRID * GRID)
        t0 = time.perf_counter()
        for n, key in enumerate(keys):
            params[key] = mi.Transform4f(new[n % len(new)])
        params.update(); dr.sync_thread()
        moves.append((time.perf_counter() - t0) * 1e3)
    print(json.dumps({'movable_instances': len(keys), 'move_all_wall_ms_median': sorted(moves[1:])[len(moves[1:]) // 2] if keys else None}), flush=True)
except Exception as e:
    print(json.dumps({'move_all_error': repr(e)[:300]}), flush=True)
