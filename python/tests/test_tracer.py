"""The Python package against an independent answer (a brute-force ray-triangle test written
here in NumPy, float64), against itself across devices and memory layouts, and on every error
path. Run: `pytest python/tests` with the wheel installed (python/README.md)."""
import os

import numpy as np
import pytest

import treelet


def random_mesh(rng, triangles, spread=10.0, size=1.0):
    """Triangles of random size and place: each a random corner plus two random edges."""
    corners = rng.uniform(-spread, spread, (triangles, 1, 3))
    edges = rng.normal(0.0, size, (triangles, 2, 3)) * rng.uniform(0.05, 1.0, (triangles, 1, 1))
    v = np.concatenate([corners, corners + edges], axis=1).reshape(-1, 3).astype(np.float32)
    return v, np.arange(3 * triangles).reshape(-1, 3)


def random_rays(rng, n, v, spread=12.0):
    """Rays from random points, three in four aimed near a random triangle's centre (so that
    many hit), the rest in random directions."""
    o = rng.uniform(-spread, spread, (n, 3)).astype(np.float32)
    centres = v.reshape(-1, 3, 3).mean(axis=1)
    aim = centres[rng.integers(0, len(centres), n)] + rng.normal(0.0, 0.02, (n, 3)) - o
    d = np.where(rng.uniform(size=(n, 1)) < 0.75, aim, rng.normal(size=(n, 3))).astype(np.float32)
    return o, d


def brute_force(v, idx, o, d):
    """Every ray against every triangle (Moller-Trumbore in float64): the nearest distance
    along the normalized direction, the triangle, and the second nearest (to spot near ties)."""
    v = v.astype(np.float64)
    a, b, c = v[idx[:, 0]], v[idx[:, 1]], v[idx[:, 2]]
    e1, e2 = b - a, c - a
    dn = d.astype(np.float64) / np.linalg.norm(d, axis=1, keepdims=True)
    o = o.astype(np.float64)
    best_t = np.full(len(o), np.inf)
    best_p = np.full(len(o), -1)
    second = np.full(len(o), np.inf)
    for k in range(len(o)):
        p = np.cross(dn[k], e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = o[k] - a
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        w = (q @ dn[k]) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= 0) & (w >= 0) & (u + w <= 1) & (t >= 0)
        ts = np.where(hit, t, np.inf)
        order = np.argsort(ts)
        best_t[k], second[k] = ts[order[0]], ts[order[1]] if len(ts) > 1 else np.inf
        best_p[k] = order[0] if np.isfinite(ts[order[0]]) else -1
    return best_t, best_p, second


def devices():
    """The CPU runner, and a Vulkan adapter where the machine has one: with CI set (as `.ci/run`
    sets it, where lavapipe is installed) a missing adapter fails the GPU case, never skips it."""
    out = ["cpu"]
    try:
        v, idx = random_mesh(np.random.default_rng(0), 4)
        treelet.Tracer(v, idx, device="gpu")
        out.append("gpu")
    except RuntimeError as e:
        if os.environ.get("CI"):
            pytest.fail(f"CI is set and no Vulkan adapter opened: {e}")
    return out


@pytest.mark.parametrize("device", devices())
@pytest.mark.parametrize("quality", ["fast", "balanced", "high"])
def test_closest_hits_equal_brute_force(device, quality):
    rng = np.random.default_rng([["cpu", "gpu"].index(device), ["fast", "balanced", "high"].index(quality)])
    v, idx = random_mesh(rng, 300)
    o, d = random_rays(rng, 400, v)
    tracer = treelet.Tracer(v, idx, device=device, quality=quality)
    hits = tracer.closest_hits(o, d)
    t, p, second = brute_force(v, idx, o, d)
    assert len(hits) == 400 and hits.hit.sum() > 150, f"too few hits to test anything: {hits}"
    # Where the nearest two are within 1e-4 of each other, either may win in f32.
    with np.errstate(invalid="ignore"):
        clear = ~np.isfinite(t) | ((second - t) > 1e-4 * np.maximum(t, 1.0))
    assert np.array_equal(hits.hit, np.isfinite(t)), "hit or miss differs from the brute force"
    h = hits.hit & clear
    assert np.array_equal(hits.primitive[h], p[h])
    np.testing.assert_allclose(hits.t[h], t[h], rtol=1e-5, atol=1e-5)
    assert np.all(hits.primitive[~hits.hit] == -1) and np.all(np.isinf(hits.t[~hits.hit]))
    assert np.all(hits.instance[hits.hit] == 0)
    # The hit point from the barycentrics lies on the ray; the normal is the triangle's.
    a, b, c = (v[idx[hits.primitive[h], k]].astype(np.float64) for k in range(3))
    b1, b2 = hits.barycentrics[h, 0:1], hits.barycentrics[h, 1:2]
    point = (1 - b1 - b2) * a + b1 * b + b2 * c
    dn = d[h] / np.linalg.norm(d[h], axis=1, keepdims=True)
    np.testing.assert_allclose(point, o[h] + hits.t[h, None] * dn, atol=1e-3)
    n = np.cross(b - a, c - a)
    np.testing.assert_allclose(hits.normal[h], n / np.linalg.norm(n, axis=1, keepdims=True), atol=1e-4)


@pytest.mark.parametrize("device", devices())
def test_out_is_filled_in_place_with_the_same_hits(device):
    rng = np.random.default_rng(7 + ["cpu", "gpu"].index(device))
    v, idx = random_mesh(rng, 300)
    tracer = treelet.Tracer(v, idx, device=device)
    o1, d1 = random_rays(rng, 500, v)
    o2, d2 = random_rays(rng, 500, v)
    out = tracer.closest_hits(o1, d1)
    arrays = [out.t, out.primitive, out.instance, out.barycentrics, out.normal, out.hit]
    again = tracer.closest_hits(o2, d2, out=out)
    assert again is out, "out is returned"
    fresh = tracer.closest_hits(o2, d2)
    assert fresh.hit.sum() > 150, f"too few hits to test anything: {fresh}"
    assert not np.array_equal(fresh.primitive, tracer.closest_hits(o1, d1).primitive), "two batches alike"
    for name, before in zip(["t", "primitive", "instance", "barycentrics", "normal", "hit"], arrays):
        now = getattr(out, name)
        assert np.shares_memory(now, before), f"out.{name} is a new array"
        np.testing.assert_array_equal(now, getattr(fresh, name), err_msg=f"out.{name}")
    # Refused by name: another number of rays; out's own array as the rays.
    with pytest.raises(ValueError, match="out: holds 500 hits, but 3 rays were given"):
        tracer.closest_hits(o2[:3], d2[:3], out=out)
    with pytest.raises(ValueError, match="out.normal: the array is in use"):
        tracer.closest_hits(o2, out.normal, out=out)
    with pytest.raises(TypeError):
        tracer.closest_hits(o2, d2, out=np.zeros(500))


@pytest.mark.parametrize("device", devices())
def test_a_large_batch_equals_the_same_rays_in_small_ones(device):
    """A batch of many rays is written on every core, in parts (`HitSlices::fill`); batches of a
    few hundred are one part. Both give the same arrays, fresh or through `out=`, and the same
    occlusion answers."""
    rng = np.random.default_rng([5, ["cpu", "gpu"].index(device)])
    v, idx = random_mesh(rng, 400)
    n = 70_001  # more than four parts of 16 384, and not a multiple of one
    o, d = random_rays(rng, n, v)
    t_max = rng.uniform(0.0, 30.0, n).astype(np.float32)
    tracer = treelet.Tracer(v, idx, device=device)
    whole = tracer.closest_hits(o, d)
    again = tracer.closest_hits(o[::-1].copy(), d[::-1].copy())
    again = tracer.closest_hits(o, d, out=again)
    occluded = tracer.occluded(o, d, t_max=t_max)
    assert 0.3 * n < whole.hit.sum() < n, f"hits to test: {whole}"
    step = 997
    for start in range(0, n, step):
        part = tracer.closest_hits(o[start:start + step], d[start:start + step])
        for name in ["t", "primitive", "instance", "barycentrics", "normal", "hit"]:
            np.testing.assert_array_equal(getattr(whole, name)[start:start + step], getattr(part, name), err_msg=name)
            np.testing.assert_array_equal(getattr(again, name)[start:start + step], getattr(part, name), err_msg=f"out= {name}")
        np.testing.assert_array_equal(occluded[start:start + step], tracer.occluded(o[start:start + step], d[start:start + step], t_max=t_max[start:start + step]))


@pytest.mark.parametrize("device", devices())
def test_occluded_agrees_with_closest_hits(device):
    rng = np.random.default_rng(7)
    v, idx = random_mesh(rng, 200)
    o, d = random_rays(rng, 300, v)
    tracer = treelet.Tracer(v, idx, device=device)
    t_max = rng.uniform(0.0, 30.0, 300).astype(np.float32)
    hits = tracer.closest_hits(o, d, t_max=t_max)
    occluded = tracer.occluded(o, d, t_max=t_max)
    assert occluded.dtype == bool and np.array_equal(occluded, hits.hit)
    assert 0 < occluded.sum() < 300
    # t_min skips what lies before it.
    far = tracer.closest_hits(o, d, t_min=np.where(hits.hit, hits.t + 1e-3, 0).astype(np.float32))
    assert np.all(far.t[hits.hit] >= hits.t[hits.hit])


def test_gpu_equals_the_cpu_runner():
    if "gpu" not in devices():
        pytest.skip("no Vulkan adapter on this machine (CI is not set)")
    rng = np.random.default_rng(11)
    v, idx = random_mesh(rng, 500)
    o, d = random_rays(rng, 500, v)
    cpu = treelet.Tracer(v, idx, device="cpu").closest_hits(o, d)
    gpu = treelet.Tracer(v, idx, device="gpu").closest_hits(o, d)
    assert np.array_equal(cpu.primitive, gpu.primitive)
    np.testing.assert_allclose(cpu.t, gpu.t, rtol=1e-6)


def test_any_layout_and_dtype_gives_the_same_hits():
    rng = np.random.default_rng(3)
    v, idx = random_mesh(rng, 100)
    o, d = random_rays(rng, 200, v)
    base = treelet.Tracer(v, idx, device="cpu").closest_hits(o, d)
    fortran = treelet.Tracer(np.asfortranarray(v.astype(np.float64)), np.asfortranarray(idx.astype(np.uint32)), device="cpu")
    strided = np.zeros((2 * len(o), 3), dtype=np.float32)
    strided[::2] = o
    other = fortran.closest_hits(strided[::2], d.tolist())
    assert np.array_equal(base.primitive, other.primitive) and np.array_equal(base.t, other.t)


def test_refit_moves_the_hits_with_the_mesh():
    rng = np.random.default_rng(5)
    v, idx = random_mesh(rng, 150)
    o, d = random_rays(rng, 300, v)
    tracer = treelet.Tracer(v, idx, device="cpu")
    moved = v + np.array([0.5, -0.25, 1.0], dtype=np.float32)
    tracer.refit(moved, idx)
    fresh = treelet.Tracer(moved, idx, device="cpu").closest_hits(o, d)
    refit = tracer.closest_hits(o, d)
    assert np.array_equal(refit.primitive, fresh.primitive)
    np.testing.assert_allclose(refit.t, fresh.t, rtol=1e-6)
    with pytest.raises(ValueError, match="150 triangles|triangles where the tree has 150"):
        tracer.refit(moved, idx[:10])


def test_an_empty_mesh_misses_everything():
    tracer = treelet.Tracer(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int64), device="cpu")
    hits = tracer.closest_hits(np.zeros((2, 3)), np.ones((2, 3)))
    assert not hits.hit.any() and np.all(hits.primitive == -1)


@pytest.mark.parametrize(
    "vertices, indices, kwargs, error, message",
    [
        (np.zeros((3, 2)), [[0, 1, 2]], {}, ValueError, r"vertices: expected shape \(n, 3\)"),
        (np.zeros(9), [[0, 1, 2]], {}, ValueError, "vertices: expected a 2-dimensional"),
        (np.array([["a", "b", "c"]] * 3), [[0, 1, 2]], {}, TypeError, "vertices: numbers expected"),
        (np.eye(3), [[0.0, 1.0, 2.0]], {}, TypeError, "indices: integers expected"),
        (np.eye(3), [[0, 1, 3]], {}, ValueError, r"indices\[0\]: vertex index 3 is not one of the 3 vertices"),
        (np.eye(3), [[0, 1, -1]], {}, ValueError, r"indices\[0\]: vertex index -1"),
        (np.eye(3), [[0, 1]], {}, ValueError, r"indices: expected shape \(m, 3\)"),
        (np.array([[np.nan, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]], {}, ValueError, "not finite"),
        (np.eye(3), [[0, 1, 2]], {"device": "tpu"}, ValueError, "device `tpu`"),
        (np.eye(3), [[0, 1, 2]], {"quality": "best"}, ValueError, "quality `best`"),
    ],
)
def test_bad_meshes_are_named(vertices, indices, kwargs, error, message):
    with pytest.raises(error, match=message):
        treelet.Tracer(vertices, np.asarray(indices), **{"device": "cpu", **kwargs})


def test_bad_rays_are_named():
    tracer = treelet.Tracer(np.eye(3), np.array([[0, 1, 2]]), device="cpu")
    o, d = np.zeros((2, 3)), np.ones((2, 3))
    with pytest.raises(ValueError, match="2 origins but 3 directions"):
        tracer.closest_hits(o, np.ones((3, 3)))
    with pytest.raises(ValueError, match=r"directions: expected shape \(n, 3\)"):
        tracer.closest_hits(o, np.ones((2, 4)))
    with pytest.raises(ValueError, match="t_max: 3 values for 2 rays"):
        tracer.occluded(o, d, t_max=np.ones(3))
    # A direction of length 0 hits nothing, as in the Rust API.
    assert not tracer.closest_hits(o, np.zeros((2, 3))).hit.any()
    with pytest.raises(ValueError, match=r"origins\[0\]: not finite"):
        tracer.closest_hits(np.full((2, 3), np.nan), d)
    with pytest.raises(ValueError, match=r"directions\[1\]: not finite"):
        tracer.closest_hits(o, np.array([[0, 0, 1], [np.inf, 0, 0]]))
    with pytest.raises(ValueError, match="t_max: 1 values for 2 rays"):
        tracer.occluded(o, d, t_max=np.array([1.0]))
    with pytest.raises(TypeError, match="t_min: numbers expected"):
        tracer.occluded(o, d, t_min=np.array(["a", "b"]))
    with pytest.raises(ValueError, match="t_max: NaN"):
        tracer.occluded(o, d, t_max=np.array([1.0, np.nan]))
    with pytest.raises(ValueError, match="t_min -1"):
        tracer.occluded(o, d, t_min=-1.0)
    with pytest.raises(TypeError, match="origins: numbers expected"):
        tracer.closest_hits(np.array([["x"] * 3] * 2), d)


class DLPackOnly:
    """An array NumPy can read only through DLPack, as it reads a PyTorch, JAX or CuPy CPU array."""

    def __init__(self, a, device=None):
        self._a, self._device = a, device

    def __dlpack__(self, **kwargs):
        return self._a.__dlpack__(**kwargs)

    def __dlpack_device__(self):
        return self._device or self._a.__dlpack_device__()


def test_dlpack_arrays_are_read_as_numpy_ones():
    rng = np.random.default_rng(17)
    v, idx = random_mesh(rng, 100)
    o, d = random_rays(rng, 200, v)
    base = treelet.Tracer(v, idx, device="cpu")
    want = base.closest_hits(o, d, t_max=np.full(200, 50.0, dtype=np.float32))
    other = treelet.Tracer(DLPackOnly(v), DLPackOnly(idx), device="cpu")
    got = other.closest_hits(DLPackOnly(o), DLPackOnly(d), t_max=DLPackOnly(np.full(200, 50.0, dtype=np.float32)))
    assert np.array_equal(want.primitive, got.primitive) and np.array_equal(want.t, got.t)
    # A tensor on a GPU (DLPack device type 2, CUDA) is refused by name, not read.
    with pytest.raises(TypeError, match="origins: not readable on the CPU through DLPack"):
        base.closest_hits(DLPackOnly(o, device=(2, 0)), d)


def test_torch_tensors_where_torch_is_installed():
    torch = pytest.importorskip("torch")  # not in CI's environment: DLPackOnly stands in there
    rng = np.random.default_rng(19)
    v, idx = random_mesh(rng, 100)
    o, d = random_rays(rng, 200, v)
    want = treelet.Tracer(v, idx, device="cpu").closest_hits(o, d)
    got = treelet.Tracer(torch.from_numpy(v), torch.from_numpy(idx), device="cpu").closest_hits(torch.from_numpy(o), torch.from_numpy(d))
    assert np.array_equal(want.primitive, got.primitive) and np.array_equal(want.t, got.t)
    # Hits to tensors without a copy.
    assert torch.from_numpy(got.t).data_ptr() == got.t.ctypes.data
