#!/usr/bin/env python3
"""Writes the fuzz targets' seed corpora (seeds/<target>/): the test corpus's files, and
structure-aware variants of them that libFuzzer's byte mutations would take long to find:
glTF JSON with one field replaced by a hostile value (every field, several values), GLB files
whose chunk headers lie, PLY headers with other types, orders and counts. Parts and HDR images
are rendered by the `treelet` binary given as the first argument.
They are committed packed (`seeds.tar.xz`, about 1 000 files that differ in a field each);
`.ci/run` unpacks them. To remake it after a change here, from the repository root:
    python3 tests/fuzz/seeds.py target/release/treelet && tar cJf tests/fuzz/seeds.tar.xz -C tests/fuzz seeds"""
import base64, copy, hashlib, json, os, struct, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "corpus")
OUT = os.path.join(HERE, "seeds")


def put(target, data):
    if isinstance(data, str):
        data = data.encode()
    d = os.path.join(OUT, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, hashlib.sha1(data).hexdigest()[:16]), "wb") as f:
        f.write(data)


def read(name):
    with open(os.path.join(CORPUS, name), "rb") as f:
        return f.read()


# Values a hostile file puts where a number, string, list or object belongs.
HOSTILE = [0, -1, 1, 3, 65535, 4294967295, 18446744073709551615, 1e30, -1e30, 0.5, "", "x", None, True, [], {}, [1e30, 1e30, 1e30]]


def leaves(value, path=()):
    """Every place in a JSON value (objects' keys and lists' items), depth first."""
    yield path
    if isinstance(value, dict):
        for k, v in value.items():
            yield from leaves(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from leaves(v, path + (i,))


def replaced(doc, path, value):
    doc = copy.deepcopy(doc)
    if not path:
        return value
    at = doc
    for p in path[:-1]:
        at = at[p]
    at[path[-1]] = value
    return doc


def without(doc, path):
    doc = copy.deepcopy(doc)
    at = doc
    for p in path[:-1]:
        at = at[p]
    del at[path[-1]]
    return doc


def glb(json_bytes, bin_bytes, version=2, json_type=0x4E4F534A, bin_type=0x004E4942, lie=0):
    j = json_bytes + b" " * (-len(json_bytes) % 4)
    chunks = struct.pack("<II", len(j), json_type) + j
    if bin_bytes is not None:
        b = bin_bytes + b"\0" * (-len(bin_bytes) % 4)
        chunks += struct.pack("<II", (len(b) + lie) & 0xFFFFFFFF, bin_type) + b
    return struct.pack("<III", 0x46546C67, version, 12 + len(chunks)) + chunks


def gltf_seeds():
    text = read("square.gltf")
    put("gltf", text)
    doc = json.loads(text)
    paths = list(leaves(doc))
    for path in paths:
        for v in HOSTILE:
            put("gltf", json.dumps(replaced(doc, path, v)))
        if path:
            put("gltf", json.dumps(without(doc, path)))
    # The buffer as a file beside it, and URIs that reach elsewhere.
    for uri in ["buffer.bin", "../buffer.bin", "/dev/zero", "/", "data:,", "data:application/octet-stream;base64,!!",
                "%2e%2e/x", "file:///etc/passwd", "a" * 300]:
        put("gltf", json.dumps(replaced(doc, ("buffers", 0, "uri"), uri)))
    # Sparse accessors, strides, other primitive modes and index types.
    for extra in [("accessors", 0, "sparse"), ("bufferViews", 0, "byteStride"), ("meshes", 0, "primitives", 0, "mode"),
                  ("accessors", 1, "componentType"), ("nodes", 0, "matrix"), ("nodes", 0, "children"),
                  ("extensionsRequired",), ("nodes", 0, "scale"), ("nodes", 0, "rotation")]:
        for v in [{"count": 1, "indices": {"bufferView": 0, "componentType": 5125}, "values": {"bufferView": 0}},
                  4, 12, 0, 1, 2, 4, 5, 6, 5121, 5123, 5126, [0], [1, 0], ["KHR_nope"],
                  [0] * 16, [1e30] * 16, [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1], [0, 0, 0, 2], [-1, 1, 1]]:
            try:
                put("gltf", json.dumps(replaced(doc, extra, v)))
            except (KeyError, IndexError, TypeError):
                pass
    return doc


def glb_seeds(doc):
    put("glb", read("square.glb"))
    uri = doc["buffers"][0]["uri"]
    binary = base64.b64decode(uri.split(",", 1)[1])
    plain = copy.deepcopy(doc)
    del plain["buffers"][0]["uri"]
    j = json.dumps(plain).encode()
    put("glb", glb(j, binary))
    put("glb", glb(j, None))
    put("glb", glb(j, binary, version=1))
    put("glb", glb(j, binary, json_type=0x004E4942, bin_type=0x4E4F534A))
    for lie in [-4, 4, 1 << 20, -(len(binary) + 8)]:
        put("glb", glb(j, binary, lie=lie))
    whole = glb(j, binary)
    for at in [8, 12, 16, 20 + len(j)]:
        for v in [0, 1, 0xFFFFFFFF, 0x7FFFFFFF]:
            put("glb", whole[:at] + struct.pack("<I", v) + whole[at + 4:])
    put("glb", whole + struct.pack("<II", 8, 0x004E4942) + b"\0" * 8)
    for path in list(leaves(plain))[::3]:
        for v in [0, -1, 4294967295]:
            put("glb", glb(json.dumps(replaced(plain, path, v)).encode(), binary))


def mesh_seeds():
    for name in ["quad.obj"]:
        put("obj", read(name))
    put("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nf -1 -2 -3\n")
    put("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf 1//1 2//1 3//1\ng a\no b\nusemtl m\nmtllib m.mtl\n")
    put("obj", "v 0 0 0\r\nv 1e39 0 0\r\nv nan 1 0\r\nf 1 2 3\r\nf 0 1 2\r\nf 1 2\r\n")
    for name in ["tetra_ascii.ply", "tetra_binary.ply"]:
        put("ply", read(name))
    verts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    faces = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
    for endian, fmt in [("binary_big_endian", ">"), ("binary_little_endian", "<")]:
        for vt, vf in [("float", "f"), ("double", "d")]:
            for it, ifm in [("int", "i"), ("uint", "I"), ("ushort", "H"), ("uchar", "B")]:
                head = (f"ply\nformat {endian} 1.0\ncomment seed\nelement vertex 4\nproperty {vt} x\nproperty {vt} y\n"
                        f"property {vt} z\nelement face 4\nproperty list uchar {it} vertex_indices\nend_header\n").encode()
                body = b"".join(struct.pack(fmt + vf * 3, *v) for v in verts)
                body += b"".join(struct.pack(fmt + "B" + ifm * 3, 3, *f) for f in faces)
                put("ply", head + body)
    put("ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
               "property uchar red\nelement face 2\nproperty list uchar int vertex_indices\nelement edge 1\n"
               "property int a\nend_header\n0 0 0 1\n1 0 0 2\n0 1 0 3\n1 1 0 4\n4 0 1 3 2\n3 0 1 9\n5\n")


def scene_seeds():
    put("scene_file", read("scene.json"))
    doc = json.loads(read("scene.json"))
    for path in list(leaves(doc)):
        for v in [0, -1, 1e30, None, "", [], {}]:
            put("scene_file", json.dumps(replaced(doc, path, v)))
    scenes = os.path.join(HERE, "..", "..", "scenes")
    for name in sorted(os.listdir(scenes)):
        if name.endswith(".json"):
            with open(os.path.join(scenes, name), "rb") as f:
                put("scene_file", f.read())


def rendered_seeds(treelet):
    with tempfile.TemporaryDirectory() as d:
        common = ["--device", "cpu", "--width", "4", "--height", "3"]
        subprocess.run([treelet, "render", *common, "--samples", "0..2", "--out", f"{d}/part.exr"], check=True,
                       stdout=subprocess.DEVNULL)
        for ext in ["exr", "pfm"]:
            subprocess.run([treelet, "render", *common, "--spp", "2", "--out", f"{d}/image.{ext}"], check=True,
                           stdout=subprocess.DEVNULL)
        with open(f"{d}/part.exr", "rb") as f:
            put("part", f.read())
        for kind, ext in [(0, "exr"), (1, "pfm")]:
            with open(f"{d}/image.{ext}", "rb") as f:
                put("hdr_image", bytes([kind]) + f.read())


if __name__ == "__main__":
    gltf_doc = gltf_seeds()
    glb_seeds(gltf_doc)
    mesh_seeds()
    scene_seeds()
    rendered_seeds(sys.argv[1] if len(sys.argv) > 1 else "target/release/treelet")
    for t in sorted(os.listdir(OUT)):
        files = os.listdir(os.path.join(OUT, t))
        print(f"{t}: {len(files)} seeds, {sum(os.path.getsize(os.path.join(OUT, t, f)) for f in files)} bytes")
