#!/usr/bin/python3
"""Writes the fuzzers' seed corpora into tests/fuzz/corpus/<target>/ (docs/robustness.md).

Each seed is a small valid file of its format, laid out here byte by byte, so the fuzzers start from
inputs that reach deep into each reader. Run from anywhere: /usr/bin/python3 scripts/make_fuzz_seeds.py
"""
import base64, json, os, shutil, struct, zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, 'tests', 'fuzz', 'corpus')


def put(target, name, data):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), 'wb') as f:
        f.write(data if isinstance(data, bytes) else data.encode())


values = [float(i) for i in range(8)]  # a 2 x 2 x 2 volume

# Scenes: the reference scenes.
os.makedirs(os.path.join(CORPUS, 'fuzz_scene'), exist_ok=True)
for n in sorted(os.listdir(os.path.join(ROOT, 'reference_scenes'))):
    if n.endswith('.json'):
        shutil.copy(os.path.join(ROOT, 'reference_scenes', n), os.path.join(CORPUS, 'fuzz_scene', n))
# The several-volumes scene with the keys it does not use: a crop preset, a row-major matrix transform,
# the fast profile.
with open(os.path.join(ROOT, 'reference_scenes', 'two-volumes-clipped.json')) as f:
    scene = json.load(f)
scene['volumes'][0]['crop'] = {'planes': [-10, 10, -12, 12, -8, 8], 'regions': 'inverted-cross'}
scene['volumes'][1]['transform'] = [1, 0, 0, 6, 0, 2, 0, 4, 0, 0, 0.5, -4, 0, 0, 0, 1]
scene['render']['profile'] = 'fast'
with open(os.path.join(CORPUS, 'fuzz_scene', 'two-volumes-crop-matrix.json'), 'w') as f:
    json.dump(scene, f, indent=1)

# Nesting near the loader's depth limit (kMaxJsonDepth = 256; issue 18: 100,000 brackets crashed it;
# that input is tests/fuzz/regressions/fuzz_scene/deep-nesting-100000.json, replayed by CI).
put('fuzz_scene', 'deep-nesting-300.json',
    '{"volume": {"transfer": {"color": ' + '[' * 150 + '{"a": ' * 150 + '0' + '}' * 150 + ']' * 150 + '}}}')

# NRRD: raw little-endian float, big-endian short, ascii, gzip.
hdr = 'NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nspacings: 1 2 3\nendian: little\nencoding: raw\n\n'
put('fuzz_nrrd', 'float-raw.nrrd', hdr.encode() + struct.pack('<8f', *values))
hdr = 'NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (1,2,3)\nendian: big\nencoding: raw\n\n'
put('fuzz_nrrd', 'short-big.nrrd', hdr.encode() + struct.pack('>8h', *range(8)))
put('fuzz_nrrd', 'ascii.nrrd', 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n0 1 2 3 4 5 6 7\n')
import gzip
put('fuzz_nrrd', 'gzip.nrrd', b'NRRD0004\ntype: double\ndimension: 3\nsizes: 2 2 2\nendian: little\nencoding: gzip\n\n' +
    gzip.compress(struct.pack('<8d', *values)))

# NIfTI-1 (.nii): 348-byte header, 4 bytes of extension flag, float32 data at vox_offset 352.
h = bytearray(348)
struct.pack_into('<i', h, 0, 348)                       # sizeof_hdr
struct.pack_into('<8h', h, 40, 3, 2, 2, 2, 1, 1, 1, 1)  # dim
struct.pack_into('<hh', h, 70, 16, 32)                  # datatype FLOAT32, bitpix
struct.pack_into('<8f', h, 76, 1, 1.5, 2, 2.5, 1, 1, 1, 1)  # pixdim
struct.pack_into('<f', h, 108, 352.0)                   # vox_offset
struct.pack_into('<ff', h, 112, 1.0, 0.0)               # scl_slope, scl_inter
struct.pack_into('<h', h, 254, 1)                       # sform_code
struct.pack_into('<4f', h, 280, 1.5, 0, 0, -3)          # srow_x
struct.pack_into('<4f', h, 296, 0, 2, 0, 4)             # srow_y
struct.pack_into('<4f', h, 312, 0, 0, 2.5, 5)           # srow_z
h[344:348] = b'n+1\0'
put('fuzz_nifti', 'float.nii', bytes(h) + b'\0\0\0\0' + struct.pack('<8f', *values))

# MetaImage with the data inline (.mha).
put('fuzz_metaimage', 'uchar.mha', 'ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementSpacing = 1 1 2\n'
    'Offset = 0 0 0\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n'.encode() + bytes(range(8)))
put('fuzz_metaimage', 'double-msb.mha', 'ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nBinaryDataByteOrderMSB = True\n'
    'ElementType = MET_DOUBLE\nElementDataFile = LOCAL\n'.encode() + struct.pack('>8d', *values))
put('fuzz_metaimage', 'compressed.mha', 'ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nCompressedData = True\n'
    'ElementType = MET_SHORT\nElementDataFile = LOCAL\n'.encode() + zlib.compress(struct.pack('<8h', *range(8))))

# VTK legacy structured points, ASCII and BINARY (big-endian).
put('fuzz_vtk', 'ascii.vtk', '# vtk DataFile Version 3.0\nseed\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n'
    'SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 8\nSCALARS s float 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n')
put('fuzz_vtk', 'binary.vtk', '# vtk DataFile Version 3.0\nseed\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n'
    'ASPECT_RATIO 1 2 3\nORIGIN 1 2 3\nPOINT_DATA 8\nSCALARS s unsigned_short\nLOOKUP_TABLE default\n'.encode()
    + struct.pack('>8H', *range(8)) + b'\n')

# VTK XML ImageData: base64 inline, and zlib-compressed appended raw data.
payload = struct.pack('<8f', *values)
b64 = base64.b64encode(struct.pack('<I', len(payload)) + payload).decode()
put('fuzz_vti', 'base64.vti', '<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" '
    'header_type="UInt32">\n<ImageData WholeExtent="0 1 0 1 0 1" Origin="0 0 0" Spacing="1 1 1">\n'
    '<Piece Extent="0 1 0 1 0 1"><PointData Scalars="s">\n'
    f'<DataArray type="Float32" Name="s" format="binary">{b64}</DataArray>\n'
    '</PointData></Piece></ImageData></VTKFile>\n')
comp = zlib.compress(payload)
block = struct.pack('<IIII', 1, len(payload), len(payload), len(comp)) + comp
put('fuzz_vti', 'zlib-appended.vti', ('<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0" '
    'byte_order="LittleEndian" header_type="UInt32" compressor="vtkZLibDataCompressor">\n'
    '<ImageData WholeExtent="0 1 0 1 0 1" Origin="0 0 0" Spacing="1 1 1">\n<Piece Extent="0 1 0 1 0 1">'
    '<PointData Scalars="s"><DataArray type="Float32" Name="s" format="appended" offset="0"/></PointData></Piece>'
    '</ImageData>\n<AppendedData encoding="raw">\n_').encode() + block + b'\n</AppendedData></VTKFile>\n')

# VolPack .den: 62-byte header (int16 fields, int32 length), u8 samples.
den = struct.pack('<h', 1) + struct.pack('<24h', *([0] * 24)) + struct.pack('<3h', 2, 2, 2) + struct.pack('<h', 0) + \
    struct.pack('<i', 8)
put('fuzz_den', 'little.den', den + bytes(range(8)))

# Meshes: a closed cube as OBJ and as ASCII PLY.
cube_v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
cube_f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6),
          (3, 0, 4), (3, 4, 7)]
put('fuzz_obj', 'cube.obj', ''.join(f'v {x} {y} {z}\n' for x, y, z in cube_v) +
    ''.join(f'f {a + 1} {b + 1} {c + 1}\n' for a, b, c in cube_f))
put('fuzz_ply', 'cube.ply', 'ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n'
    'property float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n' +
    ''.join(f'{x} {y} {z}\n' for x, y, z in cube_v) + ''.join(f'3 {a} {b} {c}\n' for a, b, c in cube_f))
# Issue 32: the bad-input classes, so the fuzzers start next to them (docs/robustness.md).
# Extreme doubles in numeric keys (each refused: 0 or a magnitude in [1e-100, 1e100]), a NUL, a key twice.
ml = {'volume': {'source': {'field': 'marschner-lobb', 'dims': [9, 9, 9]},
                 'transfer': {'opacity': [[0, 0], [1, 0.5]]}},
      'image': {'width': 8, 'height': 8}}
for name, patch in [('spacing-1e200', ('volume', 'spacing', [1e200, 1e200, 1e200])),
                    ('up-1e-200', ('camera', 'up', [1e-200, 1e-200, 0])),
                    ('step-1e-300', ('render', 'step', 1e-300)),
                    ('step-1e-90-world', ('render', 'step', 1e-90)),
                    ('unit-distance-5e-324', ('volume', 'transfer', {'opacity': [[0, 0], [1, 0.5]], 'opacity_unit_distance': 5e-324})),
                    ('radius-5e-324', ('volume', 'bounds', {'type': 'spherical', 'radius': [0, 5e-324]}))]:
    scene = json.loads(json.dumps(ml))
    scene.setdefault(patch[0], {})[patch[1]] = patch[2]
    if name == 'step-1e-90-world':
        scene['render']['step_units'] = 'world'
    put('fuzz_scene', f'extreme-{name}.json', json.dumps(scene))
put('fuzz_scene', 'nul-then-bytes.json', json.dumps(ml) + '\0garbage')
put('fuzz_scene', 'duplicate-key.json', '{"image": {"width": 8, "width": 9}, "volume": {"source": {"field": "sphere", "dims": [4, 4, 4]}}}')
# NIfTI as stored: pixdim 0, vox_offset inside the header, a NaN slope, a NaN sform entry.
for name, (fmt, off, v) in {'pixdim-0': ('<f', 80, 0.0), 'vox-offset-10': ('<f', 108, 10.0),
                            'slope-nan': ('<f', 112, float('nan')), 'sform-nan': ('<f', 300, float('nan'))}.items():
    b = bytearray(h)
    struct.pack_into(fmt, b, off, v)
    put('fuzz_nifti', f'{name}.nii', bytes(b) + b'\0\0\0\0' + struct.pack('<8f', *values))
# Headers that contradict themselves.
put('fuzz_metaimage', 'offset-vs-origin.mha', 'NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nOffset = 0 0 0\n'
    'Origin = 1 0 0\nElementDataFile = LOCAL\n' + ''.join(chr(i) for i in range(8)))
put('fuzz_vtk', 'dimensions-twice.vtk', '# vtk DataFile Version 3.0\nseed\nASCII\nDATASET STRUCTURED_POINTS\n'
    'DIMENSIONS 2 2 2\nDIMENSIONS 2 2 2\nPOINT_DATA 8\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n')
put('fuzz_nrrd', 'space-directions-1e300.nrrd', 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n'
    'space directions: (1e300,0,0) (0,1,0) (0,0,1)\nencoding: ascii\n\n0 1 2 3 4 5 6 7\n')
# OBJ: a NaN coordinate, a 20-digit index, an mtllib (never opened).
put('fuzz_obj', 'nan-vertex.obj', 'v nan 0 0\n' + ''.join(f'v {x} {y} {z}\n' for x, y, z in cube_v[1:]) +
    ''.join(f'f {a + 1} {b + 1} {c + 1}\n' for a, b, c in cube_f))
put('fuzz_obj', 'huge-index.obj', 'mtllib /dev/zero\n' + ''.join(f'v {x} {y} {z}\n' for x, y, z in cube_v) +
    'f 1 2 99999999999999999999\n')
# Tetrahedra (volume.bounds type "tetrahedra"): the reference scenes' files (ASCII, both cell layouts),
# Volumizer's cube as BINARY in both layouts, and a FIELD + METADATA block before the points.
for n in ('tetra-box.vtk', 'tetra-icosphere.vtk', 'tetra-shell.vtk'):
    with open(os.path.join(ROOT, 'reference_scenes', 'data', n), 'rb') as f:
        put('fuzz_tetrahedra', n, f.read())
cube_t = [(0, 2, 5, 7), (3, 2, 0, 7), (1, 2, 5, 0), (2, 7, 6, 5), (5, 4, 0, 7)]
points = struct.pack('>24d', *[c for v in cube_v for c in v])
put('fuzz_tetrahedra', 'cube-binary.vtk', b'# vtk DataFile Version 3.0\ncube\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 double\n' +
    points + b'\nCELLS 5 25\n' + b''.join(struct.pack('>5i', 4, *t) for t in cube_t) + b'\nCELL_TYPES 5\n' +
    struct.pack('>5i', *[10] * 5) + b'\n')
put('fuzz_tetrahedra', 'cube-binary-51.vtk', b'# vtk DataFile Version 5.1\ncube\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 float\n' +
    struct.pack('>24f', *[c for v in cube_v for c in v]) + b'\nCELLS 6 20\nOFFSETS vtktypeint64\n' +
    struct.pack('>6q', *range(0, 24, 4)) + b'\nCONNECTIVITY vtktypeint32\n' + b''.join(struct.pack('>4i', *t) for t in cube_t) +
    b'\nCELL_TYPES 5\n' + struct.pack('>5i', *[10] * 5) + b'\n')
put('fuzz_tetrahedra', 'cube-field.vtk', '# vtk DataFile Version 2.0\ncube\nASCII\nDATASET UNSTRUCTURED_GRID\n'
    'FIELD FieldData 1\nTIME 1 1 double\n0.5\nMETADATA\nINFORMATION 0\n\nPOINTS 8 double\n' +
    ''.join(f'{x} {y} {z}\n' for x, y, z in cube_v) + 'CELLS 5 25\n' + ''.join(f'4 {a} {b} {c} {d}\n' for a, b, c, d in cube_t) +
    'CELL_TYPES 5\n10 10 10 10 10\nCELL_DATA 5\nSCALARS r int 1\nLOOKUP_TABLE default\n1 2 3 4 5\n')
print('seeds written to', CORPUS)
