"""Makes large real-shaped meshes for the benchmarks: Loop subdivision
(C. Loop, 1987) of a triangle mesh, written as the binary PLY that Treelet's
loader and the OptiX peer (`../shared/tools/optix-peer/peer.py`) both read.
Needs only numpy, so it runs on the benchmark machine, where a million
triangles are cheaper to make than to carry.

    python3 subdivide.py IN.obj|IN.ply LEVELS OUT.ply

Each level splits every triangle into four. New edge vertices take 3/8 of
the edge's ends and 1/8 of the two opposite vertices (the midpoint on a
boundary edge); old vertices move by Warren's weights (boundary vertices:
3/4 themselves, 1/8 each boundary neighbour). The Stanford bunny (npm
package `bunny`, 3 674 triangles) at 4 levels gives 940 544 triangles.
"""
import sys
import time

import numpy as np


def read_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == 'v':
                verts.append([float(x) for x in parts[1:4]])
            elif parts[0] == 'f':
                idx = []
                for p in parts[1:]:
                    i = int(p.split('/')[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                for k in range(1, len(idx) - 1):  # fan polygons into triangles
                    faces.append([idx[0], idx[k], idx[k + 1]])
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64)


def read_ply(path):
    with open(path, 'rb') as f:
        header = []
        while True:
            line = f.readline().decode('ascii').strip()
            header.append(line)
            if line == 'end_header':
                break
        nv = int(next(l for l in header if l.startswith('element vertex')).split()[2])
        nf = int(next(l for l in header if l.startswith('element face')).split()[2])
        if any('ascii' in l for l in header if l.startswith('format')):
            rows = f.read().decode('ascii').split('\n')
            verts = np.array([[float(x) for x in r.split()[:3]] for r in rows[:nv]])
            faces = []
            for r in rows[nv:nv + nf]:
                idx = [int(x) for x in r.split()[1:]]
                faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
            return verts, np.array(faces, dtype=np.int64)
        # Binary little-endian: float x y z first, then uchar-counted int lists of triangles.
        props = [l.split()[-1] for l in header[header.index(next(l for l in header if l.startswith('element vertex'))) + 1:]
                 if l.startswith('property') and 'list' not in l]
        nprops = len(props[:props.index('z') + 1]) if 'z' in props else 3
        raw = np.frombuffer(f.read(nv * 4 * nprops), dtype='<f4').reshape(nv, nprops)
        verts = raw[:, :3].astype(np.float64)
        faces = np.frombuffer(f.read(nf * 13), dtype=np.uint8).reshape(nf, 13)[:, 1:].copy().view('<i4')
        return verts, faces.reshape(nf, 3).astype(np.int64)


def loop_subdivide(v, f):
    nv = len(v)
    # Unique edges; each triangle's three edges (ab, bc, ca) point into them.
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e_sorted = np.sort(e, axis=1)
    edges, edge_of, edge_count = np.unique(e_sorted, axis=0, return_inverse=True, return_counts=True)
    edge_of = edge_of.reshape(3, len(f)).T  # per face: edge ids of ab, bc, ca
    boundary = edge_count == 1
    # Opposite vertex of each face edge: c for ab, a for bc, b for ca.
    opposite = np.concatenate([f[:, 2], f[:, 0], f[:, 1]])
    opp_sum = np.zeros((len(edges), 3))
    np.add.at(opp_sum, edge_of.T.reshape(-1), v[opposite])
    ends = v[edges[:, 0]] + v[edges[:, 1]]
    edge_pts = np.where(boundary[:, None], 0.5 * ends, 0.375 * ends + 0.125 * opp_sum)
    # Old vertices: neighbours through unique edges.
    deg = np.bincount(edges.reshape(-1), minlength=nv).astype(np.float64)
    nbr_sum = np.zeros((nv, 3))
    np.add.at(nbr_sum, edges[:, 0], v[edges[:, 1]])
    np.add.at(nbr_sum, edges[:, 1], v[edges[:, 0]])
    beta = np.where(deg == 3, 3.0 / 16.0, 3.0 / (8.0 * np.maximum(deg, 1)))
    new_v = (1 - deg * beta)[:, None] * v + beta[:, None] * nbr_sum
    # Boundary vertices: 3/4 self + 1/8 of each boundary neighbour.
    b_edges = edges[boundary]
    if len(b_edges):
        b_sum = np.zeros((nv, 3))
        np.add.at(b_sum, b_edges[:, 0], v[b_edges[:, 1]])
        np.add.at(b_sum, b_edges[:, 1], v[b_edges[:, 0]])
        on_boundary = np.bincount(b_edges.reshape(-1), minlength=nv) > 0
        new_v[on_boundary] = 0.75 * v[on_boundary] + 0.125 * b_sum[on_boundary]
    verts = np.concatenate([new_v, edge_pts])
    a, b, c = f[:, 0], f[:, 1], f[:, 2]
    ab, bc, ca = (edge_of[:, k] + nv for k in range(3))
    faces = np.concatenate([
        np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1), np.stack([ab, bc, ca], 1)])
    return verts, faces


def write_ply(path, v, f):
    with open(path, 'wb') as out:
        out.write((f'ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\n'
                   'property float x\nproperty float y\nproperty float z\n'
                   f'element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n').encode())
        out.write(v.astype('<f4').tobytes())
        rec = np.zeros(len(f), dtype=[('n', 'u1'), ('i', '<i4', 3)])
        rec['n'] = 3
        rec['i'] = f
        out.write(rec.tobytes())


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    src, levels, dst = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    start = time.time()
    v, f = read_ply(src) if src.lower().endswith('.ply') else read_obj(src)
    if len(f) == 0 or f.min() < 0 or f.max() >= len(v):
        sys.exit(f'{src}: no triangles, or a face index out of range')
    for _ in range(levels):
        v, f = loop_subdivide(v, f)
    write_ply(dst, v, f)
    print(f'{dst}: {len(f)} triangles, {len(v)} vertices ({time.time() - start:.1f} s)')


if __name__ == '__main__':
    main()
