#!/usr/bin/env python3
"""Writes the hand-made seed corpus of every fuzz target into fuzz/corpus/<target>/seed-*.

Run from anywhere: `python3 fuzz/make_seeds.py`. Seeds are named by what they exercise; the
byte layouts are documented in tests/src/fuzz_props/*.rs. Minimised inputs that found bugs
(crash-*) or limitations (regress-*) are left alone.
"""
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
        nodes += bytes([2]) + i8(e)
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
    for name in ("default", "sphere-shadow", "textured-mfp"):
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

[material.skin]
type = "translucent"
kd = { texture = "textures/mfp-ramp.png" }
diffuse_mean_free_path = 0.5
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


if __name__ == "__main__":
    cache_seeds()
    table_seeds()
    scene_seeds()
    obj_seeds()
    raster_seeds()
