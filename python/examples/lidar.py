"""A spinning LiDAR over a mesh: 64 lasers from -25 to +15 degrees of elevation, 1 024 azimuth
steps a turn, ten turns while the sensor drives along a street of boxes; every return is written
to a point cloud (ASCII PLY: x y z and the laser's ring), and the rates printed.

    python python/examples/lidar.py [--device auto|gpu|cpu] [--out lidar.ply]

The street is made here (a ground quad and 200 boxes of random size), so the example needs
nothing but NumPy and the treelet package."""
import argparse
import time

import numpy as np

import treelet


def box(lo, hi):
    """A box's 12 triangles: its 8 corners and their indices."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])], dtype=np.float32)
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return corners, np.array(faces)


def street(rng, boxes=200, length=200.0):
    vertices = [np.array([[-20, -length, 0], [20, -length, 0], [20, length, 0], [-20, length, 0]], dtype=np.float32)]
    indices = [np.array([[0, 1, 2], [0, 2, 3]])]
    count = 4
    for _ in range(boxes):
        side = rng.choice([-1.0, 1.0])
        x = side * rng.uniform(6.0, 18.0)
        y = rng.uniform(-length, length)
        size = rng.uniform([1.0, 1.0, 1.0], [5.0, 8.0, 15.0])
        v, f = box([x - size[0] / 2, y - size[1] / 2, 0.0], [x + size[0] / 2, y + size[1] / 2, size[2]])
        vertices.append(v)
        indices.append(f + count)
        count += len(v)
    return np.concatenate(vertices), np.concatenate(indices)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", default="auto")
    parser.add_argument("--out", default="lidar.ply")
    parser.add_argument("--turns", type=int, default=10)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    vertices, indices = street(rng)
    tracer = treelet.Tracer(vertices, indices, device=args.device, quality="balanced")
    print(f"{len(tracer)} triangles on {tracer.device}")

    rings = np.radians(np.linspace(-25.0, 15.0, 64))
    azimuths = np.radians(np.arange(1024) * 360.0 / 1024)
    el, az = np.meshgrid(rings, azimuths, indexing="ij")
    directions = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1).reshape(-1, 3)
    ring = np.repeat(np.arange(64), 1024)
    points, rays, traced = [], 0, 0.0
    for turn in range(args.turns):
        origin = np.array([0.0, -150.0 + 30.0 * turn, 1.8], dtype=np.float32)
        origins = np.broadcast_to(origin, directions.shape)
        start = time.perf_counter()
        hits = tracer.closest_hits(origins, directions, t_max=120.0)
        traced += time.perf_counter() - start
        rays += len(hits)
        at = origins[hits.hit] + hits.t[hits.hit, None] * directions[hits.hit]
        points.append(np.column_stack([at, ring[hits.hit]]))
    cloud = np.concatenate(points)
    with open(args.out, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(cloud)}\nproperty float x\nproperty float y\nproperty float z\n"
                "property uchar ring\nend_header\n")
        np.savetxt(f, cloud, fmt=["%.4f", "%.4f", "%.4f", "%d"])
    print(f"{rays} rays, {len(cloud)} returns ({len(cloud) / rays:.0%}), {rays / traced / 1e6:.2f} M rays/s "
          f"(arrays in and out included); wrote {args.out}")
    # A return lies on the ground or on a box: never below the ground, never above the tallest box.
    assert len(cloud) > rays // 4 and cloud[:, 2].min() > -1e-3 and cloud[:, 2].max() < 15.0 + 1e-3


if __name__ == "__main__":
    main()
