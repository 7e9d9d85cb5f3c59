#!/usr/bin/env python3
"""Writes marker_post.gltf, a small example model for ArUco Workbench's scenes (issue 13's `model "..."`).

A signpost: a red base plate, a blue pole and a yellow pyramid cap turned 45 degrees, each a node with its own
transform under one root node, so a loader that ignores node transforms draws three boxes in a heap. glTF 2.0,
y up, metres; flat normals; one buffer embedded as a data URI so the model is a single file.

Run it from anywhere; it writes next to itself:  python3 scripts/models/make_gltf.py
Only the Python standard library is used.
"""

import base64
import json
import math
import os
import struct


def box():
    """A unit cube centred on the origin: 24 vertices (4 per face, so each face has its own normal), 36 indices."""
    positions, normals, indices = [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            # Two directions in the face's plane, chosen so that u x v = n (counter-clockwise seen from outside).
            u = [0.0, 0.0, 0.0]
            v = [0.0, 0.0, 0.0]
            u[(axis + 1) % 3] = 1.0
            v[(axis + 2) % 3] = sign
            base = len(positions)
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                positions.append([0.5 * n[i] + 0.5 * du * u[i] + 0.5 * dv * v[i] for i in range(3)])
                normals.append(n)
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return positions, normals, indices


def pyramid():
    """A square pyramid, base 1 x 1 on y = 0, apex at y = 1: 4 sloped faces and the base, flat normals."""
    corners = [(-0.5, 0.5), (0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)]  # (x, z), counter-clockwise seen from +y
    apex = [0.0, 1.0, 0.0]
    positions, normals, indices = [], [], []
    for k in range(4):
        (x0, z0), (x1, z1) = corners[k], corners[(k + 1) % 4]
        a, b = [x0, 0.0, z0], [x1, 0.0, z1]
        e1 = [b[i] - a[i] for i in range(3)]
        e2 = [apex[i] - a[i] for i in range(3)]
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        length = math.sqrt(sum(c * c for c in n))
        n = [c / length for c in n]
        base = len(positions)
        positions += [a, b, apex]
        normals += [n, n, n]
        indices += [base, base + 1, base + 2]
    base = len(positions)
    for x, z in reversed(corners):  # seen from below
        positions.append([x, 0.0, z])
        normals.append([0.0, -1.0, 0.0])
    indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return positions, normals, indices


def main():
    buffer = bytearray()
    views, accessors, meshes = [], [], []

    def add_view(data, target):
        while len(buffer) % 4:
            buffer.append(0)
        views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": len(data), "target": target})
        buffer.extend(data)
        return len(views) - 1

    def add_mesh(name, geometry, material):
        positions, normals, indices = geometry
        flat = [c for p in positions for c in p]
        pos = add_view(struct.pack("<%df" % len(flat), *flat), 34962)
        accessors.append({"bufferView": pos, "componentType": 5126, "count": len(positions), "type": "VEC3",
                          "min": [min(p[i] for p in positions) for i in range(3)],
                          "max": [max(p[i] for p in positions) for i in range(3)]})
        flat = [c for n in normals for c in n]
        nrm = add_view(struct.pack("<%df" % len(flat), *flat), 34962)
        accessors.append({"bufferView": nrm, "componentType": 5126, "count": len(normals), "type": "VEC3"})
        idx = add_view(struct.pack("<%dH" % len(indices), *indices), 34963)
        accessors.append({"bufferView": idx, "componentType": 5123, "count": len(indices), "type": "SCALAR"})
        meshes.append({"name": name, "primitives": [{
            "attributes": {"POSITION": len(accessors) - 3, "NORMAL": len(accessors) - 2},
            "indices": len(accessors) - 1, "material": material, "mode": 4}]})
        return len(meshes) - 1

    def material(name, rgba):
        return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": rgba, "metallicFactor": 0.0,
                                                        "roughnessFactor": 0.8}}

    materials = [material("base", [0.8, 0.1, 0.1, 1.0]), material("pole", [0.1, 0.25, 0.8, 1.0]),
                 material("cap", [0.95, 0.8, 0.1, 1.0])]
    cube = box()
    base_mesh = add_mesh("base", cube, 0)
    pole_mesh = add_mesh("pole", cube, 1)
    cap_mesh = add_mesh("cap", pyramid(), 2)

    half_turn_45 = math.sin(math.radians(22.5)), math.cos(math.radians(22.5))  # 45 degrees about y
    nodes = [
        {"name": "post", "children": [1, 2, 3], "scale": [0.5, 0.5, 0.5]},
        {"name": "base", "mesh": base_mesh, "translation": [0.0, 0.05, 0.0], "scale": [0.8, 0.1, 0.8]},
        {"name": "pole", "mesh": pole_mesh, "translation": [0.0, 0.8, 0.0], "scale": [0.15, 1.4, 0.15]},
        {"name": "cap", "mesh": cap_mesh, "translation": [0.0, 1.5, 0.0], "scale": [0.4, 0.4, 0.4],
         "rotation": [0.0, half_turn_45[0], 0.0, half_turn_45[1]]},
    ]
    doc = {
        "asset": {"version": "2.0", "generator": "ArUco Workbench scripts/models/make_gltf.py"},
        "scene": 0,
        "scenes": [{"name": "marker_post", "nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buffer)).decode()}],
    }
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "marker_post.gltf")
    with open(out, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print("wrote", out, os.path.getsize(out), "bytes")


if __name__ == "__main__":
    main()
