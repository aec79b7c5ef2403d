"""What the Mitsuba peers share: reading Treelet's binary PLY meshes, and the GPU time of a launch."""
import numpy as np

def ply_arrays(path):
    """Vertices (n x 3 float32) and triangles (m x 3 int32) of a binary little-endian PLY of float x y z
    vertices and uchar-counted int triangle lists, as Treelet's loader and `treelet export` have them;
    xz-compressed (`.ply.xz`, as `scenes/real/` keeps them) or not."""
    import lzma
    with (lzma.open(path, 'rb') if path.lower().endswith('.xz') else open(path, 'rb')) as f:
        hdr = []
        while True:
            line = f.readline().decode().strip(); hdr.append(line)
            if line == 'end_header': break
        nv = int([l for l in hdr if l.startswith('element vertex')][0].split()[2])
        nf = int([l for l in hdr if l.startswith('element face')][0].split()[2])
        v = np.frombuffer(f.read(nv * 12), dtype='<f4').reshape(nv, 3)
        raw = np.frombuffer(f.read(nf * 13), dtype=np.uint8).reshape(nf, 13)
        idx = raw[:, 1:].copy().view('<i4').reshape(nf, 3)
    return v, idx

def kernel_ms(fn):
    """GPU ms of the JIT kernels `fn` launches, from Dr.Jit's kernel history (enable `KernelHistory` first)."""
    import drjit as dr
    dr.kernel_history_clear() if hasattr(dr, 'kernel_history_clear') else dr.kernel_history()
    fn()
    dr.sync_thread()
    return sum(k.get('execution_time', 0.0) for k in dr.kernel_history() if k.get('type') == dr.KernelType.JIT)
