#!/usr/bin/env python3
# Writes a .glb (one buffer, the GLB binary chunk) whose indexed triangle primitives are replaced by non-indexed ones: every triangle
# its own three vertices, attributes copied (what some exporters write). usage: IN.glb OUT.glb
import json, struct, sys
data = open(sys.argv[1], 'rb').read()
jlen = struct.unpack_from('<I', data, 12)[0]
g = json.loads(data[20:20 + jlen])
bin_off = 20 + jlen
blen = struct.unpack_from('<I', data, bin_off)[0]
binbuf = bytearray(data[bin_off + 8:bin_off + 8 + blen])
SIZES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
COMPS = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4, 'MAT4': 16}
def elem(acc):
    return SIZES[acc['componentType']] * COMPS[acc['type']]
def read(ai):
    acc = g['accessors'][ai]; bv = g['bufferViews'][acc['bufferView']]
    size = elem(acc); stride = bv.get('byteStride', size)
    base = bv.get('byteOffset', 0) + acc.get('byteOffset', 0)
    return [bytes(binbuf[base + i * stride: base + i * stride + size]) for i in range(acc['count'])]
def indices(ai):
    acc = g['accessors'][ai]; fmt = {5121: 'B', 5123: 'H', 5125: 'I'}[acc['componentType']]
    return [struct.unpack('<' + fmt, e)[0] for e in read(ai)]
def append(elems, acc):
    while len(binbuf) % 4: binbuf.append(0)
    off = len(binbuf); binbuf.extend(b''.join(elems))
    g['bufferViews'].append({'buffer': 0, 'byteOffset': off, 'byteLength': len(binbuf) - off})
    new = {'bufferView': len(g['bufferViews']) - 1, 'componentType': acc['componentType'],
           'count': len(elems), 'type': acc['type']}
    for k in ('min', 'max', 'normalized'):
        if k in acc: new[k] = acc[k]
    g['accessors'].append(new)
    return len(g['accessors']) - 1
for mesh in g['meshes']:
    for prim in mesh['primitives']:
        if prim.get('mode', 4) != 4 or 'indices' not in prim: continue
        idx = indices(prim.pop('indices'))
        for name, ai in list(prim['attributes'].items()):
            src = read(ai)
            prim['attributes'][name] = append([src[i] for i in idx], g['accessors'][ai])
while len(binbuf) % 4: binbuf.append(0)
g['buffers'][0]['byteLength'] = len(binbuf)
js = json.dumps(g).encode(); js += b' ' * (-len(js) % 4)
out = struct.pack('<III', 0x46546C67, 2, 28 + len(js) + len(binbuf))
out += struct.pack('<II', len(js), 0x4E4F534A) + js + struct.pack('<II', len(binbuf), 0x004E4942) + bytes(binbuf)
open(sys.argv[2], 'wb').write(out)
