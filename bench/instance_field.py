#!/usr/bin/env python3
"""Writes a glTF scene of N copies of a model's meshes on a square grid, as one node per mesh with
EXT_mesh_gpu_instancing: the field used to measure LOD on real assets (a far copy should cost what
it covers on screen).

usage: instance_field.py MODEL.gltf|MODEL.glb N SPACING OUT.gltf

The output references the model's buffers: a .gltf model's buffer files must lie beside OUT.gltf
(write OUT.gltf into the model's folder); a .glb model's binary chunk is written beside OUT.gltf
as OUT.bin. Images embedded in a GLB stay in that buffer (bufferView images). The instance
translations go to OUT.instances.bin. Every string of the model is copied as JSON data only."""
import json
import math
import os
import struct
import sys


def read_model(path):
    """The model's JSON and, for a GLB, its binary chunk."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"glTF":
        return json.loads(data.decode("utf-8")), None
    length = struct.unpack_from("<I", data, 8)[0]
    offset, doc, binary = 12, None, None
    while offset + 8 <= length:
        size, kind = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8:offset + 8 + size]
        if kind == 0x4E4F534A:
            doc = json.loads(chunk.decode("utf-8"))
        elif kind == 0x004E4942:
            binary = chunk
        offset += 8 + size
    return doc, binary


def grid_translations(count, spacing):
    side = max(1, math.ceil(math.sqrt(count)))
    out = bytearray()
    for i in range(count):
        x, z = i % side, i // side
        out += struct.pack("<3f", (x - side / 2) * spacing, 0.0, -z * spacing)
    return bytes(out)


def mesh_nodes(doc):
    """(node index, mesh) of every node of the default scene's trees that holds a mesh."""
    scene = doc.get("scenes", [{}])[doc.get("scene", 0)]
    stack, found = list(scene.get("nodes", [])), []
    while stack:
        n = stack.pop()
        node = doc["nodes"][n]
        if "mesh" in node:
            found.append(n)
        stack.extend(node.get("children", []))
    return found


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    model, count, spacing, out = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    if count < 1 or not math.isfinite(spacing):
        sys.exit("instance_field.py: N must be >= 1 and SPACING finite")
    doc, binary = read_model(model)
    base = os.path.splitext(out)[0]
    if binary is not None:
        with open(base + ".bin", "wb") as f:
            f.write(binary)
        doc["buffers"][0]["uri"] = os.path.basename(base) + ".bin"
    translations = grid_translations(count, spacing)
    with open(base + ".instances.bin", "wb") as f:
        f.write(translations)
    doc["buffers"].append({"uri": os.path.basename(base) + ".instances.bin", "byteLength": len(translations)})
    doc.setdefault("bufferViews", []).append({"buffer": len(doc["buffers"]) - 1, "byteLength": len(translations)})
    doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126,
                             "count": count, "type": "VEC3"})
    accessor = len(doc["accessors"]) - 1
    # Every mesh node gets the instances; the nodes keep their own transforms, not their parents' (fine for models whose mesh nodes are roots).
    roots = []
    for n in mesh_nodes(doc):
        node = dict(doc["nodes"][n])
        node.pop("children", None)
        node["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": accessor}}}
        doc["nodes"].append(node)
        roots.append(len(doc["nodes"]) - 1)
    doc["scenes"] = [{"nodes": roots}]
    doc["scene"] = 0
    doc.pop("cameras", None)
    for node in doc["nodes"]:
        node.pop("camera", None)
    used = doc.setdefault("extensionsUsed", [])
    if "EXT_mesh_gpu_instancing" not in used:
        used.append("EXT_mesh_gpu_instancing")
    with open(out, "w") as f:
        json.dump(doc, f)


if __name__ == "__main__":
    main()
