"""The Python package's time for a batch of rays, NumPy arrays in and NumPy hits out, against
the Rust API's `closest_hits` on the same tree and rays (timed inside the module, the rays
already made: `Tracer._rust_api_ms`), the same into the first batch's arrays (`out=`) and,
with --mitsuba, Mitsuba 3's
`scene.ray_intersect_preliminary` (OptiX on NVIDIA) from Python, transfers included; with
--embree, embreex's `EmbreeScene.run` (Embree on the CPU, the same outputs: distance, triangle,
barycentrics, normal).
Incoherent rays: origins uniform in the mesh's box, directions uniform on the sphere.

    python python/examples/bench_rays.py MESH.ply[.xz] [--rays 1000000] [--device gpu] [--mitsuba] [--embree]

MESH.ply: a binary PLY as `treelet export` writes it (scenes/real/*.ply.xz are). Prints one
JSON line a method."""
import argparse
import json
import os
import time

import numpy as np

import treelet


def read_ply(path):
    """The vertices and triangles of a binary little-endian PLY of float x, y, z and a uchar/int
    face list (what `treelet export` writes)."""
    data = open(path, "rb").read()
    if path.endswith(".xz"):
        import lzma
        data = lzma.decompress(data)
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    count = {l.split()[1]: int(l.split()[2]) for l in header if l.startswith("element")}
    nv, nf = count["vertex"], count["face"]
    v = np.frombuffer(data, dtype="<f4", count=3 * nv, offset=end).reshape(nv, 3)
    faces = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]), count=nf, offset=end + 12 * nv)
    assert np.all(faces["n"] == 3), "triangles only"
    return v, faces["i"]


def median_ms(f, repeats):
    """The median wall time of `f()`; the previous result is dropped before each timing (its arrays
    freed), as the Rust API's baseline drops its hits after its own."""
    times, out = [], None
    for _ in range(repeats):
        out = None
        start = time.perf_counter()
        out = f()
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times)), out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("mesh")
    p.add_argument("--rays", type=int, default=1_000_000)
    p.add_argument("--device", default="gpu")
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--mitsuba", action="store_true")
    p.add_argument("--embree", action="store_true")
    p.add_argument("--quality", default="fast", help="Treelet's build: fast, balanced or high")
    a = p.parse_args()
    v, idx = read_ply(a.mesh)
    rng = np.random.default_rng(1)
    lo, hi = v.min(axis=0), v.max(axis=0)
    o = rng.uniform(lo, hi, (a.rays, 3)).astype(np.float32)
    d = rng.normal(size=(a.rays, 3)).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)

    start = time.perf_counter()
    tracer = treelet.Tracer(v, idx, device=a.device, quality=a.quality)
    build_ms = (time.perf_counter() - start) * 1e3
    ms, hits = median_ms(lambda: tracer.closest_hits(o, d), a.repeats)
    rust_ms = tracer._rust_api_ms(o, d, a.repeats)
    print(json.dumps({"api": "rust", "adapter": tracer.device, "rays": a.rays, "median_ms": round(rust_ms, 3),
                      "mrays_per_s": round(a.rays / rust_ms / 1e3, 1)}))
    try:
        kept_ms = tracer._rust_api_ms(o, d, a.repeats, kept=True)
    except TypeError:  # a wheel from before `kept`
        kept_ms = None
    if kept_ms:
        print(json.dumps({"api": "rust, hits into a kept buffer", "adapter": tracer.device, "rays": a.rays,
                          "median_ms": round(kept_ms, 3), "mrays_per_s": round(a.rays / kept_ms / 1e3, 1)}))
    print(json.dumps({"api": "python", "adapter": tracer.device, "python_over_rust": round(ms / rust_ms, 3), "triangles": len(tracer), "rays": a.rays,
                      "hit": int(hits.hit.sum()), "build_ms": round(build_ms, 3), "median_ms": round(ms, 3),
                      "mrays_per_s": round(a.rays / ms / 1e3, 1)}))
    try:  # batch after batch into the same arrays (out=)
        out_ms, _ = median_ms(lambda: tracer.closest_hits(o, d, out=hits), a.repeats)
        print(json.dumps({"api": "python, out=", "adapter": tracer.device, "python_over_rust": round(out_ms / rust_ms, 3), "rays": a.rays,
                          "median_ms": round(out_ms, 3), "mrays_per_s": round(a.rays / out_ms / 1e3, 1)}))
    except TypeError:  # a wheel from before `out`
        pass

    if a.mitsuba:
        import drjit as dr
        import mitsuba as mi
        mi.set_variant("cuda_ad_rgb")
        start = time.perf_counter()
        mesh = mi.Mesh("mesh", len(v), len(idx))
        params = mi.traverse(mesh)
        # As peers/mitsuba/rays.py makes the same mesh.
        params["vertex_positions"] = dr.ravel(mi.Point3f(v[:, 0], v[:, 1], v[:, 2]))
        params["faces"] = dr.ravel(mi.Vector3u(*(idx[:, k].astype(np.uint32) for k in range(3))))
        params.update()
        scene = mi.load_dict({"type": "scene", "mesh": mesh})
        dr.sync_thread()
        mi_build_ms = (time.perf_counter() - start) * 1e3

        def trace():
            ray = mi.Ray3f(mi.Point3f(o[:, 0], o[:, 1], o[:, 2]), mi.Vector3f(d[:, 0], d[:, 1], d[:, 2]))
            si = scene.ray_intersect_preliminary(ray, coherent=False)
            t, prim = si.t.numpy(), si.prim_index.numpy()
            return t, prim

        trace()
        ms, (t, prim) = median_ms(trace, a.repeats)
        print(json.dumps({"api": "mitsuba", "adapter": "OptiX (Mitsuba 3 cuda_ad_rgb)", "triangles": len(idx),
                          "rays": a.rays, "hit": int(np.isfinite(t).sum()), "build_ms": round(mi_build_ms, 3),
                          "median_ms": round(ms, 3), "mrays_per_s": round(a.rays / ms / 1e3, 1)}))
        same = np.isfinite(t) == hits.hit
        print(json.dumps({"agree_hit_or_miss": float(same.mean()),
                          "agree_primitive": float((prim[hits.hit & same] == hits.primitive[hits.hit & same]).mean())}))

    if a.embree:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
        start = time.perf_counter()
        scene = rtcore_scene.EmbreeScene()
        TriangleMesh(scene, np.ascontiguousarray(v[idx], dtype=np.float32))
        # Embree builds on the first query: the build is timed with a one-ray query.
        scene.run(o[:1], d[:1])
        embree_build_ms = (time.perf_counter() - start) * 1e3
        ms, res = median_ms(lambda: scene.run(o, d, output=1), a.repeats)
        prim = np.asarray(res["primID"])
        hit = prim >= 0
        print(json.dumps({"api": "embreex", "adapter": f"Embree (embreex), {os.cpu_count()} cores", "triangles": len(idx),
                          "rays": a.rays, "hit": int(hit.sum()), "build_ms": round(embree_build_ms, 3),
                          "median_ms": round(ms, 3), "mrays_per_s": round(a.rays / ms / 1e3, 1)}))
        same = hit == hits.hit
        print(json.dumps({"agree_hit_or_miss": float(same.mean()),
                          "agree_primitive": float((prim[hits.hit & same] == hits.primitive[hits.hit & same]).mean())}))


if __name__ == "__main__":
    main()
