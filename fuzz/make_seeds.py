#!/usr/bin/env python3
"""Writes the hand-made seed corpus of every fuzz target into fuzz/corpus/<target>/seed-*.

Run from anywhere: `python3 fuzz/make_seeds.py`. Seeds are named by what they exercise; the
byte layouts are documented in tests/src/fuzz_props/*.rs. Minimised inputs that found bugs
(crash-*) or limitations (regress-*) are left alone.
"""
import base64
import json
import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")


def write(target, name, data):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "seed-" + name), "wb") as f:
        f.write(bytes(data))


def i8(v):
    return struct.pack("<b", v)


def f32(v):
    return struct.pack("<f", v)


def u16(v):
    return struct.pack("<H", v)


def u32(v):
    return struct.pack("<I", v)


def pow2_byte(e):
    """The byte whose `as i8` is e (a scale 2^e)."""
    return e & 0xFF


# ---------------------------------------------------------------- cache_query_matches_exhaustive
EPS = {0.0: 0, 1e-4: 2, 1e-3: 3, 0.01: 4, 0.05: 5, 0.5: 6, 10.0: 7}
TOL = {0.0: 0, 1e-6: 1, 1e-4: 2, 1e-3: 3, 1e-2: 4, 0.1: 5, 0.5: 6, 1.0: 7}


def cache_header(kd=(128, 128, 128), ell_exp=20, ell=(0, 0, 0), eta=51, eps=0.0, tol=0.0,
                 k=48, pos=-3, area=-6, irr=0, queries=((0, (255, 255, 255), u16(0)),)):
    out = bytearray(kd) + bytes([ell_exp]) + bytearray(ell) + bytes([eta, EPS[eps], TOL[tol], k])
    out += bytes([pow2_byte(pos), pow2_byte(area), pow2_byte(irr), len(queries) - 1])
    for mode, e, rest in queries:
        out += bytes([mode]) + bytearray(e) + rest
    return out


def sample(pos_mode=0, coords=(0, 0, 0), area_mode=2, area=b"", irr_mode=2, irr=(128,), repeat=None):
    m = pos_mode | (area_mode << 2) | (irr_mode << 4) | ((1 << 6) if repeat is not None else 0)
    out = bytearray([m])
    if pos_mode == 0 or pos_mode == 2:
        out += b"".join(i8(c) for c in coords) if pos_mode == 0 else i8(coords[0])
    elif pos_mode == 3:
        out += b"".join(f32(c) for c in coords)
    if area_mode == 1:
        out += bytes([area])
    elif area_mode == 3:
        out += f32(area)
    if irr_mode == 1:
        out += bytearray(irr)
    elif irr_mode == 2:
        out += bytes([irr[0]])
    elif irr_mode == 3:
        out += b"".join(f32(c) for c in irr)
    if repeat is not None:
        out += bytes([repeat])
    return out


def cache_seeds():
    t = "cache_query_matches_exhaustive"
    # A uniformly lit 16 × 16 plane, ℓ_u = 1, queried at a sample and between samples.
    plane = cache_header(queries=((0, (255, 255, 255), u16(37)), (1, (128, 128, 128), u16(100) + i8(16) + i8(16) + i8(0))))
    for i in range(16):
        for j in range(16):
            plane += sample(0, (i - 8, j - 8, 0))
    write(t, "plane-exact", plane)
    # The same plane half in shadow, with the default ε and cull tolerance.
    shadow = cache_header(eps=0.05, tol=1e-4, queries=((2, (200, 200, 200), i8(0) + i8(0) + i8(0)),))
    for i in range(16):
        for j in range(16):
            shadow += sample(0, (i - 8, j - 8, 0), irr_mode=2 if j < 8 else 0)
    write(t, "plane-shadow-default-settings", shadow)
    # A sphere of 400 samples, coloured irradiance, large tolerance and ε, short ℓ_u.
    sphere = cache_header(kd=(230, 128, 30), ell_exp=17, ell=(0, 80, 255), eps=0.5, tol=0.1, pos=-2,
                          queries=((0, (255, 0, 0), u16(5)), (2, (0, 255, 0), i8(0) + i8(0) + i8(127))))
    for k in range(400):
        z = 1 - 2 * (k + 0.5) / 400
        r = math.sqrt(1 - z * z)
        phi = k * 2.399963
        c = (round(100 * r * math.cos(phi)), round(100 * r * math.sin(phi)), round(100 * z))
        sphere += sample(0, c, area_mode=1, area=200, irr_mode=1, irr=(k % 256, 255 - k % 256, 90))
    write(t, "sphere-coloured-culled", sphere)
    # 300 coincident samples (count splits), then a few distinct ones.
    co = cache_header(eps=0.01, tol=1e-3)
    co += sample(0, (3, 3, 3), repeat=255) + sample(1, repeat=43)
    for i in range(10):
        co += sample(0, (i, -i, 2 * i))
    write(t, "coincident-run", co)
    # Collinear samples along a line through samples 0 and 1.
    line = cache_header(queries=((1, (255, 255, 255), u16(0) + i8(0) + i8(64) + i8(0)),))
    line += sample(0, (-10, -5, 0)) + sample(0, (10, 5, 1))
    for t_ in range(-100, 100, 3):
        line += sample(2, (t_,))
    write(t, "collinear", line)
    # Huge and tiny scenes; zero areas mixed in.
    for name, pos, area in (("huge-coordinates", 100, 120), ("tiny-coordinates", -100, -126)):
        s = cache_header(pos=pos, area=area, eps=0.05, tol=1e-4)
        for i in range(40):
            s += sample(0, (i * 3 - 60, (i * 7) % 50, -i), area_mode=2 if i % 3 else 0)
        write(t, name, s)
    # Areas near the f32 limit, mostly unlit, a huge smoothing radius: N10's area-weighted
    # sums overflow f32 (results need only be non-negative and NaN-free there).
    big = cache_header(k=255, area=126, irr=-100, queries=((0, (255, 255, 255), u16(3)),))
    for i in range(3):
        big += sample(0, (i - 1, i, 0), irr_mode=2 if i == 0 else 0)
    write(t, "huge-areas-unlit", big)
    # One sample; an empty set; an invalid (NaN) position; a non-finite shading point.
    write(t, "one-sample", cache_header() + sample(0, (1, 2, 3)))
    write(t, "empty", cache_header())
    write(t, "nan-position", cache_header() + sample(0, (0, 0, 0)) + sample(3, (float("nan"), 0.0, 0.0)))
    write(t, "infinite-query", cache_header(queries=((3, (1, 1, 1), f32(float("inf")) + f32(0) + f32(0)),)) + sample(0, (1, 1, 1)))


# ----------------------------------------------------------------------------- table_lookup_finite
def table_seeds():
    t = "table_lookup_finite"

    def header(flags=0, kd=(32768, 32768, 32768), eta=51, alpha=0, alpha_frac=0, ell_min=b""):
        out = bytearray([flags]) + b"".join(u16(k) for k in kd) + bytes([eta])
        out += i8(alpha) + bytes([alpha_frac]) + ell_min
        return out

    sweep = bytearray()
    for e in range(-128, 128, 4):
        sweep += bytes([1]) + i8(e) + bytes([e & 0xFF])  # α·2^(e/8)·(1 + …)
    write(t, "sweep-around-alpha", header() + sweep)
    nodes = bytearray()
    for e in range(-30, 31):
        nodes += bytes([2]) + i8(e)  # exactly α·2^e: a node
    write(t, "powers-of-two", header(kd=(300, 30000, 65000), eta=255, alpha=8) + nodes)
    thr = bytearray()
    for v in (-128, -1, 0, 1, 127):
        thr += bytes([3]) + i8(v)
    write(t, "around-ell-min-prefilled", header(flags=(1 << 3) | 0x20, alpha=-12, ell_min=i8(-40)) + bytes([2]) + i8(-12) + bytes([2]) + i8(4) + thr + sweep[:60])
    raw = bytearray()
    for v in (float("nan"), float("inf"), -1.0, 0.0, 1e-45, 1e-38, 3.0e38, 1e-3):
        raw += bytes([0]) + f32(v)
    write(t, "raw-lookups", header() + raw)
    write(t, "nan-alpha", bytearray([4]) + b"".join(u16(32768) for _ in range(3)) + bytes([51]) + f32(float("nan")))
    write(t, "subnormal-ell-min", header(flags=3 << 3, ell_min=bytes([7])) + raw)
    write(t, "extreme-albedo", header(kd=(0, 65535, 1), eta=0) + sweep)


# ------------------------------------------------------------------------ scene_parse_never_panics
def scene_seeds():
    t = "scene_parse_never_panics"
    for name in ("default", "sphere-shadow", "textured-mfp", "rect-light", "environment",
                 "obj-materials", "burley-marble"):
        with open(os.path.join(ROOT, "scenes", name + ".toml"), "rb") as f:
            write(t, name + ".toml", f.read())
    every = b"""
[camera]
position = [0.0, -7.0, 1.3]
target = [0.0, 0.0, 0.9]
up = [0.0, 0.0, 1.0]
fov = 30.0
width = 64
height = 48

[[object]]
shape = "sphere"
radius = 1.0
segments = 16
translate = [0.0, 0.0, 1.0]
material = "marble"

[[object]]
obj = "mesh.obj"
rotate = [90.0, 0.0, 30.0]
scale = 0.5
material = "jelly"

[[object]]
shape = "disk"
radius = 2.0
material = "skin"

[[object]]
shape = "sphere"
radius = 0.5
segments = 12
translate = [2.0, 0.0, 0.5]
material = "wax"

[[object]]
shape = "box"
size = [3.0, 7.6, 0.05]
translate = [-1.5, 0.2, 2.6]
material = "grey"

[material.marble]
type = "translucent"
preset = "marble"
mm_per_unit = 10.0
specular = { exponent = 60.0, strength = 0.4 }

[material.jelly]
type = "translucent"
sigma_a = [0.02, 0.05, 0.3]
sigma_s_prime = [10.0, 12.0, 14.0]
eta = 1.33
profile = "better-dipole"

[material.skin]
type = "translucent"
kd = { texture = "textures/mfp-ramp.png" }
diffuse_mean_free_path = 0.5
eta = 1.4
profile = "burley-diffuse"

[material.wax]
type = "translucent"
profile = "burley"
kd = [0.8, 0.6, 0.4]
radius = { texture = "textures/mfp-ramp.png", min = 0.1, max = 2.0 }
radius_scale = 0.5
eta = 1.4

[material.grey]
type = "lambert"
albedo = 0.2

[[light]]
type = "point"
position = [0.0, -3.0, 5.0]
intensity = 25.0

[[light]]
type = "spot"
position = [0.0, -3.0, 5.0]
direction = [0.0, 1.0, -1.0]
inner_angle = 10.0
outer_angle = 20.0
intensity = 25.0

[[light]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = 1.0
color = 0.5

[[light]]
type = "sphere"
center = [1.0, 1.0, 4.0]
radius = 0.5
intensity = 10.0
samples = 4

[render]
method = "local-global"
spacing = 0.05
smoothing = 1.5
ell_min = 0.001
aa = 3
threads = 2

[output]
exr = "every.exr"
layers = ["exitance", "local", "global", "irradiance", "depth"]
"""
    write(t, "every-table.toml", every)
    write(t, "bad-number.toml", every.replace(b"radius = 1.0", b"radius = nan"))
    write(t, "truncated.toml", every[: len(every) // 2])


# --------------------------------------------------------------------------- obj_load_never_panics
def obj_seeds():
    t = "obj_load_never_panics"
    with open(os.path.join(ROOT, "assets", "bunny.obj"), "rb") as f:
        lines = f.read().decode().splitlines()
    verts = [l for l in lines if l.startswith("v ")][:200]
    faces = [l for l in lines if l.startswith("f ") and all(int(i) <= 200 for i in l.split()[1:])]
    write(t, "bunny-cut.obj", ("\n".join(lines[:2] + verts + faces) + "\n").encode())
    tetra = ("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
             "vn 0 0 -1\nvn 1 0 0\nvn 0 1 0\nvn 0 0 1\n"
             "f 1/1/1 3/3/3 2/2/2\nf 1/1/1 2/2/2 4/4/4\nf 1/1/1 4/4/4 3/3/3\nf 2/2/2 3/3/3 4/4/4\n")
    write(t, "tetra-uv-normals.obj", tetra.encode())
    write(t, "quad-negative-indices.obj", b"o quad\ng side\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\nmtllib x.mtl\nusemtl y\n")
    write(t, "only-some-normals.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n")
    write(t, "bad-index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")
    write(t, "degenerate.obj", b"v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n")
    write(t, "huge-numbers.obj", b"v 1e38 0 0\nv 0 1e38 0\nv 0 0 1e38\nf 1 2 3\nv nan 0 0\n")
    with open(os.path.join(ROOT, "scenes", "meshes", "two-materials.mtl"), "rb") as f:
        write(t, "two-materials.mtl", f.read())
    write(t, "groups-latin1.obj", b"# caf\xe9\nmtllib lib.mtl\no t\xeate\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
          b"  usemtl skin\nf 1 3 2\nusemtl lens glass\nf 1 2 4\nusemtl skin\nf 1 4 3\nf 2 3 4\n")
    write(t, "inside-out-tetra.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvn 0 1 0\nvn 1 0 0\nvn 1 1 1\n"
          b"f 1//1 2//1 3//1\nf 1//2 4//2 2//2\nf 1//3 3//3 4//3\nf 2//4 4//4 3//4\n")
    write(t, "mtl-options.mtl", b"newmtl a\nKd 1 1 1\nmap_Kd -s 1 1 1 a.png\nnewmtl b\nmap_Kd b c.png\n")


# --------------------------------------------------------------------------- ply_load_never_panics
def ply_body(fmt, verts, faces, vprops="property float x\nproperty float y\nproperty float z\n",
             count="uchar", index="int", extra=""):
    head = (f"ply\nformat {fmt} 1.0\ncomment fuzz seed\nelement vertex {len(verts)}\n{vprops}"
            f"element face {len(faces)}\nproperty list {count} {index} vertex_indices\n{extra}end_header\n")
    if fmt == "ascii":
        body = "".join(" ".join(repr(float(x)) for x in v) + "\n" for v in verts)
        body += "".join(f"{len(f)} " + " ".join(str(i) for i in f) + "\n" for f in faces)
        return (head + body).encode()
    e = "<" if fmt == "binary_little_endian" else ">"
    codes = {"uchar": "B", "ushort": "H", "int": "i", "uint": "I", "short": "h", "char": "b"}
    body = b"".join(struct.pack(e + "f" * len(v), *v) for v in verts)
    for f in faces:
        body += struct.pack(e + codes[count], len(f)) + struct.pack(e + codes[index] * len(f), *f)
    return head.encode() + body


def ply_seeds():
    t = "ply_load_never_panics"
    cube = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    write(t, "cube-ascii.ply", ply_body("ascii", cube, quads))
    write(t, "cube-le.ply", ply_body("binary_little_endian", cube, quads))
    write(t, "cube-be-ushort-uint.ply", ply_body("binary_big_endian", cube, quads, count="ushort", index="uint"))
    tri = [(0, 0, 0, 0, 0, 1, 0, 0), (1, 0, 0, 0, 0, 1, 1, 0), (0, 1, 0, 0, 0, 1, 0, 1)]
    props = "".join(f"property float {n}\n" for n in ["x", "y", "z", "nx", "ny", "nz", "s", "t"])
    write(t, "triangle-normals-uv-le.ply", ply_body("binary_little_endian", tri, [[0, 1, 2]], vprops=props))
    write(t, "triangle-normals-uv-ascii.ply", ply_body("ascii", tri, [[0, 1, 2]], vprops=props))
    # Skipped elements and list properties around the faces.
    skip = ("ply\nformat ascii 1.0\nelement material 1\nproperty list uchar float rgb\n"
            "element vertex 3\nproperty float x\nproperty float y\nproperty uchar red\nproperty float z\n"
            "element face 1\nproperty list uchar float texcoord\nproperty list uchar int vertex_index\n"
            "element edge 1\nproperty int a\nproperty int b\nend_header\n"
            "3 0.1 0.2 0.3\n0 0 7 0\n1 0 7 0\n0 1 7 0\n2 0.5 0.5 3 0 1 2\n0 1\n")
    write(t, "skipped-elements-ascii.ply", skip.encode())
    with open(os.path.join(ROOT, "tests", "data", "meshes", "bunny.ply"), "rb") as f:
        bunny = f.read()
    write(t, "bunny-head-cut.ply", bunny[:2000])
    write(t, "huge-count.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
          b"property float x\nproperty float y\nproperty float z\nelement face 1\n"
          b"property list uint int vertex_indices\nend_header\n" + b"\0" * 40)


# -------------------------------------------------------------------------- gltf_load_never_panics
def gltf_doc(buffer_json, mode=4, extra_nodes=""):
    return json.dumps({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"translation": [1, 2, 3], "rotation": [0, 0, 0.6, 0.8], "scale": [1, 2, 3], "children": [1]},
                  {"matrix": [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], "mesh": 0}],
        "meshes": [{"name": "quad", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "mode": mode, "material": 0}]}],
        "materials": [{"name": "wax"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 0, "byteOffset": 96, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteLength": 128}, {"buffer": 0, "byteOffset": 128, "byteLength": 12}],
        "buffers": [buffer_json],
    }).encode()


def quad_buffer():
    corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
    b = b"".join(struct.pack("<3f", x, y, 0) for x, y in corners)
    b += b"".join(struct.pack("<3f", 0, 0, 1) for _ in corners)
    b += b"".join(struct.pack("<2f", x, y) for x, y in corners)
    return b + struct.pack("<6H", 0, 1, 2, 0, 2, 3)


def gltf_seeds():
    t = "gltf_load_never_panics"
    data = "data:application/octet-stream;base64," + base64.b64encode(quad_buffer()).decode()
    write(t, "quad-embedded.gltf", gltf_doc({"byteLength": 140, "uri": data}))
    write(t, "quad-external.gltf", gltf_doc({"byteLength": 140, "uri": "buffer.bin"}))
    write(t, "quad-strip.gltf", gltf_doc({"byteLength": 140, "uri": data}, mode=5))
    js = gltf_doc({"byteLength": 140})
    js += b" " * (-len(js) % 4)
    bin_ = quad_buffer()
    chunks = struct.pack("<I", len(js)) + b"JSON" + js + struct.pack("<I", len(bin_)) + b"BIN\0" + bin_
    write(t, "quad.glb", b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks)
    with open(os.path.join(ROOT, "tests", "data", "meshes", "egg.glb"), "rb") as f:
        write(t, "egg.glb", f.read())


# ----------------------------------------------------------------------- raster_triangle_in_bounds
def raster_seeds():
    t = "raster_triangle_in_bounds"

    def exact(w_exp, corners):
        out = bytearray([0]) + i8(w_exp)
        for x, y, z in corners:
            out += u32(x) + u32(y) + u16(z)
        return out

    def raw(corners):
        return bytearray([1]) + b"".join(f32(c) for v in corners for c in v)

    def persp(scale, corners):
        return bytearray([3]) + i8(scale) + b"".join(i8(c) for v in corners for c in v)

    # 16 × 16 pixels, aa 4: 64 × 64 sub-samples, fixed-point corners (raw = sub-samples · 256).
    size = bytes([0xFF, 3])
    write(t, "exact-fan", size + exact(0, [(0, 0, 0), (64 * 256, 0, 30000), (0, 64 * 256, 65535)])
          + exact(3, [(32 * 256 + 128, 32 * 256 + 128, 100), (64 * 256, 0, 20000), (64 * 256, 64 * 256, 40000)])
          + exact(-5, [(1000, 7000, 500), (9000, 9001, 60000), (3333, 16000, 32768)]))
    write(t, "exact-on-centres-shared-edge", size + exact(0, [(128, 128, 100), (2176, 128, 100), (128, 2176, 100)])
          + exact(0, [(2176, 128, 100), (2176, 2176, 100), (128, 2176, 100)]))
    write(t, "raw-nan-inf-huge", size + raw([(float("nan"), 0, 0, 1), (1, 0, 0, 1), (0, 1, 0, 1)])
          + raw([(float("inf"), 0, 0, 1), (1, 0, 0, 1), (0, 1, 0, 1)])
          + raw([(1e30, -1e30, 0.5, 1), (-1e30, -1e30, 0.5, 1), (0, 1e30, 0.5, 1)])
          + raw([(0.5, 0.5, 0.5, -1), (-0.5, 0.5, 0.5, 1), (0, -0.5, 0.5, 0)]))
    write(t, "perspective-across-near", bytes([0x77, 1]) + persp(2, [(-10, -10, -5), (10, -10, 3), (0, 10, -20)])
          + persp(3, [(-100, -100, -1), (100, -100, -1), (0, 100, -127)]))
    write(t, "scaled-w-negative", bytes([0x35, 2]) + bytearray([2]) + i8(-3) + b"".join(i8(c) for c in (10, 5, 3, -8, -7, 9, 4, 8, 1, 2, 3, 4)))
    write(t, "thin-grid", bytes([0, 8 | (0 << 4)]) + raw([(-1, -1, 0.2, 1), (1, 0.5, 0.9, 1), (-1, 1, 0.5, 1)]))
    write(t, "tall-grid", bytes([0, 8 | (3 << 4)]) + exact(0, [(0, 0, 0), (1024, 4096 * 4 * 256, 5000), (0, 4096 * 4 * 128, 65535)]))


# ------------------------------------------------------------------- shadow_rays_match_brute_force
def shadow_seeds():
    t = "shadow_rays_match_brute_force"

    def g(v):
        """A grid byte for the integer v in [-4, 4] (coordinate (b mod 9) - 4)."""
        return (v + 4) % 9

    def h(v2):
        """An origin byte for the half-integer v2/2, v2 in [-8, 8]."""
        return (v2 + 8) % 17

    # Mode 0: a closed octahedron around the origin (unit vertices), and a flat fan with shared
    # edges in z = 0; rays straight at its vertices and edges, along edges, with every t code.
    octa = []
    px, nx, py, ny, pz, nz = (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)
    for a, b in ((px, py), (py, nx), (nx, ny), (ny, px)):
        octa += [(a, b, pz), (b, a, nz)]
    fan = [((0, 0, 2), (2, 0, 2), (0, 2, 2)), ((0, 0, 2), (0, 2, 2), (-2, 0, 2)),
           ((0, 0, 2), (-2, 0, 2), (0, -2, 2)), ((0, 0, 2), (0, -2, 2), (2, 0, 2))]
    tris = octa + fan
    out = bytearray([0, len(tris)])
    for tri in tris:
        out += bytes(g(c) for v in tri for c in v)
    rays = [((0, 0, 8), (0, 0, -1), 0), ((0, 0, 8), (0, 0, -1), 1), ((0, 0, 8), (0, 0, -1), 2),
            ((0, 0, 8), (0, 0, -1), 3), ((0, 0, 8), (0, 0, -1), 4), ((0, 0, 8), (0, 0, -1), 5),
            ((2, 0, 8), (0, 0, -1), 0), ((1, 1, 8), (0, 0, -1), 0), ((2, 2, 8), (0, 0, -1), 0),
            ((-8, 0, 0), (1, 0, 0), 0), ((-8, 0, 4), (1, 0, 0), 0), ((0, 0, 8), (0, 0, -1), 6 + 16 * 2),
            ((0, 0, 8), (0, 0, -1), 6 + 16 * 3), ((0, 0, 8), (0, 0, -1), 6 + 16 * 4), ((4, 4, 4), (-1, -1, -1), 0),
            ((0, 0, 0), (1, 1, 1), 0), ((0, 0, 0), (0, 0, 0), 0), ((1, 0, 8), (0, 1, -4), 0)]
    for o, d, tc in rays:
        out += bytes(h(c) for c in o) + bytes(g(c) for c in d) + bytes([tc])
    write(t, "grid-octahedron-fan", out)
    # Mode 1: triangles at scales 2^-120 … 2^120 (one around the origin at each), rays at
    # matching and mismatched scales.
    out = bytearray([1, 12])
    for k, e in enumerate(range(-120, 121, 22)):
        out += i8(e) + b"".join(i8(c) for c in (-100, -100, k, 100, -100, k, 0, 100, -k))
    for e in range(-120, 121, 20):
        out += i8(e) + i8(3) + i8(-5) + i8(100) + i8(-e // 2) + i8(0) + i8(0) + i8(-1) + bytes([0])
    write(t, "scaled-magnitudes", out)
    # Mode 2: raw bits: NaN and infinite vertices (skipped), huge and subnormal ones, and rays
    # with NaN / infinite parts and t_max.
    nan, inf = float("nan"), float("inf")
    tris = [((0, 0, 1), (1, 0, 1), (0, 1, 1)), ((nan, 0, 1), (1, 0, 1), (0, 1, 1)),
            ((3e38, -3e38, 0), (-3e38, -3e38, 0), (0, 3e38, 0)), ((inf, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((1e-45, 0, 2), (0, 1e-45, 2), (-1e-45, -1e-45, 2)), ((0, 0, 3), (1e-38, 0, 3), (0, 1e-38, 3))]
    out = bytearray([2, len(tris)])
    for tri in tris:
        out += b"".join(f32(c) for v in tri for c in v)
    for o, d, tm in (((0.25, 0.25, 5), (0, 0, -1), inf), ((0.25, 0.25, 5), (0, 0, -1), 4.5),
                     ((0, 0, 5), (0, 0, -1), nan), ((nan, 0, 5), (0, 0, -1), inf),
                     ((0, 0, 5), (0, 0, -inf), inf), ((0, 0, 5), (1e-40, 0, -1e-30), inf),
                     ((0, 0, -5), (0, 0, 3e38), 1.0), ((0, 0, 5), (0, 0, -1), -0.0)):
        out += b"".join(f32(c) for c in o + d) + f32(tm)
    write(t, "raw-nan-inf-huge", out)
    # Mode 3: the coherent scene: sphere (80), box of 2 divisions, 8 × 8 plate; a light above
    # and to the side; 64 rays from the plate in scanline order, then rays from the objects.
    light = bytes([i8(-20)[0], i8(8)[0], 40])
    write(t, "coherent-plate-scanline", bytes([3, 1 | (2 << 1) | (7 << 3)]) + light + i8(0) + bytes((k * 37) % 128 for k in range(64)))
    write(t, "coherent-objects", bytes([3, 0 | (1 << 1) | (3 << 3)]) + light + i8(0) + bytes(128 | k for k in range(64)))
    write(t, "coherent-huge-scale", bytes([3, 1 | (3 << 1) | (2 << 3)]) + light + i8(20) + bytes((128 if k % 3 else 0) | k for k in range(64)))
    write(t, "coherent-tiny-scale", bytes([3, 1 | (1 << 3)]) + bytes([0, 0, 0]) + i8(-23) + bytes(k % 256 for k in range(0, 256, 4)))


# ------------------------------------------------------------------------------ convexity_is_sound
def convexity_seeds():
    t = "convexity_is_sound"

    def arbitrary(verts, tris, scale=0, raw=False, transform=b"\x00"):
        out = bytearray([0, len(verts) - 3, 1 if raw else 0])
        if not raw:
            out += i8(scale)
        for v in verts:
            out += b"".join(f32(c) if raw else i8(c) for c in v)
        return out + bytes([len(tris)]) + bytes(i for tr in tris for i in tr) + transform

    def shape(kind, sizes=b"", perturb=(), edits=(), transform=b"\x00"):
        out = bytearray([1, kind]) + sizes + bytes([len(perturb)])
        for v, e, a, c in perturb:
            out += u16(v) + bytes([e]) + i8(a) + i8(c)
        out += bytes([len(edits)])
        for k, flip in edits:
            out += u16(k) + bytes([1 if flip else 0])
        return out + transform

    tetra = [(0, 0, 0), (10, 0, 0), (0, 10, 0), (0, 0, 10)]
    tetra_faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    write(t, "tetrahedron", arbitrary(tetra, tetra_faces))
    write(t, "tetrahedron-one-face-flipped", arbitrary(tetra, tetra_faces[:3] + [(1, 3, 2)]))
    write(t, "two-tetrahedra-sharing-a-vertex", arbitrary(tetra + [(-10, 0, 0), (0, -10, 0), (0, 0, -10)],
          tetra_faces + [(0, 4, 5), (0, 6, 4), (0, 5, 6), (4, 6, 5)]))
    write(t, "flat-fan", arbitrary([(0, 0, 0), (5, 0, 0), (5, 5, 0), (0, 5, 0), (-5, 3, 0)], [(0, 1, 2), (0, 2, 3), (0, 3, 4)], scale=-3))
    write(t, "raw-huge-coordinates", arbitrary([(3e38, 0, 0), (-3e38, 0, 0), (0, 3e38, 0), (0, 0, 3e38), (0, 0, -3e38)],
          [(0, 2, 3), (2, 1, 3), (1, 0, 4), (0, 1, 2)], raw=True))
    # Sphere (16 segments): intact, one vertex pushed out, one pushed in, a face removed.
    s16 = 1 + 3 * 4
    write(t, "sphere-intact-rotated", shape(s16, transform=bytes([1, 20, 200, 90])))
    write(t, "sphere-vertex-out", shape(s16, perturb=[(40, 3, 1, 0)]))
    write(t, "sphere-vertex-in-slightly", shape(s16, perturb=[(40, 16, -3, 0)]))
    write(t, "sphere-face-removed", shape(s16, edits=[(10, False)]))
    write(t, "sphere-face-flipped", shape(s16, edits=[(10, True)]))
    # Cuboid: a corner pushed in, a corner lifted by a hair, a face removed; scaled and moved.
    box = bytes([15, 31, 63])
    write(t, "cuboid-corner-in", shape(1, box, perturb=[(0, 2, -1, 0)]))
    write(t, "cuboid-corner-hair-out", shape(1, box, perturb=[(2, 20, 0, 3)]))
    write(t, "cuboid-face-removed-moved", shape(1, box, edits=[(4, False), (4, False)],
          transform=bytes([7, 10, 20, 30, 0x80, 0x7f, 0x10, 5, 100])))
    write(t, "cuboid-tiny-scale", shape(1, box, transform=bytes([4, 0xC1])))
    # Plane: lifted corner (not flat), tilted.
    write(t, "plane-corner-lifted", shape(2, bytes([15, 31]), perturb=[(1, 4, 0, 5)], transform=bytes([1, 7, 8, 9])))


# ----------------------------------------------------------------------- texture_load_never_panics
def texture_seeds():
    """Byte 0 picks the decoder (low 3 bits: 0-5 PNG, JPEG, TGA, BMP, HDR, OpenEXR forced;
    6, 7 detected as t.png / t.tga), bit 3 data (linear) instead of colour; then the file."""
    t = "texture_load_never_panics"
    PNG, JPEG, TGA, BMP, HDR, EXR, DETECT_PNG, DETECT_TGA, DATA = 0, 1, 2, 3, 4, 5, 6, 7, 8

    def shipped(name):
        with open(os.path.join(ROOT, "scenes", "textures", name), "rb") as f:
            return f.read()

    # 3 x 2 RGB, rows top first.
    rgb = [(255, 0, 0), (0, 128, 0), (0, 0, 64), (10, 20, 30), (188, 188, 188), (1, 254, 127)]

    def tga(kind, bits, descriptor, body):
        return bytes([0, 0, kind, 0, 0, 0, 0, 0, 0, 0, 0, 0]) + u16(3) + u16(2) + bytes([bits, descriptor]) + body

    bottom_up = rgb[3:] + rgb[:3]
    tga_raw = tga(2, 24, 0, b"".join(bytes([b, g, r]) for r, g, b in bottom_up))
    # Run-length encoded (type 10), top-down: a run of 3, then 3 raw pixels.
    tga_rle = tga(10, 24, 0x20, bytes([0x82, 64, 32, 16, 0x02]) + b"".join(bytes([b, g, r]) for r, g, b in rgb[3:]))
    row_pad = b"\0\0\0"
    bmp_pixels = b"".join(b"".join(bytes([b, g, r]) for r, g, b in row) + row_pad for row in (rgb[3:], rgb[:3]))
    bmp = (b"BM" + u32(54 + len(bmp_pixels)) + u32(0) + u32(54) + u32(40) + u32(3) + u32(2)
           + u16(1) + u16(24) + u32(0) + u32(len(bmp_pixels)) + u32(2835) + u32(2835) + u32(0) + u32(0)
           + bmp_pixels)
    hdr = (b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n"
           + bytes([128, 64, 32, 129, 0, 0, 0, 0, 200, 1, 255, 140, 128, 128, 128, 128]))
    # Width 8: new-style run-length scan lines (per channel: a run of 8, then one of 8 for E).
    hdr_rle = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n" + bytes([2, 2, 0, 8]) + bytes(
        [128 + 8, 100, 128 + 8, 50, 128 + 8, 25, 128 + 8, 129])
    write(t, "png-ramp", bytes([PNG]) + shipped("mfp-ramp.png"))
    write(t, "png-ramp-detected-data", bytes([DETECT_PNG | DATA]) + shipped("mfp-ramp.png"))
    write(t, "jpeg-checker", bytes([JPEG]) + shipped("kd-checker.jpg"))
    write(t, "jpeg-checker-detected", bytes([DETECT_PNG]) + shipped("kd-checker.jpg"))
    write(t, "tga-bottom-up", bytes([TGA]) + tga_raw)
    write(t, "tga-rle-detected-data", bytes([DETECT_TGA | DATA]) + tga_rle)
    write(t, "bmp-padded-rows", bytes([BMP]) + bmp)
    write(t, "hdr-flat", bytes([HDR]) + hdr)
    write(t, "hdr-rle-detected", bytes([DETECT_TGA]) + hdr_rle)
    write(t, "exr-disc-data", bytes([EXR | DATA]) + shipped("mfp-disc.exr"))
    write(t, "exr-disc-detected", bytes([DETECT_PNG]) + shipped("mfp-disc.exr"))
    write(t, "unrecognised-text", bytes([DETECT_PNG]) + b"not an image")


# ----------------------------------------------------------------------- exr_tile_read_never_panics
def exr_scanlines(channels, data_window, display_window, extra=b""):
    """An uncompressed scan-line OpenEXR file. `channels`: (name, values row-major) pairs, f32;
    windows as (x0, y0, x1, y1) inclusive; `extra`: more header attributes, already encoded."""
    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + u32(len(value)) + value

    def box(b):
        return b"".join(struct.pack("<i", v) for v in b)

    channels = sorted(channels)
    chlist = b"".join(name.encode() + b"\0" + u32(2) + bytes([0, 0, 0, 0]) + u32(1) + u32(1)
                      for name, _ in channels) + b"\0"
    header = (attribute("channels", "chlist", chlist)
              + attribute("compression", "compression", bytes([0]))
              + attribute("dataWindow", "box2i", box(data_window))
              + attribute("displayWindow", "box2i", box(display_window))
              + attribute("lineOrder", "lineOrder", bytes([0]))
              + attribute("pixelAspectRatio", "float", f32(1.0))
              + attribute("screenWindowCenter", "v2f", f32(0.0) + f32(0.0))
              + attribute("screenWindowWidth", "float", f32(1.0))
              + extra + b"\0")
    x0, y0, x1, y1 = data_window
    width, height = x1 - x0 + 1, y1 - y0 + 1
    start = 8 + len(header) + 8 * height
    chunks = b""
    offsets = b""
    for row in range(height):
        pixels = b"".join(f32(values[row * width + x]) for _, values in channels for x in range(width))
        offsets += struct.pack("<Q", start + len(chunks))
        chunks += struct.pack("<i", y0 + row) + u32(len(pixels)) + pixels
    return b"\x76\x2f\x31\x01" + u32(2) + header + offsets + chunks


def exr_tile_seeds():
    t = "exr_tile_read_never_panics"
    n = 2 * 3
    ramp = [i / n for i in range(n)]
    exposure = b"lucentExposure\0float\0" + u32(4) + f32(-1.5)
    tile = [("R", ramp), ("G", [0.5] * n), ("B", [1.0 - v for v in ramp]), ("A", [1.0] * n),
            ("depth.Z", [2.0] * n), ("exitance.R", ramp), ("exitance.G", ramp), ("exitance.B", ramp)]
    # A 2 x 3 tile at (3, 1) of an 8 x 6 image, with alpha, a scalar and an RGB layer.
    write(t, "tile-layers-exposure", exr_scanlines(tile, (3, 1, 4, 3), (0, 0, 7, 5), exposure))
    # A whole image (data window = display window), beauty only.
    write(t, "whole-beauty", exr_scanlines(tile[:3], (0, 0, 1, 2), (0, 0, 1, 2)))
    # The data window reaching past the display window: not a tile.
    write(t, "data-outside-display", exr_scanlines(tile[:3], (3, 1, 4, 3), (0, 0, 3, 3)))
    # A layer missing a channel, and no beauty.
    write(t, "layer-without-beauty", exr_scanlines(tile[4:7], (0, 0, 1, 2), (0, 0, 1, 2)))


# ----------------------------------------------------------------------- samples_ply_read_never_panics
def samples_ply_seeds():
    t = "samples_ply_read_never_panics"
    names = ["x", "y", "z", "nx", "ny", "nz", "area", "irradiance_r", "irradiance_g", "irradiance_b"]
    samples = [(0, 0, 0, 0, 0, 1, 0.25, 1, 0.5, 0.25), (1, 0, 0, 1, 0, 0, 0.5, 0, 0, 0),
               (0, 2, -1, 0, -1, 0, 0, 2, 2, 2)]

    def ply(header_lines, body):
        return ("\n".join(["ply"] + header_lines + ["end_header"]) + "\n").encode() + body

    def floats(rows, order=names):
        return b"".join(f32(row[names.index(n)]) for row in rows for n in order)

    def header(count, props, fmt="binary_little_endian", extra=()):
        return (["format %s 1.0" % fmt, "comment lucent sample-set v1", "comment seed 1",
                 "element vertex %d" % count] + ["property float %s" % n for n in props] + list(extra))

    write(t, "three-samples", ply(header(3, names), floats(samples)))
    # Properties shuffled, a viewer's colour bytes between them, and an empty face element.
    shuffled = names[5:] + names[:5]
    colour_rows = b"".join(floats([row], shuffled[:4]) + bytes([255, 128]) + floats([row], shuffled[4:])
                           for row in samples)
    lines = (["format binary_little_endian 1.0", "element vertex 3"]
             + ["property float %s" % n for n in shuffled[:4]]
             + ["property uchar red", "property uchar green"]
             + ["property float %s" % n for n in shuffled[4:]]
             + ["element face 0", "property list uchar int vertex_indices"])
    write(t, "shuffled-with-colours-and-faces", ply(lines, colour_rows))
    write(t, "future-version", ply(header(3, names)[:1] + ["comment lucent sample-set v2"]
                                   + header(3, names)[3:], floats(samples)))
    write(t, "truncated", ply(header(3, names), floats(samples)[:-7]))
    write(t, "ascii", ply(header(1, names, fmt="ascii"), b"0 0 0 0 0 1 1 1 1 1\n"))
    write(t, "normal-not-unit", ply(header(1, names), floats([(0, 0, 0, 0, 0, 2, 1, 1, 1, 1)])))


def crop_seed(scene=0, method=3, size=(40, 30), aa=1, step=1, tolerance=0.25, vfov=30.0,
              crop=(0, 0, 40, 30), threads_swapped=False):
    """One crops_match_the_whole_render input (layout in tests/src/fuzz_props/crops.rs)."""
    w, h = size
    x0, y0, x1, y1 = crop
    return bytes([
        scene | (method << 1),
        w - 1, h - 1,
        aa - 1,
        step - 1,
        round(tolerance * 32),
        round((vfov - 6.0) * 8),
        x0, y0, x1 - x0 - 1, y1 - y0 - 1,
        int(threads_swapped),
    ])


def crop_seeds():
    t = "crops_match_the_whole_render"
    # The tiles test's images: the sphere filling the view, its shadow edge down the middle.
    write(t, "sphere-interpolated-inner-tile",
          crop_seed(step=4, tolerance=1.0, vfov=10.0, crop=(20, 7, 29, 15)))
    write(t, "sphere-interpolated-second-pass-strip",
          crop_seed(aa=3, step=3, tolerance=1.0, vfov=10.0, crop=(14, 7, 15, 30),
                    threads_swapped=True))
    # A one-column crop at the image's left edge, whose blocks' right corners lie outside it
    # (found the grid clamped to the crop instead of the image).
    write(t, "sphere-interpolated-first-column",
          crop_seed(aa=3, step=3, tolerance=1.0, vfov=10.0, crop=(0, 7, 1, 14)))
    write(t, "sphere-second-pass-horizon-row", crop_seed(aa=2, crop=(0, 15, 14, 16)))
    write(t, "sphere-hierarchical-step-16-tiny",
          crop_seed(method=0, size=(3, 2), step=16, tolerance=7.9, vfov=10.0, crop=(1, 1, 3, 2)))
    write(t, "sphere-edge-aware-odd-step", crop_seed(method=2, size=(37, 23), step=5,
                                                     tolerance=0.5, vfov=12.0,
                                                     crop=(11, 4, 30, 19)))
    write(t, "textured-interpolated", crop_seed(scene=1, size=(32, 24), aa=2, step=4,
                                                crop=(5, 3, 21, 17)))
    write(t, "textured-local-global", crop_seed(scene=1, method=1, size=(24, 24), crop=(0, 12, 24, 24)))


if __name__ == "__main__":
    cache_seeds()
    table_seeds()
    scene_seeds()
    obj_seeds()
    ply_seeds()
    gltf_seeds()
    raster_seeds()
    shadow_seeds()
    convexity_seeds()
    texture_seeds()
    exr_tile_seeds()
    samples_ply_seeds()
    crop_seeds()
