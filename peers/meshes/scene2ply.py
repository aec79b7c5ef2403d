#!/usr/bin/env python3
"""Convert architectural scenes to a flat world-space triangle soup as binary little-endian PLY.

Output format (exactly):
    ply / format binary_little_endian 1.0 / element vertex N / property float x/y/z /
    element face M / property list uchar int vertex_indices / end_header / data

Inputs:
    scene2ply.py obj      IN.obj            OUT.ply   [--scale S]
    scene2ply.py mitsuba  scene.xml         OUT.ply   (Mitsuba 0.5/0.6 XML: obj/ply/serialized/rectangle/disk/cube shapes,
                                                      toWorld matrices; emitter-only shapes skipped)
    scene2ply.py gltf     IN.gltf|IN.glb    OUT.ply   (node hierarchy flattened, TRS/matrix applied)
    scene2ply.py stats    IN.ply            (print statistics of an existing PLY)

Polygons are triangulated as fans.  Triangles with non-finite coordinates, repeated
vertex indices, or zero area (either in float64, or zero float32 cross product) are dropped;
unreferenced vertices are removed.  Needs numpy only.
"""
import json, math, os, struct, sys
import numpy as np


# ----------------------------------------------------------------------------- output
def clean(V, F):
    V = np.asarray(V, dtype=np.float32).reshape(-1, 3)
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    n0 = len(F)
    ok = (F >= 0).all(1) & (F < len(V)).all(1)
    F = F[ok]
    fin = np.isfinite(V).all(1)
    ok = fin[F].all(1) & (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])
    F = F[ok]
    a, b, c = (V[F[:, i]] for i in range(3))
    cr64 = np.cross(b.astype(np.float64) - a, c.astype(np.float64) - a)
    cr32 = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(cr64, axis=1)
    ok = (area > 0) & np.isfinite(area) & (cr32 != 0).any(1)
    F = F[ok]
    used = np.zeros(len(V), bool)
    used[F.ravel()] = True
    remap = np.cumsum(used) - 1
    V = V[used]
    F = remap[F].astype(np.int32)
    return V, F, n0 - len(F)


def write_ply(path, V, F):
    V = np.ascontiguousarray(V, dtype='<f4')
    F = np.ascontiguousarray(F, dtype='<i4')
    hdr = ("ply\nformat binary_little_endian 1.0\n"
           f"element vertex {len(V)}\nproperty float x\nproperty float y\nproperty float z\n"
           f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    rec = np.empty(len(F), dtype=np.dtype([('n', 'u1'), ('i', '<i4', (3,))]))
    rec['n'] = 3
    rec['i'] = F
    with open(path, 'wb') as f:
        f.write(hdr)
        f.write(V.tobytes())
        f.write(rec.tobytes())


def read_ply(path):
    with open(path, 'rb') as f:
        data = f.read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    hdr = data[:end].decode().split('\n')
    assert hdr[0] == 'ply' and hdr[1] == 'format binary_little_endian 1.0', hdr[:2]
    nv = int(hdr[2].split()[2]); nf = int(hdr[6].split()[2])
    V = np.frombuffer(data, '<f4', nv * 3, end).reshape(-1, 3)
    rec = np.frombuffer(data, np.dtype([('n', 'u1'), ('i', '<i4', (3,))]), nf, end + nv * 12)
    assert (rec['n'] == 3).all() and end + nv * 12 + nf * 13 == len(data)
    return V, rec['i']


def stats(V, F):
    a, b, c = (V[F[:, i]].astype(np.float64) for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    lo, hi = V.min(0), V.max(0)
    return dict(vertices=int(len(V)), triangles=int(len(F)),
                bbox_min=[float(x) for x in lo], bbox_max=[float(x) for x in hi],
                area_min=float(area.min()), area_median=float(np.median(area)), area_max=float(area.max()),
                area_ratio=float(area.max() / area.min()),
                area_log10_span=float(math.log10(area.max() / area.min())))


def finish(V, F, out):
    V, F, dropped = clean(V, F)
    write_ply(out, V, F)
    V2, F2 = read_ply(out)          # round-trip check
    assert len(V2) == len(V) and len(F2) == len(F)
    s = stats(V2, F2)
    s['dropped_triangles'] = int(dropped)
    s['file'] = out
    s['bytes'] = os.path.getsize(out)
    print(json.dumps(s, indent=1))
    with open(os.path.splitext(out)[0] + '.stats.json', 'w') as f:
        json.dump(s, f, indent=1)
    return s


# ----------------------------------------------------------------------------- OBJ
def load_obj(path):
    """Return V (n,3) float64, F (m,3) int64; polygons fan-triangulated; groups ignored."""
    vs, faces = [], []
    with open(path, 'r', errors='replace') as f:
        for line in f:
            if line.startswith('v '):
                p = line.split()
                vs.append((float(p[1]), float(p[2]), float(p[3])))
            elif line.startswith('f '):
                idx = []
                nv = len(vs)
                for tok in line.split()[1:]:
                    i = int(tok.split('/', 1)[0])
                    idx.append(i - 1 if i > 0 else nv + i)
                for k in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[k], idx[k + 1]))
    V = np.array(vs, dtype=np.float64).reshape(-1, 3)
    F = np.array(faces, dtype=np.int64).reshape(-1, 3)
    return V, F


# ----------------------------------------------------------------------------- Mitsuba XML
def _mts_matrix(tr):
    M = np.eye(4)
    if tr is None:
        return M
    for el in tr:
        tag = el.tag
        if tag == 'matrix':
            T = np.array([float(x) for x in el.get('value').replace(',', ' ').split()]).reshape(4, 4)
        elif tag == 'translate':
            T = np.eye(4); T[:3, 3] = [float(el.get(k, 0)) for k in 'xyz']
        elif tag == 'scale':
            T = np.eye(4)
            if el.get('value') is not None:
                s = float(el.get('value')); T[0, 0] = T[1, 1] = T[2, 2] = s
            else:
                for i, k in enumerate('xyz'):
                    T[i, i] = float(el.get(k, 1))
        elif tag == 'rotate':
            ax = np.array([float(el.get(k, 0)) for k in 'xyz']); ax /= np.linalg.norm(ax)
            th = math.radians(float(el.get('angle')))
            K = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
            T = np.eye(4); T[:3, :3] = np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K
        else:
            raise ValueError('unsupported transform element ' + tag)
        M = T @ M                      # later elements apply after earlier ones
    return M


def _xform(V, M):
    return V @ M[:3, :3].T + M[:3, 3]


def _resolve(base, fn):
    """Path join that falls back to a case-insensitive match (scenes authored on Windows)."""
    p = os.path.join(base, fn)
    if os.path.exists(p):
        return p
    cur = base
    for part in fn.replace('\\', '/').split('/'):
        cands = [c for c in os.listdir(cur) if c.lower() == part.lower()]
        if not cands:
            raise FileNotFoundError(p)
        cur = os.path.join(cur, cands[0])
    return cur


def load_mitsuba(xml_path):
    import xml.etree.ElementTree as ET
    root = ET.parse(xml_path).getroot()
    base = os.path.dirname(xml_path)
    Vs, Fs, off = [], [], 0
    skipped = {}
    for sh in root.iter('shape'):
        typ = sh.get('type')
        if sh.find('emitter') is not None and typ in ('rectangle', 'disk', 'sphere'):
            skipped[typ + '(emitter)'] = skipped.get(typ + '(emitter)', 0) + 1
            continue
        tr = sh.find("transform[@name='toWorld']")
        if tr is None:
            tr = sh.find("transform[@name='to_world']")
        M = _mts_matrix(tr)
        if typ == 'obj':
            fn = sh.find("string[@name='filename']").get('value')
            V, F = load_obj(_resolve(base, fn))
        elif typ == 'ply':
            fn = sh.find("string[@name='filename']").get('value')
            V, F = read_ply_any(_resolve(base, fn))
        elif typ == 'serialized':
            fn = sh.find("string[@name='filename']").get('value')
            si = sh.find("integer[@name='shapeIndex']")
            V, F = read_serialized(_resolve(base, fn), int(si.get('value')) if si is not None else 0)
        elif typ == 'rectangle':
            V = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
            F = np.array([[0, 1, 2], [0, 2, 3]])
        elif typ == 'disk':
            n = 64
            t = np.linspace(0, 2 * np.pi, n, endpoint=False)
            V = np.vstack([[0, 0, 0], np.stack([np.cos(t), np.sin(t), np.zeros(n)], 1)])
            F = np.array([[0, 1 + i, 1 + (i + 1) % n] for i in range(n)])
        elif typ == 'cube':
            V = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
            F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                          [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        else:
            skipped[typ] = skipped.get(typ, 0) + 1
            continue
        Vs.append(_xform(V, M)); Fs.append(F + off); off += len(V)
    print('mitsuba: shapes used', len(Vs), 'skipped', skipped, file=sys.stderr)
    return np.vstack(Vs), np.vstack(Fs)


def read_serialized(path, index=0):
    """Mitsuba 0.x '.serialized' mesh (format 0x041C, version 3/4): zlib-compressed
    flags, [name], uint64 nverts, uint64 ntris, positions, [normals], [uvs], [colors], indices."""
    import zlib
    data = open(path, 'rb').read()
    fmt, ver = struct.unpack_from('<HH', data, 0)
    assert fmt == 0x041C, hex(fmt)
    count = struct.unpack_from('<I', data, len(data) - 4)[0]
    if ver >= 4:
        offs = struct.unpack_from('<%dQ' % count, data, len(data) - 4 - 8 * count)
    else:
        offs = struct.unpack_from('<%dI' % count, data, len(data) - 4 - 4 * count)
    o = offs[index]
    fmt, ver = struct.unpack_from('<HH', data, o)
    raw = zlib.decompressobj().decompress(data[o + 4:])
    flags = struct.unpack_from('<I', raw, 0)[0]
    p = 4
    if ver >= 4:
        p = raw.index(b'\0', p) + 1
    nv, nt = struct.unpack_from('<QQ', raw, p); p += 16
    fdt = np.dtype('<f8') if flags & 0x2000 else np.dtype('<f4')
    V = np.frombuffer(raw, fdt, nv * 3, p).reshape(-1, 3).astype(np.float64); p += nv * 3 * fdt.itemsize
    if flags & 0x0001: p += nv * 3 * fdt.itemsize   # normals
    if flags & 0x0002: p += nv * 2 * fdt.itemsize   # uvs
    if flags & 0x0008: p += nv * 3 * fdt.itemsize   # colors
    idt = np.dtype('<u8') if nv > 0xFFFFFFFF else np.dtype('<u4')
    F = np.frombuffer(raw, idt, nt * 3, p).reshape(-1, 3).astype(np.int64)
    assert p + nt * 3 * idt.itemsize == len(raw), (p, nt, len(raw))
    return V, F


def read_ply_any(path):
    """Minimal PLY reader (ascii or binary_little_endian) for vertex xyz + face lists."""
    with open(path, 'rb') as f:
        data = f.read()
    end = data.index(b'end_header') + len(b'end_header')
    end = data.index(b'\n', end) + 1
    lines = data[:end].decode('ascii', 'replace').split('\n')
    fmt = lines[1].split()[1]
    elems = []
    for ln in lines:
        p = ln.split()
        if not p:
            continue
        if p[0] == 'element':
            elems.append([p[1], int(p[2]), []])
        elif p[0] == 'property':
            elems[-1][2].append(p[1:])
    tmap = dict(char='i1', int8='i1', uchar='u1', uint8='u1', short='<i2', int16='<i2', ushort='<u2',
                uint16='<u2', int='<i4', int32='<i4', uint='<u4', uint32='<u4', float='<f4',
                float32='<f4', double='<f8', float64='<f8')
    V = F = None
    if fmt == 'ascii':
        toks = data[end:].split()
        pos = 0
        for name, n, props in elems:
            if name == 'vertex':
                k = len(props)
                arr = np.array(toks[pos:pos + n * k], float).reshape(n, k); pos += n * k
                names = [p[-1] for p in props]
                V = arr[:, [names.index('x'), names.index('y'), names.index('z')]]
            elif name == 'face':
                faces = []
                for _ in range(n):
                    c = int(toks[pos]); idx = [int(t) for t in toks[pos + 1:pos + 1 + c]]; pos += 1 + c
                    faces += [(idx[0], idx[j], idx[j + 1]) for j in range(1, c - 1)]
                F = np.array(faces, np.int64).reshape(-1, 3)
            else:
                pos += n * len(props)
        return V, F
    assert fmt == 'binary_little_endian', fmt
    pos = end
    for name, n, props in elems:
        if all(p[0] != 'list' for p in props):
            dt = np.dtype([(p[-1], tmap[p[0]]) for p in props])
            arr = np.frombuffer(data, dt, n, pos); pos += n * dt.itemsize
            if name == 'vertex':
                V = np.stack([arr['x'], arr['y'], arr['z']], 1).astype(np.float64)
        else:
            # assume a single list property (+ optional scalars before it); try fixed-size fast path
            lp = [p for p in props if p[0] == 'list'][0]
            ct, it = np.dtype(tmap[lp[1]]), np.dtype(tmap[lp[2]])
            if len(props) == 1:
                c0 = np.frombuffer(data, ct, 1, pos)[0]
                dt = np.dtype([('c', ct), ('i', it, (int(c0),))])
                arr = np.frombuffer(data, dt, n, pos)
                if (arr['c'] == c0).all():
                    pos += n * dt.itemsize
                    idx = arr['i'].astype(np.int64)
                    if name == 'face':
                        F = np.vstack([idx[:, [0, j, j + 1]] for j in range(1, int(c0) - 1)])
                    continue
            faces = []
            for _ in range(n):
                for p in props:
                    if p[0] == 'list':
                        c = int(np.frombuffer(data, ct, 1, pos)[0]); pos += ct.itemsize
                        idx = np.frombuffer(data, it, c, pos).astype(np.int64); pos += c * it.itemsize
                        if name == 'face':
                            faces += [(idx[0], idx[j], idx[j + 1]) for j in range(1, c - 1)]
                    else:
                        pos += np.dtype(tmap[p[0]]).itemsize
            if name == 'face':
                F = np.array(faces, np.int64).reshape(-1, 3)
    return V, F


# ----------------------------------------------------------------------------- glTF
_CT = {5120: 'i1', 5121: 'u1', 5122: '<i2', 5123: '<u2', 5125: '<u4', 5126: '<f4'}
_NC = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4, 'MAT4': 16}


def _q2m(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def load_gltf(path):
    base = os.path.dirname(path)
    raw = open(path, 'rb').read()
    glb_bin = None
    if raw[:4] == b'glTF':
        ln = struct.unpack_from('<I', raw, 12)[0]
        js = json.loads(raw[20:20 + ln])
        p = 20 + ln
        if p < len(raw):
            bl = struct.unpack_from('<I', raw, p)[0]
            glb_bin = raw[p + 8:p + 8 + bl]
    else:
        js = json.loads(raw)
    ext = set(js.get('extensionsRequired', []))
    if ext - {'KHR_materials_pbrSpecularGlossiness', 'KHR_texture_transform', 'KHR_mesh_quantization'}:
        raise SystemExit('unsupported required extensions: %s' % ext)
    bufs = []
    for b in js['buffers']:
        if 'uri' not in b:
            bufs.append(glb_bin)
        elif b['uri'].startswith('data:'):
            import base64
            bufs.append(base64.b64decode(b['uri'].split(',', 1)[1]))
        else:
            from urllib.parse import unquote
            bufs.append(open(os.path.join(base, unquote(b['uri'])), 'rb').read())

    def accessor(i):
        a = js['accessors'][i]
        nc = _NC[a['type']]; dt = np.dtype(_CT[a['componentType']]); n = a['count']
        if 'bufferView' in a:
            bv = js['bufferViews'][a['bufferView']]
            buf = bufs[bv['buffer']]
            off = bv.get('byteOffset', 0) + a.get('byteOffset', 0)
            stride = bv.get('byteStride', 0) or nc * dt.itemsize
            arr = np.lib.stride_tricks.as_strided(
                np.frombuffer(buf, np.uint8, len(buf) - off, off), (n, nc * dt.itemsize), (stride, 1))
            out = np.ascontiguousarray(arr).view(dt).reshape(n, nc).astype(np.float64)
        else:
            out = np.zeros((n, nc))
        if a.get('normalized'):
            out = {'i1': lambda x: np.maximum(x / 127, -1), 'u1': lambda x: x / 255,
                   '<i2': lambda x: np.maximum(x / 32767, -1), '<u2': lambda x: x / 65535}[_CT[a['componentType']]](out)
        if 'sparse' in a:
            raise SystemExit('sparse accessors not supported')
        return out

    def local(node):
        if 'matrix' in node:
            return np.array(node['matrix'], float).reshape(4, 4).T   # column-major
        M = np.eye(4)
        S = np.diag(node.get('scale', [1, 1, 1]))
        R = _q2m(node.get('rotation', [0, 0, 0, 1]))
        M[:3, :3] = R @ S
        M[:3, 3] = node.get('translation', [0, 0, 0])
        return M

    Vs, Fs, off = [], [], 0
    cache = {}
    scene = js['scenes'][js.get('scene', 0)] if 'scenes' in js else {'nodes': list(range(len(js['nodes'])))}
    stack = [(n, np.eye(4)) for n in scene['nodes']]
    while stack:
        ni, P = stack.pop()
        node = js['nodes'][ni]
        M = P @ local(node)
        if 'mesh' in node:
            for prim in js['meshes'][node['mesh']]['primitives']:
                mode = prim.get('mode', 4)
                if mode not in (4, 5, 6):
                    continue
                if 'extensions' in prim and 'KHR_draco_mesh_compression' in prim['extensions']:
                    raise SystemExit('draco primitives not supported')
                key = (prim['attributes']['POSITION'], prim.get('indices'), mode)
                if key not in cache:
                    P3 = accessor(prim['attributes']['POSITION'])
                    I = (accessor(prim['indices'])[:, 0].astype(np.int64) if 'indices' in prim
                         else np.arange(len(P3)))
                    if mode == 4:
                        T = I[:len(I) // 3 * 3].reshape(-1, 3)
                    elif mode == 5:
                        T = np.array([(I[k], I[k + 1], I[k + 2]) if k % 2 == 0 else (I[k + 1], I[k], I[k + 2])
                                      for k in range(len(I) - 2)]).reshape(-1, 3)
                    else:
                        T = np.array([(I[0], I[k], I[k + 1]) for k in range(1, len(I) - 1)]).reshape(-1, 3)
                    cache[key] = (P3, T)
                P3, T = cache[key]
                Vs.append(_xform(P3, M)); Fs.append(T + off); off += len(P3)
        for c in node.get('children', []):
            stack.append((c, M))
    return np.vstack(Vs), np.vstack(Fs)


# ----------------------------------------------------------------------------- main
def main():
    if len(sys.argv) < 3:
        print(__doc__); sys.exit(1)
    kind = sys.argv[1]
    if kind == 'stats':
        V, F = read_ply(sys.argv[2]); print(json.dumps(stats(V, F), indent=1)); return
    src, out = sys.argv[2], sys.argv[3]
    scale = 1.0
    if '--scale' in sys.argv:
        scale = float(sys.argv[sys.argv.index('--scale') + 1])
    if kind == 'obj':
        V, F = load_obj(src)
    elif kind == 'mitsuba':
        V, F = load_mitsuba(src)
    elif kind == 'gltf':
        V, F = load_gltf(src)
    elif kind == 'ply':
        V, F = read_ply_any(src)
    else:
        raise SystemExit('unknown kind ' + kind)
    finish(V * scale, F, out)


if __name__ == '__main__':
    main()
