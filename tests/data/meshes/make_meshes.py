#!/usr/bin/env python3
"""Writes the mesh files of the golden scenes in tests/data/ (run: python3 tests/data/meshes/make_meshes.py).

- bunny.ply: assets/bunny.obj as a binary little-endian PLY laid out like the Stanford scans
  (x y z, then per-vertex `confidence` and `intensity` floats that lucent skips; faces as
  `list uchar int vertex_indices`).
- egg.gltf / egg.glb: a UV sphere (normals, UVs, u16 indices, material "wax") under two nodes:
  `stand` (translation and a rotation about z) with child `egg` (non-uniform scale), so the
  node hierarchy and the inverse-transpose normal transform are exercised. The .gltf embeds its
  buffer as a base64 data URI; the .glb carries the same bytes in its binary chunk.
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))


def bunny_ply():
    verts, faces = [], []
    with open(os.path.join(ROOT, "assets", "bunny.obj")) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                verts.append([float(x) for x in w[1:4]])
            elif w[0] == "f":
                faces.append([int(x.split("/")[0]) - 1 for x in w[1:]])
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        "comment assets/bunny.obj (Stanford bunny, reduced) converted by make_meshes.py\n"
        f"element vertex {len(verts)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float confidence\nproperty float intensity\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    body = bytearray()
    for v in verts:
        body += struct.pack("<5f", *v, 1.0, 0.5)
    for f in faces:
        body += struct.pack("<B", len(f)) + struct.pack(f"<{len(f)}i", *f)
    with open(os.path.join(HERE, "bunny.ply"), "wb") as f:
        f.write(header.encode() + bytes(body))


def egg():
    seg, rings = 32, 16
    pos, nrm, uv, idx = [], [], [], []
    for j in range(rings + 1):
        theta = math.pi * j / rings  # from the south pole
        for i in range(seg + 1):
            phi = 2 * math.pi * i / seg
            n = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), -math.cos(theta))
            pos.append(n)
            nrm.append(n)
            uv.append((i / seg, j / rings))
    for j in range(rings):
        for i in range(seg):
            a = j * (seg + 1) + i
            b = a + seg + 1
            # Counter-clockwise seen from outside.
            if j > 0:
                idx += [a, a + 1, b + 1]
            if j < rings - 1:
                idx += [a, b + 1, b]
    blob = bytearray()
    views = []

    def add(data):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        return len(views) - 1

    vp = add(b"".join(struct.pack("<3f", *p) for p in pos))
    vn = add(b"".join(struct.pack("<3f", *n) for n in nrm))
    vt = add(b"".join(struct.pack("<2f", *t) for t in uv))
    vi = add(b"".join(struct.pack("<H", i) for i in idx))
    # The min/max glTF requires on POSITION.
    lo = [min(p[k] for p in pos) for k in range(3)]
    hi = [max(p[k] for p in pos) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "lucent tests/data/meshes/make_meshes.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {
                "name": "stand",
                "translation": [0.25, -0.5, 1.0],
                # 30° about z: (0, 0, sin 15°, cos 15°).
                "rotation": [0.0, 0.0, math.sin(math.radians(15)), math.cos(math.radians(15))],
                "children": [1],
            },
            {"name": "egg", "scale": [1.0, 0.6, 0.8], "mesh": 0},
        ],
        "meshes": [
            {
                "name": "egg",
                "primitives": [
                    {
                        "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                        "indices": 3,
                        "material": 0,
                    }
                ],
            }
        ],
        "materials": [{"name": "wax"}],
        "accessors": [
            {"bufferView": vp, "componentType": 5126, "count": len(pos), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": vn, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
            {"bufferView": vt, "componentType": 5126, "count": len(uv), "type": "VEC2"},
            {"bufferView": vi, "componentType": 5123, "count": len(idx), "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
    }
    while len(blob) % 4:
        blob.append(0)
    embedded = json.loads(json.dumps(doc))
    embedded["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
        bytes(blob)
    ).decode()
    with open(os.path.join(HERE, "egg.gltf"), "w") as f:
        json.dump(embedded, f, indent=1)
        f.write("\n")
    js = json.dumps(doc, separators=(",", ":")).encode()
    while len(js) % 4:
        js += b" "
    glb = (
        struct.pack("<I", len(js)) + b"JSON" + js + struct.pack("<I", len(blob)) + b"BIN\0" + bytes(blob)
    )
    with open(os.path.join(HERE, "egg.glb"), "wb") as f:
        f.write(b"glTF" + struct.pack("<II", 2, 12 + len(glb)) + glb)


bunny_ply()
egg()
